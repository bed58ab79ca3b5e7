//! `vkhair render`: headless frames of a simulated, rendered head of hair.

use std::path::PathBuf;

use glam::Vec3;
use vkhair::groom::mesh::TriMesh;
use vkhair::headless::{coverage, MeshDrawer, Offscreen, Submit};
use vkhair::render::{Camera, Transparency};
use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
use vkhair::sim::RigidTransform;
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

use crate::args::scene::SceneArgs;
use crate::destinations::{self, Kind, Output};
use crate::output::{clear_stale_frames, progress, Error, FrameSink};
use crate::profile::{host_now_ns, Profile, ProfileArgs};
use crate::say;
use crate::scene::{self, framing, make_renderer, parameters};

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Frames to render (30 per second of motion; 1..=1,000,000).
    #[arg(long, default_value_t = 24)]
    frames: usize,
    /// Output folder for frame PNGs and the contact sheet.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Where the simulation runs [default: async compute when the device has a
    /// second queue, else single queue].
    #[arg(long, value_enum)]
    schedule: Option<ScheduleMode>,
    /// SECOND DEVICE hand-off [default: external memory when both devices can
    /// share it, else staging].
    #[arg(long, value_enum)]
    hand_off: Option<HandOff>,
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

/// The most frames `--frames` takes (a PNG each: 4.6 hours at 60 frames a
/// second), not the edge of its integer type.
const MAX_FRAMES: usize = 1_000_000;

/// The flags `render` adds to the scene's: values out of range and options that
/// need others, before any file is read or GPU work done.
fn check_options(a: &RenderArgs) -> Result<(), String> {
    a.scene.check()?;
    if a.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    if a.frames > MAX_FRAMES {
        return Err(format!("--frames must be at most {MAX_FRAMES} (got {})", a.frames));
    }
    if a.schedule != Some(ScheduleMode::SecondDevice) {
        let given = [("--hand-off", a.hand_off.is_some()), ("--sim-device", a.sim_device.is_some())];
        if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
            return Err(format!("{flag} needs --schedule second-device"));
        }
    }
    Ok(())
}

/// The scheduler options the flags ask for (creating the simulation device).
fn schedule_options(a: &RenderArgs) -> Result<SchedulerOptions, vkhair::Error> {
    let sim_device = match a.schedule {
        Some(ScheduleMode::SecondDevice) => {
            let options = ContextOptions { device_name: a.sim_device.clone(), ..ContextOptions::default() };
            Some(GpuContext::headless(&options)?)
        }
        _ => None,
    };
    Ok(SchedulerOptions {
        mode: a.schedule,
        sim_device,
        hand_off: a.hand_off,
        pipelining: if a.latency { Pipelining::Latency } else { Pipelining::Throughput },
        frames_in_flight: 1,
        ..SchedulerOptions::default()
    })
}

