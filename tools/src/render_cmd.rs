//! `vkhair render`: headless frames of a simulated, rendered head of hair.

use std::path::PathBuf;

use glam::Vec3;
use vkhair::config::Config;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes::{self, THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS};
use vkhair::groom::Groom;
use vkhair::headless::{MeshDrawer, Offscreen, Submit};
use vkhair::render::{
    Camera, InterpolationMode, Light, Primitive, Renderer, ShadingMode, ShadowCaster, ShadowParams, Transparency,
};
use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
use vkhair::sim::{motion, Collider, RigidTransform, SimParams, VolumeMode, VolumeParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

use crate::groom_input::{self, InputArgs};
use crate::output::{progress, Error, FrameSink, MIN_IMAGE_SIDE};
use crate::profile::{host_now_ns, Profile, ProfileArgs};
use crate::say;
use crate::simulate_cmd::MotionArg;

mod bench;
pub use bench::bench_frames;

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

/// `--transparency`: how hair is blended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TransparencyArg {
    /// Opaque ribbons at least a pixel wide, nearest layer only.
    Off,
    /// Weighted blended transparency: one pass, no lists.
    Fast,
    /// Per-pixel lists, the nearest fragments sorted exactly.
    Exact,
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
    #[command(flatten)]
    input: InputArgs,
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
    /// Camera distance from the centre of the groom and mesh, in their units
    /// [default: framed to their bounds].
    #[arg(long)]
    distance: Option<f32>,
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
    /// Draw one-pixel lines instead of ribbons (opaque: turns transparency off
    /// unless --transparency is given).
    #[arg(long)]
    lines: bool,
    /// How hair is blended: opaque ribbons, weighted blended transparency or
    /// per-pixel sorted lists [default: the --config file's, else exact].
    #[arg(long, value_enum)]
    transparency: Option<TransparencyArg>,
    /// Fragments sorted exactly per pixel by --transparency exact (1..=32) [default: 8].
    #[arg(long)]
    sorted_fragments: Option<u32>,
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
    /// Head motion about the neck: still, the shake (0.6 rad at 1 Hz) or violent
    /// (1.2 rad at 3 Hz with a nod and jolts of the whole head).
    #[arg(long, value_enum, default_value = "shake")]
    motion: MotionArg,
    /// Where the simulation runs.
    #[arg(long, value_enum, default_value_t = Schedule::Auto)]
    schedule: Schedule,
    /// SECOND DEVICE hand-off.
    #[arg(long, value_enum)]
    hand_off: Option<HandOffArg>,
    /// Show each frame's own steps (latency) instead of the previous frame's while
    /// this frame's run (throughput).
    #[arg(long)]
    latency: bool,
    /// Device name substring for the simulation device of --schedule second-device
    /// (default: a second logical device of the rendering GPU).
    #[arg(long)]
    sim_device: Option<String>,
    #[command(flatten)]
    profile_out: ProfileArgs,
}

/// The renderer `render` draws with: parameters, lights, the two spot lights'
/// shadows and the material of `config`.
fn make_renderer(
    a: &RenderArgs,
    ctx: &GpuContext,
    config: &Config,
    key_hairs: vkhair::sim::KeyHairs<'_>,
    radius: f32,
) -> Result<Renderer, vkhair::Error> {
    let mut renderer = Renderer::new(ctx, key_hairs, &config.render)?;
    renderer.set_lights(&config.lights)?;
    if !a.no_shadows {
        // The thesis' setup: both spot lights cast shadows through their own maps.
        let casters = if a.volume_shadows {
            vec![ShadowCaster::density_volume(0), ShadowCaster::density_volume(1)]
        } else {
            vec![0.into(), 1.into()]
        };
        let layers = ShadowParams::default().layers.map(|l| l * drawing_scale(radius));
        let shadows = ShadowParams { casters, resolution: a.shadow_resolution, layers, ..ShadowParams::default() };
        renderer.set_shadows(key_hairs, &shadows)?;
    }
    let mut material = config.material.clone();
    if material.represented_hairs == 1.0 {
        material.represented_hairs = represented_hairs(renderer.hair_counts().0);
    }
    renderer.set_material(&material)?;
    Ok(renderer)
}

/// Hairs on a full head of real hair, for the tool's default of
/// [`vkhair::render::HairMaterial::represented_hairs`].
pub const FULL_HEAD_HAIRS: f32 = 100_000.0;

