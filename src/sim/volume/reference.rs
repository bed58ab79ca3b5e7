//! CPU reference of the volume stage: the oracle of the GPU tests.
//!
//! The scatter, cells and transfer repeat the GPU's f32 operations, and its
//! fixed-point sums ([`fixed_point`]) bit for bit: integer sums, so the order
//! the particles add in does not matter on either side. The pressure solve is different on purpose: conjugate gradients in f64
//! preconditioned with modified incomplete Cholesky (MIC(0), τ = 0.97,
//! σ = 0.25, as in Bridson's fluid notes), the preconditioner the thesis' CPU
//! version used; it converges in a handful of iterations and gives the GPU
//! solvers an independent answer to agree with.

use glam::{Mat4, Vec3, Vec4, Vec4Swizzles};

use super::grid::GridLayout;
pub(crate) use crate::codes::vol_cell::{AIR, FLUID, SOLID};
use crate::codes::vol_mode;
use crate::gpu_types::{ColliderShape, VolumeStep};
use crate::sim::reference::MeshField;

/// Every intermediate result of one volume step.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct VolumeSnapshot {
    /// Particles per cell (those outside the grid in none).
    pub counts: Vec<u32>,
    /// Per cell: mean velocity (grid axes), density.
    pub cells: Vec<Vec4>,
    pub labels: Vec<u32>,
    /// Face velocities after the projection.
    pub face_vel: Vec<f32>,
    /// Face velocities as transferred.
    pub face_star: Vec<f32>,
    pub face_weight: Vec<f32>,
    /// Pressure per cell (scaled: the face velocity changes by its difference).
    pub pressure: Vec<f32>,
    /// Right-hand side b per cell.
    pub rhs: Vec<f32>,
    /// MIC(0)-PCG iterations.
    pub iterations: u32,
}

fn affine(m: &Mat4, p: Vec3) -> Vec3 {
    let c = |k: usize| m.col(k).truncate();
    ((c(0) * p.x + c(1) * p.y) + c(2) * p.z) + c(3)
}

fn linear(m: &Mat4, v: Vec3) -> Vec3 {
    let c = |k: usize| m.col(k).truncate();
    (c(0) * v.x + c(1) * v.y) + c(2) * v.z
}

/// The largest f32 below 2³¹: the transfer's fixed point caps |x| there.
const FIXED_MAX: f32 = 2_147_483_520.0;

/// x in the transfer's fixed point (`vol_fixed`, `glsl/include/volume_fixed.glsl`):
/// trunc(x · 2³²), |x| capped below 2³¹, NaN as 0. Sums of these wrap as the
/// GPU's two 32-bit words do.
pub(crate) fn fixed_point(x: f32) -> i64 {
    let a = x.abs();
    let a = if a.is_nan() { 0.0 } else { a.min(FIXED_MAX) };
    let whole = a.floor();
    let magnitude = (i64::from(whole as u32) << 32) | i64::from(((a - whole) * 4_294_967_296.0) as u32);
    if x < 0.0 {
        -magnitude
    } else {
        magnitude
    }
}

/// A fixed-point sum as the GPU reads it (`vol_fixed_value`): its
/// magnitude's high word plus its low word × 2⁻³², each rounded to f32, then
/// the sign.
pub(crate) fn fixed_value(sum: i64) -> f32 {
    let m = sum.unsigned_abs();
    let x = (m >> 32) as u32 as f32 + m as u32 as f32 * 2.328_306_4e-10;
    if sum < 0 {
        -x
    } else {
        x
    }
}

/// Cell grid shape helper.
#[derive(Clone, Copy)]
pub(crate) struct Dims(pub [u32; 3]);

