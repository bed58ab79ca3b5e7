//! Whole-groom changes of units, and the thickness a groom gives its strands.

use super::Groom;
use crate::error::{Error, Result};

impl Groom {
    /// The groom with every length multiplied by `factor`: the positions and the
    /// per-point thickness (a diameter, so a length); transparency and colors kept.
    /// `factor` must be finite and above 0, else [`Error::InvalidParameter`].
    pub fn scaled(&self, factor: f32) -> Result<Groom> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(Error::param("scale", factor, "finite and > 0"));
        }
        let mut attributes = self.attributes();
        if let Some(t) = &mut attributes.thickness {
            t.iter_mut().for_each(|v| *v *= factor);
        }
        let counts: Vec<u32> = self.offsets.windows(2).map(|w| w[1] - w[0]).collect();
        Groom::with_attributes(self.positions.iter().map(|p| *p * factor).collect(), &counts, attributes)
    }

    /// The groom moved rigidly by `m` (a rotation and a translation; thickness
    /// kept). Refuses a matrix that is not finite or not rigid (a scale or
    /// shear changes the strands' lengths: use [`Groom::scaled`]).
    pub fn rigidly_moved(&self, m: &glam::Mat4) -> Result<Groom> {
        let (scale, _, _) = m.to_scale_rotation_translation();
        let rigid = m.is_finite()
            && (scale - glam::Vec3::ONE).abs().max_element() < 1e-3
            && (m.row(3) - glam::Vec4::W).abs().max_element() == 0.0;
        if !rigid {
            return Err(Error::param("groom transform", format!("{m:?}"), "finite, a rotation and a translation"));
        }
        let counts: Vec<u32> = self.offsets.windows(2).map(|w| w[1] - w[0]).collect();
        Groom::with_attributes(
            self.positions.iter().map(|p| m.transform_point3(*p)).collect(),
            &counts,
            self.attributes(),
        )
    }

    /// Each strand's colour at its root and at its tip (its first and last
    /// point's), when the groom has per-point colours.
    pub fn end_colors(&self) -> Option<Vec<[glam::Vec3; 2]>> {
        let c = self.colors()?;
        Some(
            (0..self.strand_count())
                .map(|s| {
                    let r = self.strand_range(s);
                    [c[r.start], c[r.end - 1]]
                })
                .collect(),
        )
    }

    /// The thickness at the root and at the tip when the groom has per-point
    /// thickness: the median over the strands of their first and of their last
    /// point's thickness (the groom's length unit; robust to a few odd strands).
    pub fn end_thickness(&self) -> Option<(f32, f32)> {
        let t = self.thickness.as_ref()?;
        let ends = |pick: fn(&[u32]) -> u32| -> f32 {
            let mut v: Vec<f32> = self.offsets.windows(2).map(|w| t[pick(w) as usize]).collect();
            v.sort_by(f32::total_cmp);
            let mid = v.len() / 2;
            if v.len() % 2 == 1 {
                v[mid]
            } else {
                0.5 * (v[mid - 1] + v[mid])
            }
        };
        Some((ends(|w| w[0]), ends(|w| w[1] - 1)))
    }
}

#[cfg(test)]
mod tests {
    use super::super::Attributes;
    use super::*;
    use glam::Vec3;

    fn groom(thickness: Option<Vec<f32>>) -> Groom {
        let positions = (0..9).map(|i| Vec3::new((i / 3) as f32, (i % 3) as f32, 0.0)).collect();
        let attributes = Attributes { thickness, transparency: Some(vec![0.5; 9]), ..Attributes::default() };
        Groom::with_attributes(positions, &[3, 3, 3], attributes).expect("valid groom")
    }

    #[test]
    fn scaling_multiplies_positions_and_thickness_only() {
        let g = groom(Some((1..=9).map(|i| i as f32).collect())).scaled(0.01).expect("scaled");
        assert_eq!(g.strand(2)[1], Vec3::new(0.02, 0.01, 0.0));
        assert_eq!(g.thickness().expect("kept")[8], 9.0 * 0.01);
        assert_eq!(g.transparency().expect("kept")[0], 0.5);
        assert_eq!(g.offsets(), &[0, 3, 6, 9]);
        assert!(matches!(groom(None).scaled(f32::NAN), Err(Error::InvalidParameter { .. })));
        assert!(matches!(groom(None).scaled(0.0), Err(Error::InvalidParameter { .. })));
    }

    #[test]
    fn end_thickness_is_the_median_over_strands() {
        // Roots 1, 4, 15 (one odd strand): median 4; tips 3, 6, 0: median 3.
        let g = groom(Some(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 15.0, 8.0, 0.0]));
        assert_eq!(g.end_thickness(), Some((4.0, 3.0)));
        assert_eq!(groom(None).end_thickness(), None);
        let two = Groom::with_attributes(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
            &[2, 2],
            Attributes { thickness: Some(vec![1.0, 0.5, 3.0, 0.25]), ..Attributes::default() },
        )
        .expect("valid");
        assert_eq!(two.end_thickness(), Some((2.0, 0.375)));
    }
}
