//! Roots bound to a scalp mesh: each strand's root is the nearest point of
//! one triangle, kept as the triangle and its barycentric weights, so that the
//! root can be found again on the same mesh deformed (a skinned scalp).

use glam::Vec3;

use super::mesh::TriMesh;
use crate::error::{Error, Result};

/// A root's place on a mesh: a triangle and barycentric weights (summing to 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootBinding {
    /// Index into the mesh's triangles.
    pub triangle: u32,
    /// Weights of its three corners.
    pub weights: [f32; 3],
}

impl RootBinding {
    /// The bound point on the mesh whose vertices are `positions` (the mesh
    /// bound to, or the same triangles deformed).
    pub fn point(&self, triangles: &[[u32; 3]], positions: &[Vec3]) -> Vec3 {
        let t = triangles[self.triangle as usize];
        (0..3).map(|k| positions[t[k] as usize] * self.weights[k]).sum()
    }
}

/// Binds every root to the nearest point of `mesh`. A root farther than
/// `tolerance` (in the mesh's units) from the mesh is refused, the error
/// naming the strand and its distance.
pub fn bind_roots(roots: &[Vec3], mesh: &TriMesh, tolerance: f32) -> Result<Vec<RootBinding>> {
    let grid = TriangleGrid::new(mesh, tolerance)?;
    roots
        .iter()
        .enumerate()
        .map(|(s, &root)| {
            if !root.is_finite() {
                return Err(Error::param("root", format!("strand {s} at {root}"), "finite"));
            }
            match grid.nearest(root) {
                Some(n) => Ok(n.binding),
                None => Err(far(s, distance_to(mesh, root), tolerance)),
            }
        })
        .collect()
}

/// The nearest point of a mesh to a query: its place and how far it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// The triangle and barycentric weights of the point.
    pub binding: RootBinding,
    /// The point.
    pub point: Vec3,
    /// Its distance from the query, in the mesh's units.
    pub distance: f32,
}

/// A mesh's triangles bucketed on a grid of cells at least `radius` wide, to
/// find the nearest point of the mesh within `radius` of a query by looking
/// only at the triangles near it.
pub struct TriangleGrid<'m> {
    mesh: &'m TriMesh,
    radius: f32,
    lo: Vec3,
    cell: f32,
    dims: Vec3,
    cells: Vec<Vec<u32>>,
}

impl<'m> TriangleGrid<'m> {
    /// Buckets `mesh` for queries within `radius` (in the mesh's units; finite, > 0).
    pub fn new(mesh: &'m TriMesh, radius: f32) -> Result<Self> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::param("nearest-point radius", radius, "finite and > 0"));
        }
        let (lo, hi) = mesh.bounds();
        let lo = lo - Vec3::splat(radius);
        let span = hi - lo + Vec3::splat(radius);
        // About 32 cells along the longest side, none narrower than the radius.
        let cell = (span.max_element() / 32.0).max(radius);
        let dims = (span / cell).ceil().max(Vec3::ONE);
        let [nx, ny, nz] = dims.to_array().map(|n| n as usize);
        let mut grid = TriangleGrid { mesh, radius, lo, cell, dims, cells: vec![Vec::new(); nx * ny * nz] };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let c = tri.map(|v| mesh.positions[v as usize]);
            let a = grid.cell_of(c[0].min(c[1]).min(c[2]) - Vec3::splat(radius));
            let b = grid.cell_of(c[0].max(c[1]).max(c[2]) + Vec3::splat(radius));
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        let i = grid.index([x, y, z]);
                        grid.cells[i].push(t as u32);
                    }
                }
            }
        }
        Ok(grid)
    }

    fn cell_of(&self, p: Vec3) -> [usize; 3] {
        let c = ((p - self.lo) / self.cell).floor().max(Vec3::ZERO).min(self.dims - Vec3::ONE);
        c.to_array().map(|x| x as usize)
    }

    fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        let [nx, ny, _] = self.dims.to_array().map(|n| n as usize);
        (z * ny + y) * nx + x
    }

    /// The nearest point of the mesh to `p` when one lies within the radius.
    pub fn nearest(&self, p: Vec3) -> Option<Nearest> {
        let inside = p.is_finite() && p.cmpge(self.lo).all() && p.cmple(self.lo + self.dims * self.cell).all();
        if !inside {
            return None;
        }
        self.cells[self.index(self.cell_of(p))]
            .iter()
            .map(|&t| {
                let [a, b, c] = self.mesh.triangles[t as usize].map(|v| self.mesh.positions[v as usize]);
                let (point, weights) = closest_on_triangle(p, a, b, c);
                Nearest { binding: RootBinding { triangle: t, weights }, point, distance: p.distance(point) }
            })
            .filter(|n| n.distance <= self.radius)
            .min_by(|x, y| x.distance.total_cmp(&y.distance))
    }
}

