//! What `vkhair bench` measures of a render frame: `render`'s scene, parameters
//! and renderer, timed per frame.

use glam::{Mat4, Vec3, Vec4};
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::reference::{composite_strands, linear_rgb, srgb_error, CompositeScene};
use vkhair::render::{Camera, HairMaterial, LodParams, Renderer};
use vkhair::sim::{HairSim, RigidTransform};
use vkhair::{GpuContext, GpuProfiler};

use super::measure::Samples;
use crate::args::scene::SceneArgs;
use crate::args::sim::SimArgs;
use crate::output::Error;
use crate::scene::{self, framing, make_renderer, parameters};

/// What `vkhair bench` measures of a frame: the render passes' GPU time (from
/// their timestamp scopes), the wall time of the submission holding them (the
/// simulation's steps go in a submission of their own before it), and what
/// the render passes record.
pub struct FrameFigures {
    pub gpu: Samples,
    pub wall: Samples,
    pub work: vkhair::RecordedWork,
    pub hairs: u64,
    pub segments: u64,
    pub pixels: u64,
    /// GPU memory of the transparency mode (lists or accumulation images), bytes.
    pub transparency_bytes: u64,
    /// The last frame drawn once more unlit, when asked for.
    pub unlit: Option<UnlitFrame>,
    /// The last frame as drawn (linear RGB per pixel, rows from the top), when
    /// asked for.
    pub lit: Option<Vec<Vec3>>,
}

/// What [`bench_frames`] keeps of its last frame besides the figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    /// Nothing.
    Figures,
    /// The frame drawn once more unlit ([`FrameFigures::unlit`]).
    Unlit,
    /// The frame as drawn ([`FrameFigures::lit`]).
    Lit,
}

/// Background of the bench's lit frames (linear).
pub const LIT_BACKGROUND: Vec3 = Vec3::splat(0.02);

/// Albedo at the root and the tip of the unlit frame.
const UNLIT_ROOT: Vec3 = Vec3::new(0.9, 0.2, 0.05);
const UNLIT_TIP: Vec3 = Vec3::new(0.1, 0.5, 0.9);
/// Background of the unlit frame (linear).
const UNLIT_BACKGROUND: Vec3 = Vec3::splat(0.02);

/// A frame drawn unlit (no lights, ambient 1, albedo from [`UNLIT_ROOT`] to
/// [`UNLIT_TIP`] along each hair, level of detail off; the frame's widths,
/// opacity, hairs per strand and transparency mode): what
/// `render::reference::composite_strands` can draw exactly, to measure a
/// transparency mode's error.
pub struct UnlitFrame {
    /// Linear RGB per pixel, rows from the top.
    pub image: Vec<Vec3>,
    /// The hairs drawn (position, t along the hair).
    pub strands: Vec<Vec<Vec4>>,
    view_proj: Mat4,
    camera: Vec3,
    extent: (u32, u32),
    material: HairMaterial,
    /// The drawn strands' spacing at the root and tip (m).
    spacing: (f32, f32),
}

impl UnlitFrame {
    /// The exact image of this frame's hairs (the CPU reference; slow at full
    /// size: every core, seconds).
    pub fn reference(&self) -> Vec<Vec3> {
        let color = |t: f32| UNLIT_ROOT.lerp(UNLIT_TIP, t);
        let image = composite_strands(&CompositeScene {
            hairs: &self.strands,
            view_proj: self.view_proj,
            camera: self.camera,
            extent: self.extent,
            widths: (self.material.root_width, self.material.tip_width),
            represented_hairs: self.material.represented_hairs,
            band_spacing: self.spacing,
            opacity: self.material.opacity,
            color: &color,
            background: UNLIT_BACKGROUND,
        });
        image.iter().map(|p| p.truncate()).collect()
    }

    /// Mean absolute error against `reference` in 8-bit sRGB steps over the hair
    /// pixels (NaN when there is no hair).
    pub fn error(&self, reference: &[Vec3]) -> f64 {
        srgb_error(&self.image, reference, UNLIT_BACKGROUND).map_or(f64::NAN, |e| e.0)
    }
}

