//! Choosing the guides of a dense groom: the strands simulated, which every
//! strand drawn follows (see `render::followers`).

use glam::Vec3;

use super::Groom;
use crate::error::{Error, Result};

/// The most strands × guides steps [`spread`] takes (about ten seconds).
pub const MAX_WORK: u64 = 10_000_000_000;

/// `count` strands of `groom` whose roots spread evenly over its roots:
/// farthest-point sampling (each next guide the root farthest from every
/// guide so far), from the root nearest the roots' centroid; ties go to the
/// lower index, so the choice is the same every run; strands sharing a root
/// are told apart. Indices in strand order. Refused beyond [`MAX_WORK`].
pub fn spread(groom: &Groom, count: usize) -> Result<Vec<usize>> {
    let n = groom.strand_count();
    if !(1..=n).contains(&count) {
        return Err(Error::param("guides", count, format!("1..={n} (the groom's strands)")));
    }
    if (n as u64) * (count as u64) > MAX_WORK {
        return Err(Error::param(
            "guides",
            count,
            format!(
                "at most {} for {n} strands (choosing them takes strands × guides steps; mark guides in the file or \
                 ask for fewer)",
                MAX_WORK / n as u64
            ),
        ));
    }
    let roots: Vec<Vec3> = (0..n).map(|s| groom.strand(s)[0]).collect();
    let centroid = roots.iter().copied().sum::<Vec3>() / n as f32;
    let first = nearest(&roots, centroid);
    let mut chosen = vec![first];
    let mut gap: Vec<f32> = roots.iter().map(|r| r.distance_squared(roots[first])).collect();
    // A chosen root is never chosen again, even where roots coincide.
    gap[first] = -1.0;
    while chosen.len() < count {
        let next = (0..n).fold(0, |best, s| if gap[s] > gap[best] { s } else { best });
        chosen.push(next);
        for (g, r) in gap.iter_mut().zip(&roots) {
            *g = g.min(r.distance_squared(roots[next]));
        }
        gap[next] = -1.0;
    }
    chosen.sort_unstable();
    Ok(chosen)
}

/// The strands `marks` marks (a file's `groom_guide`), refused when none is.
pub fn marked(marks: &[bool]) -> Result<Vec<usize>> {
    let guides: Vec<usize> = marks.iter().enumerate().filter(|&(_, &m)| m).map(|(s, _)| s).collect();
    if guides.is_empty() {
        return Err(Error::param("guides", "none marked", "at least one strand marked as a guide"));
    }
    Ok(guides)
}

fn nearest(points: &[Vec3], to: Vec3) -> usize {
    (0..points.len()).fold(
        0,
        |best, s| {
            if points[s].distance_squared(to) < points[best].distance_squared(to) {
                s
            } else {
                best
            }
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_guides_cover_the_roots_evenly() {
        // A 10 × 10 grid of roots 1 cm apart: the centre-most root first, then
        // each farthest root — the four corners.
        let strands: Vec<Vec<Vec3>> = (0..100)
            .map(|i| {
                let r = Vec3::new((i % 10) as f32 * 0.01, 0.0, (i / 10) as f32 * 0.01);
                vec![r, r - Vec3::Y * 0.1]
            })
            .collect();
        let groom = Groom::from_strands(&strands).expect("groom");
        let g = spread(&groom, 5).expect("guides");
        // The centre-most root (index 44, at 4 cm, 4 cm) and the corners.
        assert_eq!(g, vec![0, 9, 44, 90, 99]);
        // With 16 guides every root is within 2.5 cm of one (the grid is 9 cm
        // across: 4 × 4 even cells would leave at most 1.6 cm).
        let g = spread(&groom, 16).expect("guides");
        let worst = (0..100)
            .map(|s| g.iter().map(|&k| groom.strand(s)[0].distance(groom.strand(k)[0])).fold(f32::MAX, f32::min))
            .fold(0.0f32, f32::max);
        assert!(worst < 0.025, "a root {worst} m from every guide");
        assert!(spread(&groom, 0).is_err() && spread(&groom, 101).is_err());
        // Every root in one place: still distinct strands.
        let same = Groom::from_strands(&vec![vec![Vec3::ZERO, Vec3::NEG_Y]; 10]).expect("groom");
        assert_eq!(spread(&same, 4).expect("guides"), vec![0, 1, 2, 3]);
        assert_eq!(marked(&[false, true, true]).expect("marked"), vec![1, 2]);
        assert!(marked(&[false, false]).is_err());
    }
}