impl Dims {
    pub(crate) fn count(self) -> usize {
        self.0.iter().map(|&n| n as usize).product()
    }
    pub(crate) fn index(self, c: [i64; 3]) -> Option<usize> {
        let [nx, ny, nz] = self.0.map(i64::from);
        if c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= nx || c[1] >= ny || c[2] >= nz {
            return None;
        }
        Some((c[0] + nx * (c[1] + ny * c[2])) as usize)
    }
    pub(crate) fn coords(self, c: usize) -> [i64; 3] {
        let [nx, ny, _] = self.0.map(|n| n as usize);
        [(c % nx) as i64, ((c / nx) % ny) as i64, (c / (nx * ny)) as i64]
    }
}

/// Face grid of `axis` and the index of face `ijk` in the face arrays.
pub(crate) fn face_index(grid: &GridLayout, axis: usize, ijk: [i64; 3]) -> Option<usize> {
    let mut fd = grid.dims;
    fd[axis] += 1;
    let base = [0, grid.faces[0], grid.faces[1]][axis] as usize;
    Dims(fd).index(ijk).map(|i| base + i)
}

/// Every face as (axis, coordinates on that axis' face grid), in face-array order.
fn faces(grid: &GridLayout) -> impl Iterator<Item = (usize, [i64; 3])> + '_ {
    (0..3).flat_map(move |axis| {
        let mut fd = grid.dims;
        fd[axis] += 1;
        let fdims = Dims(fd);
        (0..fdims.count()).map(move |local| (axis, fdims.coords(local)))
    })
}

fn cell_of(g: Vec3, dims: [u32; 3]) -> Option<[i64; 3]> {
    let d = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
    if g.cmpge(Vec3::ZERO).all() && g.cmplt(d).all() {
        Some([0, 1, 2].map(|a| (g[a] as u32).min(dims[a] - 1) as i64))
    } else {
        None
    }
}

fn inside(colliders: &[ColliderShape], p: Vec3) -> bool {
    // (the mesh collider is checked by the caller, in the head frame)
    colliders.iter().any(|c| {
        let a = c.a;
        let mut closest = a;
        if c.is_capsule() {
            let ab = c.b - a;
            let len2 = ab.dot(ab);
            let t = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
            closest = a + ab * t;
        }
        let d = p - closest;
        d.dot(d) < c.radius * c.radius
    })
}

