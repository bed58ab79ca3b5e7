//! Resampling strands to a fixed point count by arc length.

use super::{Attributes, Groom, MAX_POINTS_PER_STRAND};
use crate::error::{Error, Result};

/// Where on a polyline the arc-length parameter `s` falls: segment index and
/// the fraction along it.
fn locate(cumulative: &[f32], s: f32) -> (usize, f32) {
    let last = cumulative.len() - 2;
    // First segment whose end lies at or beyond s.
    let seg = cumulative[1..].partition_point(|&c| c < s).min(last);
    let (a, b) = (cumulative[seg], cumulative[seg + 1]);
    let t = if b > a { ((s - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
    (seg, t)
}

impl Groom {
    /// Every strand resampled to `points` points equally spaced along its length
    /// (root and tip kept exactly); attributes are interpolated linearly.
    pub fn resampled(&self, points: usize) -> Result<Groom> {
        if !(2..=MAX_POINTS_PER_STRAND).contains(&points) {
            return Err(Error::param("points per strand", points, format!("2..={MAX_POINTS_PER_STRAND}")));
        }
        let total = points.checked_mul(self.strand_count()).filter(|&t| t <= super::MAX_POINTS).ok_or(
            Error::TooManyPoints { count: (points as u64) * self.strand_count() as u64, max: super::MAX_POINTS as u64 },
        )?;
        let mut positions = Vec::with_capacity(total);
        let mut attributes = Attributes {
            thickness: self.thickness.as_ref().map(|_| Vec::with_capacity(total)),
            transparency: self.transparency.as_ref().map(|_| Vec::with_capacity(total)),
            colors: self.colors.as_ref().map(|_| Vec::with_capacity(total)),
        };
        let mut cumulative = Vec::new();
        for strand in 0..self.strand_count() {
            let range = self.strand_range(strand);
            let src = &self.positions[range.clone()];
            cumulative.clear();
            cumulative.push(0.0f32);
            for w in src.windows(2) {
                let next = cumulative[cumulative.len() - 1] + (w[1] - w[0]).length();
                cumulative.push(next);
            }
            let length = cumulative[cumulative.len() - 1];
            for k in 0..points {
                let (seg, t) = if k == 0 {
                    (0, 0.0)
                } else if k == points - 1 {
                    (src.len() - 2, 1.0)
                } else {
                    locate(&cumulative, length * k as f32 / (points - 1) as f32)
                };
                let (i, j) = (range.start + seg, range.start + seg + 1);
                let lerp_f = |v: &[f32]| v[i] + (v[j] - v[i]) * t;
                positions.push(if t == 1.0 { self.positions[j] } else { self.positions[i].lerp(self.positions[j], t) });
                if let (Some(dst), Some(src)) = (&mut attributes.thickness, &self.thickness) {
                    dst.push(lerp_f(src));
                }
                if let (Some(dst), Some(src)) = (&mut attributes.transparency, &self.transparency) {
                    dst.push(lerp_f(src));
                }
                if let (Some(dst), Some(src)) = (&mut attributes.colors, &self.colors) {
                    dst.push(src[i].lerp(src[j], t));
                }
            }
        }
        let counts = vec![points as u32; self.strand_count()];
        Groom::with_attributes(positions, &counts, attributes)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn bent() -> Groom {
        // An L-shaped strand of length 3 with uneven segments, and a straight one.
        Groom::from_strands(&[
            vec![Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::X * 2.0, Vec3::new(2.0, 1.0, 0.0)],
            vec![Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 2.0)],
        ])
        .expect("valid")
    }

    #[test]
    fn resampling_spaces_points_evenly_and_keeps_ends() {
        let g = bent().resampled(7).expect("resample");
        assert_eq!(g.strand_count(), 2);
        assert_eq!(g.uniform_points_per_strand(), Some(7));
        let s = g.strand(0);
        assert_eq!(s[0], Vec3::ZERO);
        assert_eq!(s[6], Vec3::new(2.0, 1.0, 0.0));
        // Arc length 3 in 6 segments: points at 0, 0.5, 1, 1.5, 2 along x, then up the y leg.
        let expected = [0.0, 0.5, 1.0, 1.5, 2.0];
        for (k, x) in expected.iter().enumerate() {
            assert!((s[k] - Vec3::new(*x, 0.0, 0.0)).length() < 1e-6, "point {k}: {:?}", s[k]);
        }
        assert!((s[5] - Vec3::new(2.0, 0.5, 0.0)).length() < 1e-6);
        // Length of a polyline through points of the original is preserved here
        // because no corner is cut (the corner at arc length 2 is a sample).
        assert!((g.strand_length(0) - 3.0).abs() < 1e-5);
    }

    #[test]
    fn resampling_rejects_bad_counts() {
        assert!(matches!(bent().resampled(1), Err(Error::InvalidParameter { .. })));
        assert!(matches!(bent().resampled(MAX_POINTS_PER_STRAND + 1), Err(Error::InvalidParameter { .. })));
    }

    #[test]
    fn resampling_interpolates_attributes() {
        let g = Groom::with_attributes(
            vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            &[3],
            Attributes {
                thickness: Some(vec![1.0, 2.0, 3.0]),
                transparency: None,
                colors: Some(vec![Vec3::ZERO, Vec3::ONE, Vec3::ONE]),
            },
        )
        .expect("valid");
        let r = g.resampled(5).expect("resample");
        let t = r.thickness().expect("thickness kept");
        assert!(t.iter().zip([1.0, 1.5, 2.0, 2.5, 3.0]).all(|(a, b)| (a - b).abs() < 1e-6), "{t:?}");
        assert!(r.transparency().is_none());
        assert!((r.colors().expect("colors")[1] - Vec3::splat(0.5)).length() < 1e-6);
    }
}
