//! Rendering a full head of hair from the simulated key hairs.
//!
//! [`Renderer`] is the orchestrator: it owns one value of each pass type (see
//! `render/pass.rs` for the convention they follow) and records them in frame order.
//! [`RenderPass`] names their debug labels and timestamp scopes.
//!
//! 1. **Smooth** (`smooth.rs`): key hairs straight from the simulation's GPU
//!    buffers, as patches of 4 control points, tessellated as isolines into
//!    uniform cubic B-splines; positions and tangents stored for the next passes.
//! 2. **Interpolate** (`interpolate.rs`): a draw with no vertex buffer grows
//!    `hairs_per_key` hairs around every smoothed key hair (or inside every
//!    triangle of key-hair roots), each offset in the key hair's frame by a
//!    stable random clump coordinate.
//! 3. **Shadows** (`shadow/`, optional): deep opacity maps of the
//!    shadow-casting lights from the interpolated hairs, or the transmittance
//!    through the simulation's density volume.
//! 4. **Draw** (`draw/`): the hairs as camera-facing ribbons (or lines),
//!    Kajiya-Kay diffuse plus two shifted specular highlights, or Marschner
//!    ([`HairMaterial`]), for every [`Light`], into the host's color and depth
//!    images ([`RenderTarget`]), attenuated by the shadows.
//! 5. **Resolve** (`resolve.rs`, with [`RenderParams::supersampling`]): the draw
//!    goes to images twice the target's size, then a 5-tap filter blends it into
//!    the host's target.
//!
//! Passes 1–2 are recorded by [`Renderer::record_prepare`], 3 by
//! [`Renderer::record_shadows`], 4–5 by [`Renderer::record_draw`]. Each
//! entry point keeps a frame graph (`graph.rs`): every pass declares the
//! buffers and images it reads and writes, and the barriers between passes
//! are derived from those declarations.

mod draw;
pub mod followers;
mod frame;
pub(crate) mod graph;
mod interpolate;
pub mod marschner;
mod motion_reference;
mod params;
pub(crate) mod pass;
mod readback;
pub mod reference;
mod resolve;
pub mod scalp;
mod scalp_coverage;
mod scalp_hair;
mod shading;
mod shadow;
mod smooth;
pub(crate) mod strand_frames;
mod target;

pub use draw::{OitPool, OitStats, VELOCITY_FORMATS};
pub use followers::Followers;
pub use marschner::MarschnerParams;
pub use params::{
    Detail, InterpolationMode, Interpolator, LodParams, MotionDirection, MotionParams, MotionUnits, OitParams,
    Primitive, Raster, RenderParams, Transparency, MAX_HAIRS_PER_KEY, MAX_SMOOTHING_LEVEL,
};
pub use pass::RenderPass;
pub use scalp_coverage::{scalp_coverage, ScalpCoverage, MAX_COVERAGE_PROBES};
pub use scalp_hair::{scalp_area_cm2, ScalpHairParams, SCALP_DENSITY_RANGE};
pub use shading::{Camera, DepthConvention, HairMaterial, Light, ShadingMode, MAX_LIGHTS};
pub use shadow::{
    layer_of, layer_opacity, ShadowCaster, ShadowMethod, ShadowParams, MAX_SHADOW_MAPS, SHADOW_ATLAS_FORMAT,
};

use std::sync::Arc;

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu_types::GpuLight;
use crate::profiler::{GpuProfiler, Timing};
use crate::sim::KeyHairs;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use draw::DrawPass;
use graph::FrameGraph;
use interpolate::InterpolatePass;
use resolve::ResolvePass;
use shadow::{Bounds, DrawnHairs, ShadowFootprint, Shadows};
use smooth::SmoothPass;
use target::Placement;
pub use target::RenderTarget;

