//! GPU tests of the volume stage against the CPU reference (lavapipe, validated).

use glam::{Mat4, Vec3, Vec4, Vec4Swizzles};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;

use super::grid::GridLayout;
use super::reference::{self, face_index, Dims, VolumeSnapshot, FLUID, SOLID};
use super::{Preconditioner, PressureSolver, VolumeMode, VolumeParams, VolumeStage, VolumeStats};
use crate::codes::collider_kind::SPHERE;
use crate::gpu_types::{ColliderShape, GpuCollider, GpuVolumeParams, VolumeStep};
use crate::sim::MAX_COLLIDERS;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::tests::TestGpu;

/// What one GPU volume step produced.
struct GpuRun {
    snapshot: VolumeSnapshot,
    velocities: Vec<Vec4>,
    stats: VolumeStats,
}

/// Runs one volume step on the GPU over the given particles.
fn run_gpu(
    gpu: &TestGpu,
    grid: &GridLayout,
    params: &VolumeParams,
    block: &VolumeStep,
    colliders: &[ColliderShape],
    positions: &[Vec4],
    velocities: &[Vec4],
) -> GpuRun {
    let d = gpu.device();
    let n = positions.len() as u64;
    let pos = Buffer::storage(d, "test positions", n * 16).expect("buffer");
    let vel = Buffer::storage(d, "test velocities", n * 16).expect("buffer");
    d.upload_pod(&pos, positions).expect("upload");
    d.upload_pod(&vel, velocities).expect("upload");
    let collider_buffer = Buffer::new(
        d,
        &BufferDesc {
            name: "test colliders",
            size: (MAX_COLLIDERS * std::mem::size_of::<GpuCollider>()) as u64,
            usage: ash::vk::BufferUsageFlags::UNIFORM_BUFFER | ash::vk::BufferUsageFlags::TRANSFER_DST,
            location: gpu_allocator::MemoryLocation::GpuOnly,
        },
    )
    .expect("buffer");
    let mut padded: Vec<GpuCollider> = colliders.iter().map(GpuCollider::from).collect();
    padded.resize(MAX_COLLIDERS, GpuCollider::default());
    d.upload_pod(&collider_buffer, &padded).expect("upload");
    let no_mesh = Buffer::storage(d, "test no mesh collider", 16).expect("buffer");
    let stage = VolumeStage::new(d, grid.clone(), params, &collider_buffer, &no_mesh, &[(&pos, &vel)]).expect("stage");
    let uploaded = barrier::memory(
        &[AccessKind::TransferWrite],
        &[AccessKind::ComputeRead, AccessKind::ComputeUniformRead, AccessKind::ComputeWrite, AccessKind::IndirectRead],
    );
    d.submit_once("volume test", |cmd| {
        // SAFETY: a recording command buffer of this device; submit_once waited for
        // all earlier work (the uploads).
        unsafe {
            stage.record_uploads(cmd, &GpuVolumeParams::from(block));
            d.cmd_barrier(cmd, &[uploaded], &[], &[]);
            stage.record(cmd, 0, ["scatter", "transfer", "pressure", "update"], crate::profiler::Timing::default());
        }
    })
    .expect("submit");
    let b = &stage.buffers;
    let cells = grid.cells() as usize;
    let faces = grid.faces[2] as usize;
    let snapshot = VolumeSnapshot {
        counts: d.readback_pod(&b.counts, cells).expect("readback"),
        cells: d.readback_pod(&b.cells, cells).expect("readback"),
        labels: d.readback_pod(&b.labels, cells).expect("readback"),
        face_vel: d.readback_pod(&b.face_vel, faces).expect("readback"),
        face_star: d.readback_pod(&b.face_star, faces).expect("readback"),
        face_weight: d.readback_pod(&b.face_weight, faces).expect("readback"),
        pressure: d.readback_pod(&b.pressure, cells).expect("readback"),
        rhs: Vec::new(),
        iterations: 0,
    };
    let stats = stage.read_stats().expect("stats");
    let velocities = d.readback_pod(&vel, n as usize).expect("readback");
    GpuRun { snapshot: VolumeSnapshot { iterations: stats.iterations, ..snapshot }, velocities, stats }
}

