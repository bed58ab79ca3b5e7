//! The volume stage on the `thesis` scene (1750 × 6 key hairs, 20 iterations,
//! shaking head), the thesis' Tables 2–4 side by side: for 16³, 32³ and 64³
//! grids, GPU ms per full step (timestamps), the volume stage's share of it,
//! and PCG iterations per step for the GPU with the Jacobi and the multigrid
//! preconditioner and for the CPU reference with MIC(0). Baselines measured in
//! the same run: the GPU step without the volume stage, and the CPU reference
//! with the same volume stage.
//!
//! The table is printed and written to `target/vkhair-bench/volume.csv`;
//! `vkhair plot target/vkhair-bench/volume.csv` charts it. Criterion measures
//! the GPU step at 32³ with each preconditioner. `-- summary` skips criterion;
//! `-- quick` measures fewer steps.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use vkhair::groom::{scenes, Groom};
use vkhair::sim::{
    motion, CpuHairSim, HairSim, Preconditioner, RigidTransform, SimParams, SimStage, VolumeMode, VolumeParams,
};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

mod common;

fn head(i: usize) -> RigidTransform {
    motion::reference_motion(i as f32 / 60.0)
}

fn params(resolution: u32, preconditioner: Preconditioner) -> SimParams {
    SimParams {
        volume: VolumeParams { preconditioner, max_iterations: 200, ..VolumeParams::flip([resolution; 3]) },
        ..SimParams::default()
    }
}

fn make_sim(ctx: &GpuContext, groom: &Groom, params: &SimParams) -> HairSim {
    let mut sim = HairSim::new(ctx, groom, params, &RigidTransform::default()).expect("sim");
    sim.set_colliders(&motion::thesis_colliders()).expect("colliders");
    sim
}

/// Per step: GPU ms (all scopes), volume-stage ms, PCG iterations. One submission per
/// step so that each step's iteration count can be read.
struct GpuStats {
    ms: f64,
    volume_ms: f64,
    iterations: f64,
}

fn measure_gpu(sim: &mut HairSim, profiler: &mut GpuProfiler, start: usize, steps: usize) -> GpuStats {
    let (mut total, mut volume, mut iterations) = (0.0, 0.0, 0.0);
    for i in 0..steps {
        let report = sim.run(1, |_| head(start + i), Some(profiler)).expect("run").expect("timestamps");
        for (name, ns) in report.totals_by_name() {
            total += ns;
            if SimStage::ALL.iter().any(|s| s.is_volume() && s.label() == name) {
                volume += ns;
            }
        }
        if let Some(stats) = sim.volume_stats().expect("stats") {
            iterations += f64::from(stats.iterations);
        }
    }
    let n = steps as f64;
    GpuStats { ms: total / n / 1e6, volume_ms: volume / n / 1e6, iterations: iterations / n }
}

fn bench_volume(c: &mut Criterion) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 64).expect("profiler");
    let groom = scenes::thesis().expect("thesis");
    let mut g = c.benchmark_group("volume step thesis 32^3");
    g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(5));
    for (name, preconditioner) in [("gpu jacobi", Preconditioner::Jacobi), ("gpu multigrid", Preconditioner::Multigrid)]
    {
        let mut sim = make_sim(&ctx, &groom, &params(32, preconditioner));
        let mut at = 0;
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let s = measure_gpu(&mut sim, &mut profiler, at, iters as usize);
                at += iters as usize;
                Duration::from_secs_f64(s.ms * 1e-3 * iters as f64)
            })
        });
    }
    g.finish();
}

fn summary(steps: usize) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let mut profiler = GpuProfiler::new(&ctx, 1, 64).expect("profiler");
    let groom = scenes::thesis().expect("thesis");
    let warm = 3;
    let mut csv = String::from("grid,config,ms_per_step,volume_ms,volume_share,pcg_iterations,ratio_to_cpu\n");
    println!("\n{} — thesis scene, full simulation step with the volume stage", ctx.info().name);
    println!(
        "{:<6} {:<30} {:>10} {:>10} {:>8} {:>10} {:>8}",
        "grid", "config", "ms/step", "volume ms", "share", "PCG iter", "vs CPU"
    );
    // Baseline without the volume stage.
    let mut plain = make_sim(&ctx, &groom, &SimParams::default());
    measure_gpu(&mut plain, &mut profiler, 0, warm);
    let base = measure_gpu(&mut plain, &mut profiler, warm, steps);
    println!("{:<6} {:<30} {:>10.3}", "-", "gpu, no volume stage (baseline)", base.ms);
    let _ = writeln!(csv, "0,gpu no volume,{:.4},0,0,0,0", base.ms);
    drop(plain);
    for resolution in [16u32, 32, 64] {
        let mut cpu =
            CpuHairSim::new(&groom, &params(resolution, Preconditioner::Multigrid), &RigidTransform::default())
                .expect("cpu");
        cpu.set_colliders(&motion::thesis_colliders()).expect("colliders");
        for i in 0..warm {
            cpu.step(&head(i)).expect("step");
        }
        let mut cpu_iterations = 0.0;
        let t0 = Instant::now();
        for i in 0..steps {
            cpu.step(&head(warm + i)).expect("step");
            cpu_iterations += f64::from(cpu.volume_iterations().unwrap_or(0));
        }
        let cpu_ms = t0.elapsed().as_secs_f64() * 1e3 / steps as f64;
        cpu_iterations /= steps as f64;
        let grid = format!("{resolution}^3");
        let mut row = |config: &str, ms: f64, volume_ms: f64, iterations: f64| {
            let share = if volume_ms > 0.0 { 100.0 * volume_ms / ms } else { f64::NAN };
            println!(
                "{grid:<6} {config:<30} {ms:>10.3} {volume_ms:>10.3} {share:>7.1}% {iterations:>10.2} {:>7.2}x",
                cpu_ms / ms
            );
            let _ = writeln!(
                csv,
                "{resolution},{config},{ms:.4},{volume_ms:.4},{share:.2},{iterations:.3},{:.4}",
                cpu_ms / ms
            );
        };
        row("cpu reference MIC(0)", cpu_ms, f64::NAN, cpu_iterations);
        for (config, preconditioner) in
            [("gpu jacobi", Preconditioner::Jacobi), ("gpu multigrid", Preconditioner::Multigrid)]
        {
            let mut sim = make_sim(&ctx, &groom, &params(resolution, preconditioner));
            measure_gpu(&mut sim, &mut profiler, 0, warm);
            let s = measure_gpu(&mut sim, &mut profiler, warm, steps);
            row(config, s.ms, s.volume_ms, s.iterations);
        }
        let friction = SimParams {
            volume: VolumeParams { mode: VolumeMode::Friction, ..VolumeParams::flip([resolution; 3]) },
            ..SimParams::default()
        };
        let mut sim = make_sim(&ctx, &groom, &friction);
        measure_gpu(&mut sim, &mut profiler, 0, warm);
        let s = measure_gpu(&mut sim, &mut profiler, warm, steps);
        row("gpu friction (no solve)", s.ms, s.volume_ms, 0.0);
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("volume.csv"), csv).is_ok() {
        println!("written to {}", dir.join("volume.csv").display());
    }
}

criterion_group!(benches, bench_volume);

fn main() {
    common::criterion_then_summary(benches, |quick| summary(if quick { 3 } else { 10 }));
}
