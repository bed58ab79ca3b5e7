//! `vkhair render`: headless frames of a simulated, rendered head of hair.

use std::path::{Path, PathBuf};

use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use vkhair::config::Config;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes::{self, THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS};
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::Groom;
use vkhair::headless::{MeshDrawer, Offscreen, Submit};
use vkhair::render::{Camera, InterpolationMode, Light, Primitive, Renderer, ShadingMode, ShadowCaster, ShadowParams};
use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
use vkhair::sim::{motion, Collider, RigidTransform, SimParams, VolumeMode, VolumeParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

/// `--schedule`: where the simulation runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Schedule {
    /// Async compute when the device has a second queue, else single queue.
    Auto,
    /// Recorded in order with rendering on one queue.
    Single,
    /// On a second queue of the rendering device.
    Async,
    /// On a second logical device (same GPU, or --sim-device), worker thread.
    SecondDevice,
}

/// `--hand-off`: how a second device's state reaches the rendering device.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum HandOffArg {
    /// External memory when both devices can share it, else staging.
    Auto,
    /// VK_KHR_external_memory_fd shared memory.
    External,
    /// Host-visible staging buffers.
    Staging,
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Image width, pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Image height, pixels.
    #[arg(long, default_value_t = 480)]
    height: u32,
    /// Frames to render (30 per second of motion).
    #[arg(long, default_value_t = 24)]
    frames: usize,
    /// Output folder for frame PNGs and the contact sheet.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Groom file (.hair or .tfx) instead of the `thesis` scene; it is held in its
    /// authored style unless --config says otherwise (see `SimParams::styled`).
    #[arg(long)]
    input: Option<PathBuf>,
    /// Head mesh (OBJ) to draw, to place the camera by and (with --input) for the
    /// strands to collide with through its signed distance field.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Draw the --obj mesh but do not collide with it.
    #[arg(long)]
    no_mesh_collider: bool,
    /// Multiply input positions (groom and mesh) by this (0.01: Blender units → m).
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
    /// Resample input strands to this many points (at most 64).
    #[arg(long, default_value_t = 16)]
    points: usize,
    /// Parameter file (TOML, see `vkhair config`): simulation, rendering, lights and
    /// material; the flags below win over it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Hairs grown per key hair [default: 16].
    #[arg(long)]
    hairs_per_key: Option<u32>,
    /// Smoothed segments per key segment [default: 4].
    #[arg(long)]
    level: Option<u32>,
    /// Camera distance from the head, meters.
    #[arg(long, default_value_t = 0.9)]
    distance: f32,
    /// Supersample 2× and resolve with the 5-tap filter.
    #[arg(long)]
    ssaa: bool,
    /// Turn level of detail off (always full detail).
    #[arg(long)]
    no_lod: bool,
    /// Grow hairs inside triangles of key-hair roots (barycentric) instead of
    /// around each key hair.
    #[arg(long)]
    barycentric: bool,
    /// Shade with Marschner lookup tables instead of Kajiya-Kay.
    #[arg(long)]
    marschner: bool,
    /// Draw one-pixel lines instead of ribbons.
    #[arg(long)]
    lines: bool,
    /// No self-shadowing (by default the two spot lights cast deep opacity maps).
    #[arg(long)]
    no_shadows: bool,
    /// Side of each light's opacity map, texels.
    #[arg(long, default_value_t = 512)]
    shadow_resolution: u32,
    /// Shadow the spot lights through the simulation's density volume instead of
    /// opacity maps (turns the simulation's FLIP volume stage on).
    #[arg(long)]
    volume_shadows: bool,
    /// Where the simulation runs.
    #[arg(long, value_enum, default_value_t = Schedule::Auto)]
    schedule: Schedule,
    /// SECOND DEVICE hand-off.
    #[arg(long, value_enum, default_value_t = HandOffArg::Auto)]
    hand_off: HandOffArg,
    /// Show each frame's own steps (latency) instead of the previous frame's while
    /// this frame's run (throughput).
    #[arg(long)]
    latency: bool,
    /// Device name substring for the simulation device of --schedule second-device
    /// (default: a second logical device of the rendering GPU).
    #[arg(long)]
    sim_device: Option<String>,
}