/// A grid whose coordinates are world coordinates (unit cells at the origin).
fn unit_grid(dims: [u32; 3], particles: usize) -> GridLayout {
    GridLayout::placed(dims, 1.0, Vec3::ZERO, particles as u32)
}

fn block(grid: &GridLayout, params: &VolumeParams, previous: Mat4, colliders: u32) -> VolumeStep {
    grid.step_params(params, &previous, &Mat4::IDENTITY, 1.0 / 60.0, colliders, None)
}

/// A sphere collider as the volume stage sees it.
fn sphere(center: Vec3, radius: f32) -> ColliderShape {
    ColliderShape { a: center, radius, b: center, kind: SPHERE as f32, ..ColliderShape::default() }
}

fn random_particles(rng: &mut Pcg32, n: usize, lo: Vec3, hi: Vec3, speed: f32) -> (Vec<Vec4>, Vec<Vec4>) {
    let positions = (0..n)
        .map(|_| {
            let t = Vec3::new(rng.random(), rng.random(), rng.random());
            (lo + (hi - lo) * t).extend(1.0)
        })
        .collect();
    let velocities =
        (0..n).map(|_| (Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0).extend(0.0) * speed).collect();
    (positions, velocities)
}

fn assert_close(what: &str, gpu: &[f32], cpu: &[f32], tolerance: f32) {
    assert_eq!(gpu.len(), cpu.len(), "{what}: length");
    for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        assert!((g - c).abs() <= tolerance * c.abs().max(1.0), "{what}[{i}]: GPU {g} vs CPU {c}");
    }
}

fn cell_floats(cells: &[Vec4]) -> Vec<f32> {
    cells.iter().flat_map(|c| c.to_array()).collect()
}

