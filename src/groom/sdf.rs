//! A signed distance field of a triangle mesh on a regular grid: the CPU
//! reference of the mesh collider.
//!
//! - **Grid:** cubic cells over the mesh's bounds plus a margin on every side;
//!   the longest axis gets `resolution` cells. Values live at the cell corners
//!   and are sampled trilinearly.
//! - **Distance:** at every grid point, the exact Euclidean distance to a
//!   triangle of the mesh, chosen by jump flooding. Points within 1.5 cells of a
//!   triangle's box start from the nearest such triangle; then each pass offers
//!   every point the triangles of its 26 neighbours `step` points away, each
//!   measured exactly, for steps of half the grid down to 1 and a last pass at
//!   1 again. A pass reads the previous pass's choices only (no order
//!   dependence), ties go to the lower triangle index, so the GPU build
//!   ([`crate::sim::MeshCollider`]) makes the same choices. `tests/sdf.rs`
//!   compares samples against a brute-force distance to every triangle, within
//!   half a voxel diagonal.
//! - **Sign:** ray parity along each of the three axes, with a majority vote.
//!   One ray per grid line and axis counts the crossings on each side of every
//!   point. An open mesh, such as a bust cut at the chest, misleads the rays
//!   that leave through its opening; the two other axes outvote them. A point
//!   within `SDF_FACE_BAND_CELLS` cells of
//!   its triangle whose closest point lies inside the face (not on an edge or
//!   a corner) takes the side of that face instead (read by the mesh's overall
//!   winding: its signed volume's sign): near the skin the rays
//!   also cross a character's inner parts (mouth, eyes, open cards), which
//!   mislead two axes as easily as one.
//!
//! Negative values are inside the mesh.

use glam::Vec3;

use super::mesh::TriMesh;
use crate::error::{Error, Result};

/// Most grid points per axis.
pub const MAX_SDF_RESOLUTION: u32 = crate::limits::SDF_MAX_RESOLUTION;

/// A mesh's signed distance field (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSdf {
    /// Position of grid point (0, 0, 0).
    pub origin: Vec3,
    /// Cell edge length (the mesh's units).
    pub cell: f32,
    /// Grid points per axis.
    pub dims: [u32; 3],
    /// Signed distances, x fastest, then y, then z.
    pub values: Vec<f32>,
}

impl MeshSdf {
    /// Builds the field of `mesh` with `resolution` cells along the longest axis of
    /// its bounds (8..=[`MAX_SDF_RESOLUTION`]), the bounds grown by `margin` on every
    /// side (≥ 0, the mesh's units; at least two cells are always added).
    pub fn build(mesh: &TriMesh, resolution: u32, margin: f32) -> Result<MeshSdf> {
        let (origin, cell, dims) = Self::placement(mesh, resolution, margin)?;
        let mut sdf = MeshSdf { origin, cell, dims, values: Vec::new() };
        let closest = sdf.closest_triangles(mesh);
        let inside = sdf.inside(mesh);
        let facing = facing(mesh);
        let mut values = Vec::with_capacity(closest.len());
        for (k, (&t, &inside)) in closest.iter().zip(&inside).enumerate() {
            // Unreachable: the seeds cover the mesh and the floods reach every point.
            let (d, side) = if t == u32::MAX {
                (f32::MAX, 0.0)
            } else {
                let [a, b, c] = mesh.corners(t as usize);
                let p = sdf.point(sdf.grid_point(k));
                let d = triangle_distance(p, a, b, c);
                let near = d < crate::limits::SDF_FACE_BAND_CELLS as f32 * sdf.cell;
                (d, if near { face_side(p, a, b, c) * facing } else { 0.0 })
            };
            let inside = if side != 0.0 { side < 0.0 } else { inside };
            values.push(if inside { -d } else { d });
        }
        sdf.values = values;
        Ok(sdf)
    }

