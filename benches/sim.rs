//! Simulation step cost: GPU time from timestamp queries (sum of the stage
//! scopes) against the CPU reference implementation in the same run.
//!
//! Scenes: `thesis` (1750 × 6, 20 iterations); a 2,228 × 32 groom with 3
//! iterations (the size of TressFX's "mohawk" sample); a 10,000 × 32 groom
//! (20 iterations). Solver variants: automatic packing (default),
//! workgroup barriers with as many hairs as fit, and one hair per workgroup.
//! ("auto" uses subgroup barriers when they keep as many lanes busy.)
//!
//! The summary adds the default packing with every root bound to a skinned
//! scalp (`HairSim::bind_scalp_bones`; a small triangle around each root,
//! skinned by one bone): the cost of placing each hair by its root's frame
//! against the same row with the rigid head.
//!
//! Besides criterion's own report, a summary table (ms per step, particle-steps
//! per second, per-stage share, ratio to the CPU reference) is printed and
//! written to `target/vkhair-bench/sim.csv`.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use glam::{Mat4, Vec3};
use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::{scenes, Groom};
use vkhair::sim::scalp::{Scalp, VertexSkin};
use vkhair::sim::{motion, CpuHairSim, HairSim, RigidTransform, SimParams, SimStage};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

struct Scene {
    name: &'static str,
    groom: Groom,
    params: SimParams,
}

fn scenes() -> Vec<Scene> {
    let grown = |strands, points| {
        let p = GrowParams { strands, points_per_strand: points, length: 0.35, seed: 3, ..GrowParams::default() };
        grow(&scenes::thesis_scalp(), &p).expect("groom")
    };
    vec![
        Scene { name: "thesis 1750x6 it20", groom: scenes::thesis().expect("thesis"), params: SimParams::default() },
        Scene {
            name: "mohawk-size 2228x32 it3",
            groom: grown(2228, 32),
            params: SimParams { iterations: 3, ..SimParams::default() },
        },
        Scene { name: "10000x32 it20", groom: grown(10_000, 32), params: SimParams::default() },
    ]
}

fn variants(base: &SimParams) -> Vec<(&'static str, SimParams)> {
    vec![
        ("gpu auto packing (default)", base.clone()),
        ("gpu workgroup sync", SimParams { subgroup_sync: false, ..base.clone() }),
        ("gpu one hair per workgroup", SimParams { subgroup_sync: false, hairs_per_workgroup: 1, ..base.clone() }),
    ]
}

fn head(i: usize) -> RigidTransform {
    motion::reference_motion(i as f32 / 60.0)
}

/// GPU time of `steps` steps (sum of stage scopes) and the per-stage totals.
fn gpu_time(
    sim: &mut HairSim,
    profiler: &mut GpuProfiler,
    start: usize,
    steps: usize,
) -> (Duration, Vec<(String, f64)>) {
    let report = sim.run(steps, |i| head(start + i), Some(profiler)).expect("run").expect("timestamps");
    let totals = report.totals_by_name();
    let ns: f64 = totals.iter().map(|(_, t)| t).sum();
    (Duration::from_nanos(ns as u64), totals)
}

fn make_sim(ctx: &GpuContext, scene: &Scene, params: &SimParams) -> HairSim {
    let mut sim = HairSim::new(ctx, &scene.groom, params, &RigidTransform::default()).expect("sim");
    sim.set_colliders(&motion::thesis_colliders()).expect("colliders");
    sim
}

/// A scalp of one small triangle centred on each root, every vertex on one bone.
fn scalp_under(groom: &Groom) -> Scalp {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for s in 0..groom.strand_count() {
        let root = groom.strand(s)[0];
        let base = positions.len() as u32;
        positions.extend(
            [Vec3::new(2e-3, 0.0, 0.0), Vec3::new(-1e-3, 0.0, 2e-3), Vec3::new(-1e-3, 0.0, -2e-3)].map(|d| root + d),
        );
        triangles.push([base, base + 1, base + 2]);
    }
    let skin = vec![VertexSkin { joints: [0; 4], weights: [1.0, 0.0, 0.0, 0.0] }; positions.len()];
    Scalp { skin, ..Scalp::new(TriMesh::new(positions, triangles).expect("scalp")) }
}