fn friction_params() -> VolumeParams {
    VolumeParams { mode: VolumeMode::Friction, ..VolumeParams::default() }
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

fn bits4(values: &[Vec4]) -> Vec<[u32; 4]> {
    values.iter().map(|v| v.to_array().map(f32::to_bits)).collect()
}

/// The transfer's fixed point: trunc(x · 2³²), |x| capped below 2³¹, NaN as 0;
/// sums of a value and its negation cancel exactly; values with no bits below
/// 2⁻³² come back exactly.
#[test]
fn the_fixed_point_of_the_transfer_is_exact_where_it_can_be() {
    use reference::{fixed_point, fixed_value};
    assert_eq!(fixed_point(0.0), 0);
    assert_eq!(fixed_point(-0.0), 0);
    assert_eq!(fixed_point(1.0), 1 << 32);
    assert_eq!(fixed_point(-0.5), -(1 << 31));
    assert_eq!(fixed_point(1e-12), 0, "below 2⁻³²");
    assert_eq!(fixed_point(f32::NAN), 0);
    assert_eq!(fixed_point(f32::INFINITY), fixed_point(3e9), "capped");
    assert_eq!(fixed_point(f32::NEG_INFINITY), -fixed_point(3e9));
    assert_eq!(fixed_value(fixed_point(3e9)), 2_147_483_520.0);
    for x in [1.5f32, -2.25, 0.125, -1e-3, 12345.678, -0.999_999_9] {
        let q = fixed_point(x);
        assert_eq!(q.wrapping_add(fixed_point(-x)), 0, "{x}");
        assert!((fixed_value(q) - x).abs() <= 2.4e-10 + x.abs() * 6e-8, "{x}: {}", fixed_value(q));
    }
    assert_eq!(fixed_value(fixed_point(1.5)), 1.5);
    assert_eq!(fixed_value(fixed_point(-2.25)), -2.25);
}

/// The scatter's ways of adding: 64-bit atomics where the device has them
/// (then the 32-bit pairs too, forced), else the 32-bit pairs alone.
fn atomic_paths(gpu: &TestGpu) -> Vec<bool> {
    use std::sync::atomic::Ordering;
    if gpu.device().int64_atomics.load(Ordering::Relaxed) {
        vec![true, false]
    } else {
        eprintln!("64-bit atomics: not on this device; the 32-bit pairs only");
        vec![false]
    }
}

/// The scatter against the reference on particles inside, on cell boundaries,
/// outside (below, on the far faces, NaN, infinite) and with a NaN and a
/// huge velocity: counts, densities and face weights bit for bit (the same
/// integer sums), means and face velocities to the division's rounding;
/// particles outside keep their velocity; both ways of adding where the device has
/// 64-bit atomics.
#[test]
fn the_scatter_matches_the_reference_bit_for_bit() {
    let gpu = TestGpu::new();
    for int64 in atomic_paths(&gpu) {
        gpu.device().int64_atomics.store(int64, std::sync::atomic::Ordering::Relaxed);
        eprintln!("64-bit atomics: {int64}");
        scatter_matches_the_reference(&gpu);
    }
}

fn scatter_matches_the_reference(gpu: &TestGpu) {
    let mut rng = Pcg32::seed_from_u64(5);
    let grid_dims = [8, 6, 5];
    let (mut positions, mut velocities) = random_particles(&mut rng, 1000, Vec3::ZERO, Vec3::new(8.0, 6.0, 5.0), 1.0);
    for (k, p) in positions.iter_mut().enumerate().take(100) {
        *p = Vec4::new((k % 9) as f32, (k % 7) as f32, (k % 6) as f32, 1.0);
    }
    positions[100] = Vec4::new(-0.001, 1.0, 1.0, 1.0);
    positions[101] = Vec4::new(8.0, 1.0, 1.0, 1.0);
    positions[102] = Vec4::new(f32::NAN, 1.0, 1.0, 1.0);
    positions[103] = Vec4::new(1.0, f32::INFINITY, 1.0, 1.0);
    velocities[200] = Vec4::new(f32::NAN, 0.0, 0.0, 0.0);
    velocities[201] = Vec4::new(1e10, -1e10, 0.0, 0.0);
    let grid = unit_grid(grid_dims, positions.len());
    let params = VolumeParams::flip(grid_dims);
    let b = block(&grid, &params, Mat4::IDENTITY, 0);
    let run = run_gpu(gpu, &grid, &params, &b, &[], &positions, &velocities);
    let mut cpu_vel = velocities.clone();
    let cpu = reference::step(&grid, &b, &[], None, &positions, &mut cpu_vel);
    assert_eq!(run.snapshot.counts, cpu.counts, "particles per cell");
    let d = Vec3::new(8.0, 6.0, 5.0);
    let inside = positions.iter().filter(|p| p.xyz().cmpge(Vec3::ZERO).all() && p.xyz().cmplt(d).all()).count();
    assert!(inside < 996, "boundary points on the far faces are outside too");
    assert_eq!(cpu.counts.iter().sum::<u32>() as usize, inside);
    assert!(cpu.counts.contains(&0), "some cells are empty");
    let density = |s: &VolumeSnapshot| s.cells.iter().map(|c| c.w).collect::<Vec<f32>>();
    assert_eq!(bits(&density(&run.snapshot)), bits(&density(&cpu)), "densities");
    assert_eq!(bits(&run.snapshot.face_weight), bits(&cpu.face_weight), "face weights");
    assert_close("cells", &cell_floats(&run.snapshot.cells), &cell_floats(&cpu.cells), 1e-6);
    assert_close("face velocities", &run.snapshot.face_star, &cpu.face_star, 1e-6);
    assert_eq!(bits4(&run.velocities[100..104]), bits4(&velocities[100..104]), "particles outside keep their velocity");
}

/// The sums do not depend on the order the particles add in: the particles
/// reversed give the same bits on the GPU. 700 particles in one cell far from
/// the grid's edges (each a whole trilinear weight) sum to 700 at the centres
/// and on each axis' faces, and count 700 in their cell.
#[test]
fn the_scatter_is_the_same_in_any_order() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(6);
    let (positions, velocities) = random_particles(&mut rng, 700, Vec3::splat(30.1), Vec3::splat(30.9), 0.5);
    let grid = unit_grid([64, 64, 64], positions.len());
    let params = VolumeParams { max_iterations: 1, ..VolumeParams::flip([64; 3]) };
    let b = block(&grid, &params, Mat4::IDENTITY, 0);
    let reversed = |v: &[Vec4]| v.iter().rev().copied().collect::<Vec<_>>();
    // Forward and backward, by each way of adding: all the same bits.
    let mut runs = Vec::new();
    for int64 in atomic_paths(&gpu) {
        gpu.device().int64_atomics.store(int64, std::sync::atomic::Ordering::Relaxed);
        runs.push(run_gpu(&gpu, &grid, &params, &b, &[], &positions, &velocities));
        runs.push(run_gpu(&gpu, &grid, &params, &b, &[], &reversed(&positions), &reversed(&velocities)));
    }
    let forward = &runs[0];
    for other in &runs[1..] {
        assert_eq!(bits(&cell_floats(&forward.snapshot.cells)), bits(&cell_floats(&other.snapshot.cells)));
        assert_eq!(bits(&forward.snapshot.face_star), bits(&other.snapshot.face_star));
        assert_eq!(bits(&forward.snapshot.face_weight), bits(&other.snapshot.face_weight));
    }
    let cell = 30 + 64 * (30 + 64 * 30);
    assert_eq!(forward.snapshot.counts[cell], 700);
    assert_eq!(forward.snapshot.counts.iter().sum::<u32>(), 700);
    let total: f64 = forward.snapshot.cells.iter().map(|c| f64::from(c.w)).sum();
    assert!((total - 700.0).abs() < 1e-3, "summed density {total}");
    for axis in 0..3 {
        let range = [0, grid.faces[0], grid.faces[1], grid.faces[2]];
        let faces = &forward.snapshot.face_weight[range[axis] as usize..range[axis + 1] as usize];
        let total: f64 = faces.iter().map(|&w| f64::from(w)).sum();
        assert!((total - 700.0).abs() < 1e-3, "axis {axis}: summed face weight {total}");
    }
}

