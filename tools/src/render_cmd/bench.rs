//! What `vkhair bench` measures of a render frame: `render`'s scene, parameters
//! and renderer, timed per frame.

use glam::Vec3;
use vkhair::headless::{Offscreen, Submit};
use vkhair::sim::RigidTransform;
use vkhair::{GpuContext, GpuProfiler};

use super::{check_options, framing, make_renderer, parameters, scene, RenderArgs};
use crate::output::Error;

/// What `vkhair bench` measures of a frame: the render passes' GPU time (from
/// their timestamp scopes), the wall time of the submission holding them (the
/// simulation's steps go in a submission of their own before it), and what
/// the render passes record.
pub struct FrameFigures {
    pub gpu: crate::bench_measure::Samples,
    pub wall: crate::bench_measure::Samples,
    pub work: vkhair::RecordedWork,
    pub hairs: u64,
    pub segments: u64,
    pub pixels: u64,
    /// GPU memory of the transparency mode (lists or accumulation images), bytes.
    pub transparency_bytes: u64,
}

/// Renders `samples` frames (after two warm-up frames) of the scene `render`
/// would draw with `args` (its flags, e.g. `["--width", "1280"]`), the
/// simulation on the same queue, and measures the render passes.
pub fn bench_frames(ctx: &GpuContext, args: &[&str], samples: usize) -> Result<FrameFigures, Error> {
    #[derive(clap::Parser)]
    struct Wrapper {
        #[command(flatten)]
        render: RenderArgs,
    }
    let a = <Wrapper as clap::Parser>::try_parse_from(std::iter::once("render").chain(args.iter().copied()))
        .map_err(|e| format!("bench render arguments: {e}"))?
        .render;
    check_options(&a)?;
    let s = scene(&a)?;
    let config = parameters(&a, s.center, s.radius)?;
    let mut sim = vkhair::sim::HairSim::new(ctx, &s.groom, &config.sim, &RigidTransform::default())?;
    sim.set_colliders(&s.colliders)?;
    let mut renderer = make_renderer(&a, ctx, &config, sim.key_hairs(), s.radius)?;
    let offscreen = Offscreen::new(ctx, a.width, a.height)?;
    let camera = framing(&s, a.distance, a.width as f32 / a.height as f32)?;
    let mut profiler = GpuProfiler::new(ctx, 1, 64)?;
    let (lo, hi) = s.groom.bounds();
    let size = (hi - lo).max_element();
    let (hairs, per_hair) = renderer.hair_counts();
    let mut figures = FrameFigures {
        gpu: Default::default(),
        wall: Default::default(),
        work: Default::default(),
        hairs: u64::from(hairs),
        segments: u64::from(hairs) * u64::from(per_hair.saturating_sub(1)),
        pixels: u64::from(a.width) * u64::from(a.height),
        transparency_bytes: renderer
            .transparency_memory(vkhair::ash::vk::Extent2D { width: a.width, height: a.height }),
    };
    for frame in 0..samples + 2 {
        let heads: Vec<RigidTransform> =
            (0..2).map(|k| a.motion.head((frame * 2 + k + 1) as f32 * config.sim.dt, s.pivot, size)).collect();
        sim.run(heads.len(), |k| heads[k], None)?;
        let started = std::time::Instant::now();
        let mut render_work = vkhair::RecordedWork::default();
        let mut result = Ok(());
        ctx.run_commands("vkhair bench frame", |cmd| {
            // SAFETY: a recording command buffer of the context's device; the
            // previous frame completed (run_commands waits) and was drained.
            result = unsafe {
                (|| -> Result<(), vkhair::Error> {
                    profiler.begin_frame(cmd, frame as u64);
                    let before = ctx.recorded_work();
                    renderer.record_prepare(cmd, &sim, Some(&camera), Some(&mut profiler))?;
                    renderer.record_shadows(cmd, &sim, Some(&mut profiler))?;
                    offscreen.record_clear(cmd, Vec3::splat(0.02));
                    renderer.record_draw(cmd, frame as u64, &offscreen.target(), &camera, Some(&mut profiler))?;
                    render_work = ctx.recorded_work() - before;
                    Ok(())
                })()
            };
        })?;
        result?;
        let wall = started.elapsed().as_secs_f64() * 1e3;
        let report = profiler.drain().pop().ok_or("the device wrote no timestamps")?;
        if frame >= 2 {
            figures.gpu.0.push(report.total_nanoseconds() / 1e6);
            figures.wall.0.push(wall);
            figures.work = render_work;
        }
    }
    Ok(figures)
}