fn far(strand: usize, distance: f32, tolerance: f32) -> Error {
    Error::param(
        "root",
        format!("strand {strand}, {distance} from the scalp"),
        format!("within {tolerance} of the scalp mesh"),
    )
}

/// The distance from `p` to the nearest point of `mesh`, every triangle tried
/// (for the error of a root too far for the grid).
fn distance_to(mesh: &TriMesh, p: Vec3) -> f32 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            p.distance(closest_on_triangle(p, a, b, c).0)
        })
        .fold(f32::INFINITY, f32::min)
}

/// The point of triangle `a b c` nearest `p`, and its barycentric weights
/// (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom.abs() < f32::MIN_POSITIVE {
        return (a, [1.0, 0.0, 0.0]); // a degenerate triangle: its first corner
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Roots on, above and beside a unit sphere mesh: bound within the
    /// tolerance to the point they touch (computed here from the sphere's
    /// triangles by brute force), and the one too far named.
    #[test]
    fn roots_bind_to_the_nearest_point_and_far_ones_are_named() {
        let mesh = TriMesh::uv_sphere(Vec3::ZERO, 0.1, 12, 16).expect("sphere");
        let roots: Vec<Vec3> = (0..40)
            .map(|i| {
                let a = i as f32 * 0.37;
                Vec3::new(a.cos() * 0.6, 0.8 - 0.03 * i as f32, a.sin() * 0.6).normalize()
                    * (0.1 + 0.002 * (i % 3) as f32)
            })
            .collect();
        let bound = bind_roots(&roots, &mesh, 0.01).expect("bound");
        for (s, (root, b)) in roots.iter().zip(&bound).enumerate() {
            let got = b.point(&mesh.triangles, &mesh.positions);
            let brute = (0..mesh.triangles.len())
                .map(|t| {
                    let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
                    root.distance(closest_on_triangle(*root, a, b, c).0)
                })
                .fold(f32::MAX, f32::min);
            assert!(
                (root.distance(got) - brute).abs() < 1e-6,
                "strand {s}: {} vs brute force {brute}",
                root.distance(got)
            );
            assert!((b.weights.iter().sum::<f32>() - 1.0).abs() < 1e-5 && b.weights.iter().all(|&w| w >= -1e-6));
        }
        let mut far_roots = roots.clone();
        far_roots[7] = Vec3::new(0.0, 0.2, 0.0);
        let err = bind_roots(&far_roots, &mesh, 0.01).expect_err("too far");
        assert!(err.to_string().contains("strand 7, 0.1"), "{err}");
        far_roots[7] = Vec3::new(0.0, f32::NAN, 0.0);
        assert!(bind_roots(&far_roots, &mesh, 0.01).is_err());
        assert!(bind_roots(&roots, &mesh, 0.0).is_err());
    }

    /// The barycentric point of each region of a triangle.
    #[test]
    fn the_nearest_point_covers_corners_edges_and_face() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let cases = [
            (Vec3::new(-1.0, -1.0, 0.0), a),
            (Vec3::new(2.0, -0.5, 0.0), b),
            (Vec3::new(-0.2, 3.0, 1.0), c),
            (Vec3::new(0.5, -1.0, 0.0), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(-1.0, 0.5, 0.0), Vec3::new(0.0, 0.5, 0.0)),
            (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0)),
            (Vec3::new(0.25, 0.25, 2.0), Vec3::new(0.25, 0.25, 0.0)),
        ];
        for (p, expected) in cases {
            let (q, w) = closest_on_triangle(p, a, b, c);
            assert!(q.distance(expected) < 1e-6, "{p}: {q} vs {expected}");
            assert!((a * w[0] + b * w[1] + c * w[2]).distance(q) < 1e-6);
        }
    }
}