/// Cells, labels and the friction update against the reference; then the
/// same particles in FLIP, whose faces (the friction mode has none) take the
/// moving sphere's velocity next to its solid cells.
#[test]
fn transfer_and_friction_match_the_reference() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(7);
    let (positions, velocities) = random_particles(&mut rng, 3000, Vec3::splat(2.0), Vec3::new(10.0, 9.0, 7.0), 1.0);
    let grid = unit_grid([12, 11, 9], positions.len());
    let friction = VolumeParams { repulsion_threshold: 2.0, repulsion: 5.0, friction: 0.3, ..friction_params() };
    // A moving sphere marks solid cells and gives their faces a velocity.
    let colliders = [sphere(Vec3::new(6.0, 5.0, 4.0), 2.2)];
    let previous = Mat4::from_translation(Vec3::new(-0.01, 0.02, 0.0));
    let b = block(&grid, &friction, previous, 1);
    let run = run_gpu(&gpu, &grid, &friction, &b, &colliders, &positions, &velocities);
    let mut cpu_vel = velocities.clone();
    let cpu = reference::step(&grid, &b, &colliders, None, &positions, &mut cpu_vel);
    assert_eq!(run.snapshot.labels, cpu.labels);
    assert!(cpu.labels.contains(&SOLID) && cpu.labels.contains(&FLUID));
    assert!(cpu.face_weight.iter().all(|&w| w == 0.0), "the friction mode sums no faces");
    // Same operations in the same order: agreement to a few ulps (the division of a
    // vector may be a multiply by the reciprocal on the GPU).
    assert_close("cells", &cell_floats(&run.snapshot.cells), &cell_floats(&cpu.cells), 1e-6);
    let gpu_v: Vec<f32> = run.velocities.iter().flat_map(|v| v.to_array()).collect();
    let cpu_v: Vec<f32> = cpu_vel.iter().flat_map(|v| v.to_array()).collect();
    assert_close("friction velocities", &gpu_v, &cpu_v, 1e-5);
    let flip = VolumeParams { mode: VolumeMode::Flip, ..friction };
    let b = block(&grid, &flip, previous, 1);
    let run = run_gpu(&gpu, &grid, &flip, &b, &colliders, &positions, &velocities);
    let cpu = reference::step(&grid, &b, &colliders, None, &positions, &mut velocities.clone());
    assert_eq!(run.snapshot.labels, cpu.labels);
    assert_eq!(bits(&run.snapshot.face_weight), bits(&cpu.face_weight), "face weights");
    assert_close("face velocities", &run.snapshot.face_star, &cpu.face_star, 1e-6);
    // Solid faces carry the sphere's velocity: (0.01, −0.02, 0) / dt.
    let expected = Vec3::new(0.6, -1.2, 0.0);
    let dims = Dims(grid.dims);
    let mut solid_faces = 0;
    for c in 0..dims.count() {
        if cpu.labels[c] != SOLID {
            continue;
        }
        let ijk = dims.coords(c);
        for axis in 0..3 {
            let f = face_index(&grid, axis, ijk).expect("face");
            assert!((run.snapshot.face_star[f] - expected[axis]).abs() < 1e-4, "solid face {f}");
            solid_faces += 1;
        }
    }
    assert!(solid_faces > 0);
}