/// Renders hair from a [`crate::sim::HairSim`]'s key hairs into the host's images.
///
/// The crate-level example records a whole frame; this one adds a
/// shadow-casting light, supersampling and per-pass timings:
///
/// ```
/// use glam::Vec3;
/// use vkhair::headless::{Offscreen, Submit};
/// use vkhair::render::{Camera, Light, RenderParams, RenderPass, Renderer, ShadowParams};
/// use vkhair::sim::{HairSim, RigidTransform, SimParams};
/// use vkhair::{groom, ContextOptions, GpuContext, GpuProfiler, ValidationLog};
///
/// let log = ValidationLog::new();
/// {
///     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
///     let params = groom::grow::GrowParams { strands: 32, points_per_strand: 6, ..Default::default() };
///     let groom = groom::grow::grow(&groom::scenes::thesis_scalp(), &params)?;
///     let sim = HairSim::new(&ctx, &groom, &SimParams::default(), &RigidTransform::default())?;
///     let mut renderer = Renderer::new(&ctx, &sim, &RenderParams { supersampling: true, ..Default::default() })?;
///     renderer.set_lights(&[Light::Directional { direction: Vec3::NEG_Y, color: Vec3::ONE }])?;
///     renderer.set_shadows(&sim, &ShadowParams { casters: vec![0.into()], resolution: 64, ..Default::default() })?;
///     let target = Offscreen::new(&ctx, 32, 32)?;
///     let camera = Camera::look_at(Vec3::new(0.0, 1.6, 0.6), Vec3::new(0.0, 1.6, 0.0), 0.8, 1.0, 0.01, 10.0)?;
///     let mut profiler = GpuProfiler::new(&ctx, 1, 16)?;
///     let mut result = Ok(());
///     ctx.run_commands("frame", |cmd| {
///         // SAFETY: a recording command buffer of the context's device.
///         result = unsafe {
///             let _ = profiler.begin_frame(cmd, 0);
///             target.record_clear(cmd, Vec3::ZERO);
///             renderer
///                 .record_prepare(cmd, &sim, Some(&camera), Some(&mut profiler))
///                 .and_then(|_| renderer.record_shadows(cmd, &sim, Some(&mut profiler)))
///                 .and_then(|_| renderer.record_draw(cmd, 0, &target.target(), &camera, Some(&mut profiler)))
///         };
///     })?;
///     result?;
///     let report = profiler.drain().pop().expect("the frame completed");
///     for pass in [RenderPass::Smooth, RenderPass::ShadowOpacity, RenderPass::Draw, RenderPass::Resolve] {
///         assert!(report.pass(pass.label()).is_some(), "{pass:?} was timed");
///     }
/// }
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
pub struct Renderer {
    device: Arc<Device>,
    params: RenderParams,
    strands: u32,
    points: u32,
    /// Smoothing level and interpolated hairs (all units together) the
    /// buffers were sized for.
    capacity_level: u32,
    capacity_hairs: u64,
    smooth: SmoothPass,
    interpolate: InterpolatePass,
    shadows: Shadows,
    draw: DrawPass,
    resolve: ResolvePass,
    material: HairMaterial,
    lights: Vec<GpuLight>,
    /// Where the hair is: rest bounds, and the head pose of the latest prepared frame.
    placement: Placement,
    /// The detail of the latest prepared frame.
    detail: Detail,
    /// The key-hair buffers the smoothing pass is bound to.
    source: [vk::Buffer; 4],
    /// The last frame index `record_draw` was given.
    last_frame: Option<u64>,
    /// Followers drawn instead of grown hairs, when created with them.
    followers: Option<FollowerCounts>,
    /// The previous frame's drawn positions and camera, made by the first
    /// frame that writes motion vectors.
    motion: Option<draw::MotionHistory>,
}

/// What the renderer keeps of its [`Followers`].
#[derive(Debug, Clone, Copy)]
struct FollowerCounts {
    count: u32,
    points: u32,
    root_spacing: f32,
    /// The smoothing level the followers were bound at: they are drawn at it.
    level: u32,
}

