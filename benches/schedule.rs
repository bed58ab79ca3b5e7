//! Frame time of the `thesis` scene in each scheduling mode: the simulation with
//! the FLIP volume step at 32³ (one 1/60 s step per frame), rendering 28,000
//! hairs at 640×480 with the thesis' three lights, two of them casting deep
//! opacity map shadows.
//!
//! For each mode and pipelining choice the table gives the host's wall-clock time
//! per frame (the host records a frame, submits it and waits for it, as a
//! one-frame-in-flight renderer would), its ratio to SINGLE QUEUE with latency
//! measured in the same run, the GPU time of the rendering device's passes and of
//! the simulation from timestamp queries, and how long the two overlapped on the
//! host clock (calibrated timestamps; SINGLE QUEUE runs both in one queue, so
//! nothing overlaps there). Written to `target/vkhair-bench/schedule.csv`.
//!
//! On lavapipe every "device" is the same CPU cores, so a second queue or device
//! cannot be faster; the figures show the hand-off cost and that the overlap
//! happens. `cargo bench --features bench --bench schedule` (`-- summary` skips criterion,
//! `-- quick` measures fewer frames).

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use criterion::{criterion_group, Criterion};
use glam::Vec3;
use vkhair::groom::scenes::{self, THESIS_BOUNDING_RADIUS, THESIS_HEAD_CENTER};
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::{Camera, Light, RenderParams, Renderer, ShadowParams};
use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
use vkhair::sim::{motion, RigidTransform, SimParams, VolumeParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler, ProfileReport};

mod common;

const W: u32 = 640;
const H: u32 = 480;

struct Frame {
    scheduler: FrameScheduler,
    renderer: Renderer,
    offscreen: Offscreen,
    camera: Camera,
    profiler: GpuProfiler,
    step: usize,
    frame: u64,
}

/// The configurations measured, baseline first.
fn configs() -> Vec<(&'static str, ScheduleMode, Option<HandOff>, Pipelining)> {
    use Pipelining::{Latency, Throughput};
    vec![
        ("single queue, latency", ScheduleMode::SingleQueue, None, Latency),
        ("single queue, throughput", ScheduleMode::SingleQueue, None, Throughput),
        ("async compute, throughput", ScheduleMode::AsyncCompute, None, Throughput),
        ("second device ext, latency", ScheduleMode::SecondDevice, Some(HandOff::ExternalMemory), Latency),
        ("second device ext, throughput", ScheduleMode::SecondDevice, Some(HandOff::ExternalMemory), Throughput),
        ("second device staging, throughput", ScheduleMode::SecondDevice, Some(HandOff::HostStaging), Throughput),
    ]
}

fn setup(
    ctx: &GpuContext,
    sim_ctx: &GpuContext,
    mode: ScheduleMode,
    hand_off: Option<HandOff>,
    pipelining: Pipelining,
) -> Frame {
    let groom = scenes::thesis().expect("thesis");
    let params = SimParams { volume: VolumeParams::flip([32, 32, 32]), ..SimParams::default() };
    let options = SchedulerOptions {
        mode: Some(mode),
        pipelining,
        hand_off,
        sim_device: (mode == ScheduleMode::SecondDevice).then(|| sim_ctx.clone()),
        // lavapipe has no second queue: the async hand-off then runs on the one queue.
        async_on_graphics_queue: true,
        ..SchedulerOptions::default()
    };
    let scheduler =
        FrameScheduler::new(ctx, &groom, &params, &RigidTransform::default(), &motion::thesis_colliders(), &options)
            .expect("scheduler");
    let mut renderer = Renderer::new(ctx, scheduler.key_hairs(), &RenderParams::default()).expect("renderer");
    renderer.set_lights(&Light::thesis_rig(THESIS_HEAD_CENTER, THESIS_BOUNDING_RADIUS)).expect("lights");
    let shadows = ShadowParams { casters: vec![0.into(), 1.into()], ..ShadowParams::default() };
    renderer.set_shadows(scheduler.key_hairs(), &shadows).expect("shadows");
    let camera = Camera::look_at(
        THESIS_HEAD_CENTER + Vec3::new(0.0, 0.05, 0.9),
        THESIS_HEAD_CENTER - Vec3::new(0.0, 0.08, 0.0),
        40f32.to_radians(),
        W as f32 / H as f32,
        0.01,
        10.0,
    )
    .expect("camera");
    Frame {
        scheduler,
        renderer,
        offscreen: Offscreen::new(ctx, W, H).expect("offscreen"),
        camera,
        profiler: GpuProfiler::new(ctx, 1, 1024).expect("profiler"),
        step: 0,
        frame: 0,
    }
}