#[test]
fn uniform_motion_transfers_to_a_uniform_field_and_stays_untouched() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(8);
    let (positions, _) = random_particles(&mut rng, 2000, Vec3::splat(3.0), Vec3::splat(9.0), 0.0);
    let v0 = Vec4::new(0.7, -0.3, 0.2, 0.0);
    let velocities = vec![v0; positions.len()];
    let grid = unit_grid([12, 12, 12], positions.len());
    let params = VolumeParams::flip([12, 12, 12]);
    let b = block(&grid, &params, Mat4::IDENTITY, 0);
    let run = run_gpu(&gpu, &grid, &params, &b, &[], &positions, &velocities);
    let mut weighted = 0;
    for axis in 0..3 {
        let range = [0, grid.faces[0], grid.faces[1], grid.faces[2]];
        for f in range[axis] as usize..range[axis + 1] as usize {
            if run.snapshot.face_weight[f] > 0.0 {
                weighted += 1;
                assert!((run.snapshot.face_star[f] - v0[axis]).abs() < 1e-6, "face {f}: {}", run.snapshot.face_star[f]);
            }
        }
    }
    assert!(weighted > 1000);
    for (i, v) in run.velocities.iter().enumerate() {
        assert!((*v - v0).length() < 1e-5, "particle {i}: {v} instead of {v0}");
    }
}

/// Max |divergence| over fluid cells of a face field.
fn max_divergence(grid: &GridLayout, labels: &[u32], faces: &[f32]) -> f32 {
    reference::rhs(grid, labels, faces).iter().fold(0.0, |m, v| m.max(v.abs()))
}