/// Rejects key hairs that live on another device than the renderer's.
fn check_device(device: &Arc<Device>, sim: &KeyHairs<'_>) -> Result<()> {
    if Arc::ptr_eq(device, sim.device) {
        Ok(())
    } else {
        Err(Error::incompatible("key hairs", "they live on another device than the renderer's context"))
    }
}

/// Construction and parameters.
impl Renderer {
    /// Creates the passes and buffers for the key hairs of `sim`: a
    /// [`crate::sim::HairSim`] (`&sim`) or a scheduler's hand-off copy
    /// ([`crate::schedule::FrameScheduler::key_hairs`]). Later frames must come from
    /// the same source.
    pub fn new<'a>(ctx: &GpuContext, sim: impl Into<KeyHairs<'a>>, params: &RenderParams) -> Result<Self> {
        Self::build(ctx, sim.into(), params, None)
    }

    /// Creates a renderer that draws `followers` — every strand of a dense
    /// groom, bound to the guides `sim` simulates ([`Followers::bind`] with
    /// `sim`'s rest state and `params.smoothing_level`) — instead of growing
    /// hairs: the interpolation mode and `hairs_per_key` no longer grow hairs;
    /// level of detail draws the share `detail.hairs_per_key / hairs_per_key`
    /// of the followers (a prefix of their stable random order), as it thins
    /// grown hairs (the smoothing level stays the one they were bound at:
    /// [`Renderer::set_params`] refuses another).
    pub fn with_followers<'a>(
        ctx: &GpuContext,
        sim: impl Into<KeyHairs<'a>>,
        params: &RenderParams,
        followers: &Followers,
    ) -> Result<Self> {
        Self::build(ctx, sim.into(), params, Some(followers))
    }

    fn build(
        ctx: &GpuContext,
        sim: KeyHairs<'_>,
        params: &RenderParams,
        followers: Option<&Followers>,
    ) -> Result<Self> {
        params.validate()?;
        let device = ctx.device.clone();
        check_device(&device, &sim)?;
        if device.info.max_tessellation_level < params.smoothing_level {
            return Err(Error::MissingRequirement(format!(
                "tessellation level {} (device allows {})",
                params.smoothing_level, device.info.max_tessellation_level
            )));
        }
        let (strands, points) = sim.size();
        // Sized for the level asked for at creation: level-of-detail only lowers it.
        let stride = (points as u64 - 1) * u64::from(params.smoothing_level) + 1;
        let triangles = scalp::root_triangles(sim.rest);
        let fits = |hairs: u64, stride: u64| hairs * stride * 16 <= u64::from(device.info.max_storage_buffer_range);
        let (capacity_hairs, hair_vertices) = match followers {
            Some(f) => {
                followers::check(f, strands, params.smoothing_level)?;
                (f.count() as u64, f.count() as u64 * f.points() as u64)
            }
            None => {
                interpolate::check_mode(params.interpolation, triangles.len() as u32)?;
                // Room for the hairs of either mode (key hairs or scalp
                // triangles, each growing hairs) where the device's storage
                // range holds them, else for the mode asked for.
                let units = u64::from(interpolate::units(params.interpolation, strands as u32, triangles.len() as u32));
                let both = (strands as u64).max(triangles.len() as u64) * u64::from(params.hairs_per_key);
                let hairs = if fits(both, stride) { both } else { units * u64::from(params.hairs_per_key) };
                (hairs, hairs * stride)
            }
        };
        if hair_vertices * 16 > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::device(
                "the interpolated hairs",
                format!(
                    "{} bytes exceed the device's storage range; lower the smoothing level or hairs_per_key",
                    hair_vertices * 16
                ),
            ));
        }
        let smooth = SmoothPass::new(&device, sim.halves, sim.before, strands as u64 * stride)?;
        let interpolate = InterpolatePass::new(&device, sim.rest, &triangles, &smooth, hair_vertices, followers)?;
        let draw = DrawPass::new(&device, hair_vertices)?;
        let shadows = Shadows::new(&device, interpolate.hairs().0)?;
        let detail = params.detail_at(0.0);
        Ok(Renderer {
            params: params.clone(),
            strands: strands as u32,
            points: points as u32,
            capacity_level: params.smoothing_level,
            capacity_hairs,
            smooth,
            interpolate,
            shadows,
            draw,
            resolve: ResolvePass::new(&device),
            material: HairMaterial::default(),
            lights: Vec::new(),
            placement: Placement::of(sim.rest, sim.head.rotation.normalize()),
            detail,
            source: sim.bound_buffers(),
            last_frame: None,
            motion: None,
            followers: followers.map(|f| FollowerCounts {
                count: f.count() as u32,
                points: f.points() as u32,
                root_spacing: f.root_spacing(),
                level: f.level(),
            }),
            device,
        })
    }

    /// Current parameters.
    pub fn params(&self) -> &RenderParams {
        &self.params
    }

    /// Changes parameters from the next recorded frame on (validated first). The
    /// smoothing level may not exceed the one the renderer was created with, nor
    /// the hairs drawn at full detail (key hairs, or scalp triangles in
    /// barycentric mode, × `hairs_per_key`) those it holds: those of its
    /// creation's `hairs_per_key` in either mode, or only in its creation's mode
    /// where the device's `maxStorageBufferRange` cannot hold both.
    pub fn set_params(&mut self, params: &RenderParams) -> Result<()> {
        params.validate()?;
        if params.smoothing_level > self.capacity_level {
            return Err(Error::param(
                "smoothing_level",
                params.smoothing_level,
                format!("at most {}, the level this renderer was created for", self.capacity_level),
            ));
        }
        match self.followers {
            None => self.check_hairs(params)?,
            Some(f) if params.smoothing_level != f.level => {
                return Err(Error::param(
                    "smoothing_level",
                    params.smoothing_level,
                    format!("{}, the level the followers were bound at", f.level),
                ))
            }
            Some(_) => {}
        }
        self.params = params.clone();
        self.detail = self.detail.min_with(params);
        Ok(())
    }

    /// Rejects `params` whose grown hairs do not fit the renderer's buffers.
    fn check_hairs(&self, params: &RenderParams) -> Result<()> {
        self.interpolate.check_mode(params.interpolation)?;
        let units = u64::from(self.units_of(params.interpolation));
        if units * u64::from(params.hairs_per_key) > self.capacity_hairs {
            return Err(Error::param(
                "hairs_per_key",
                params.hairs_per_key,
                format!(
                    "at most {} in {:?} interpolation: {} hairs, those this renderer was created for",
                    self.capacity_hairs / units.max(1),
                    params.interpolation,
                    self.capacity_hairs
                ),
            ));
        }
        Ok(())
    }

    /// The hair material.
    pub fn material(&self) -> &HairMaterial {
        &self.material
    }

    /// Changes the material from the next recorded draw on (validated first).
    pub fn set_material(&mut self, material: &HairMaterial) -> Result<()> {
        material.validate()?;
        self.material = material.clone();
        Ok(())
    }

    /// Replaces the lights (at most [`MAX_LIGHTS`]).
    pub fn set_lights(&mut self, lights: &[Light]) -> Result<()> {
        if lights.len() > MAX_LIGHTS {
            return Err(Error::param("lights", lights.len(), format!("at most {MAX_LIGHTS}")));
        }
        let gpu: Vec<GpuLight> = lights.iter().map(|l| l.to_gpu()).collect::<Result<_>>()?;
        shadow::check_casters(&gpu, self.shadows.params())?;
        self.lights = gpu;
        Ok(())
    }

    /// The shadow parameters.
    pub fn shadows(&self) -> &ShadowParams {
        self.shadows.params()
    }

    /// Chooses the shadow-casting lights and the maps' parameters for `sim` (validated
    /// first). A new atlas size (map count or resolution) or a larger density volume
    /// creates new GPU resources and waits for the device to be idle first. Maps are
    /// drawn by [`Renderer::record_shadows`].
    ///
    /// A deep-opacity-map caster must be a directional or spot light of the
    /// current [`Renderer::set_lights`] list: a point light is refused here with
    /// [`Error::UnsupportedFeature`] (give it a density-volume caster instead),
    /// as is a later `set_lights` that would turn a map caster into a point light.
    pub fn set_shadows<'a>(&mut self, sim: impl Into<KeyHairs<'a>>, params: &ShadowParams) -> Result<()> {
        shadow::check_casters(&self.lights, params)?;
        let sim = sim.into();
        let changed = self.shadows.set(&sim, params, self.interpolate.hairs().0);
        if !matches!(changed, Ok(false)) {
            // The draw's descriptor sets name images and buffers that were (or, after
            // a failure half way, may have been) replaced.
            self.draw.forget();
        }
        changed.map(|_| ())
    }
}