/// Draws the current state of `sim` once more, unlit (see [`UnlitFrame`]).
fn draw_unlit(
    ctx: &GpuContext,
    sim: &HairSim,
    renderer: &mut Renderer,
    offscreen: &Offscreen,
    camera: &Camera,
    frame: u64,
) -> Result<UnlitFrame, Error> {
    let lit = renderer.material().clone();
    let material = HairMaterial {
        root_color: UNLIT_ROOT,
        tip_color: UNLIT_TIP,
        ambient: 1.0,
        root_width: lit.root_width,
        tip_width: lit.tip_width,
        opacity: lit.opacity,
        represented_hairs: lit.represented_hairs,
        ..HairMaterial::default()
    };
    renderer.set_material(&material)?;
    renderer.set_lights(&[])?;
    let params = vkhair::render::RenderParams {
        lod: LodParams { enabled: false, ..renderer.params().lod },
        ..renderer.params().clone()
    };
    renderer.set_params(&params)?;
    let mut result = Ok(());
    ctx.run_commands("vkhair bench unlit frame", |cmd| {
        // SAFETY: a recording command buffer of the context's device; the
        // previous frame completed (run_commands waits).
        result = unsafe {
            (|| -> Result<(), vkhair::Error> {
                renderer.record_prepare(cmd, sim, Some(camera), None)?;
                offscreen.record_clear(cmd, UNLIT_BACKGROUND);
                renderer.record_draw(cmd, frame, &offscreen.target(), camera, None)
            })()
        };
    })?;
    result?;
    let (w, h) = offscreen.size();
    Ok(UnlitFrame {
        image: linear_rgb(&offscreen.read_rgba8()?),
        strands: renderer.read_strands()?,
        view_proj: camera.projection * camera.view,
        camera: camera.position(),
        extent: (w, h),
        material,
        spacing: renderer.strand_spacing(),
    })
}

/// Renders `samples` frames (after two warm-up frames) of the scene `render`
/// would draw with `args` (its scene flags, e.g. `["--width", "1280"]`) and
/// the simulation knobs `sim`, the simulation on the same queue, and measures
/// the render passes; then keeps what `keep` asks for of the last frame.
pub fn bench_frames(
    ctx: &GpuContext,
    args: &[&str],
    sim: &SimArgs,
    samples: usize,
    keep: Keep,
) -> Result<FrameFigures, Error> {
    #[derive(clap::Parser)]
    struct Wrapper {
        #[command(flatten)]
        scene: SceneArgs,
    }
    let mut a = <Wrapper as clap::Parser>::try_parse_from(std::iter::once("render").chain(args.iter().copied()))
        .map_err(|e| format!("bench render arguments: {e}"))?
        .scene;
    a.sim = sim.clone();
    a.check()?;
    let s = scene::load(&a)?;
    let config = parameters(&a, &s)?;
    let simulated = a.sim.simulated_count(s.groom.strand_count())?;
    let mut sim = HairSim::new(ctx, &s.groom, &config.sim, &RigidTransform::default())?;
    sim.set_colliders(&s.colliders)?;
    if let Some(count) = simulated {
        sim.set_simulated_hairs(count)?;
    }
    let mut renderer = make_renderer(&a, ctx, &config, sim.key_hairs(), &s)?;
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
        unlit: None,
        lit: None,
    };
    for frame in 0..samples + 2 {
        let heads: Vec<RigidTransform> =
            (0..2).map(|k| a.sim.motion.head((frame * 2 + k + 1) as f32 * config.sim.dt, s.pivot, size)).collect();
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
                    offscreen.record_clear(cmd, LIT_BACKGROUND);
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
    match keep {
        Keep::Figures => {}
        Keep::Unlit => {
            figures.unlit = Some(draw_unlit(ctx, &sim, &mut renderer, &offscreen, &camera, samples as u64 + 2)?)
        }
        Keep::Lit => figures.lit = Some(linear_rgb(&offscreen.read_rgba8()?)),
    }
    Ok(figures)
}
