//! A strand's smoothed shape and its offset frames on the CPU, as the
//! smoothing pass (`glsl/render/smooth.tese`) and `render.glsl` compute them:
//! followers are bound with these ([`super::followers`]), and the render
//! passes' CPU references (`render::reference`) re-export them; and how far
//! the hairs a drawn strand stands for spread, which the opacity maps' filter
//! follows.

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

/// Per key hair of `rest`, the normal of the plane its rest shape lies in
/// (head frame), the reference vector of its offset frames: root tangent ×
/// (tip − root), or any perpendicular of the root tangent for a straight hair.
pub fn rest_plane_normals(rest: &crate::sim::SimState) -> Vec<Vec3> {
    (0..rest.strands)
        .map(|s| {
            let base = s * rest.points;
            let root = rest.rest[base].truncate();
            let t0 = (rest.rest[base + 1].truncate() - root).normalize_or(Vec3::NEG_Y);
            let tip = rest.rest[base + rest.points - 1].truncate();
            t0.cross(tip - root).try_normalize().unwrap_or_else(|| t0.any_orthonormal_vector())
        })
        .collect()
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

/// The width the hairs of a drawn strand standing for `n` hairs spread over
/// where the drawn strands lie `spacing` apart: (1 − 1/n) × spacing (none for
/// one hair). The transparent bands (`reference::strand_band`) and the opacity maps'
/// filter reach follow it.
pub fn strand_spread(n: f32, spacing: f32) -> f32 {
    (1.0 - 1.0 / n.max(1.0)) * spacing
}