#[test]
fn projection_is_divergence_free_and_agrees_with_mic_pcg() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(9);
    let (positions, velocities) = random_particles(&mut rng, 6000, Vec3::new(2.0, 2.5, 3.0), Vec3::splat(14.0), 1.0);
    let grid = unit_grid([16, 16, 16], positions.len());
    let colliders = [sphere(Vec3::splat(8.0), 3.0)];
    let previous = Mat4::from_translation(Vec3::new(0.0, 0.01, 0.0));
    let (mut iterations, mut residuals) = (Vec::new(), Vec::new());
    // Both ways of reducing: subgroup arithmetic where the device has it, and the
    // shared-memory fallback, forced.
    // Then the solve in one workgroup, which reduces its sums itself.
    let paths = if gpu.device().info.subgroup_reductions { vec![false, true] } else { vec![true] };
    let runs =
        paths.into_iter().map(|shared| (PressureSolver::Dispatched, shared)).chain([(PressureSolver::Workgroup, true)]);
    let runs = runs.flat_map(|(solver, shared)| {
        [Preconditioner::Jacobi, Preconditioner::Multigrid].map(|preconditioner| (solver, shared, preconditioner))
    });
    for (solver, shared, preconditioner) in runs {
        gpu.device().shared_reductions.store(shared, std::sync::atomic::Ordering::Relaxed);
        let params = VolumeParams { preconditioner, solver, max_iterations: 200, ..VolumeParams::flip([16, 16, 16]) };
        let b = block(&grid, &params, previous, 1);
        let run = run_gpu(&gpu, &grid, &params, &b, &colliders, &positions, &velocities);
        let mut cpu_vel = velocities.clone();
        let cpu = reference::step(&grid, &b, &colliders, None, &positions, &mut cpu_vel);
        assert_eq!(run.snapshot.labels, cpu.labels);
        let before = max_divergence(&grid, &cpu.labels, &cpu.face_star);
        let after = max_divergence(&grid, &cpu.labels, &run.snapshot.face_vel);
        let cpu_after = max_divergence(&grid, &cpu.labels, &cpu.face_vel);
        eprintln!(
            "{solver:?} {preconditioner:?}, shared-memory reductions {shared}: {} iterations (MIC {}), divergence \
             {before} -> GPU {after}, CPU {cpu_after}; {:?}",
            run.stats.iterations, cpu.iterations, run.stats
        );
        assert!(run.stats.converged && run.stats.iterations < params.max_iterations, "{:?}", run.stats);
        assert!(before > 1.0, "the random field is far from divergence free");
        assert!(after <= 1e-5 * before * 4.0, "GPU divergence {after} from {before}");
        let pmax = cpu.pressure.iter().fold(0.0f32, |m, p| m.max(p.abs()));
        for (c, (g, r)) in run.snapshot.pressure.iter().zip(&cpu.pressure).enumerate() {
            assert!((g - r).abs() <= 1e-3 * pmax, "pressure of cell {c}: GPU {g} vs MIC {r} (max {pmax})");
        }
        let gpu_v: Vec<f32> = run.velocities.iter().flat_map(|v| v.to_array()).collect();
        let cpu_v: Vec<f32> = cpu_vel.iter().flat_map(|v| v.to_array()).collect();
        assert_close("FLIP velocities", &gpu_v, &cpu_v, 1e-3);
        iterations.push(run.stats.iterations);
        residuals.push(run.stats.relative_residual);
    }
    // The reductions sum the same values in different orders: the solves take the
    // same iterations to residuals equal but for rounding; so does the solve in one
    // workgroup (the last pair), whose per-cell arithmetic is the dispatched kernels'.
    let n = iterations.len();
    for k in 0..n - 2 {
        let (i, j) = (k % 2, k + 2);
        assert_eq!(iterations[i], iterations[j], "run {j} takes other iterations than run {i}: {iterations:?}");
        let (a, b) = (residuals[i], residuals[j]);
        assert!((a - b).abs() <= 1e-2 * a, "residuals {a} and {b} of runs {i} and {j}");
    }
    for pair in iterations.chunks(2) {
        assert!(pair[1] * 2 <= pair[0], "multigrid needs {} iterations, Jacobi {}", pair[1], pair[0]);
    }
}

#[test]
fn flip_ratio_zero_is_pic_and_one_is_flip() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(10);
    let (positions, velocities) = random_particles(&mut rng, 1500, Vec3::splat(2.0), Vec3::splat(8.0), 1.0);
    let grid = unit_grid([10, 10, 10], positions.len());
    for alpha in [0.0f32, 1.0] {
        let params = VolumeParams { flip_ratio: alpha, ..VolumeParams::flip([10, 10, 10]) };
        let b = block(&grid, &params, Mat4::IDENTITY, 0);
        let run = run_gpu(&gpu, &grid, &params, &b, &[], &positions, &velocities);
        let s = &run.snapshot;
        let mut changed = 0;
        for i in 0..positions.len() {
            let g = positions[i].xyz();
            let [u, v, w] = [0, 1, 2].map(|axis| reference::sample_faces(&grid, &s.face_vel, &s.face_star, g, axis));
            let expected =
                if alpha == 0.0 { Vec3::new(u.0, v.0, w.0) } else { velocities[i].xyz() + Vec3::new(u.1, v.1, w.1) };
            let got = run.velocities[i].xyz();
            assert!((got - expected).length() < 1e-5, "α = {alpha}, particle {i}: {got} vs {expected}");
            changed += usize::from((got - velocities[i].xyz()).length() > 1e-3);
        }
        assert!(changed > positions.len() / 2, "the projection changed most velocities");
    }
}