/// The tool's default hairs per drawn strand for `drawn` strands: a full head
/// ([`FULL_HEAD_HAIRS`]) over the strands drawn at full detail, at least 1
/// (`material.represented_hairs` in a `--config` file other than 1 wins).
pub fn represented_hairs(drawn: u32) -> f32 {
    (FULL_HEAD_HAIRS / drawn.max(1) as f32).clamp(1.0, 10_000.0)
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
            None | Some(HandOffArg::Auto) => None,
            Some(HandOffArg::External) => Some(HandOff::ExternalMemory),
            Some(HandOffArg::Staging) => Some(HandOff::HostStaging),
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
    /// Radius of the sphere around the groom and the mesh (their units).
    radius: f32,
    /// Root and tip thickness the groom file gives (its units after --scale).
    thickness: Option<(f32, f32)>,
    pivot: Vec3,
    credit: Option<&'static str>,
}

/// Options that mean something only with others, and values out of range: an
/// error saying what the option needs, before any file is read or GPU work done.
fn check_options(a: &RenderArgs) -> Result<(), String> {
    if a.width < MIN_IMAGE_SIDE || a.height < MIN_IMAGE_SIDE {
        return Err(format!(
            "--width and --height must be at least {MIN_IMAGE_SIDE} pixels (got {}×{})",
            a.width, a.height
        ));
    }
    if a.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    a.input.check()?;
    if a.schedule != Schedule::SecondDevice {
        let given = [("--hand-off", a.hand_off.is_some()), ("--sim-device", a.sim_device.is_some())];
        if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
            return Err(format!("{flag} needs --schedule second-device"));
        }
    }
    if let Some(d) = a.distance {
        if !(d.is_finite() && d > 0.0) {
            return Err(format!("--distance must be a finite number above 0 (got {d})"));
        }
    }
    Ok(())
}

/// The sphere around a set of points: centre of the box and half its diagonal.
fn bounds_sphere(points: impl Iterator<Item = Vec3>) -> (Vec3, f32) {
    let (lo, hi) =
        points.fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
    (0.5 * (lo + hi), 0.5 * (hi - lo).length())
}

fn scene(a: &RenderArgs) -> Result<Scene, Error> {
    let sintel =
        |p: &Option<PathBuf>| p.as_ref().is_some_and(|p| p.to_string_lossy().to_lowercase().contains("sintel"));
    let (groom, thickness, colliders, head_mesh, pivot, credit) = match &a.input.input {
        None => {
            let head = TriMesh::uv_sphere(THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS * 0.97, 24, 32)?;
            (scenes::thesis()?, None, motion::thesis_colliders(), head, Some(motion::NECK_PIVOT), None)
        }
        Some(path) => {
            let scale = a.input.scale();
            let groom_input::Scaled { groom, thickness } = a.input.groom(path)?;
            let head_mesh = match &a.input.obj {
                Some(obj) => {
                    let m = TriMesh::load_obj(obj)?;
                    TriMesh::new(m.positions.iter().map(|p| *p * scale).collect(), m.triangles)?
                }
                None => {
                    // A stand-in head under the roots, sized by the groom's largest
                    // extent (a flat groom has no extent along one axis).
                    let (lo, hi) = groom.bounds();
                    let r = 0.25 * (hi - lo).max_element();
                    TriMesh::uv_sphere(0.5 * (lo + hi), r, 16, 24)?
                }
            };
            let credit = (sintel(&a.input.input) || sintel(&a.input.obj))
                .then_some("Sintel © Blender Foundation | durian.blender.org (CC BY 3.0)");
            (groom, thickness, Vec::new(), head_mesh, None, credit)
        }
    };
    let (center, radius) = bounds_sphere(groom.positions().iter().chain(&head_mesh.positions).copied());
    if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
        return Err(format!("the groom and mesh span no finite volume (bounding radius {radius})").into());
    }
    let (lo, _) = groom.bounds();
    let pivot = pivot.unwrap_or(Vec3::new(center.x, lo.y, center.z));
    Ok(Scene { groom, colliders, head_mesh, center, radius, thickness, pivot, credit })
}

/// Lights for a scene of bounding radius `radius` around `center`: two spots
/// (key and fill) and a rim light, placed as the thesis' setup is for its head.
fn lights(center: Vec3, radius: f32) -> Vec<Light> {
    // The thesis' offsets (meters) are for its head and hair.
    // Spot lights fall off with the squared distance: brighter by k² at k times
    // the distance, the same light reaches the hair.
    let k = radius / HEAD_OF_HAIR_RADIUS;
    let spot = |offset: Vec3, color: Vec3| Light::Spot {
        position: center + k * offset,
        direction: -offset,
        outer_angle: 0.6,
        inner_angle: 0.4,
        color: color * k * k,
    };
    vec![
        spot(Vec3::new(-0.6, 0.5, 0.8), Vec3::splat(1.1)),
        spot(Vec3::new(0.9, 0.1, 0.4), Vec3::new(0.25, 0.27, 0.33)),
        Light::Directional { direction: Vec3::new(0.2, -0.3, 1.0), color: Vec3::new(0.25, 0.22, 0.2) },
    ]
}