fn bench_sim(c: &mut Criterion) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024).expect("profiler");
    for scene in scenes() {
        let mut g = c.benchmark_group(format!("sim step {}", scene.name));
        g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4));
        let mut cpu = CpuHairSim::new(&scene.groom, &scene.params, &RigidTransform::default()).expect("cpu");
        cpu.set_colliders(&motion::thesis_colliders()).expect("colliders");
        let mut k = 0;
        g.bench_function("cpu reference (baseline)", |b| {
            b.iter(|| {
                k += 1;
                cpu.step(&head(k)).expect("step")
            })
        });
        for (name, params) in variants(&scene.params) {
            let mut sim = make_sim(&ctx, &scene, &params);
            gpu_time(&mut sim, &mut profiler, 0, 2); // JIT warm-up
            let mut at = 2;
            g.bench_function(name, |b| {
                b.iter_custom(|iters| {
                    let (t, _) = gpu_time(&mut sim, &mut profiler, at, iters as usize);
                    at += iters as usize;
                    t
                })
            });
        }
        g.finish();
    }
}

/// A fixed-length measurement of every configuration, printed as one table.
fn summary() {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024).expect("profiler");
    let steps = 10;
    let mut csv = String::from("scene,config,ms_per_step,particle_steps_per_s,ratio_to_cpu,step_share\n");
    println!("\n{} — simulation step, GPU time from timestamps, CPU reference in the same run", ctx.info().name);
    println!(
        "{:<26} {:<28} {:>10} {:>14} {:>9}  share of the step kernel",
        "scene", "config", "ms/step", "particle-st/s", "vs CPU"
    );
    for scene in scenes() {
        let particles = scene.groom.point_count() as f64;
        let mut cpu = CpuHairSim::new(&scene.groom, &scene.params, &RigidTransform::default()).expect("cpu");
        cpu.set_colliders(&motion::thesis_colliders()).expect("colliders");
        cpu.step(&head(0)).expect("warm-up");
        let t0 = Instant::now();
        for i in 0..steps {
            cpu.step(&head(i + 1)).expect("step");
        }
        let cpu_ms = t0.elapsed().as_secs_f64() * 1e3 / steps as f64;
        let row = |config: &str, ms: f64, shares: [f64; 1], csv: &mut String| {
            let rate = particles / (ms / 1e3);
            println!(
                "{:<26} {:<28} {:>10.3} {:>14.3e} {:>8.2}x  {:.0} %",
                scene.name,
                config,
                ms,
                rate,
                cpu_ms / ms,
                shares[0]
            );
            let _ = writeln!(csv, "{},{config},{ms:.4},{rate:.1},{:.3},{:.1}", scene.name, cpu_ms / ms, shares[0]);
        };
        row("cpu reference (baseline)", cpu_ms, [0.0; 1], &mut csv);
        for (name, params) in variants(&scene.params) {
            let mut sim = make_sim(&ctx, &scene, &params);
            gpu_time(&mut sim, &mut profiler, 0, 2);
            let (t, totals) = gpu_time(&mut sim, &mut profiler, 2, steps);
            let total: f64 = totals.iter().map(|(_, v)| v).sum();
            let share = |stage: SimStage| {
                100.0 * totals.iter().find(|(n, _)| n == stage.label()).map_or(0.0, |(_, v)| *v) / total
            };
            let shares = [share(SimStage::Step)];
            row(name, t.as_secs_f64() * 1e3 / steps as f64, shares, &mut csv);
        }
        let mut sim = make_sim(&ctx, &scene, &scene.params);
        sim.bind_scalp_bones(&scalp_under(&scene.groom), &[Mat4::IDENTITY]).expect("scalp");
        gpu_time(&mut sim, &mut profiler, 0, 2);
        let (t, _) = gpu_time(&mut sim, &mut profiler, 2, steps);
        row("gpu auto, skinned scalp", t.as_secs_f64() * 1e3 / steps as f64, [100.0], &mut csv);
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("sim.csv"), csv).is_ok() {
        println!("written to {}", dir.join("sim.csv").display());
    }
}

criterion_group!(benches, bench_sim);

fn main() {
    // `cargo bench --features bench --bench sim -- summary` prints only the table.
    let summary_only = std::env::args().any(|a| a == "summary");
    if !summary_only {
        benches();
        Criterion::default().configure_from_args().final_summary();
    }
    summary();
}