/// Runs one volume step on `positions` / `velocities` (world space) and returns
/// everything it computed; `velocities` get the update.
pub(crate) fn step(
    grid: &GridLayout,
    p: &VolumeStep,
    colliders: &[ColliderShape],
    mesh: Option<MeshField<'_>>,
    positions: &[Vec4],
    velocities: &mut [Vec4],
) -> VolumeSnapshot {
    let mesh = mesh.filter(|_| p.mesh_solid == 1);
    let n = positions.len();
    let dims = Dims(grid.dims);
    let cells = dims.count();
    let colliders = &colliders[..(p.colliders as usize).min(colliders.len())];
    // 1. Scatter: grid position and velocity, a count per cell, and the
    // fixed-point sums of w and v·w at the cell centres and faces around each
    // particle (any order: integer sums).
    let grid_pos: Vec<Vec4> = positions.iter().map(|x| affine(&p.grid_from_world, x.xyz()).extend(x.w)).collect();
    let grid_vel: Vec<Vec3> = velocities.iter().map(|v| linear(&p.axes, v.xyz())).collect();
    let face_count = grid.faces[2] as usize;
    let mut counts = vec![0u32; cells];
    let mut cell_sums = vec![[0i64; 4]; cells];
    let mut face_sums = vec![[0i64; 2]; face_count];
    let add = |sum: &mut i64, x: f32| *sum = sum.wrapping_add(fixed_point(x));
    let flip = p.mode == vol_mode::FLIP as f32;
    for (g, v) in grid_pos.iter().map(|g| g.xyz()).zip(&grid_vel) {
        let Some(cell) = cell_of(g, grid.dims).and_then(|c| dims.index(c)) else { continue };
        counts[cell] += 1;
        let s = g - 0.5;
        for (q, w) in trilinear(s) {
            let Some(c) = dims.index(q) else { continue };
            let sum = &mut cell_sums[c];
            add(&mut sum[0], w);
            add(&mut sum[1], v.x * w);
            add(&mut sum[2], v.y * w);
            add(&mut sum[3], v.z * w);
        }
        // Faces serve the pressure solve only: FLIP.
        for axis in (0..3).filter(|_| flip) {
            let mut fs = s;
            fs[axis] = g[axis];
            for (q, w) in trilinear(fs) {
                let Some(f) = face_index(grid, axis, q) else { continue };
                add(&mut face_sums[f][0], w);
                add(&mut face_sums[f][1], v[axis] * w);
            }
        }
    }
    // 2. Cells and labels.
    let at = |q: [i64; 3]| Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32) + 0.5;
    let mut cell_data = vec![Vec4::ZERO; cells];
    let mut labels = vec![AIR; cells];
    for c in 0..cells {
        let centre = at(dims.coords(c));
        let [w, mx, my, mz] = cell_sums[c].map(fixed_value);
        labels[c] = if counts[c] > 0 { FLUID } else { AIR };
        let in_mesh = mesh.is_some_and(|m| m.sample(affine(&p.mesh_from_grid, centre)).1 < 0.0);
        if in_mesh || inside(colliders, affine(&p.world_from_grid, centre)) {
            labels[c] = SOLID;
        }
        let mean = if w > 0.0 { Vec3::new(mx, my, mz) / w } else { Vec3::ZERO };
        cell_data[c] = mean.extend(w);
    }
    // Faces: Σ w·v / Σ w, or the colliders' velocity next to a solid cell.
    let mut face_vel = vec![0.0f32; face_count];
    let mut face_weight = vec![0.0f32; face_count];
    for (axis, ijk) in faces(grid).filter(|_| flip) {
        let mut x = at(ijk);
        x[axis] -= 0.5;
        let f = face_index(grid, axis, ijk).unwrap_or(0);
        let [wsum, sum] = face_sums[f].map(fixed_value);
        let mut u = if wsum > 0.0 { sum / wsum } else { 0.0 };
        let mut below = ijk;
        below[axis] -= 1;
        let solid = [below, ijk].iter().any(|c| dims.index(*c).is_some_and(|c| labels[c] == SOLID));
        if solid {
            u = affine(&p.solid_velocity, x)[axis];
        }
        face_vel[f] = u;
        face_weight[f] = wsum;
    }
    // 3. Air cells whose six faces all carry particle weight are fluid too (FLIP).
    for (c, label) in labels.iter_mut().enumerate().filter(|_| flip) {
        let ijk = dims.coords(c);
        let covered = (0..3).all(|axis| {
            let mut up = ijk;
            up[axis] += 1;
            [ijk, up].iter().all(|&q| face_index(grid, axis, q).is_some_and(|f| face_weight[f] > 0.0))
        });
        if *label == AIR && covered {
            *label = FLUID;
        }
    }
    let face_star = face_vel.clone();
    let mut snapshot = VolumeSnapshot {
        counts,
        cells: cell_data,
        labels,
        face_vel,
        face_star,
        face_weight,
        pressure: vec![0.0; cells],
        rhs: vec![0.0; cells],
        iterations: 0,
    };
    // 4. Pressure.
    if p.mode == vol_mode::FLIP as f32 {
        snapshot.rhs = rhs(grid, &snapshot.labels, &snapshot.face_vel);
        let (pressure, iterations) = mic_pcg(grid, &snapshot.labels, &snapshot.rhs, p.tolerance.into(), 1000);
        snapshot.pressure = pressure.iter().map(|&v| v as f32).collect();
        snapshot.iterations = iterations;
        subtract_gradient(grid, &snapshot.labels, &snapshot.pressure, &mut snapshot.face_vel);
    }
    // 5. Grid to particles.
    for i in 0..n {
        let g = grid_pos[i];
        if g.w == 0.0 || cell_of(g.xyz(), grid.dims).is_none() {
            continue;
        }
        let v = grid_to_particle(grid, p, &snapshot, g.xyz(), grid_vel[i]);
        let to_world =
            glam::Mat3::from_cols(p.axes.col(0).truncate(), p.axes.col(1).truncate(), p.axes.col(2).truncate())
                .transpose();
        velocities[i] = (to_world * v).extend(0.0);
    }
    snapshot
}