/// One frame: wall time, the render device's profile and the latest simulation
/// profile (SECOND DEVICE and ASYNC COMPUTE).
fn frame(ctx: &GpuContext, f: &mut Frame) -> (Duration, Option<ProfileReport>, Option<ProfileReport>) {
    f.step += 1;
    let head = motion::shaking_head_about(f.step as f32 / 60.0, 0.6, 1.0, motion::NECK_PIVOT);
    let t0 = Instant::now();
    let Frame { scheduler, renderer, offscreen, camera, profiler, frame, .. } = f;
    ctx.run_frame("bench frame", |cmd| {
        // SAFETY: a recording command buffer of the rendering device; the previous
        // frame was waited for.
        unsafe {
            let _ = profiler.begin_frame(cmd, *frame);
            let sync = scheduler.record_frame(cmd, &[head], Some(profiler))?;
            renderer.record_prepare(cmd, scheduler.key_hairs(), Some(camera), Some(profiler))?;
            renderer.record_shadows(cmd, scheduler.key_hairs(), Some(profiler))?;
            offscreen.record_clear(cmd, Vec3::splat(0.02));
            renderer.record_draw(cmd, *frame, &offscreen.target(), camera, Some(profiler))?;
            Ok(sync)
        }
    })
    .expect("frame");
    let wall = t0.elapsed();
    *frame += 1;
    (wall, profiler.drain().pop(), scheduler.sim_profile())
}

fn sim_ns(report: &ProfileReport) -> f64 {
    report.passes.iter().filter(|p| p.depth == 0 && p.name.starts_with("vkhair sim")).map(|p| p.nanoseconds).sum()
}

fn summary(frames: usize) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let sim_ctx = GpuContext::headless(&ContextOptions::default()).expect("simulation context");
    println!(
        "{} — thesis scene (32³ FLIP, 28,000 hairs, 2 opacity maps, {W}×{H}), mean of {frames} frames",
        ctx.info().name
    );
    println!(
        "{:<36} {:>9} {:>8} {:>10} {:>9} {:>10}",
        "mode", "frame ms", "ratio", "render ms", "sim ms", "overlap ms"
    );
    let mut csv = String::from("mode,frame_ms,ratio,render_gpu_ms,sim_gpu_ms,overlap_ms\n");
    let mut baseline = None;
    for (name, mode, hand_off, pipelining) in configs() {
        let mut f = setup(&ctx, &sim_ctx, mode, hand_off, pipelining);
        for _ in 0..3 {
            frame(&ctx, &mut f);
        }
        let (mut wall, mut render, mut sim, mut overlap, mut overlaps) = (0.0, 0.0, 0.0, 0.0, 0);
        for _ in 0..frames {
            let (w, r, s) = frame(&ctx, &mut f);
            wall += w.as_secs_f64() * 1e3;
            if let Some(r) = &r {
                // SINGLE QUEUE: the simulation's passes are in the render profile.
                let in_render = sim_ns(r);
                render += (r.total_nanoseconds() - in_render) / 1e6;
                sim += in_render / 1e6;
                if let Some(s) = &s {
                    sim += s.total_nanoseconds() / 1e6;
                    if let Some(o) = r.overlap_ns(s) {
                        overlap += o / 1e6;
                        overlaps += 1;
                    }
                }
            }
        }
        let n = frames as f64;
        let ms = wall / n;
        let base = *baseline.get_or_insert(ms);
        let overlap = if overlaps > 0 { overlap / f64::from(overlaps) } else { 0.0 };
        println!("{name:<36} {ms:>9.2} {:>7.2}x {:>10.2} {:>9.2} {overlap:>10.2}", ms / base, render / n, sim / n);
        let _ = writeln!(csv, "{name},{ms:.3},{:.4},{:.3},{:.3},{overlap:.3}", ms / base, render / n, sim / n);
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("schedule.csv"), csv).is_ok() {
        println!("written to {}", dir.join("schedule.csv").display());
    }
}

fn bench_schedule(c: &mut Criterion) {
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let sim_ctx = GpuContext::headless(&ContextOptions::default()).expect("simulation context");
    let mut group = c.benchmark_group("thesis frame");
    group.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(5));
    for (name, mode, hand_off, pipelining) in configs() {
        let mut f = setup(&ctx, &sim_ctx, mode, hand_off, pipelining);
        group.bench_function(name, |b| b.iter_custom(|iters| (0..iters).map(|_| frame(&ctx, &mut f).0).sum()));
    }
    group.finish();
}

criterion_group!(benches, bench_schedule);

fn main() {
    common::criterion_then_summary(benches, |quick| summary(if quick { 4 } else { 12 }));
}
