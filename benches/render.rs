//! Render cost over the grid of seed 000's Table 5: GPU time per pass
//! (smoothing, interpolation, draw, and the resolve with 2× supersampling)
//! from timestamp queries for the `thesis` scene at 800×600, 1024×712,
//! 1152×802 and 1280×968 and camera distances 0.2, 0.4, 0.6, 1.0, 1.5 and
//! 3.0 m (level of detail on), without and with supersampling. Printed as a
//! table and written to `target/vkhair-bench/render.csv`; `vkhair plot` charts it.
//!
//! A second table (`target/vkhair-bench/shadows.csv`) times self-shadowing at
//! 800×600 and 1280×968, camera at 0.6 m: the two opacity-map passes and the
//! lighting (draw) pass with 0, 1 and 2 shadow-casting lights, and with both
//! lights shadowed through the simulation's density volume instead.
//!
//! `cargo bench --features bench --bench render` (add `-- quick` for one resolution, `-- shadows`
//! for the shadow table alone).

use std::fmt::Write as _;

use glam::Vec3;
use vkhair::groom::scenes;
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::{Camera, Light, RenderParams, RenderPass, Renderer, ShadowCaster, ShadowParams};

const PASSES: [RenderPass; 4] = [RenderPass::Smooth, RenderPass::Interpolate, RenderPass::Draw, RenderPass::Resolve];
use vkhair::sim::{motion, HairSim, RigidTransform, SimParams, VolumeMode, VolumeParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    // `-- shadows` runs only the shadow table.
    let shadows_only = std::env::args().any(|a| a == "shadows");
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let groom = scenes::thesis().expect("thesis");
    // The volume stage (friction, the cheap mode) provides the density volume the
    // density-volume shadows read; it does not change the render passes' cost.
    let sim_params = SimParams {
        volume: VolumeParams { mode: VolumeMode::Friction, ..VolumeParams::default() },
        ..SimParams::default()
    };
    let mut sim = HairSim::new(&ctx, &groom, &sim_params, &RigidTransform::default()).expect("sim");
    sim.set_colliders(&motion::thesis_colliders()).expect("colliders");
    sim.run(30, |i| motion::reference_motion((i + 1) as f32 / 60.0), None).expect("settle");
    let mut renderer = Renderer::new(&ctx, &sim, &RenderParams::default()).expect("renderer");
    renderer
        .set_lights(&[
            Light::Directional { direction: Vec3::new(0.4, -0.3, -1.0), color: Vec3::splat(0.9) },
            Light::Directional { direction: Vec3::new(-0.8, -0.2, -0.3), color: Vec3::splat(0.3) },
            Light::Directional { direction: Vec3::new(0.0, -0.3, 1.0), color: Vec3::splat(0.3) },
        ])
        .expect("lights");
    let mut profiler = GpuProfiler::new(&ctx, 1, 16).expect("profiler");
    let resolutions: &[(u32, u32)] =
        if quick { &[(800, 600)] } else { &[(800, 600), (1024, 712), (1152, 802), (1280, 968)] };
    let distances = [0.2f32, 0.4, 0.6, 1.0, 1.5, 3.0];
    let frames = FRAMES;
    let mut csv = String::from(
        "width,height,ssaa,distance_m,hairs,segments,smooth_ms,interpolate_ms,draw_ms,resolve_ms,total_ms\n",
    );
    println!("{} — thesis scene, GPU ms per pass (mean of {frames} frames after one warm-up)", ctx.info().name);
    println!(
        "{:>10} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "size", "ssaa", "dist", "hairs", "segments", "smooth", "interp", "draw", "resolve", "total"
    );
    let mut frame = 0u64;
    let grid = if shadows_only { &[][..] } else { resolutions };
    for (&(w, h), ssaa) in grid.iter().flat_map(|r| [(r, false), (r, true)]) {
        let params = RenderParams { supersampling: ssaa, ..renderer.params().clone() };
        renderer.set_params(&params).expect("params");
        let offscreen = Offscreen::new(&ctx, w, h).expect("offscreen");
        for &distance in &distances {
            let camera = camera_at(w, h, distance);
            let sums = frames_mean(&ctx, &sim, &mut renderer, &mut profiler, &camera, &offscreen, &mut frame, &PASSES);
            let (hairs, per_hair) = renderer.hair_counts();
            let segments = u64::from(hairs) * u64::from(per_hair - 1);
            let total: f64 = sums.iter().sum();
            println!(
                "{:>10} {:>5} {:>6.1} {:>7} {:>9} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3}",
                format!("{w}x{h}"),
                if ssaa { "2x" } else { "off" },
                distance,
                hairs,
                segments,
                sums[0],
                sums[1],
                sums[2],
                sums[3],
                total
            );
            let _ = writeln!(
                csv,
                "{w},{h},{},{distance},{hairs},{segments},{:.4},{:.4},{:.4},{:.4},{total:.4}",
                u8::from(ssaa),
                sums[0],
                sums[1],
                sums[2],
                sums[3]
            );
        }
    }
    if !shadows_only {
        write_csv("render.csv", &csv);
    }
    shadow_table(&ctx, &sim, &mut renderer, &mut profiler, quick, frame);
}