/// b = −(net outflow) per fluid cell.
pub(crate) fn rhs(grid: &GridLayout, labels: &[u32], face_vel: &[f32]) -> Vec<f32> {
    let dims = Dims(grid.dims);
    (0..dims.count())
        .map(|c| {
            if labels[c] != FLUID {
                return 0.0;
            }
            let ijk = dims.coords(c);
            let mut outflow = 0.0f32;
            for axis in 0..3 {
                let mut up = ijk;
                up[axis] += 1;
                let hi = face_vel[face_index(grid, axis, up).unwrap_or(0)];
                let lo = face_vel[face_index(grid, axis, ijk).unwrap_or(0)];
                outflow += hi - lo;
            }
            -outflow
        })
        .collect()
}

/// The 7-point pressure matrix over fluid cells (f64).
pub(crate) struct Matrix {
    dims: Dims,
    pub diagonal: Vec<f64>,
    /// −1 where the cell and its +x / +y / +z neighbour are both fluid.
    pub plus: [Vec<f64>; 3],
}

impl Matrix {
    pub(crate) fn new(grid: &GridLayout, labels: &[u32]) -> Self {
        let dims = Dims(grid.dims);
        let cells = dims.count();
        let mut m =
            Matrix { dims, diagonal: vec![0.0; cells], plus: [vec![0.0; cells], vec![0.0; cells], vec![0.0; cells]] };
        for c in 0..cells {
            if labels[c] != FLUID {
                continue;
            }
            let ijk = dims.coords(c);
            for axis in 0..3 {
                for step in [-1, 1] {
                    let mut q = ijk;
                    q[axis] += step;
                    let label = dims.index(q).map_or(AIR, |q| labels[q]);
                    if label != SOLID {
                        m.diagonal[c] += 1.0;
                    }
                    if step == 1 && label == FLUID {
                        m.plus[axis][c] = -1.0;
                    }
                }
            }
        }
        m
    }

    fn neighbour(&self, c: usize, axis: usize, step: i64) -> Option<usize> {
        let mut q = self.dims.coords(c);
        q[axis] += step;
        self.dims.index(q)
    }

    /// y = A x.
    pub(crate) fn apply(&self, x: &[f64]) -> Vec<f64> {
        (0..x.len())
            .map(|c| {
                let mut y = self.diagonal[c] * x[c];
                for axis in 0..3 {
                    if let Some(q) = self.neighbour(c, axis, 1) {
                        y += self.plus[axis][c] * x[q];
                    }
                    if let Some(q) = self.neighbour(c, axis, -1) {
                        y += self.plus[axis][q] * x[q];
                    }
                }
                y
            })
            .collect()
    }
}