#[test]
fn a_grid_of_one_multigrid_level_is_solved_by_its_coarsest_pass() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(11);
    let (positions, velocities) = random_particles(&mut rng, 800, Vec3::splat(0.5), Vec3::splat(5.5), 1.0);
    let grid = unit_grid([6, 6, 6], positions.len());
    assert_eq!(grid.levels.len(), 1, "216 cells are the coarsest level already");
    for solver in [PressureSolver::Dispatched, PressureSolver::Workgroup] {
        let params = VolumeParams { max_iterations: 100, solver, ..VolumeParams::flip([6, 6, 6]) };
        let b = block(&grid, &params, Mat4::IDENTITY, 0);
        let run = run_gpu(&gpu, &grid, &params, &b, &[], &positions, &velocities);
        let mut cpu_vel = velocities.clone();
        let cpu = reference::step(&grid, &b, &[], None, &positions, &mut cpu_vel);
        let before = max_divergence(&grid, &cpu.labels, &cpu.face_star);
        let after = max_divergence(&grid, &cpu.labels, &run.snapshot.face_vel);
        eprintln!(
            "one level, {solver:?}: {} iterations (MIC {}), divergence {before} -> {after}",
            run.stats.iterations, cpu.iterations
        );
        assert!(run.stats.converged && !run.stats.non_finite && run.stats.iterations < 100, "{:?}", run.stats);
        assert!(before > 0.5 && after <= 4e-5 * before, "divergence {before} -> {after}");
        let pmax = cpu.pressure.iter().fold(0.0f32, |m, p| m.max(p.abs()));
        for (c, (g, r)) in run.snapshot.pressure.iter().zip(&cpu.pressure).enumerate() {
            assert!((g - r).abs() <= 1e-3 * pmax, "pressure of cell {c}: GPU {g} vs MIC {r} (max {pmax})");
        }
    }
}

/// The solve in one workgroup on a grid whose loops would outrun lavapipe's loop
/// limit in one dispatch: its shares take the dispatched solve's iterations (give
/// or take one: the sums are reduced in other orders) to the same tolerance.
#[test]
fn a_workgroup_solve_of_many_shares_converges_like_the_dispatched_one() {
    let gpu = TestGpu::new();
    let mut rng = Pcg32::seed_from_u64(12);
    let (positions, velocities) = random_particles(&mut rng, 60000, Vec3::new(4.0, 5.0, 6.0), Vec3::splat(58.0), 1.0);
    let grid = unit_grid([64, 64, 64], positions.len());
    for preconditioner in [Preconditioner::Jacobi, Preconditioner::Multigrid] {
        let mut stats = Vec::new();
        for solver in [PressureSolver::Dispatched, PressureSolver::Workgroup] {
            let params = VolumeParams { preconditioner, solver, max_iterations: 100, ..VolumeParams::flip([64; 3]) };
            let b = block(&grid, &params, Mat4::IDENTITY, 0);
            let run = run_gpu(&gpu, &grid, &params, &b, &[], &positions, &velocities);
            eprintln!("64³, {preconditioner:?}, {solver:?}: {:?}", run.stats);
            assert!(run.stats.converged && run.stats.relative_residual <= params.tolerance, "{:?}", run.stats);
            stats.push(run.stats);
        }
        assert!(stats[0].iterations.abs_diff(stats[1].iterations) <= 1, "{preconditioner:?}: {stats:?}");
    }
}