/// A camera `distance` meters in front of the thesis head for a `w` × `h` image.
fn camera_at(w: u32, h: u32, distance: f32) -> Camera {
    let center = scenes::THESIS_HEAD_CENTER;
    Camera::look_at(
        center + Vec3::new(0.0, 0.0, distance),
        center - Vec3::new(0.0, 0.1, 0.0),
        0.7,
        w as f32 / h as f32,
        0.01,
        20.0,
    )
    .expect("camera")
}

/// Frames measured per configuration, after one warm-up frame.
const FRAMES: u32 = 3;

/// Mean GPU ms of `passes` over `FRAMES` frames (prepare, shadows, draw).
#[allow(clippy::too_many_arguments)]
fn frames_mean(
    ctx: &GpuContext,
    sim: &HairSim,
    renderer: &mut Renderer,
    profiler: &mut GpuProfiler,
    camera: &Camera,
    offscreen: &Offscreen,
    frame: &mut u64,
    passes: &[RenderPass],
) -> Vec<f64> {
    let mut sums = vec![0.0f64; passes.len()];
    for k in 0..=FRAMES {
        ctx.run_commands("bench frame", |cmd| {
            // SAFETY: a recording command buffer of the context's device; the
            // previous frame completed (run_commands waits).
            unsafe {
                profiler.begin_frame(cmd, *frame);
                renderer.record_prepare(cmd, sim, Some(camera), Some(&mut *profiler)).expect("prepare");
                // Without casters this only marks every light unshadowed.
                renderer.record_shadows(cmd, sim, Some(&mut *profiler)).expect("shadows");
                offscreen.record_clear(cmd, Vec3::ZERO);
                renderer.record_draw(cmd, *frame, &offscreen.target(), camera, Some(&mut *profiler)).expect("draw");
            }
        })
        .expect("submit");
        *frame += 1;
        let report = profiler.drain().pop().expect("timestamps");
        if k > 0 {
            for (sum, pass) in sums.iter_mut().zip(passes) {
                *sum += report.pass(pass.label()).unwrap_or(0.0) / 1e6 / f64::from(FRAMES);
            }
        }
    }
    sums
}

fn write_csv(name: &str, csv: &str) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join(name), csv).is_ok() {
        println!("written to {}", dir.join(name).display());
    }
}

/// GPU ms of the shadow passes and the lighting pass per shadow configuration.
fn shadow_table(
    ctx: &GpuContext,
    sim: &HairSim,
    renderer: &mut Renderer,
    profiler: &mut GpuProfiler,
    quick: bool,
    mut frame: u64,
) {
    let params = RenderParams { supersampling: false, ..renderer.params().clone() };
    renderer.set_params(&params).expect("params");
    let configs: [(&str, Vec<ShadowCaster>); 4] = [
        ("no shadows", vec![]),
        ("1 opacity map", vec![0.into()]),
        ("2 opacity maps", vec![0.into(), 1.into()]),
        ("2 density volume", vec![ShadowCaster::density_volume(0), ShadowCaster::density_volume(1)]),
    ];
    let passes = [RenderPass::ShadowDepth, RenderPass::ShadowOpacity, RenderPass::ShadowVolume, RenderPass::Draw];
    let resolutions: &[(u32, u32)] = if quick { &[(800, 600)] } else { &[(800, 600), (1280, 968)] };
    let mut csv =
        String::from("width,height,config,shadow_depth_ms,shadow_opacity_ms,shadow_volume_ms,draw_ms,total_ms\n");
    println!("\n{} — thesis scene at 0.6 m, self-shadowing (512² maps), GPU ms per pass", ctx.info().name);
    println!(
        "{:>10} {:<18} {:>12} {:>14} {:>13} {:>9} {:>9}",
        "size", "shadows", "shadow depth", "shadow opacity", "shadow volume", "draw", "total"
    );
    for &(w, h) in resolutions {
        let offscreen = Offscreen::new(ctx, w, h).expect("offscreen");
        let camera = camera_at(w, h, 0.6);
        for (name, casters) in &configs {
            let shadows = ShadowParams { casters: casters.clone(), ..ShadowParams::default() };
            renderer.set_shadows(sim, &shadows).expect("shadows");
            let sums = frames_mean(ctx, sim, renderer, profiler, &camera, &offscreen, &mut frame, &passes);
            let total: f64 = sums.iter().sum();
            println!(
                "{:>10} {:<18} {:>12.3} {:>14.3} {:>13.3} {:>9.3} {:>9.3}",
                format!("{w}x{h}"),
                name,
                sums[0],
                sums[1],
                sums[2],
                sums[3],
                total
            );
            let _ =
                writeln!(csv, "{w},{h},{name},{:.4},{:.4},{:.4},{:.4},{total:.4}", sums[0], sums[1], sums[2], sums[3]);
        }
    }
    renderer.set_shadows(sim, &ShadowParams::default()).expect("shadows off");
    write_csv("shadows.csv", &csv);
}
