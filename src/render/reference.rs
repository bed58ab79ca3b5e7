//! CPU references of the render passes (test oracles).

use glam::Vec3;

/// The key point `idx` of a strand, mirrored beyond root and tip as the
/// smoothing pass does.
fn control_point(points: &[Vec3], idx: isize) -> Vec3 {
    let n = points.len() as isize;
    if idx < 0 {
        2.0 * points[0] - points[1]
    } else if idx >= n {
        2.0 * points[(n - 1) as usize] - points[(n - 2) as usize]
    } else {
        points[idx as usize]
    }
}

/// Smoothed vertices (position, unit tangent) of one key hair with `level`
/// segments per key segment: (points − 1)·level + 1 of them, root to tip.
pub fn smooth_strand(points: &[Vec3], level: u32) -> Vec<(Vec3, Vec3)> {
    let segs = points.len() - 1;
    let mut out = Vec::with_capacity(segs * level as usize + 1);
    for seg in 0..segs {
        let c: Vec<Vec3> = (0..4).map(|k| control_point(points, seg as isize - 1 + k)).collect();
        let last = if seg + 1 == segs { level } else { level - 1 };
        for j in 0..=last {
            let u = j as f32 / level as f32;
            let v = 1.0 - u;
            let (u2, u3) = (u * u, u * u * u);
            let b = [v * v * v, 3.0 * u3 - 6.0 * u2 + 4.0, -3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0, u3].map(|x| x / 6.0);
            let db = [-v * v, 3.0 * u2 - 4.0 * u, -3.0 * u2 + 2.0 * u + 1.0, u2].map(|x| x * 0.5);
            let p = c[0] * b[0] + c[1] * b[1] + c[2] * b[2] + c[3] * b[3];
            let d = c[0] * db[0] + c[1] * db[1] + c[2] * db[2] + c[3] * db[3];
            out.push((p, d.try_normalize().unwrap_or(Vec3::NEG_Y)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_passes_through_root_and_tip_with_end_tangents() {
        let pts = [Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0), Vec3::new(1.0, -2.0, 0.0), Vec3::new(1.0, -3.0, 1.0)];
        let s = smooth_strand(&pts, 4);
        assert_eq!(s.len(), 13);
        assert!((s[0].0 - pts[0]).length() < 1e-6);
        assert!((s[12].0 - pts[3]).length() < 1e-6);
        assert!((s[0].1 - (pts[1] - pts[0]).normalize()).length() < 1e-6);
        assert!((s[12].1 - (pts[3] - pts[2]).normalize()).length() < 1e-6);
        // A straight strand stays straight and evenly spaced.
        let line: Vec<Vec3> = (0..5).map(|i| Vec3::X * i as f32).collect();
        let s = smooth_strand(&line, 3);
        for (k, (p, t)) in s.iter().enumerate() {
            assert!((*p - Vec3::X * (k as f32 / 3.0)).length() < 1e-5, "{k}: {p}");
            assert!((*t - Vec3::X).length() < 1e-6);
        }
    }
}