/// The scheduler options the flags ask for (creating the simulation device).
fn schedule_options(a: &RenderArgs) -> Result<SchedulerOptions, vkhair::Error> {
    let mode = match a.schedule {
        Schedule::Auto => None,
        Schedule::Single => Some(ScheduleMode::SingleQueue),
        Schedule::Async => Some(ScheduleMode::AsyncCompute),
        Schedule::SecondDevice => Some(ScheduleMode::SecondDevice),
    };
    let sim_device = match a.schedule {
        Schedule::SecondDevice => {
            let options = ContextOptions { device_name: a.sim_device.clone(), ..ContextOptions::default() };
            Some(GpuContext::headless(&options)?)
        }
        _ => None,
    };
    Ok(SchedulerOptions {
        mode,
        sim_device,
        hand_off: match a.hand_off {
            HandOffArg::Auto => None,
            HandOffArg::External => Some(HandOff::ExternalMemory),
            HandOffArg::Staging => Some(HandOff::HostStaging),
        },
        pipelining: if a.latency { Pipelining::Latency } else { Pipelining::Throughput },
        frames_in_flight: 1,
        ..SchedulerOptions::default()
    })
}

struct Scene {
    groom: Groom,
    colliders: Vec<Collider>,
    head_mesh: TriMesh,
    center: Vec3,
    pivot: Vec3,
    credit: Option<&'static str>,
}

fn load_groom(path: &Path, scale: f32, points: usize) -> Result<Groom, vkhair::Error> {
    let groom = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("tfx")) {
        TfxFile::open(path)?.groom
    } else {
        HairFile::open(path)?.groom
    };
    let counts: Vec<u32> = (0..groom.strand_count()).map(|i| groom.strand_len(i) as u32).collect();
    let scaled = groom.positions().iter().map(|p| *p * scale).collect();
    Groom::new(scaled, &counts)?.resampled(points)
}

fn scene(a: &RenderArgs) -> Result<Scene, Box<dyn std::error::Error>> {
    let sintel =
        |p: &Option<PathBuf>| p.as_ref().is_some_and(|p| p.to_string_lossy().to_lowercase().contains("sintel"));
    match &a.input {
        None => Ok(Scene {
            groom: scenes::thesis()?,
            colliders: motion::thesis_colliders(),
            head_mesh: TriMesh::uv_sphere(THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS * 0.97, 24, 32)?,
            center: THESIS_HEAD_CENTER,
            pivot: motion::NECK_PIVOT,
            credit: None,
        }),
        Some(path) => {
            let groom = load_groom(path, a.scale, a.points)?;
            let head_mesh = match &a.obj {
                Some(obj) => {
                    let m = TriMesh::load_obj(obj)?;
                    TriMesh::new(m.positions.iter().map(|p| *p * a.scale).collect(), m.triangles)?
                }
                None => {
                    let (lo, hi) = groom.bounds();
                    TriMesh::uv_sphere(0.5 * (lo + hi), 0.25 * (hi - lo).min_element(), 16, 24)?
                }
            };
            let (lo, hi) = groom.bounds();
            let center = 0.5 * (lo + hi);
            Ok(Scene {
                groom,
                colliders: Vec::new(),
                head_mesh,
                center,
                pivot: Vec3::new(center.x, lo.y, center.z),
                credit: (sintel(&a.input) || sintel(&a.obj))
                    .then_some("Sintel © Blender Foundation | durian.blender.org (CC BY 3.0)"),
            })
        }
    }
}

/// The thesis scene's three lights: two spots (key and fill) and a rim light.
fn lights(center: Vec3) -> Vec<Light> {
    let spot = |offset: Vec3, color: Vec3| Light::Spot {
        position: center + offset,
        direction: -offset,
        outer_angle: 0.6,
        inner_angle: 0.4,
        color,
    };
    vec![
        spot(Vec3::new(-0.6, 0.5, 0.8), Vec3::splat(1.1)),
        spot(Vec3::new(0.9, 0.1, 0.4), Vec3::new(0.25, 0.27, 0.33)),
        Light::Directional { direction: Vec3::new(0.2, -0.3, 1.0), color: Vec3::new(0.25, 0.22, 0.2) },
    ]
}

fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), Box<dyn std::error::Error>> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.write_header()?.write_image_data(rgba)?;
    Ok(())
}