pub fn render(a: &RenderArgs) -> Result<(), Error> {
    check_options(a)?;
    let sa = &a.scene;
    let mut inputs = sa.input.files();
    inputs.extend(sa.config.as_deref());
    let mut outputs = vec![Output { flag: "--out", path: &a.out, kind: Kind::Folder }];
    outputs.extend(a.profile_out.outputs());
    let _made = destinations::check(&inputs, &outputs)?;
    let stale = clear_stale_frames(&a.out, a.frames)?;
    if stale > 0 {
        say!("removed {stale} frames of an earlier run from {} (this run writes {})", a.out.display(), a.frames);
    }
    let s = scene::load(sa)?;
    let config = parameters(sa, &s)?;
    let simulated = sa.sim.simulated_count(s.groom.strand_count())?;
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let sim_params = config.sim.clone();
    let options = schedule_options(a)?;
    let mut sim = FrameScheduler::new(&ctx, &s.groom, &sim_params, &s.start_head, &s.colliders, &options)?;
    if let Some(ch) = &s.character {
        // The roots ride the character's skinned mesh (skinned by vkhair from
        // the joints' matrices, set every frame below).
        sim.bind_scalp_bones(&ch.scalp()?, &ch.scalp_bones(0.0))?;
    }
    say!("simulation: {} ({})", sim.mode().name(), sim.reason());
    if let Some(count) = simulated {
        sim.set_simulated_hairs(count)?;
        say!("simulated: {count} of {} key hairs (the others follow them)", s.groom.strand_count());
    }
    say!("{}", sa.sim.describe(&sim_params, ctx.info().device_type));
    if let Some(ch) = &s.character {
        // The body near the head as one field that follows the character's bones.
        let (body, skin) = ch.body_region()?;
        sim.set_skinned_mesh_collider(&body, &skin, &ch.scalp_bones(0.0), &config.mesh_collider)?;
        say!(
            "mesh collider: the body within {} m of the head, {} triangles at {} grid points along the longest axis, \
             following its bones",
            vkhair::character::BODY_REACH,
            body.triangles.len(),
            config.mesh_collider.resolution
        );
    } else if sa.input.colliding() {
        sim.set_mesh_collider(Some(&s.head_mesh), &config.mesh_collider)?;
        say!(
            "mesh collider: {} triangles at {} grid points along the longest axis",
            s.head_mesh.triangles.len(),
            config.mesh_collider.resolution
        );
    }
    let renderer = make_renderer(sa, &ctx, &config, sim.key_hairs(), &s)?;
    let mut offscreen = Offscreen::new(&ctx, sa.width, sa.height)?;
    // A character's face, measured every frame: how much of it the hair hides.
    let mut face = match &s.character {
        Some(ch) => {
            offscreen.keep_snapshots()?;
            Some(FaceCover::new(ch.face_region()?))
        }
        None => None,
    };
    let offscreen = offscreen;
    // The head mesh (lit along the key spot light's direction) takes that light's hair
    // shadow the way a host would, through glsl/include/shadow.glsl.
    // A character's whole body is drawn, deformed every frame (in the world).
    let drawn_mesh = match &s.character {
        Some(ch) => ch.body_at(0.0)?,
        None => s.head_mesh.clone(),
    };
    let head = if sa.no_shadows || sa.volume_shadows {
        MeshDrawer::new(&ctx, &drawn_mesh)?
    } else {
        MeshDrawer::with_hair_shadows(&ctx, &drawn_mesh, &renderer, 0)?
    };
    let camera = framing(&s, sa.distance, sa.width as f32 / sa.height as f32)?;
    let mut renderer = renderer;
    let mut profiler = GpuProfiler::new(&ctx, 1, 64)?;
    let (strands, points) = sim.key_hairs().size();
    let (hairs, per_hair) = renderer.hair_counts();
    say!(
        "{}: {strands} key hairs × {points} points → {hairs} hairs × {} segments ({} segments), {}×{}, {} frames",
        ctx.info().name,
        per_hair - 1,
        hairs as u64 * (per_hair as u64 - 1),
        sa.width,
        sa.height,
        a.frames
    );
    let bar = progress(a.frames, "frames");
    let steps_per_frame = 2; // 1/60 s steps, 30 frames per second
    let (lo, hi) = s.groom.bounds();
    let size = (hi - lo).max_element();
    let mut profile = Profile::new("frame");
    let sim_track = format!("simulation, {}", sim.mode().name());
    let mut last_sim_frame = None;
    let mut sink = FrameSink::new(&a.out, sa.width, sa.height, a.frames);
    for frame in 0..a.frames {
        let first_step = frame * steps_per_frame;
        let time = |step: usize| step as f32 * sim_params.dt;
        let heads: Vec<RigidTransform> = (0..steps_per_frame)
            .map(|k| match &s.character {
                Some(ch) => ch.head_at(time(first_step + k + 1)),
                None => sa.sim.motion.head(time(first_step + k + 1), s.pivot, size),
            })
            .collect();
        if let Some(ch) = &s.character {
            // The capsules where the body is at the end of this frame's steps
            // (the first step's sub-steps move them there from the previous
            // frame's; the scheduler takes them per frame, the head per step).
            sim.set_body_colliders(&ch.colliders_at(time(first_step + steps_per_frame)))?;
            let bones = ch.scalp_bones(time(first_step + steps_per_frame));
            sim.set_scalp_bones(&bones)?;
            sim.set_mesh_bones(&bones)?;
        }
        let started = host_now_ns();
        let mut shown_time = 0.0;
        ctx.run_frame("vkhair render frame", |cmd| {
            // SAFETY: run_frame hands over a recording command buffer of the
            // context's device, submits it with the returned waits and waits for it;
            // the profiler's single slot was drained after the previous frame.
            unsafe {
                profiler.begin_frame(cmd, frame as u64);
                let sync = sim.record_frame(cmd, &heads, Some(&mut profiler))?;
                if let Some(ch) = &s.character {
                    // The body where the shown hair state is (uploaded before this
                    // frame is submitted; the previous frame has completed).
                    shown_time = time(sim.shown_steps() as usize);
                    head.update(&ch.character.mesh(&ch.pose(shown_time))?)?;
                }
                renderer.record_prepare(cmd, sim.key_hairs(), Some(&camera), Some(&mut profiler))?;
                renderer.record_shadows(cmd, sim.key_hairs(), Some(&mut profiler))?;
                offscreen.record_clear(cmd, Vec3::splat(0.02));
                let scope = profiler.begin_scope(cmd, "host: head mesh");
                let h = match &s.character {
                    Some(_) => RigidTransform::default(),
                    None => sim.key_hairs().head(),
                };
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
                if face.is_some() {
                    offscreen.record_snapshot(cmd)?;
                }
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
        if let (Some(face), Some(ch)) = (&mut face, &s.character) {
            offscreen.read_snapshot_into(&mut face.before)?;
            let head = ch.head_at(shown_time).matrix();
            face.add(&rgba, head, &camera, (sa.width, sa.height));
        }
        sink.push(frame, rgba)?;
        profile.add_cpu_span("frame: read back, hand to the PNG writer", read, host_now_ns());
        bar.inc(1);
    }
    bar.finish_and_clear();
    sink.finish()?;
    profile.print_table();
    let grower = match renderer.interpolator() {
        vkhair::render::Interpolator::Tessellation => "the tessellation stages",
        _ => "a compute dispatch",
    };
    say!("interpolation: hairs grown by {grower}");
    if !sa.no_shadows && !sa.volume_shadows {
        say!("shadows: deep opacity maps drawn by {}", rasteriser(renderer.shadow_raster()));
    }
    let mode = renderer.params().transparency;
    if mode != Transparency::Off {
        let extent = vkhair::ash::vk::Extent2D { width: sa.width, height: sa.height };
        let mib = renderer.transparency_memory(extent) as f64 / (1024.0 * 1024.0);
        say!(
            "transparency: {mode:?}, strands drawn by {}, {mib:.1} MiB of lists, accumulation buffers and vertex colours",
            rasteriser(renderer.raster())
        );
    }
    if let Some(stats) = renderer.transparency_stats() {
        if stats.tile_capacity > 0 {
            let short = if stats.tile_entries > stats.tile_capacity {
                " — more than the list held: those past it were not drawn (later frames' list has grown; \
                 raise oit.tile_entries_per_vertex to hold them from the first)"
            } else {
                ""
            };
            say!(
                "last frame: {} hair fragments, every one sorted or in the tail; {} tile entries of a list of {}{short}",
                stats.fragments,
                stats.tile_entries,
                stats.tile_capacity
            );
        } else {
            say!(
                "last frame: {} hair fragments, {} stored, {} beyond the pool blended unsorted (pool of {}{}; raise oit.fragments_per_pixel if many are)",
                stats.fragments,
                stats.stored,
                stats.overflowed,
                stats.capacity,
                if stats.capacity < stats.requested { format!(" of the {} asked for", stats.requested) } else { String::new() }
            );
        }
        if let Some([x0, y0, x1, y1]) = stats.composited {
            say!("composited over {}×{} pixels from ({x0}, {y0}), where the ribbons reach", x1 - x0, y1 - y0);
        }
    }
    if let Some(face) = &face {
        face.report();
    }
    say!("wrote {} frames and contact_sheet.png to {}", a.frames, a.out.display());
    a.profile_out.write(&profile, || {
        serde_json::json!({
            "command": "render",
            "device": ctx.info().name,
            "scene": sa.input.input.as_ref().or(sa.input.gltf.as_ref()).map_or("thesis".to_owned(), |p| p.display().to_string()),
            "simulation": sim.mode().name(),
            "key_hairs": strands,
            "points_per_key_hair": points,
            "hairs": hairs,
            "segments_per_hair": per_hair - 1,
            "width": sa.width,
            "height": sa.height,
            "frames": a.frames,
            "iterations": sim_params.iterations,
            "substeps": sim_params.substeps,
            "volume": format!("{:?}", sim_params.volume.mode),
            "face_covered": face.as_ref().map(FaceCover::json),
        })
    })?;
    if let Some(credit) = s.credit {
        say!("{credit}");
    }
    Ok(())
}

/// How much of a character's face the hair hides, frame after frame
/// ([`vkhair::headless::coverage`]).
struct FaceCover {
    /// The face, in the head's frame ([`vkhair::character::HairRig::face_region`]).
    region: TriMesh,
    /// The frame before the hair was drawn (the snapshot's copy).
    before: Vec<u8>,
    /// Per frame: face pixels covered by hair, face pixels.
    frames: Vec<(usize, usize)>,
}

impl FaceCover {
    fn new(region: TriMesh) -> Self {
        FaceCover { region, before: Vec::new(), frames: Vec::new() }
    }

    /// Adds a frame: `after` with the hair, `self.before` without, the head
    /// placed by `head`.
    fn add(&mut self, after: &[u8], head: glam::Mat4, camera: &Camera, extent: (u32, u32)) {
        let view_proj = camera.projection * camera.view;
        let mask = coverage::front_facing_pixels(&self.region, head, view_proj, camera.position(), extent);
        if let Some(counts) = coverage::covered_pixels(&self.before, after, &mask) {
            self.frames.push(counts);
        }
    }

    /// The share of the face's pixels covered over all frames, and in the worst.
    fn shares(&self) -> (f64, f64) {
        let share = |(c, n): (usize, usize)| if n == 0 { 0.0 } else { c as f64 / n as f64 };
        let (c, n) = self.frames.iter().fold((0, 0), |(c, n), f| (c + f.0, n + f.1));
        (share((c, n)), self.frames.iter().copied().map(share).fold(0.0, f64::max))
    }

    fn report(&self) {
        let (all, worst) = self.shares();
        let pixels = self.frames.iter().map(|f| f.1).sum::<usize>() / self.frames.len().max(1);
        say!(
            "face: hair covers {:.2} % of the face's pixels over {} frames (the worst frame {:.2} %; about {pixels} face \
             pixels a frame; covered: changed by more than {} sRGB steps)",
            100.0 * all,
            self.frames.len(),
            100.0 * worst,
            coverage::COVERED_STEPS
        );
    }

    fn json(&self) -> serde_json::Value {
        let (all, worst) = self.shares();
        serde_json::json!({ "share": all, "worst_frame_share": worst, "frames": self.frames.len() })
    }
}

/// How the tool names a rasteriser.
fn rasteriser(raster: vkhair::render::Raster) -> &'static str {
    match raster {
        vkhair::render::Raster::Compute => "the compute rasteriser",
        vkhair::render::Raster::Tiles => "the tiled compute rasteriser",
        _ => "the hardware raster pipeline",
    }
}