/// Solves A p = b with MIC(0)-preconditioned conjugate gradients until
/// max |r| ≤ `tolerance` · max |b|; returns p and the iterations.
pub(crate) fn mic_pcg(grid: &GridLayout, labels: &[u32], b: &[f32], tolerance: f64, cap: u32) -> (Vec<f64>, u32) {
    const TAU: f64 = 0.97;
    const SIGMA: f64 = 0.25;
    let a = Matrix::new(grid, labels);
    let cells = b.len();
    let mut precon = vec![0.0f64; cells];
    let back = |c: usize, axis: usize| a.neighbour(c, axis, -1);
    for c in 0..cells {
        if labels[c] != FLUID || a.diagonal[c] == 0.0 {
            continue;
        }
        let mut e = a.diagonal[c];
        for axis in 0..3 {
            if let Some(q) = back(c, axis) {
                let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
                e -= (a.plus[axis][q] * precon[q]).powi(2);
                e -= TAU * a.plus[axis][q] * (a.plus[o1][q] + a.plus[o2][q]) * precon[q].powi(2);
            }
        }
        if e < SIGMA * a.diagonal[c] {
            e = a.diagonal[c];
        }
        precon[c] = 1.0 / e.sqrt();
    }
    let apply_precon = |r: &[f64]| {
        let mut q = vec![0.0f64; cells];
        for c in 0..cells {
            if precon[c] == 0.0 {
                continue;
            }
            let mut t = r[c];
            for axis in 0..3 {
                if let Some(n) = back(c, axis) {
                    t -= a.plus[axis][n] * precon[n] * q[n];
                }
            }
            q[c] = t * precon[c];
        }
        let mut z = vec![0.0f64; cells];
        for c in (0..cells).rev() {
            if precon[c] == 0.0 {
                continue;
            }
            let mut t = q[c];
            for axis in 0..3 {
                if let Some(n) = a.neighbour(c, axis, 1) {
                    t -= a.plus[axis][c] * precon[c] * z[n];
                }
            }
            z[c] = t * precon[c];
        }
        z
    };
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let max_abs = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut p = vec![0.0f64; cells];
    let mut r: Vec<f64> = b.iter().map(|&v| f64::from(v)).collect();
    let bmax = max_abs(&r);
    if bmax == 0.0 {
        return (p, 0);
    }
    let mut z = apply_precon(&r);
    let mut s = z.clone();
    let mut sigma = dot(&z, &r);
    for iteration in 1..=cap {
        let q = a.apply(&s);
        let alpha = sigma / dot(&q, &s);
        for c in 0..cells {
            p[c] += alpha * s[c];
            r[c] -= alpha * q[c];
        }
        if max_abs(&r) <= tolerance * bmax {
            return (p, iteration);
        }
        z = apply_precon(&r);
        let sigma_new = dot(&z, &r);
        let beta = sigma_new / sigma;
        for c in 0..cells {
            s[c] = z[c] + beta * s[c];
        }
        sigma = sigma_new;
    }
    (p, cap)
}

/// Subtracts the pressure difference on faces between a fluid cell and a non-solid one.
pub(crate) fn subtract_gradient(grid: &GridLayout, labels: &[u32], pressure: &[f32], face_vel: &mut [f32]) {
    let dims = Dims(grid.dims);
    for (axis, ijk) in faces(grid) {
        let mut below = ijk;
        below[axis] -= 1;
        let side = |c: [i64; 3]| {
            dims.index(c).map_or((AIR, 0.0), |c| (labels[c], if labels[c] == FLUID { pressure[c] } else { 0.0 }))
        };
        let (bl, bp) = side(below);
        let (al, ap) = side(ijk);
        if (bl == FLUID || al == FLUID) && bl != SOLID && al != SOLID {
            let f = face_index(grid, axis, ijk).unwrap_or(0);
            face_vel[f] -= ap - bp;
        }
    }
}

/// Trilinear sample of component `axis` on its face grid: (Lerp(v), Lerp(v − v*)).
pub(crate) fn sample_faces(grid: &GridLayout, face_vel: &[f32], face_star: &[f32], g: Vec3, axis: usize) -> (f32, f32) {
    let mut fd = grid.dims;
    fd[axis] += 1;
    let mut q = g - 0.5;
    q[axis] += 0.5;
    let mut result = (0.0f32, 0.0f32);
    for (at, w) in trilinear_corners(q, fd) {
        let f = face_index(grid, axis, at).unwrap_or(0);
        result.0 += face_vel[f] * w;
        result.1 += (face_vel[f] - face_star[f]) * w;
    }
    result
}