/// Up to 12 frames, halved, on a 4-column sheet.
fn contact_sheet(frames: &[Vec<u8>], width: u32, height: u32) -> (u32, u32, Vec<u8>) {
    let picked: Vec<&Vec<u8>> = if frames.len() <= 12 {
        frames.iter().collect()
    } else {
        (0..12).map(|i| &frames[i * (frames.len() - 1) / 11]).collect()
    };
    let (tw, th) = (width / 2, height / 2);
    let cols = 4u32.min(picked.len() as u32).max(1);
    let rows = (picked.len() as u32).div_ceil(cols).max(1);
    let (sw, sh) = (cols * tw, rows * th);
    let mut sheet = vec![0u8; (sw * sh * 4) as usize];
    for (k, frame) in picked.iter().enumerate() {
        let (ox, oy) = ((k as u32 % cols) * tw, (k as u32 / cols) * th);
        for y in 0..th {
            for x in 0..tw {
                for c in 0..4 {
                    let at =
                        |dx: u32, dy: u32| u32::from(frame[(((2 * y + dy) * width + 2 * x + dx) * 4 + c) as usize]);
                    let v = (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1) + 2) / 4;
                    sheet[(((oy + y) * sw + ox + x) * 4 + c) as usize] = v as u8;
                }
            }
        }
    }
    (sw, sh, sheet)
}

/// The parameters: vkhair's defaults (an `--input` groom held in its authored
/// style, [`SimParams::styled`]), then the `--config` file, then the flags given;
/// the tool's lights when the file lists none. Checked before any GPU work.
fn parameters(a: &RenderArgs, center: Vec3) -> Result<Config, vkhair::Error> {
    let sim = if a.input.is_some() { SimParams::styled() } else { SimParams::default() };
    let base = Config { sim, ..Config::default() };
    let mut config = match &a.config {
        Some(path) => base.load_over(path)?,
        None => base,
    };
    let r = &mut config.render;
    if let Some(level) = a.level {
        r.smoothing_level = level;
    }
    if let Some(hairs) = a.hairs_per_key {
        r.hairs_per_key = hairs;
    }
    r.supersampling |= a.ssaa;
    r.lod.enabled &= !a.no_lod;
    if a.barycentric {
        r.interpolation = InterpolationMode::Barycentric;
    }
    if a.lines {
        r.primitive = Primitive::Lines;
    }
    if a.marschner {
        config.material.shading = ShadingMode::Marschner;
    }
    if a.volume_shadows && config.sim.volume.mode == VolumeMode::Off {
        config.sim.volume = VolumeParams::flip([32, 32, 32]);
    }
    if config.lights.is_empty() {
        config.lights = lights(center);
    }
    config.validate()?;
    Ok(config)
}

