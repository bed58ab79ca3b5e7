//! Triangles between key-hair roots, for barycentric interpolation.
//!
//! The roots (rest shape, head frame) are projected stereographically from
//! below their centre onto a plane — a scalp cap becomes a disc — and
//! triangulated there (Delaunay, by `delaunator`). Triangles whose longest edge
//! on the head is more than three times the median edge are dropped, so open
//! regions (the face) are not bridged.

use glam::Vec3;

use crate::sim::SimState;

/// The area of triangle `t` of `roots` (their units squared).
pub fn triangle_area(roots: &[Vec3], t: &[u32; 3]) -> f32 {
    let [a, b, c] = t.map(|i| roots[i as usize]);
    0.5 * (b - a).cross(c - a).length()
}

/// Triangles of key-hair indices (at most 2 per key hair).
pub fn root_triangles(rest: &SimState) -> Vec<[u32; 3]> {
    let roots: Vec<Vec3> = (0..rest.strands).map(|s| rest.rest[s * rest.points].truncate()).collect();
    if roots.len() < 3 {
        return Vec::new();
    }
    let (lo, hi) =
        roots.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).max_element().max(1e-6);
    // Below the middle of the roots: a cap of roots then subtends less than a sphere.
    let center = 0.5 * (lo + hi) - Vec3::Y * (0.25 * size);
    let points: Vec<delaunator::Point> = roots
        .iter()
        .map(|r| {
            let d = (*r - center).normalize_or(Vec3::Y);
            let k = 1.0 / (1.0 + d.y).max(1e-3);
            delaunator::Point { x: f64::from(d.x * k), y: f64::from(d.z * k) }
        })
        .collect();
    let t = delaunator::triangulate(&points);
    let tris: Vec<[u32; 3]> = t.triangles.chunks_exact(3).map(|c| [c[0] as u32, c[1] as u32, c[2] as u32]).collect();
    let longest = |tri: &[u32; 3]| {
        let p = tri.map(|i| roots[i as usize]);
        (p[0] - p[1]).length().max((p[1] - p[2]).length()).max((p[2] - p[0]).length())
    };
    let mut edges: Vec<f32> = tris.iter().map(longest).collect();
    edges.sort_by(f32::total_cmp);
    let median = edges.get(edges.len() / 2).copied().unwrap_or(0.0);
    tris.into_iter().filter(|t| longest(t) <= 3.0 * median).collect()
}