/// Passes 1–2: the geometry.
impl Renderer {
    /// Records the geometry passes (smoothing, interpolation) for `sim`'s latest
    /// state into `cmd`, at the detail for `camera` ([`LodParams`]; full detail
    /// without a camera). Leaves the interpolation pipeline bound (a graphics
    /// one with a 1 × 1 viewport and scissor set through the tessellation
    /// stages, a compute one through a dispatch, [`Renderer::interpolator`]; the
    /// smoothing pass's graphics pipeline and 1 × 1 viewport and scissor
    /// stay bound too then): a host binds its own pipeline and state again
    /// afterwards.
    ///
    /// # Safety
    /// `cmd` is a command buffer of the context's device in the recording state,
    /// outside a render pass, for a queue of the graphics family; `sim` is the
    /// simulation this renderer was created for. Work recorded earlier in submission
    /// order (the simulation step) is ordered before it by the recorded barriers.
    pub unsafe fn record_prepare<'a>(
        &mut self,
        cmd: vk::CommandBuffer,
        sim: impl Into<KeyHairs<'a>>,
        camera: Option<&Camera>,
        profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let sim = sim.into();
        check_device(&self.device, &sim)?;
        if sim.bound_buffers() != self.source {
            return Err(Error::incompatible("key hairs", "they are not the ones this renderer was created for"));
        }
        self.placement.update(&sim);
        let distance = camera.map_or(0.0, |c| (c.position() - self.placement.head_center).length());
        self.detail = self.params.detail_at(distance);
        if let Some(f) = self.followers {
            // Followers' offsets hold against guides smoothed at their level.
            self.detail.smoothing_level = f.level;
        }
        let (smooth_push, interpolate_push) = (self.smooth_push(sim.alpha), self.interpolate_push());
        let timing = Timing::of(profiler.as_deref());
        let keys = (sim.current, [sim.halves[sim.current], sim.before[sim.current]]);
        let mut graph = FrameGraph::new();
        // SAFETY: guaranteed by the caller.
        unsafe {
            self.smooth.record(cmd, keys, &smooth_push, &mut graph, timing);
            let interpolator = self.interpolator();
            let inputs = (&mut graph, self.smooth.outputs());
            self.interpolate.record(cmd, self.params.interpolation, interpolator, &interpolate_push, inputs, timing);
            graph.settle(&self.device, cmd);
        }
        Ok(())
    }

    /// Who grows the drawn hairs on this device: [`RenderParams::interpolator`]
    /// resolved for the device's type ([`Interpolator::resolve`]).
    pub fn interpolator(&self) -> Interpolator {
        self.params.interpolator.resolve(self.device.info.device_type)
    }

    /// Records [`Renderer::record_prepare`] in its own submission and waits (headless
    /// use: tests and tools).
    pub fn prepare_now<'a>(&mut self, sim: impl Into<KeyHairs<'a>>, camera: Option<&Camera>) -> Result<()> {
        let sim = sim.into();
        let device = self.device.clone();
        let mut result = Ok(());
        device.submit_once("vkhair prepare", |cmd| {
            // SAFETY: submit_once hands over a recording command buffer of this device.
            result = unsafe { self.record_prepare(cmd, sim, camera, None) };
        })?;
        result
    }
}