    /// Where the grid of `mesh`'s field lies: origin, cell edge and points per axis
    /// (see [`MeshSdf::build`] for the arguments).
    pub fn placement(mesh: &TriMesh, resolution: u32, margin: f32) -> Result<(Vec3, f32, [u32; 3])> {
        Self::check_grid(resolution, margin)?;
        if let Some(bad) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::incompatible("mesh", format!("vertex {bad} is not finite")));
        }
        if mesh.triangles.is_empty() {
            return Err(Error::incompatible("mesh", "it has no triangles"));
        }
        let (lo, hi) = mesh.bounds();
        let extent = (hi - lo).max_element();
        if !(extent.is_finite() && extent > 0.0) {
            return Err(Error::incompatible("mesh", "its bounds are empty or not finite"));
        }
        let cell = (extent + 2.0 * margin) / (resolution - 4) as f32;
        let pad = Vec3::splat(margin + 2.0 * cell);
        let origin = lo - pad;
        let span = hi + pad - origin;
        let dims = [0, 1, 2].map(|a| ((span[a] / cell).ceil() as u32 + 1).min(MAX_SDF_RESOLUTION));
        Ok((origin, cell, dims))
    }

    /// Checks a resolution and a margin for [`MeshSdf::build`].
    pub fn check_grid(resolution: u32, margin: f32) -> Result<()> {
        if !(8..=MAX_SDF_RESOLUTION).contains(&resolution) {
            return Err(Error::param("sdf resolution", resolution, format!("8..={MAX_SDF_RESOLUTION}")));
        }
        if !(margin.is_finite() && (0.0..=1e3).contains(&margin)) {
            return Err(Error::param("sdf margin", margin, "0..=1000"));
        }
        Ok(())
    }

    /// The jump-flooding steps, largest first: half the grid's longest axis
    /// (rounded up to a power of two) down to 1, then 1 again.
    pub(crate) fn flood_steps(dims: [u32; 3]) -> Vec<u32> {
        let longest = dims.iter().copied().max().unwrap_or(1).max(2);
        let mut steps = Vec::new();
        let mut step = longest.next_power_of_two() / 2;
        while step >= 1 {
            steps.push(step);
            step /= 2;
        }
        steps.push(1);
        steps
    }

    pub(crate) fn point(&self, [x, y, z]: [u32; 3]) -> Vec3 {
        self.origin + Vec3::new(x as f32, y as f32, z as f32) * self.cell
    }

    pub(crate) fn grid_point(&self, k: usize) -> [u32; 3] {
        let k = k as u32;
        let [nx, ny, _] = self.dims;
        [k % nx, (k / nx) % ny, k / (nx * ny)]
    }

    fn index(&self, [x, y, z]: [u32; 3]) -> usize {
        ((z * self.dims[1] + y) * self.dims[0] + x) as usize
    }

    /// Per grid point, the closest triangle found by jump flooding (see the module
    /// docs). Every point has one: the seeds cover the mesh and floods reach all.
    pub(crate) fn closest_triangles(&self, mesh: &TriMesh) -> Vec<u32> {
        let [nx, ny, nz] = self.dims;
        let mut best = vec![(f32::INFINITY, u32::MAX); self.values_len()];
        // Seeds: the grid points within 1.5 cells of each triangle's box.
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let lo = a.min(b).min(c) - Vec3::splat(1.5 * self.cell);
            let hi = a.max(b).max(c) + Vec3::splat(1.5 * self.cell);
            let first = ((lo - self.origin) / self.cell).ceil().max(Vec3::ZERO);
            let last = ((hi - self.origin) / self.cell).floor();
            for z in first.z as u32..=(last.z as u32).min(nz - 1) {
                for y in first.y as u32..=(last.y as u32).min(ny - 1) {
                    for x in first.x as u32..=(last.x as u32).min(nx - 1) {
                        let g = [x, y, z];
                        let d = triangle_distance(self.point(g), a, b, c);
                        let slot = &mut best[self.index(g)];
                        if d < slot.0 {
                            *slot = (d, t as u32);
                        }
                    }
                }
            }
        }
        let mut ids: Vec<u32> = best.iter().map(|&(_, t)| t).collect();
        let mut next = ids.clone();
        for step in Self::flood_steps(self.dims) {
            for (k, out) in next.iter_mut().enumerate() {
                let g = self.grid_point(k);
                let p = self.point(g);
                let own = ids[k];
                let mut slot = if own == u32::MAX {
                    (f32::INFINITY, own)
                } else {
                    let [a, b, c] = mesh.corners(own as usize);
                    (triangle_distance(p, a, b, c), own)
                };
                for dz in -1i32..=1 {
                    for dy in -1i32..=1 {
                        for dx in -1i32..=1 {
                            let s = step as i32;
                            let q = [g[0] as i32 + dx * s, g[1] as i32 + dy * s, g[2] as i32 + dz * s];
                            if q.iter().zip(&self.dims).any(|(&c, &n)| c < 0 || c >= n as i32) {
                                continue;
                            }
                            let t = ids[self.index(q.map(|c| c as u32))];
                            if t == u32::MAX || t == slot.1 {
                                continue;
                            }
                            let [a, b, c] = mesh.corners(t as usize);
                            let d = triangle_distance(p, a, b, c);
                            if d < slot.0 || (d == slot.0 && t < slot.1) {
                                slot = (d, t);
                            }
                        }
                    }
                }
                *out = slot.1;
            }
            std::mem::swap(&mut ids, &mut next);
        }
        ids
    }

    /// Per grid point, whether at least two of the three axis rays through it
    /// cross the mesh an odd number of times on its lower side.
    fn inside(&self, mesh: &TriMesh) -> Vec<bool> {
        let total = self.values_len();
        let mut votes = vec![0u8; total];
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let (nu, nv, nw) = (self.dims[u], self.dims[v], self.dims[axis]);
            // Triangles binned by the grid lines their projection may cover.
            let mut lines: Vec<Vec<u32>> = vec![Vec::new(); (nu * nv) as usize];
            for t in 0..mesh.triangles.len() {
                let [a, b, c] = mesh.corners(t);
                let lo = (a.min(b).min(c) - self.origin) / self.cell;
                let hi = (a.max(b).max(c) - self.origin) / self.cell;
                // A superset of the lines (each ray lies a little above its line).
                let range = |i: usize, n: u32| {
                    let first = (lo[i] - 0.01).ceil().max(0.0) as i64;
                    let last = (hi[i].floor() as i64).min(n as i64 - 1);
                    first..=last
                };
                for j in range(v, nv) {
                    for i in range(u, nu) {
                        lines[(j as u32 * nu + i as u32) as usize].push(t as u32);
                    }
                }
            }
            for j in 0..nv {
                for i in 0..nu {
                    // A ray along `axis` through grid line (i, j), nudged off the
                    // lattice so that it does not run through edges and vertices.
                    let mut origin = self.origin;
                    origin[u] += (i as f32 + 1e-3) * self.cell;
                    origin[v] += (j as f32 + 2e-3) * self.cell;
                    let mut hits: Vec<f32> = lines[(j * nu + i) as usize]
                        .iter()
                        .filter_map(|&t| {
                            let [a, b, c] = mesh.corners(t as usize);
                            ray_crossing(origin, axis, a, b, c)
                        })
                        .collect();
                    hits.sort_by(f32::total_cmp);
                    let mut crossed = 0;
                    for w in 0..nw {
                        let at = w as f32 * self.cell;
                        while crossed < hits.len() && hits[crossed] < at {
                            crossed += 1;
                        }
                        if crossed % 2 == 1 {
                            let mut g = [0u32; 3];
                            g[axis] = w;
                            g[u] = i;
                            g[v] = j;
                            votes[self.index(g)] += 1;
                        }
                    }
                }
            }
        }
        votes.into_iter().map(|v| v >= 2).collect()
    }

    fn values_len(&self) -> usize {
        self.dims.iter().map(|&n| n as usize).product()
    }

    /// The signed distance at `p`, trilinear between grid points; outside the
    /// grid, the nearest grid point's value plus the distance to the grid.
    pub fn sample(&self, p: Vec3) -> f32 {
        let max = Vec3::new(self.dims[0] as f32 - 1.0, self.dims[1] as f32 - 1.0, self.dims[2] as f32 - 1.0);
        let g = (p - self.origin) / self.cell;
        let clamped = g.clamp(Vec3::ZERO, max);
        let outside = (g - clamped).length() * self.cell;
        let base = clamped.floor().min(max - Vec3::ONE).max(Vec3::ZERO);
        let f = clamped - base;
        let at = |dx: u32, dy: u32, dz: u32| {
            self.values[self.index([base.x as u32 + dx, base.y as u32 + dy, base.z as u32 + dz])]
        };
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), f.x);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), f.x);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), f.x);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), f.x);
        lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z) + outside
    }
}

