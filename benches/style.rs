//! What holding a style and colliding with the character cost: per-step GPU
//! time (timestamp queries) of the simulation with the global and local shape
//! constraints and with the mesh collider, each as a ratio to the same step
//! without them, in one run; and the mesh collider's build time (GPU) for the
//! Sintel bust at 64 and 128 grid points along its longest axis, against the
//! CPU reference build.
//!
//! Scenes: `thesis` (1750 × 6, 20 iterations) and a 2,228 × 32 groom (3
//! iterations, as in `benches/sim.rs`). The mesh collider is the thesis head
//! sphere as a 24 × 32 triangle mesh at 64³ (the analytic sphere stays, so the
//! only difference is the field's sampling). `-- summary` prints only the table,
//! which is also written to `target/vkhair-bench/style.csv`.

mod common;

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes::{self, THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS};
use vkhair::groom::sdf::MeshSdf;
use vkhair::groom::Groom;
use vkhair::sim::{motion, HairSim, MeshCollider, MeshColliderParams, RigidTransform, SimParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

struct Scene {
    name: &'static str,
    groom: Groom,
    params: SimParams,
}

fn scenes() -> Vec<Scene> {
    let p = GrowParams { strands: 2228, points_per_strand: 32, length: 0.35, seed: 3, ..GrowParams::default() };
    vec![
        Scene { name: "thesis 1750x6 it20", groom: scenes::thesis().expect("thesis"), params: SimParams::default() },
        Scene {
            name: "2228x32 it3",
            groom: grow(&scenes::thesis_scalp(), &p).expect("groom"),
            params: SimParams { iterations: 3, ..SimParams::default() },
        },
    ]
}

/// The configurations: name, parameters, whether the mesh collider is set.
fn configs(base: &SimParams) -> Vec<(&'static str, SimParams, bool)> {
    let shape =
        SimParams { global_shape_stiffness: 0.15, global_shape_range: 1.0, local_shape_stiffness: 0.5, ..base.clone() };
    vec![
        ("baseline (spheres, capsules)", base.clone(), false),
        ("+ global and local shape", shape.clone(), false),
        ("+ mesh collider 64^3", base.clone(), true),
        ("+ shape and mesh collider", shape, true),
    ]
}

fn head(i: usize) -> RigidTransform {
    motion::reference_motion(i as f32 / 60.0)
}

fn head_mesh() -> TriMesh {
    TriMesh::uv_sphere(THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS, 24, 32).expect("sphere")
}

fn make_sim(ctx: &GpuContext, scene: &Scene, params: &SimParams, mesh: bool) -> HairSim {
    let mut sim = HairSim::new(ctx, &scene.groom, params, &RigidTransform::default()).expect("sim");
    sim.set_colliders(&motion::thesis_colliders()).expect("colliders");
    if mesh {
        sim.set_mesh(Some(&head_mesh()), &MeshColliderParams::default()).expect("mesh collider");
    }
    sim
}

/// GPU time of `steps` steps: the sum of the stage scopes.
fn gpu_time(sim: &mut HairSim, profiler: &mut GpuProfiler, start: usize, steps: usize) -> Duration {
    let report = sim.run(steps, |i| head(start + i), Some(profiler)).expect("run").expect("timestamps");
    Duration::from_nanos(report.totals_by_name().iter().map(|(_, t)| t).sum::<f64>() as u64)
}

fn bench_style(c: &mut Criterion) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024).expect("profiler");
    for scene in scenes() {
        let mut g = c.benchmark_group(format!("style step {}", scene.name));
        g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
        for (name, params, mesh) in configs(&scene.params) {
            let mut sim = make_sim(&ctx, &scene, &params, mesh);
            gpu_time(&mut sim, &mut profiler, 0, 2);
            let mut at = 2;
            g.bench_function(name, |b| {
                b.iter_custom(|iters| {
                    let t = gpu_time(&mut sim, &mut profiler, at, iters as usize);
                    at += iters as usize;
                    t
                })
            });
        }
        g.finish();
    }
}

fn sintel_bust() -> Option<TriMesh> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/sintel/sintel_bust.obj");
    if !path.exists() {
        println!("mesh collider build: skipped, {} is absent", path.display());
        return None;
    }
    Some(TriMesh::load_obj(&path).expect("bust"))
}

fn summary(quick: bool) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024).expect("profiler");
    let steps = if quick { 4 } else { 10 };
    let mut csv = String::from("scene,config,ms_per_step,ratio_to_baseline\n");
    println!("\n{} — style constraints and mesh collider, GPU time from timestamps", ctx.info().name);
    println!("{:<22} {:<30} {:>10} {:>12}", "scene", "config", "ms/step", "vs baseline");
    for scene in scenes() {
        // Rounds over every configuration in turn, so that drifts of the machine
        // (a software rasterizer shares the CPU) hit all of them alike; the median
        // round is reported.
        let configs = configs(&scene.params);
        let mut sims: Vec<HairSim> = configs.iter().map(|(_, p, mesh)| make_sim(&ctx, &scene, p, *mesh)).collect();
        let mut times = vec![Vec::new(); sims.len()];
        let rounds = if quick { 1 } else { 5 };
        for round in 0..=rounds {
            for (sim, t) in sims.iter_mut().zip(&mut times) {
                let ms = gpu_time(sim, &mut profiler, round * steps, steps).as_secs_f64() * 1e3 / steps as f64;
                // Round 0 warms up (shader compilation, caches).
                if round > 0 {
                    t.push(ms);
                }
            }
        }
        let median = |t: &mut Vec<f64>| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        };
        let base = median(&mut times[0]);
        for ((name, _, _), t) in configs.iter().zip(&mut times) {
            let ms = median(t);
            println!("{:<22} {:<30} {:>10.3} {:>11.2}x", scene.name, name, ms, ms / base);
            let _ = writeln!(csv, "{},{name},{ms:.4},{:.3}", scene.name, ms / base);
        }
    }
    if let Some(bust) = sintel_bust() {
        println!("\nmesh collider build, Sintel bust ({} triangles)", bust.triangles.len());
        println!("{:<12} {:>14} {:>12} {:>16} {:>9}", "resolution", "grid", "GPU ms", "CPU reference ms", "CPU/GPU");
        // The bust is in centimetres: a 2 cm margin.
        for resolution in [64, 128] {
            let params = MeshColliderParams { resolution, margin: 2.0 };
            let (collider, report) = MeshCollider::new_profiled(&ctx, &bust, &params, &mut profiler).expect("build");
            let gpu_ms = report.map_or(f64::NAN, |r| r.total_nanoseconds() / 1e6);
            let t0 = Instant::now();
            let _ = MeshSdf::build(&bust, resolution, 2.0).expect("cpu build");
            let cpu_ms = t0.elapsed().as_secs_f64() * 1e3;
            let [nx, ny, nz] = collider.dims();
            println!(
                "{:<12} {:>14} {:>12.1} {:>16.1} {:>8.1}x",
                resolution,
                format!("{nx}x{ny}x{nz}"),
                gpu_ms,
                cpu_ms,
                cpu_ms / gpu_ms
            );
            let _ = writeln!(csv, "sintel bust,build {resolution},{gpu_ms:.3},{:.3}", cpu_ms / gpu_ms);
        }
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("style.csv"), csv).is_ok() {
        println!("written to {}", dir.join("style.csv").display());
    }
}

criterion_group!(benches, bench_style);

fn main() {
    common::criterion_then_summary(benches, summary);
}