/// The 8 grid points around `q` (q in that grid's coordinates; bit 0 of the
/// index +x, bit 1 +y, bit 2 +z) with their trilinear weights, in the order and
/// rounding of the GPU's loops (`corner_of` in `scatter.comp`, the samplers of
/// `g2p.comp`): 1 − t below and t above along each axis, (x · y) · z.
fn trilinear(q: Vec3) -> impl Iterator<Item = ([i64; 3], f32)> {
    let base = q.floor();
    let t = q - base;
    (0..8usize).map(move |k| {
        let corner = [k & 1, (k >> 1) & 1, k >> 2];
        let at = [0, 1, 2].map(|a| base[a] as i64 + corner[a] as i64);
        let w3 = Vec3::new(
            if corner[0] == 1 { t.x } else { 1.0 - t.x },
            if corner[1] == 1 { t.y } else { 1.0 - t.y },
            if corner[2] == 1 { t.z } else { 1.0 - t.z },
        );
        (at, (w3.x * w3.y) * w3.z)
    })
}

/// [`trilinear`] with the points clamped into `dims`, as the samplers read them.
fn trilinear_corners(q: Vec3, dims: [u32; 3]) -> impl Iterator<Item = ([i64; 3], f32)> {
    trilinear(q).map(move |(at, w)| ([0, 1, 2].map(|a| at[a].clamp(0, i64::from(dims[a]) - 1)), w))
}

fn sample_cells(grid: &GridLayout, cells: &[Vec4], g: Vec3) -> Vec4 {
    let dims = Dims(grid.dims);
    let mut result = Vec4::ZERO;
    for (at, w) in trilinear_corners(g - 0.5, grid.dims) {
        let cell = cells[dims.index(at).unwrap_or(0)];
        result += (cell.xyz() * cell.w).extend(cell.w) * w;
    }
    result
}

/// The updated velocity (grid axes) of a particle at grid position `g` with velocity `v`.
fn grid_to_particle(grid: &GridLayout, p: &VolumeStep, s: &VolumeSnapshot, g: Vec3, v: Vec3) -> Vec3 {
    if p.mode == vol_mode::FLIP as f32 {
        let alpha = p.flip_ratio;
        let [u, vv, w] = [0, 1, 2].map(|a| sample_faces(grid, &s.face_vel, &s.face_star, g, a));
        let pic = Vec3::new(u.0, vv.0, w.0);
        let flip = v + Vec3::new(u.1, vv.1, w.1);
        return flip * alpha + pic * (1.0 - alpha);
    }
    let cell = sample_cells(grid, &s.cells, g);
    let mut v = v;
    let friction = p.friction;
    if cell.w > 0.0 {
        let mean = cell.xyz() / cell.w;
        v = v * (1.0 - friction) + mean * friction;
    }
    let threshold = p.repulsion_threshold;
    if p.repulsion > 0.0 && cell.w > threshold {
        let dims = Dims(grid.dims);
        let c = [0, 1, 2].map(|a| (g[a] as i64).min(i64::from(grid.dims[a]) - 1));
        let mut gradient = Vec3::ZERO;
        for axis in 0..3 {
            let (mut lo, mut hi) = (c, c);
            lo[axis] = (c[axis] - 1).max(0);
            hi[axis] = (c[axis] + 1).min(i64::from(grid.dims[axis]) - 1);
            let density = |q: [i64; 3]| dims.index(q).map_or(0.0, |q| s.cells[q].w);
            gradient[axis] = density(hi) - density(lo);
        }
        let len = gradient.length();
        if len > 0.0 {
            let excess = ((cell.w - threshold) / threshold.max(1e-6)).min(1.0);
            v -= gradient * (p.repulsion * p.dt * excess / len);
        }
    }
    v
}