pub fn render(a: &RenderArgs) -> Result<(), Box<dyn std::error::Error>> {
    let s = scene(a)?;
    let config = parameters(a, s.center)?;
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let sim_params = config.sim.clone();
    let options = schedule_options(a)?;
    let mut sim = FrameScheduler::new(&ctx, &s.groom, &sim_params, &RigidTransform::default(), &s.colliders, &options)?;
    println!("simulation: {} ({})", sim.mode().name(), sim.reason());
    if a.input.is_some() && a.obj.is_some() && !a.no_mesh_collider {
        sim.set_mesh_collider(Some(&s.head_mesh), &config.mesh_collider)?;
        println!(
            "mesh collider: {} triangles at {} grid points along the longest axis",
            s.head_mesh.triangles.len(),
            config.mesh_collider.resolution
        );
    }
    let params = config.render.clone();
    let mut renderer = Renderer::new(&ctx, sim.key_hairs(), &params)?;
    renderer.set_lights(&config.lights)?;
    if !a.no_shadows {
        // The thesis' setup: both spot lights cast shadows through their own maps.
        let casters = if a.volume_shadows {
            vec![ShadowCaster::density_volume(0), ShadowCaster::density_volume(1)]
        } else {
            vec![0.into(), 1.into()]
        };
        let shadows = ShadowParams { casters, resolution: a.shadow_resolution, ..ShadowParams::default() };
        renderer.set_shadows(sim.key_hairs(), &shadows)?;
    }
    renderer.set_material(&config.material)?;
    let offscreen = Offscreen::new(&ctx, a.width, a.height)?;
    // The head mesh (lit along the key spot light's direction) takes that light's hair
    // shadow the way a host would, through glsl/include/shadow.glsl.
    let head = if a.no_shadows || a.volume_shadows {
        MeshDrawer::new(&ctx, &s.head_mesh)?
    } else {
        MeshDrawer::with_hair_shadows(&ctx, &s.head_mesh, &renderer, 0)?
    };
    let aspect = a.width as f32 / a.height as f32;
    let camera = Camera::look_at(
        s.center + Vec3::new(0.0, 0.05, a.distance),
        s.center - Vec3::new(0.0, 0.08, 0.0),
        40f32.to_radians(),
        aspect,
        0.01,
        10.0,
    )?;
    let mut profiler = GpuProfiler::new(&ctx, 1, 64)?;
    std::fs::create_dir_all(&a.out)?;
    let (strands, points) = sim.key_hairs().size();
    let (hairs, per_hair) = renderer.hair_counts();
    println!(
        "{}: {strands} key hairs × {points} points → {hairs} hairs × {} segments ({} segments), {}×{}, {} frames",
        ctx.info().name,
        per_hair - 1,
        hairs as u64 * (per_hair as u64 - 1),
        a.width,
        a.height,
        a.frames
    );
    let bar = ProgressBar::new(a.frames as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let steps_per_frame = 2; // 1/60 s steps, 30 frames per second
    let mut totals: Vec<(String, f64, u32)> = Vec::new();
    let mut add = |report: vkhair::ProfileReport| {
        for (name, ns) in report.totals_by_name() {
            match totals.iter_mut().find(|(n, _, _)| *n == name) {
                Some(entry) => {
                    entry.1 += ns;
                    entry.2 += 1;
                }
                None => totals.push((name, ns, 1)),
            }
        }
    };
    let mut frames = Vec::new();
    let (mut sim_ns, mut overlap_ns, mut sim_reports) = (0.0, 0.0, 0u32);
    for frame in 0..a.frames {
        let first_step = frame * steps_per_frame;
        let heads: Vec<RigidTransform> = (0..steps_per_frame)
            .map(|k| motion::shaking_head_about((first_step + k + 1) as f32 * sim_params.dt, 0.6, 1.0, s.pivot))
            .collect();
        ctx.run_frame("vkhair render frame", |cmd| {
            // SAFETY: run_frame hands over a recording command buffer of the
            // context's device, submits it with the returned waits and waits for it.
            unsafe {
                if let Some(report) = profiler.begin_frame(cmd, frame as u64) {
                    add(report);
                }
                let sync = sim.record_frame(cmd, &heads, Some(&mut profiler))?;
                renderer.record_prepare(cmd, sim.key_hairs(), Some(&camera), Some(&mut profiler))?;
                renderer.record_shadows(cmd, sim.key_hairs(), Some(&mut profiler))?;
                offscreen.record_clear(cmd, Vec3::splat(0.02));
                let scope = profiler.begin_scope(cmd, "host: head mesh");
                let h = sim.key_hairs().head();
                let view_proj = camera.projection * camera.view;
                head.record(
                    cmd,
                    &offscreen.target(),
                    view_proj,
                    (h.rotation, h.translation),
                    Vec3::new(0.55, 0.4, 0.32),
                    Vec3::new(0.6, -0.5, -0.8),
                );
                profiler.end_scope(cmd, scope);
                renderer.record_draw(cmd, frame as u64, &offscreen.target(), &camera, Some(&mut profiler))?;
                Ok(sync)
            }
        })?;
        // The simulation's own queue or device (ASYNC COMPUTE, SECOND DEVICE).
        if let (Some(sim_report), Some(render_report)) = (sim.sim_profile(), profiler.drain().pop()) {
            sim_ns += sim_report.total_nanoseconds();
            overlap_ns += render_report.overlap_ns(&sim_report).unwrap_or(0.0);
            sim_reports += 1;
            add(render_report);
        }
        let rgba = offscreen.read_rgba8()?;
        write_png(&a.out.join(format!("frame_{frame:04}.png")), a.width, a.height, &rgba)?;
        frames.push(rgba);
        bar.inc(1);
    }
    bar.finish_and_clear();
    for report in profiler.drain() {
        add(report);
    }
    let (sw, sh, sheet) = contact_sheet(&frames, a.width, a.height);
    write_png(&a.out.join("contact_sheet.png"), sw, sh, &sheet)?;
    println!("{:<28} {:>10}", "pass (GPU, mean per frame)", "ms");
    let mut sum = 0.0;
    for (name, ns, count) in &totals {
        // Each report sums a pass over the frame (the simulation's two steps too).
        let per_frame = ns / (*count as f64).max(1.0);
        sum += per_frame;
        println!("{name:<28} {:>10.3}", per_frame / 1e6);
    }
    println!("{:<28} {:>10.3}", "total", sum / 1e6);
    if sim_reports > 0 {
        let n = f64::from(sim_reports);
        println!("{:<28} {:>10.3}", format!("simulation ({})", sim.mode().name()), sim_ns / n / 1e6);
        println!("{:<28} {:>10.3}", "overlap with rendering", overlap_ns / n / 1e6);
    }
    println!("wrote {} frames and contact_sheet.png to {}", frames.len(), a.out.display());
    if let Some(credit) = s.credit {
        println!("{credit}");
    }
    Ok(())
}