/// Shares of the solve in one workgroup: the default cap in one dispatch at 32³,
/// 6 iterations a share at 64³ (lavapipe stopped an unshared 64³ solve after 7),
/// and no share at all where one iteration would outrun the loop budget.
#[test]
fn the_workgroup_solve_is_shared_to_stay_within_the_loop_budget() {
    use super::record::workgroup_share;
    let grid = |n: u32| unit_grid([n; 3], 1000);
    assert_eq!(workgroup_share(&grid(32), Preconditioner::Multigrid), Some(47));
    assert_eq!(workgroup_share(&grid(64), Preconditioner::Multigrid), Some(6));
    assert_eq!(workgroup_share(&grid(64), Preconditioner::Jacobi), Some(11));
    // The edge PressureSolver::Workgroup names: about 1.9 million cells.
    assert_eq!(workgroup_share(&grid(120), Preconditioner::Multigrid), Some(1), "1.73 million cells");
    assert_eq!(workgroup_share(&grid(128), Preconditioner::Multigrid), None, "2.10 million cells");
    assert_eq!(workgroup_share(&unit_grid([160, 160, 160], 1000), Preconditioner::Multigrid), None);
}

/// `Auto` records the solve in one workgroup on a CPU device and dispatched on
/// a GPU; a chosen solver stays as chosen. On this device the stage records the
/// resolved one.
#[test]
fn the_pressure_solver_is_chosen_by_the_device_type() {
    use ash::vk::PhysicalDeviceType as T;
    for (device, auto) in [
        (T::CPU, PressureSolver::Workgroup),
        (T::DISCRETE_GPU, PressureSolver::Dispatched),
        (T::INTEGRATED_GPU, PressureSolver::Dispatched),
        (T::VIRTUAL_GPU, PressureSolver::Dispatched),
        (T::OTHER, PressureSolver::Dispatched),
    ] {
        assert_eq!(PressureSolver::Auto.on_device(device), auto, "{device:?}");
        for chosen in [PressureSolver::Workgroup, PressureSolver::Dispatched] {
            assert_eq!(chosen.on_device(device), chosen, "{device:?}");
        }
    }
    assert_eq!(VolumeParams::default().solver, PressureSolver::Auto);
    let gpu = TestGpu::new();
    let d = gpu.device();
    let pos = Buffer::storage(d, "test positions", 16).expect("buffer");
    let vel = Buffer::storage(d, "test velocities", 16).expect("buffer");
    let colliders = Buffer::new(
        d,
        &BufferDesc {
            name: "test colliders",
            size: (MAX_COLLIDERS * std::mem::size_of::<GpuCollider>()) as u64,
            usage: ash::vk::BufferUsageFlags::UNIFORM_BUFFER,
            location: gpu_allocator::MemoryLocation::GpuOnly,
        },
    )
    .expect("buffer");
    let no_mesh = Buffer::storage(d, "test no mesh collider", 16).expect("buffer");
    let params = VolumeParams::flip([8; 3]);
    let stage =
        VolumeStage::new(d, unit_grid([8; 3], 1), &params, &colliders, &no_mesh, &[(&pos, &vel)]).expect("stage");
    assert_eq!(stage.params.solver, PressureSolver::Auto.on_device(d.info.device_type));
    assert_ne!(stage.params.solver, PressureSolver::Auto);
}

/// The dispatched solve leaves its levels of at most 16³ below the finest to
/// one workgroup when they are two or more (the coarsest included), else
/// dispatches every level's passes.
#[test]
fn the_coarse_cycle_starts_at_the_first_level_of_at_most_16_cubed() {
    use super::record::cycle_start;
    let start = |dims: [u32; 3]| cycle_start(&unit_grid(dims, 1));
    assert_eq!(start([32; 3]), Some(1), "32³: 16³, 8³, 4³ in one workgroup");
    assert_eq!(start([64; 3]), Some(2), "64³: 16³ and below");
    assert_eq!(start([16; 3]), Some(1), "16³: the finest stays dispatched");
    assert_eq!(start([64, 64, 16]), Some(2), "64 × 64 × 16: 16 × 16 × 4 and below");
    assert_eq!(start([8; 3]), None, "8³: the coarsest alone below the finest");
    assert_eq!(start([4; 3]), None, "one level");
}