/// Pass 3: shadows.
impl Renderer {
    /// Records the shadows of the casters for the hairs of the latest
    /// [`Renderer::record_prepare`] of `sim`: the frame's shadow uniforms, the opacity
    /// maps, and a copy of `sim`'s density volume for density-volume casters (only the
    /// uniforms without casters). Call it every frame after `record_prepare` and
    /// before [`Renderer::record_draw`]; the draw then attenuates those lights.
    /// Afterwards the atlas ([`Renderer::shadow_atlas`]) is in
    /// `SHADER_READ_ONLY_OPTIMAL`, written by `COLOR_ATTACHMENT_OUTPUT` (or by
    /// `COMPUTE_SHADER`, [`Renderer::shadow_raster`]) and made visible to
    /// fragment and compute shaders, for a host that shades its own surfaces with it.
    /// When a map was drawn through the hardware raster pipeline, the viewport and
    /// scissor are left set to its tile and a shadow pipeline stays bound; through
    /// the compute rasteriser, a compute pipeline stays bound.
    ///
    /// # Safety
    /// As for [`Renderer::record_prepare`], recorded after it (and after `sim`'s step)
    /// in submission order; the atlas is not in use by pending work of other frames in
    /// a conflicting way (the usual frames-in-flight wait covers the renderer's own
    /// draws).
    pub unsafe fn record_shadows<'a>(
        &mut self,
        cmd: vk::CommandBuffer,
        sim: impl Into<KeyHairs<'a>>,
        profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let sim = sim.into();
        let bounds = Bounds { centre: self.placement.head_center, radius: self.placement.bound_radius };
        let timing = Timing::of(profiler.as_deref());
        let (root, tip) = self.strand_spacing();
        let footprint = ShadowFootprint { hairs: self.strand_hairs(), spacing: 0.5 * (root + tip) };
        let drawn = DrawnHairs { counts: self.hair_counts(), footprint };
        let raster = (self.shadow_raster(), self.interpolate.hairs().0);
        let mut graph = FrameGraph::new();
        // SAFETY: guaranteed by the caller.
        unsafe {
            let recorded = self.shadows.record(cmd, &sim, &self.lights, bounds, drawn, raster, &mut graph, timing);
            graph.settle(&self.device, cmd);
            recorded
        }
    }

    /// The rasteriser the current parameters draw the deep opacity maps with on
    /// this device: [`RenderParams::raster`] resolved for the device's type
    /// ([`Raster::resolve_shadows`]), whatever the transparency mode.
    pub fn shadow_raster(&self) -> Raster {
        self.params.raster.resolve_shadows(self.device.info.device_type)
    }

    /// The opacity atlas (format [`SHADOW_ATLAS_FORMAT`], one tile per caster, two tiles
    /// per row) and a nearest sampler, for a host shading its own surfaces with
    /// `glsl/include/shadow.glsl`.
    pub fn shadow_atlas(&self) -> (vk::ImageView, vk::Sampler) {
        self.shadows.atlas()
    }

    /// Reads the opacity atlas back, row after row (this submits and waits): per texel
    /// the opacity summed to the end of each layer and z0 (0 where no hair is).
    pub fn read_shadow_atlas(&self) -> Result<(vk::Extent2D, Vec<[f32; 4]>)> {
        self.shadows.read_atlas()
    }

    /// The uniform buffer holding the frame's `ShadowParams` (`glsl/include/shadow.glsl`;
    /// std140), written by [`Renderer::record_shadows`] with a transfer and made
    /// visible to vertex and fragment shaders.
    pub fn shadow_uniforms(&self) -> vk::Buffer {
        self.shadows.uniforms().raw()
    }

    pub(crate) fn shadow_uniform_buffer(&self) -> &Buffer {
        self.shadows.uniforms()
    }
}