/// Bounding radius of the thesis scene (head sphere and hair), meters: the size
/// the render parameters' lengths and the tool's lights are set for.
const HEAD_OF_HAIR_RADIUS: f32 = 0.465;

/// How much wider than given the render's lengths are drawn for a scene of
/// bounding radius `radius`: 1 for anything a head of hair in meters could be
/// (5 cm to 1.5 m), else the factor that gives the thesis head's proportions.
fn drawing_scale(radius: f32) -> f32 {
    if (0.05..=1.5).contains(&radius) {
        1.0
    } else {
        radius / HEAD_OF_HAIR_RADIUS
    }
}

/// Vertical field of view of the tool's camera, radians.
const FOV_Y: f32 = 0.698_131_7; // 40°

/// The camera looking at the scene from the front (+Z): at `--distance` when
/// given, else far enough that the bounding sphere fits the image's shorter side.
fn framing(s: &Scene, distance: Option<f32>, aspect: f32) -> Result<Camera, vkhair::Error> {
    let half = 0.5 * FOV_Y;
    let half_narrow = if aspect >= 1.0 { half } else { (half.tan() * aspect).atan() };
    let d = distance.unwrap_or(s.radius / half_narrow.sin());
    let r = s.radius;
    let eye = s.center + Vec3::new(0.0, 0.1 * r, d);
    let near = (d - 1.5 * r).max(0.002 * d);
    let far = d + 1.5 * r;
    Camera::look_at(eye, s.center, FOV_Y, aspect, near, far)
}
/// The parameters: vkhair's defaults (an `--input` groom held in its authored
/// style, [`SimParams::styled`]; strands as wide as the groom file says when it
/// says something plausible), then the `--config` file, then the flags given;
/// the tool's lights when the file lists none. Checked before any GPU work.
fn parameters(a: &RenderArgs, s: &Scene) -> Result<Config, vkhair::Error> {
    let (center, radius) = (s.center, s.radius);
    let sim = if a.input.input.is_some() { SimParams::styled() } else { SimParams::default() };
    let mut base = Config { sim, ..Config::default() };
    // The tool draws soft hair unless told otherwise (the library's default is opaque).
    base.render.transparency = Transparency::Exact;
    let k = drawing_scale(radius);
    let from_groom = groom_input::strand_widths(s.thickness, k);
    if let Some((root, tip)) = from_groom {
        // In the units the scale below converts from, so that they come out as given.
        (base.material.root_width, base.material.tip_width) = (root / k, tip / k);
    }
    let base_widths = (base.material.root_width, base.material.tip_width);
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
        r.transparency = Transparency::Off;
    }
    if let Some(k) = a.sorted_fragments {
        r.oit.sorted_fragments = k;
    }
    if let Some(t) = a.transparency {
        r.transparency = match t {
            TransparencyArg::Off => Transparency::Off,
            TransparencyArg::Fast => Transparency::Fast,
            TransparencyArg::Exact => Transparency::Exact,
        };
    }
    if a.marschner {
        config.material.shading = ShadingMode::Marschner;
    }
    if a.volume_shadows && config.sim.volume.mode == VolumeMode::Off {
        config.sim.volume = VolumeParams::flip([32, 32, 32]);
    }
    if config.lights.is_empty() {
        config.lights = lights(center, radius);
    }
    let m = &config.material;
    let source = match from_groom {
        _ if a.config.is_some() && (m.root_width, m.tip_width) != base_widths => "--config",
        Some(_) => "the groom's thickness",
        None => "vkhair's default",
    };
    say!("strand width: {:.1} µm at the root, {:.1} µm at the tip ({source})", m.root_width * 1e6, m.tip_width * 1e6);
    if k != 1.0 {
        eprintln!(
            "vkhair: warning: the groom and mesh span {:.3} units around their centre, not the size of a \
             head of hair in meters (vkhair's unit); drawing clumps, hair widths and shadow layers {k:.3}× as wide to match \
             (give --scale to convert the groom itself: the simulation stays in meters)",
            radius
        );
        config.render.clump_width *= k;
        config.render.lod.full_detail_distance *= k;
        config.material.root_width *= k;
        config.material.tip_width *= k;
    }
    config.validate()?;
    Ok(config)
}