/// Where the ray from `origin` along `axis` crosses triangle (a, b, c), as the
/// distance along the ray, when it does. The rays are nudged off the grid
/// lattice, so meeting an edge or a vertex exactly is rare.
fn ray_crossing(origin: Vec3, axis: usize, a: Vec3, b: Vec3, c: Vec3) -> Option<f32> {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let p = (origin[u], origin[v]);
    let (a2, b2, c2) = ((a[u], a[v]), (b[u], b[v]), (c[u], c[v]));
    let edge = |p0: (f32, f32), p1: (f32, f32)| (p1.0 - p0.0) * (p.1 - p0.1) - (p1.1 - p0.1) * (p.0 - p0.0);
    let (w0, w1, w2) = (edge(b2, c2), edge(c2, a2), edge(a2, b2));
    let positive = w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0;
    let negative = w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0;
    let area = w0 + w1 + w2;
    if !(positive || negative) || area == 0.0 {
        return None;
    }
    let depth = (w0 * a[axis] + w1 * b[axis] + w2 * c[axis]) / area;
    Some(depth - origin[axis])
}

/// Distance from `p` to triangle (a, b, c) (Ericson, closest point on a triangle).
pub fn triangle_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).length();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).length();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).length()
}

/// Whether `mesh`'s faces wind inward as a whole: its signed volume (the sum
/// over its triangles of a · (b × c), in f64) is negative.
pub(crate) fn winds_inward(mesh: &TriMesh) -> bool {
    let volume: f64 = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t).map(|v| v.as_dvec3());
            a.dot(b.cross(c))
        })
        .sum();
    volume < 0.0
}

/// 1 for a mesh wound outward, −1 for one wound inward ([`winds_inward`]).
pub(crate) fn facing(mesh: &TriMesh) -> f32 {
    if winds_inward(mesh) {
        -1.0
    } else {
        1.0
    }
}

/// Which side of triangle (a, b, c) `p` lies on when its closest point is
/// inside the face, not on an edge or a corner: -1 behind it (against the
/// normal of its winding), 1 in front, 0 otherwise (`sdf_face_side` of
/// `glsl/include/sdf.glsl`).
pub(crate) fn face_side(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (ab, ac) = (b - a, c - a);
    let (ap, bp, cp) = (p - a, p - b, p - c);
    let (d1, d2, d3, d4, d5, d6) = (ab.dot(ap), ac.dot(ap), ab.dot(bp), ac.dot(bp), ab.dot(cp), ac.dot(cp));
    let (va, vb, vc) = (d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2);
    let in_face = va > 0.0 && vb > 0.0 && vc > 0.0;
    if !in_face {
        return 0.0;
    }
    let s = ab.cross(ac).dot(ap);
    if s < 0.0 {
        -1.0
    } else if s > 0.0 {
        1.0
    } else {
        0.0
    }
}
