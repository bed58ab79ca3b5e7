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

/// The stable clump coordinate of interpolated hair `hair` of key hair `key`,
/// uniform in the unit disk (as `clump_coordinate` in `render.glsl`).
pub fn clump_coordinate(key: u32, hair: u32) -> glam::Vec2 {
    let seed = key.wrapping_mul(64).wrapping_add(hair);
    let r = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x9e37_79b9)).sqrt();
    let a = std::f32::consts::TAU * crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x7f4a_7c15));
    glam::Vec2::new(r * a.cos(), r * a.sin())
}

/// Barycentric weights of hair `hair` of scalp triangle `tri`, as
/// `barycentric_weights` in `render.glsl`.
pub fn barycentric_weights(tri: u32, hair: u32) -> Vec3 {
    let seed = tri.wrapping_mul(64).wrapping_add(hair);
    let r1 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x51ed_270b)).sqrt();
    let r2 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x2545_f491));
    let u = 1.0 - r1;
    let v = r1 * (1.0 - r2);
    Vec3::new(u, v, 1.0 - u - v)
}

/// The offset frame (B1, B2) of a key vertex with unit tangent `t` and reference
/// vector `reference` (world), as `key_frame` in `render.glsl`.
pub fn key_frame(t: Vec3, reference: Vec3) -> (Vec3, Vec3) {
    let mut r = reference - reference.dot(t) * t;
    if r.length() < 1e-4 {
        let any = if t.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        r = any - any.dot(t) * t;
    }
    let b1 = r.normalize();
    (b1, t.cross(b1))
}

/// Bertails et al.'s light-oriented density map (2005), the CPU reference of
/// density-volume shadows: `particles` splatted into cubic cells of side `ds` in a
/// frame whose first axis is the light's direction of travel `light_dir`;
/// transmittance at each of `points` = exp(−σ · Σ N / ds²) over the cells of its
/// column strictly before its own cell along the light (N particles per cell, so
/// Σ N / ds² is the particles per area crossed, ∫ particle density ds). The counts
/// are box-filtered over (2·`filter` + 1)² neighbouring columns, the map's filtering
/// step, which hides where the particle lattice happens to fall on the cells.
pub fn light_oriented_transmittance(
    particles: &[Vec3],
    light_dir: Vec3,
    cross_section: f32,
    ds: f32,
    filter: i64,
    points: &[Vec3],
) -> Vec<f32> {
    let x = light_dir.normalize();
    let helper = if x.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let y = x.cross(helper).normalize();
    let z = x.cross(y);
    let cell = |p: Vec3| [p.dot(x), p.dot(y), p.dot(z)].map(|c| (c / ds).floor() as i64);
    let mut columns: std::collections::HashMap<(i64, i64), Vec<i64>> = std::collections::HashMap::new();
    for &p in particles {
        let [i, j, k] = cell(p);
        columns.entry((j, k)).or_default().push(i);
    }
    points
        .iter()
        .map(|&q| {
            let [i, j, k] = cell(q);
            let mut before = 0;
            for dj in -filter..=filter {
                for dk in -filter..=filter {
                    let column = columns.get(&(j + dj, k + dk));
                    before += column.map_or(0, |c| c.iter().filter(|&&ci| ci < i).count());
                }
            }
            let columns_averaged = ((2 * filter + 1) * (2 * filter + 1)) as f32;
            (-cross_section * before as f32 / columns_averaged / (ds * ds)).exp()
        })
        .collect()
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