pub fn render(a: &RenderArgs) -> Result<(), Error> {
    check_options(a)?;
    let s = scene(a)?;
    let config = parameters(a, &s)?;
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let sim_params = config.sim.clone();
    let options = schedule_options(a)?;
    let mut sim = FrameScheduler::new(&ctx, &s.groom, &sim_params, &RigidTransform::default(), &s.colliders, &options)?;
    say!("simulation: {} ({})", sim.mode().name(), sim.reason());
    if a.input.colliding() {
        sim.set_mesh_collider(Some(&s.head_mesh), &config.mesh_collider)?;
        say!(
            "mesh collider: {} triangles at {} grid points along the longest axis",
            s.head_mesh.triangles.len(),
            config.mesh_collider.resolution
        );
    }
    let renderer = make_renderer(a, &ctx, &config, sim.key_hairs(), s.radius)?;
    let offscreen = Offscreen::new(&ctx, a.width, a.height)?;
    // The head mesh (lit along the key spot light's direction) takes that light's hair
    // shadow the way a host would, through glsl/include/shadow.glsl.
    let head = if a.no_shadows || a.volume_shadows {
        MeshDrawer::new(&ctx, &s.head_mesh)?
    } else {
        MeshDrawer::with_hair_shadows(&ctx, &s.head_mesh, &renderer, 0)?
    };
    let camera = framing(&s, a.distance, a.width as f32 / a.height as f32)?;
    let mut renderer = renderer;
    let mut profiler = GpuProfiler::new(&ctx, 1, 64)?;
    std::fs::create_dir_all(&a.out).map_err(|e| format!("cannot create {}: {e}", a.out.display()))?;
    let (strands, points) = sim.key_hairs().size();
    let (hairs, per_hair) = renderer.hair_counts();
    say!(
        "{}: {strands} key hairs × {points} points → {hairs} hairs × {} segments ({} segments), {}×{}, {} frames",
        ctx.info().name,
        per_hair - 1,
        hairs as u64 * (per_hair as u64 - 1),
        a.width,
        a.height,
        a.frames
    );
    let bar = progress(a.frames, "frames");
    let steps_per_frame = 2; // 1/60 s steps, 30 frames per second
    let (lo, hi) = s.groom.bounds();
    let size = (hi - lo).max_element();
    let mut profile = Profile::new("frame");
    let sim_track = format!("simulation, {}", sim.mode().name());
    let mut last_sim_frame = None;
    let mut sink = FrameSink::new(&a.out, a.width, a.height, a.frames);
    for frame in 0..a.frames {
        let first_step = frame * steps_per_frame;
        let heads: Vec<RigidTransform> = (0..steps_per_frame)
            .map(|k| a.motion.head((first_step + k + 1) as f32 * sim_params.dt, s.pivot, size))
            .collect();
        let started = host_now_ns();
        ctx.run_frame("vkhair render frame", |cmd| {
            // SAFETY: run_frame hands over a recording command buffer of the
            // context's device, submits it with the returned waits and waits for it;
            // the profiler's single slot was drained after the previous frame.
            unsafe {
                profiler.begin_frame(cmd, frame as u64);
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
        profile.add_cpu_span("frame: record, submit, wait", started, host_now_ns());
        for report in profiler.drain() {
            profile.add(&report, "graphics queue", 1);
        }
        // The simulation's own queue or device (ASYNC COMPUTE, SECOND DEVICE): its
        // latest report, once per simulated frame.
        if let Some(report) = sim.sim_profile().filter(|r| Some(r.frame) != last_sim_frame) {
            last_sim_frame = Some(report.frame);
            profile.add(&report, &sim_track, 1);
        }
        let read = host_now_ns();
        let mut rgba = sink.buffer();
        offscreen.read_rgba8_into(&mut rgba)?;
        sink.push(frame, rgba)?;
        profile.add_cpu_span("frame: read back, hand to the PNG writer", read, host_now_ns());
        bar.inc(1);
    }
    bar.finish_and_clear();
    sink.finish()?;
    profile.print_table();
    let mode = renderer.params().transparency;
    if mode != Transparency::Off {
        let extent = vkhair::ash::vk::Extent2D { width: a.width, height: a.height };
        let mib = renderer.transparency_memory(extent) as f64 / (1024.0 * 1024.0);
        say!("transparency: {mode:?}, {mib:.1} MiB of lists or accumulation images");
    }
    if let Some(stats) = renderer.transparency_stats() {
        say!(
            "last frame: {} hair fragments, {} stored, {} beyond the pool blended unsorted (pool of {}; raise oit.fragments_per_pixel if many are)",
            stats.fragments,
            stats.stored,
            stats.overflowed,
            stats.capacity
        );
    }
    say!("wrote {} frames and contact_sheet.png to {}", a.frames, a.out.display());
    a.profile_out.write(&profile, || {
        serde_json::json!({
            "command": "render",
            "device": ctx.info().name,
            "scene": a.input.input.as_ref().map_or("thesis".to_owned(), |p| p.display().to_string()),
            "simulation": sim.mode().name(),
            "key_hairs": strands,
            "points_per_key_hair": points,
            "hairs": hairs,
            "segments_per_hair": per_hair - 1,
            "width": a.width,
            "height": a.height,
            "frames": a.frames,
        })
    })?;
    if let Some(credit) = s.credit {
        say!("{credit}");
    }
    Ok(())
}
