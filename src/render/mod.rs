//! Rendering a full head of hair from the simulated key hairs.
//!
//! The passes, in recording order ([`RenderPass`] names their debug labels
//! and timestamp scopes):
//!
//! 1. **Smooth** ([`smooth`]): key hairs straight from the simulation's GPU
//!    buffers, as patches of 4 control points, tessellated as isolines into
//!    uniform cubic B-splines (mirrored phantom points put the curve exactly
//!    through root and tip); positions and tangents stored for the next passes.
//! 2. **Interpolate** ([`interpolate`]): a draw with no vertex buffer grows
//!    `hairs_per_key` hairs around every smoothed key hair, each offset in the
//!    key hair's frame by a stable random clump coordinate.
//!
//! 3. **Shadows** ([`shadow`], optional): deep opacity maps of the
//!    shadow-casting lights from the interpolated hairs — the depth where the
//!    hair starts, then opacity accumulated into three layers behind it.
//! 4. **Draw** ([`draw`]): the hairs as camera-facing ribbons, Kajiya-Kay
//!    diffuse plus two shifted specular highlights ([`HairMaterial`]) for every
//!    [`Light`], into the host's color and depth images ([`RenderTarget`]),
//!    attenuated by the opacity maps.
//! 5. **Resolve** ([`resolve`], with [`RenderParams::supersampling`]): the draw
//!    goes to images twice the target's size, then a 5-tap filter blends it into
//!    the host's target.

pub mod draw;
pub mod interpolate;
pub mod marschner;
mod offscreen;
pub mod reference;
pub mod resolve;
pub mod scalp;
mod shading;
pub mod shadow;
pub mod smooth;

pub use marschner::MarschnerParams;
pub use offscreen::{MeshDrawer, Offscreen, OFFSCREEN_COLOR, OFFSCREEN_DEPTH};
pub use shading::{Camera, HairMaterial, Light, ShadingMode, MAX_LIGHTS};
pub use shadow::{ShadowCaster, ShadowMethod, ShadowParams, MAX_SHADOW_MAPS, SHADOW_ATLAS_FORMAT};

use std::sync::Arc;

use ash::vk;
use glam::Vec4;
use gpu_allocator::MemoryLocation;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu_types::{DrawParams, GpuLight, InterpolatePush, SmoothPush};
use crate::profiler::GpuProfiler;
use crate::sim::KeyHairs;
use crate::vk::barrier::{self, Access};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use draw::{DrawPass, TargetKey};
use interpolate::InterpolatePass;
use smooth::SmoothPass;

/// Most smoothed segments per key segment (the tessellation level limit vkhair uses).
pub const MAX_SMOOTHING_LEVEL: u32 = 64;

/// The passes of a frame, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RenderPass {
    /// Pass 1: B-spline smoothing of the key hairs.
    Smooth,
    /// Pass 2: single-strand interpolation.
    Interpolate,
    /// Shadows, pass 1: the depth where the hair starts, per light.
    ShadowDepth,
    /// Shadows, pass 2: opacity accumulated into three layers, per light.
    ShadowOpacity,
    /// Density-volume shadows: transmittance toward the light at every cell.
    ShadowVolume,
    /// Pass 3: drawing and shading.
    Draw,
    /// Pass 4: supersampling resolve.
    Resolve,
}

impl RenderPass {
    /// The debug label and timestamp scope name of the pass.
    pub fn label(self) -> &'static str {
        match self {
            RenderPass::Smooth => "vkhair render: smooth",
            RenderPass::Interpolate => "vkhair render: interpolate",
            RenderPass::ShadowDepth => "vkhair render: shadow depth",
            RenderPass::ShadowOpacity => "vkhair render: shadow opacity",
            RenderPass::ShadowVolume => "vkhair render: shadow volume",
            RenderPass::Draw => "vkhair render: draw",
            RenderPass::Resolve => "vkhair render: resolve",
        }
    }
}

/// Rendering parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderParams {
    /// Smoothed segments per key segment (1..=64). Default: 4 (a 6-point key hair
    /// becomes 20 segments, as in the thesis scene).
    pub smoothing_level: u32,
    /// Hairs grown around each key hair (1..=64). Default: 16 (1750 key hairs give
    /// 28,000 hairs, as in the thesis scene).
    pub hairs_per_key: u32,
    /// Radius of a clump around its key hair, meters (≥ 0). Default: 0.012.
    pub clump_width: f32,
    /// Fraction of `clump_width` at the root (≥ 0). Default: 0.3.
    pub root_width: f32,
    /// Fraction of `clump_width` at the tip (≥ 0). Default: 1.0.
    pub tip_width: f32,
    /// Level of detail by camera distance.
    pub lod: LodParams,
    /// Draw at twice the target's width and height and resolve with a 5-tap filter
    /// (thesis 3.5). Default: false (a host may use MSAA targets instead).
    pub supersampling: bool,
    /// How hairs are grown from key hairs. Default: [`InterpolationMode::SingleStrand`].
    pub interpolation: InterpolationMode,
    /// What each hair segment is drawn as. Default: [`Primitive::Ribbons`].
    pub primitive: Primitive,
    /// Frames the host has in flight (1..=16): images a new target size makes
    /// obsolete are freed this many frames after their last use. Default: 2.
    pub frames_in_flight: u32,
}

/// What the draw pass turns each hair segment into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Primitive {
    /// Camera-facing quads from the geometry stage, [`HairMaterial`] widths.
    #[default]
    Ribbons,
    /// One-pixel lines (no geometry stage; cheapest).
    Lines,
}

/// How the interpolation pass grows hairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InterpolationMode {
    /// `hairs_per_key` hairs around each key hair, offset in its frame (thesis 3.2).
    #[default]
    SingleStrand,
    /// `hairs_per_key` hairs inside each triangle of key-hair roots, blending the
    /// three key hairs with stable random barycentric weights (Nalu).
    Barycentric,
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams {
            smoothing_level: 4,
            hairs_per_key: 16,
            clump_width: 0.012,
            root_width: 0.3,
            tip_width: 1.0,
            lod: LodParams::default(),
            supersampling: false,
            interpolation: InterpolationMode::SingleStrand,
            primitive: Primitive::Ribbons,
            frames_in_flight: 2,
        }
    }
}

/// Level of detail by camera distance d (to the centre of the hair), stepped:
/// with d0 = `full_detail_distance`, hairs per key = round(full · (d0/d)²) (they
/// cover screen area) and segments per key segment = round(full · d0/d) (they
/// follow screen length), each clamped between its minimum and the full count of
/// [`RenderParams`]; ribbon width grows by √(full hairs / hairs) to keep coverage.
#[derive(Debug, Clone, PartialEq)]
pub struct LodParams {
    /// Whether detail falls with distance. Default: true.
    pub enabled: bool,
    /// Distance up to which full detail is drawn, meters (> 0). Default: 0.6.
    pub full_detail_distance: f32,
    /// Fewest hairs per key hair (≥ 1). Default: 2.
    pub min_hairs_per_key: u32,
    /// Lowest smoothing level (≥ 1). Default: 1.
    pub min_smoothing_level: u32,
}

impl Default for LodParams {
    fn default() -> Self {
        LodParams { enabled: true, full_detail_distance: 0.6, min_hairs_per_key: 2, min_smoothing_level: 1 }
    }
}

/// The detail actually drawn (see [`LodParams`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detail {
    /// Smoothed segments per key segment.
    pub smoothing_level: u32,
    /// Hairs per key hair.
    pub hairs_per_key: u32,
    /// Ribbon width factor.
    pub width_scale: f32,
}

impl RenderParams {
    /// The detail at camera distance `distance` (full detail when LOD is off).
    pub fn detail_at(&self, distance: f32) -> Detail {
        let full =
            Detail { smoothing_level: self.smoothing_level, hairs_per_key: self.hairs_per_key, width_scale: 1.0 };
        if !self.lod.enabled || !distance.is_finite() || distance <= self.lod.full_detail_distance {
            return full;
        }
        let ratio = self.lod.full_detail_distance / distance;
        let hairs = ((self.hairs_per_key as f32 * ratio * ratio).round() as u32)
            .clamp(self.lod.min_hairs_per_key.min(self.hairs_per_key), self.hairs_per_key);
        let level = ((self.smoothing_level as f32 * ratio).round() as u32)
            .clamp(self.lod.min_smoothing_level.min(self.smoothing_level), self.smoothing_level);
        Detail {
            smoothing_level: level,
            hairs_per_key: hairs,
            width_scale: (self.hairs_per_key as f32 / hairs as f32).sqrt(),
        }
    }
}

impl RenderParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SMOOTHING_LEVEL).contains(&self.smoothing_level) {
            return Err(Error::param(
                "smoothing_level",
                format!("{} is outside 1..={MAX_SMOOTHING_LEVEL}", self.smoothing_level),
            ));
        }
        if !(1..=MAX_SMOOTHING_LEVEL).contains(&self.hairs_per_key) {
            return Err(Error::param("hairs_per_key", format!("{} is outside 1..=64", self.hairs_per_key)));
        }
        for (name, v) in
            [("clump_width", self.clump_width), ("root_width", self.root_width), ("tip_width", self.tip_width)]
        {
            if !(v.is_finite() && (0.0..=1e3).contains(&v)) {
                return Err(Error::param(name, format!("{v} is outside 0..=1000")));
            }
        }
        Ok(())
    }
}

/// Renders hair from a [`HairSim`]'s key hairs into the host's images.
pub struct Renderer {
    device: Arc<Device>,
    params: RenderParams,
    strands: u32,
    points: u32,
    /// Smoothing level and hairs per key the buffers were sized for.
    capacity_level: u32,
    capacity_hairs: u32,
    smoothed_positions: Buffer,
    smoothed_tangents: Buffer,
    reference: Buffer,
    hair_positions: Buffer,
    hair_tangents: Buffer,
    smooth: SmoothPass,
    interpolate: InterpolatePass,
    draw: DrawPass,
    draw_params: Buffer,
    material: HairMaterial,
    lights: Vec<GpuLight>,
    /// Head rotation of the latest prepared frame (for readers of the hair buffers).
    head_rotation: glam::Quat,
    /// Centre of the rest shape's bounds, head frame (LOD distance).
    rest_center: glam::Vec3,
    /// `rest_center` in the world at the latest prepared frame.
    head_center: glam::Vec3,
    /// The detail of the latest prepared frame.
    detail: Detail,
    /// Supersampling images for the current target size, made on first use.
    supersampling: Option<resolve::Supersampling>,
    /// Images of earlier target sizes with the last frame that used them, freed
    /// `frames_in_flight` frames later.
    retired: Vec<(u64, resolve::Supersampling)>,
    /// The last frame index `record_draw` was given.
    last_frame: Option<u64>,
    /// Marschner lookup tables, rebuilt when their parameters change.
    marschner: marschner::MarschnerTables,
    /// Scalp triangles between key-hair roots (barycentric mode).
    triangles: u32,
    _triangle_buffer: Buffer,
    interpolate_barycentric: InterpolatePass,
    /// Deep opacity maps.
    shadows: shadow::ShadowMaps,
    /// Radius around `rest_center` that the hair can reach (roots plus strand length).
    bound_radius: f32,
    /// Density-volume shadows (placeholder buffers while no light uses them).
    volume_shadows: shadow::VolumeShadows,
    /// The key-hair buffers the smoothing pass is bound to.
    source: [vk::Buffer; 2],
}

/// Rejects key hairs that live on another device than the renderer's.
fn check_device(device: &Arc<Device>, sim: &KeyHairs<'_>) -> Result<()> {
    if Arc::ptr_eq(device, sim.device) {
        Ok(())
    } else {
        Err(Error::param("key hairs", "they live on another device than the renderer's context"))
    }
}

impl Renderer {
    /// Creates the passes and buffers for the key hairs of `sim`: a
    /// [`crate::sim::HairSim`] (`&sim`) or a scheduler's hand-off copy
    /// ([`crate::schedule::FrameScheduler::key_hairs`]). Later frames must come from
    /// the same source.
    pub fn new<'a>(ctx: &GpuContext, sim: impl Into<KeyHairs<'a>>, params: &RenderParams) -> Result<Self> {
        let sim: KeyHairs<'a> = sim.into();
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
        let size = strands as u64 * stride * 16;
        let triangles = scalp::root_triangles(sim.rest);
        // Room for either mode: key hairs or scalp triangles, each growing hairs.
        let units = (strands as u64).max(triangles.len() as u64);
        let hair_size = units * stride * 16 * u64::from(params.hairs_per_key);
        if hair_size > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::param(
                "hairs_per_key",
                format!("{hair_size} bytes of interpolated strands exceed the device's storage range; lower the level or hair count"),
            ));
        }
        let storage = |name: &str, size: u64| Buffer::storage(&device, name, size);
        let smoothed_positions = storage("vkhair smoothed positions", size)?;
        let smoothed_tangents = storage("vkhair smoothed tangents", size)?;
        let hair_positions = storage("vkhair hair positions", hair_size)?;
        let hair_tangents = storage("vkhair hair tangents", hair_size)?;
        let reference_data = interpolate::reference_vectors(sim.rest);
        let reference = Buffer::storage(&device, "vkhair key frames", reference_data.len() as u64 * 16)?;
        device.upload_pod(&reference, &reference_data)?;
        let smooth = SmoothPass::new(&device, sim.halves, &smoothed_positions, &smoothed_tangents)?;
        let triangle_data: Vec<[u32; 4]> = triangles.iter().map(|t| [t[0], t[1], t[2], 0]).collect();
        let triangle_buffer =
            Buffer::storage(&device, "vkhair scalp triangles", (triangle_data.len().max(1) * 16) as u64)?;
        device.upload_pod(&triangle_buffer, &triangle_data)?;
        let bindings = [
            (0, &smoothed_positions),
            (1, &smoothed_tangents),
            (2, &reference),
            (3, &hair_positions),
            (4, &hair_tangents),
            (5, &triangle_buffer),
        ];
        let interpolate = InterpolatePass::new(&device, &crate::vk::shaders::RENDER_INTERPOLATE_TESE, &bindings)?;
        let interpolate_barycentric =
            InterpolatePass::new(&device, &crate::vk::shaders::RENDER_INTERPOLATE_BARY_TESE, &bindings)?;
        if params.interpolation == InterpolationMode::Barycentric && triangles.is_empty() {
            return Err(Error::param(
                "interpolation",
                "barycentric mode needs at least 3 key hairs forming a triangle",
            ));
        }
        let marschner = marschner::MarschnerTables::new(&device)?;
        let draw = DrawPass::new(&device)?;
        let shadows = shadow::ShadowMaps::new(&device, &ShadowParams::default(), &hair_positions)?;
        let volume_shadows = shadow::VolumeShadows::new(&device, &shadows.uniforms, 0, 0)?;
        let rest_shape = sim.rest;
        let (lo, hi) =
            rest_shape.rest.iter().fold((glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)), |(lo, hi), p| {
                (lo.min(p.truncate()), hi.max(p.truncate()))
            });
        let rest_center = 0.5 * (lo + hi);
        let bound_radius = (0..rest_shape.strands)
            .map(|s| {
                let root = rest_shape.rest[s * rest_shape.points].truncate();
                (root - rest_center).length() + rest_shape.rest_strand_length(s)
            })
            .fold(0.0f32, f32::max);
        let draw_params = Buffer::new(
            &device,
            &BufferDesc {
                name: "vkhair draw params",
                size: std::mem::size_of::<DrawParams>() as u64,
                usage: vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        Ok(Renderer {
            device,
            params: params.clone(),
            strands: strands as u32,
            points: points as u32,
            capacity_level: params.smoothing_level,
            capacity_hairs: params.hairs_per_key,
            smoothed_positions,
            smoothed_tangents,
            reference,
            hair_positions,
            hair_tangents,
            smooth,
            interpolate,
            draw,
            draw_params,
            material: HairMaterial::default(),
            lights: Vec::new(),
            head_rotation: sim.head.rotation.normalize(),
            source: sim.bound_buffers(),
            rest_center,
            detail: params.detail_at(0.0),
            supersampling: None,
            retired: Vec::new(),
            last_frame: None,
            marschner,
            triangles: triangles.len() as u32,
            _triangle_buffer: triangle_buffer,
            interpolate_barycentric,
            shadows,
            bound_radius,
            head_center: rest_center,
            volume_shadows,
        })
    }

    /// Current parameters.
    pub fn params(&self) -> &RenderParams {
        &self.params
    }

    /// Changes parameters from the next recorded frame on (validated first). The
    /// smoothing level may not exceed the one the renderer was created with.
    pub fn set_params(&mut self, params: &RenderParams) -> Result<()> {
        params.validate()?;
        if params.smoothing_level > self.capacity_level {
            return Err(Error::param(
                "smoothing_level",
                format!("{} exceeds the {} this renderer was created for", params.smoothing_level, self.capacity_level),
            ));
        }
        if params.interpolation == InterpolationMode::Barycentric && self.triangles == 0 {
            return Err(Error::param(
                "interpolation",
                "barycentric mode needs at least 3 key hairs forming a triangle",
            ));
        }
        if params.hairs_per_key > self.capacity_hairs {
            return Err(Error::param(
                "hairs_per_key",
                format!("{} exceeds the {} this renderer was created for", params.hairs_per_key, self.capacity_hairs),
            ));
        }
        self.params = params.clone();
        self.detail = self.detail.min_with(params);
        Ok(())
    }

    /// Smoothed vertices per key hair at the detail of the latest prepared frame.
    pub fn smoothed_vertices_per_strand(&self) -> u32 {
        (self.points - 1) * self.detail.smoothing_level + 1
    }

    /// The detail of the latest prepared frame.
    pub fn detail(&self) -> Detail {
        self.detail
    }

    fn smooth_push(&self) -> SmoothPush {
        SmoothPush {
            strands: self.strands,
            points: self.points,
            level: self.detail.smoothing_level,
            stride: self.smoothed_vertices_per_strand(),
        }
    }

    /// Key hairs, or scalp triangles in barycentric mode: what hairs are grown from.
    fn interpolation_units(&self) -> u32 {
        match self.params.interpolation {
            InterpolationMode::SingleStrand => self.strands,
            InterpolationMode::Barycentric => self.triangles,
        }
    }

    /// Scalp triangles between key-hair roots (barycentric mode).
    pub fn scalp_triangle_count(&self) -> u32 {
        self.triangles
    }

    fn interpolate_push(&self) -> InterpolatePush {
        InterpolatePush {
            head_rotation: self.head_rotation.to_array(),
            strands: self.interpolation_units(),
            points: self.points,
            level: self.detail.smoothing_level,
            stride: self.smoothed_vertices_per_strand(),
            hairs: self.detail.hairs_per_key,
            clump_width: self.params.clump_width,
            root_width: self.params.root_width,
            tip_width: self.params.tip_width,
        }
    }

    /// Interpolated hairs and vertices per hair of the latest prepared frame.
    pub fn hair_counts(&self) -> (u32, u32) {
        (self.interpolation_units() * self.detail.hairs_per_key, self.smoothed_vertices_per_strand())
    }

    /// Records one storing pass: label or timestamp scope, an attachment-less
    /// rendering instance, then a barrier making its pre-rasterization storage
    /// writes visible to every later shader stage.
    ///
    /// # Safety
    /// `cmd` is recording outside a render pass (see [`Renderer::record_prepare`]).
    unsafe fn capture_pass(
        &self,
        cmd: vk::CommandBuffer,
        pass: RenderPass,
        profiler: &mut Option<&mut GpuProfiler>,
        record: impl FnOnce(vk::CommandBuffer),
    ) {
        let d = &self.device;
        let written = barrier::memory(
            Access {
                stage: vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_WRITE,
            },
            Access {
                stage: vk::PipelineStageFlags2::VERTEX_SHADER
                    | vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER
                    | vk::PipelineStageFlags2::GEOMETRY_SHADER
                    | vk::PipelineStageFlags2::FRAGMENT_SHADER
                    | vk::PipelineStageFlags2::COMPUTE_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_READ,
            },
        );
        let extent = vk::Extent2D { width: 1, height: 1 };
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
            .layer_count(1);
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            let scope = begin_pass(d, cmd, profiler, pass);
            d.raw.cmd_begin_rendering(cmd, &rendering);
            set_viewport(d, cmd, extent);
            record(cmd);
            d.raw.cmd_end_rendering(cmd);
            d.cmd_barrier(cmd, &[written], &[], &[]);
            end_pass(d, cmd, profiler, scope);
        }
    }

    /// Records the geometry passes (smoothing, interpolation) for `sim`'s latest
    /// state into `cmd`, at the detail for `camera` ([`LodParams`]; full detail
    /// without a camera).
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
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let sim = sim.into();
        check_device(&self.device, &sim)?;
        if sim.bound_buffers() != self.source {
            return Err(Error::param("key hairs", "they are not the ones this renderer was created for"));
        }
        let half = sim.current;
        let head = sim.head;
        self.head_rotation = head.rotation.normalize();
        self.head_center = head.matrix().transform_point3(self.rest_center);
        let distance = camera.map_or(0.0, |c| (c.position() - self.head_center).length());
        self.detail = self.params.detail_at(distance);
        let d = &self.device;
        let entry = barrier::memory(
            Access::ANY_WRITE,
            Access {
                stage: vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            },
        );
        let smooth_push = self.smooth_push();
        let interpolate_push = self.interpolate_push();
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_barrier(cmd, &[entry], &[], &[]);
            self.capture_pass(cmd, RenderPass::Smooth, &mut profiler, |cmd| {
                self.smooth.record(d, cmd, half, &smooth_push)
            });
            let pass = match self.params.interpolation {
                InterpolationMode::SingleStrand => &self.interpolate,
                InterpolationMode::Barycentric => &self.interpolate_barycentric,
            };
            self.capture_pass(cmd, RenderPass::Interpolate, &mut profiler, |cmd| {
                pass.record(d, cmd, &interpolate_push)
            });
        }
        Ok(())
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

    /// Reads the smoothed positions and unit tangents back, strand after strand
    /// ([`Renderer::smoothed_vertices_per_strand`] each; this submits and waits).
    pub fn read_smoothed(&self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let n = self.strands as usize * self.smoothed_vertices_per_strand() as usize;
        let positions = self.device.readback_pod(&self.smoothed_positions, n)?;
        let tangents = self.device.readback_pod(&self.smoothed_tangents, n)?;
        Ok((positions, tangents))
    }
}

impl Renderer {
    /// Reads the interpolated hairs back: positions and (tangent, t along the hair),
    /// hair after hair ([`Renderer::hair_counts`]; this submits and waits).
    pub fn read_hairs(&self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let (hairs, per_hair) = self.hair_counts();
        let n = hairs as usize * per_hair as usize;
        Ok((self.device.readback_pod(&self.hair_positions, n)?, self.device.readback_pod(&self.hair_tangents, n)?))
    }

    /// The key hairs' reference vectors (rest-plane normals, head frame).
    pub fn reference_vectors(&self) -> Result<Vec<Vec4>> {
        self.device.readback_pod(&self.reference, self.strands as usize)
    }
}

/// The host's images the hair is drawn into.
#[derive(Debug, Clone, Copy)]
pub struct RenderTarget {
    /// Color attachment view, in `COLOR_ATTACHMENT_OPTIMAL`.
    pub color: vk::ImageView,
    /// Its format.
    pub color_format: vk::Format,
    /// Depth attachment view (in `DEPTH_ATTACHMENT_OPTIMAL`), or null for none.
    pub depth: vk::ImageView,
    /// Its format (`UNDEFINED` for none).
    pub depth_format: vk::Format,
    /// Extent of both.
    pub extent: vk::Extent2D,
    /// Sample count of both.
    pub samples: vk::SampleCountFlags,
}

impl Renderer {
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
            return Err(Error::param("lights", format!("{} exceed the limit of {MAX_LIGHTS}", lights.len())));
        }
        self.lights = lights.iter().map(|l| l.to_gpu()).collect::<Result<_>>()?;
        Ok(())
    }

    fn draw_params(&self, camera: &Camera, extent: vk::Extent2D) -> DrawParams {
        let m = &self.material;
        let (hairs, per_hair) = self.hair_counts();
        let mut lights = [GpuLight::default(); MAX_LIGHTS];
        lights[..self.lights.len()].copy_from_slice(&self.lights);
        // World size of one pixel at distance 1.
        let pixel = 2.0 * (0.5 * camera.fov_y).tan() / extent.height.max(1) as f32;
        DrawParams {
            view_proj: (camera.projection * camera.view).to_cols_array_2d(),
            camera: camera.position().extend(pixel).to_array(),
            root_color: m.root_color.extend(m.ambient).to_array(),
            tip_color: m.tip_color.extend(m.diffuse_wrap).to_array(),
            primary: m.primary_color.extend(m.primary_exponent).to_array(),
            secondary: m.secondary_color.extend(m.secondary_exponent).to_array(),
            shifts: [m.primary_shift, m.secondary_shift, m.shift_jitter, m.highlight_breakup],
            widths: [
                m.root_width * self.detail.width_scale,
                m.tip_width * self.detail.width_scale,
                m.least_pixel_width,
                0.0,
            ],
            counts: [hairs, per_hair, self.lights.len() as u32, self.material.shading as u32],
            lights,
        }
    }

    /// The shadow parameters.
    pub fn shadows(&self) -> &ShadowParams {
        &self.shadows.params
    }

    /// Chooses the shadow-casting lights and the maps' parameters for `sim` (validated
    /// first). A new atlas size (map count or resolution) or a larger density volume
    /// creates new GPU resources and waits for the device to be idle first. Maps are
    /// drawn by [`Renderer::record_shadows`].
    pub fn set_shadows<'a>(&mut self, sim: impl Into<KeyHairs<'a>>, params: &ShadowParams) -> Result<()> {
        let sim = sim.into();
        params.validate()?;
        let volume_lights = params.volume_casters();
        let cells = if volume_lights > 0 {
            let grid = sim.volume_grid().ok_or_else(|| {
                Error::param(
                    "shadow casters",
                    "density-volume shadows need the simulation's volume stage (SimParams::volume)",
                )
            })?;
            grid.dims.iter().product::<u32>()
        } else {
            0
        };
        let new_atlas = params.atlas_extent() != self.shadows.params.atlas_extent();
        let new_volume = self.volume_shadows.cells != cells
            || self.volume_shadows.transmittance.size() < u64::from(cells) * u64::from(volume_lights) * 4;
        if new_atlas || new_volume {
            self.device.wait_idle()?;
            if new_atlas {
                self.shadows = shadow::ShadowMaps::new(&self.device, params, &self.hair_positions)?;
            }
            self.volume_shadows =
                shadow::VolumeShadows::new(&self.device, &self.shadows.uniforms, cells, volume_lights)?;
            self.draw.forget();
        }
        self.shadows.params = params.clone();
        Ok(())
    }

    /// Records the shadows of the casters for the hairs of the latest
    /// [`Renderer::record_prepare`] of `sim`: the frame's shadow uniforms, the opacity
    /// maps, and a copy of `sim`'s density volume for density-volume casters (only the
    /// uniforms without casters). Call it
    /// every frame after `record_prepare` and before [`Renderer::record_draw`]; the
    /// draw then attenuates those lights. Afterwards the atlas
    /// ([`Renderer::shadow_atlas`]) is in `SHADER_READ_ONLY_OPTIMAL`, written by
    /// `COLOR_ATTACHMENT_OUTPUT` and made visible to fragment shaders, for a host that
    /// shades its own surfaces with it.
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
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let sim = sim.into();
        let params = &self.shadows.params;
        let (hairs, per_hair) = self.hair_counts();
        let mut uniforms = shadow::no_shadows();
        let (mut tile, mut slot) = (0, 0);
        let mut volume_maps = Vec::new();
        let cells = self.volume_shadows.cells;
        for (k, caster) in params.casters.iter().enumerate() {
            let gpu = self.lights.get(caster.light).ok_or_else(|| {
                Error::param(
                    "shadow casters",
                    format!("light {} does not exist ({} lights)", caster.light, self.lights.len()),
                )
            })?;
            uniforms.maps[k] = match caster.method {
                ShadowMethod::DeepOpacity => {
                    tile += 1;
                    shadow::light_map(gpu, caster.light, self.head_center, self.bound_radius, params, tile - 1)?
                }
                ShadowMethod::DensityVolume => {
                    slot += 1;
                    volume_maps.push(k as u32);
                    shadow::volume_map(gpu, slot - 1, cells)
                }
            };
            uniforms.light_map[caster.light / 4][caster.light % 4] = k as u32;
        }
        uniforms.counts = [hairs, per_hair, params.casters.len() as u32, 0];
        let mut copy = None;
        if !volume_maps.is_empty() {
            let (grid, buffer) = sim.volume.map(|(g, b)| (g, b.raw())).ok_or_else(|| {
                Error::param("shadow casters", "density-volume shadows need the simulation's volume stage")
            })?;
            if grid.dims.iter().product::<u32>() != cells {
                return Err(Error::param(
                    "shadow casters",
                    "the simulation's volume grid changed; call set_shadows again",
                ));
            }
            let h = grid.cell_size;
            uniforms.grid_from_world = grid.world_from_grid.inverse().to_cols_array_2d();
            uniforms.grid_dims = [grid.dims[0], grid.dims[1], grid.dims[2], 1];
            uniforms.grid = [h, params.volume_cross_section / (h * h * h), params.volume_step, 0.0];
            copy = Some((buffer, u64::from(cells) * 16));
        }
        // SAFETY: guaranteed by the caller.
        unsafe {
            self.shadows.record(cmd, &uniforms, hairs * (per_hair - 1) * 2, &mut profiler);
            if let Some((source, bytes)) = copy {
                let scope = begin_pass(&self.device, cmd, &mut profiler, RenderPass::ShadowVolume);
                self.volume_shadows.record(cmd, source, bytes, &volume_maps);
                end_pass(&self.device, cmd, &mut profiler, scope);
            }
        }
        Ok(())
    }

    /// The opacity atlas (format [`SHADOW_ATLAS_FORMAT`], one tile per caster, two tiles
    /// per row) and a nearest sampler, for a host shading its own surfaces with
    /// `glsl/include/shadow.glsl`.
    pub fn shadow_atlas(&self) -> (vk::ImageView, vk::Sampler) {
        (self.shadows.atlas.view(), self.shadows.sampler.raw)
    }

    /// Reads the opacity atlas back, row after row (this submits and waits): per texel
    /// the opacity summed to the end of each layer and z0 (0 where no hair is).
    pub fn read_shadow_atlas(&self) -> Result<(vk::Extent2D, Vec<[f32; 4]>)> {
        let atlas = &self.shadows.atlas;
        let bytes = self.device.readback_image(atlas, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, 16)?;
        let texels = bytes
            .chunks_exact(16)
            .map(|t| std::array::from_fn(|k| f32::from_le_bytes([t[4 * k], t[4 * k + 1], t[4 * k + 2], t[4 * k + 3]])))
            .collect();
        Ok((atlas.extent, texels))
    }

    /// The uniform buffer holding the frame's `ShadowParams` (`glsl/include/shadow.glsl`;
    /// std140), written by [`Renderer::record_shadows`] with a transfer and made
    /// visible to vertex and fragment shaders.
    pub fn shadow_uniforms(&self) -> vk::Buffer {
        self.shadows.uniforms.raw()
    }

    pub(crate) fn shadow_uniform_buffer(&self) -> &Buffer {
        &self.shadows.uniforms
    }

    /// Sets of size-dependent images waiting for their frames to complete.
    pub fn retired_image_sets(&self) -> usize {
        self.retired.len()
    }

    /// Frees retired images whose last frame is `frames_in_flight` frames behind.
    fn collect_retired(&mut self, frame: u64) {
        let keep = u64::from(self.params.frames_in_flight);
        self.retired.retain(|(last, _)| last.saturating_add(keep) > frame);
    }

    /// Records the hair draw into a rendering instance (`rendering`) of images with
    /// `key`'s formats and `extent`, preceded by the parameter update.
    ///
    /// # Safety
    /// `cmd` is recording outside a render pass; the attachments are in attachment
    /// layouts and earlier writes to them are ordered before (by the caller).
    unsafe fn draw_hair(
        &mut self,
        cmd: vk::CommandBuffer,
        key: TargetKey,
        rendering: &vk::RenderingInfo<'_>,
        extent: vk::Extent2D,
        params: &DrawParams,
    ) -> Result<()> {
        let device = self.device.clone();
        let d = &device;
        let (hairs, per_hair) = self.hair_counts();
        let tables = [
            (4, self.marschner.m.view(), self.marschner.sampler.raw),
            (5, self.marschner.n.view(), self.marschner.sampler.raw),
        ];
        let shadow_atlas = (7, self.shadows.atlas.view(), self.shadows.sampler.raw);
        let (pipeline, set) = self.draw.pipeline(
            key,
            &[
                (0, &self.draw_params),
                (1, &self.hair_positions),
                (2, &self.hair_tangents),
                (6, &self.shadows.uniforms),
                (8, &self.volume_shadows.transmittance),
            ],
            &[tables[0], tables[1], shadow_atlas],
        )?;
        let before_update = barrier::memory(Access::ANY_WRITE, Access::TRANSFER_WRITE);
        let updated = barrier::memory(
            Access::TRANSFER_WRITE,
            Access {
                stage: vk::PipelineStageFlags2::VERTEX_SHADER
                    | vk::PipelineStageFlags2::GEOMETRY_SHADER
                    | vk::PipelineStageFlags2::FRAGMENT_SHADER,
                access: vk::AccessFlags2::UNIFORM_READ,
            },
        );
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            // The draw pipeline may sample the Marschner tables: build them first.
            self.marschner.record_update(d, cmd, &self.material.marschner);
            d.cmd_barrier(cmd, &[before_update], &[], &[]);
            d.raw.cmd_update_buffer(cmd, self.draw_params.raw(), 0, bytemuck::bytes_of(params));
            d.cmd_barrier(cmd, &[updated], &[], &[]);
            d.raw.cmd_begin_rendering(cmd, rendering);
            set_viewport(d, cmd, extent);
            pipeline.bind(cmd, &[*set]);
            d.raw.cmd_draw(cmd, hairs * (per_hair - 1) * 2, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
        }
        Ok(())
    }

    /// Records the draw pass for the host's frame `frame`: the hairs prepared by
    /// [`Renderer::record_prepare`] into the host's `target`, seen by `camera`. The color (and depth) image is loaded,
    /// drawn into with depth test and write against what the host drew, and stored.
    /// With [`RenderParams::supersampling`], the hair is drawn at twice the size into
    /// the renderer's own images and resolved into `target` (depth tested, not
    /// written). When the target's size changes, the images of the old size are
    /// kept until `frame` is [`RenderParams::frames_in_flight`] frames later.
    ///
    /// # Safety
    /// As for [`Renderer::record_prepare`], which must have been recorded before in
    /// submission order. `target`'s views belong to the context's device, are in the
    /// layouts [`RenderTarget`] names, and are not used by other pending work in a
    /// conflicting way; writes to them recorded earlier on the same queue are ordered
    /// before the draw by the recorded barrier. Frame indices increase by one per host
    /// frame, and the command buffers of frame `frame − frames_in_flight` and earlier
    /// have completed (the usual frames-in-flight wait).
    pub unsafe fn record_draw(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        target: &RenderTarget,
        camera: &Camera,
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        if target.extent.width == 0 || target.extent.height == 0 {
            return Err(Error::param("render target", "extent is zero"));
        }
        if self.last_frame.is_some_and(|last| frame < last) {
            return Err(Error::param("frame", format!("{frame} is before the previous frame {:?}", self.last_frame)));
        }
        self.last_frame = Some(frame);
        self.collect_retired(frame);
        let device = self.device.clone();
        let d = &device;
        let finite = camera.view.is_finite() && camera.projection.is_finite() && camera.fov_y.is_finite();
        if !finite {
            return Err(Error::param("camera", "view, projection and field of view must be finite"));
        }
        let host_key = TargetKey {
            color: target.color_format,
            depth: target.depth_format,
            samples: target.samples,
            primitive: self.params.primitive,
        };
        // The host's earlier attachment writes (its head, its clear) before ours.
        let attachments = barrier::memory(
            Access {
                stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                    | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS
                    | vk::PipelineStageFlags2::ALL_TRANSFER,
                access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE
                    | vk::AccessFlags2::TRANSFER_WRITE,
            },
            Access {
                stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                    | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                access: vk::AccessFlags2::COLOR_ATTACHMENT_READ
                    | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
            },
        );
        let host_color = [vk::RenderingAttachmentInfo::default()
            .image_view(target.color)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let host_depth = vk::RenderingAttachmentInfo::default()
            .image_view(target.depth)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE);
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: target.extent };
        let mut host_rendering =
            vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&host_color);
        if target.depth_format != vk::Format::UNDEFINED {
            host_rendering = host_rendering.depth_attachment(&host_depth);
        }

        if !self.params.supersampling {
            let params = self.draw_params(camera, target.extent);
            // SAFETY: guaranteed by the caller.
            unsafe {
                let scope = begin_pass(d, cmd, &mut profiler, RenderPass::Draw);
                d.cmd_barrier(cmd, &[attachments], &[], &[]);
                let result = self.draw_hair(cmd, host_key, &host_rendering, target.extent, &params);
                end_pass(d, cmd, &mut profiler, scope);
                return result;
            }
        }

        if self.supersampling.as_ref().is_some_and(|s| s.target_extent != target.extent) {
            if let Some(old) = self.supersampling.take() {
                // Frames up to the previous one may still be using the old images.
                self.retired.push((frame.saturating_sub(1), old));
            }
        }
        if self.supersampling.is_none() {
            self.supersampling = Some(resolve::Supersampling::new(&self.device, target.extent)?);
        }
        let big = vk::Extent2D { width: target.extent.width * 2, height: target.extent.height * 2 };
        let params = self.draw_params(camera, big);
        let Some(ss) = self.supersampling.take() else { return Ok(()) };
        let ss_key = TargetKey {
            color: resolve::SUPERSAMPLED_COLOR,
            depth: resolve::SUPERSAMPLED_DEPTH,
            samples: vk::SampleCountFlags::TYPE_1,
            primitive: self.params.primitive,
        };
        let ss_color = [vk::RenderingAttachmentInfo::default()
            .image_view(ss.color.view())
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } })];
        let ss_depth = vk::RenderingAttachmentInfo::default()
            .image_view(ss.depth.view())
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
        let ss_rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent: big })
            .layer_count(1)
            .color_attachments(&ss_color)
            .depth_attachment(&ss_depth);
        let sampled =
            Access { stage: vk::PipelineStageFlags2::FRAGMENT_SHADER, access: vk::AccessFlags2::SHADER_SAMPLED_READ };
        let to_attachments = [
            barrier::image(
                &ss.color,
                sampled,
                Access::COLOR_ATTACHMENT_WRITE,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            ),
            barrier::image(
                &ss.depth,
                sampled,
                Access::DEPTH_ATTACHMENT,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            ),
        ];
        let to_sampled = [
            barrier::image(
                &ss.color,
                Access::COLOR_ATTACHMENT_WRITE,
                sampled,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            ),
            barrier::image(
                &ss.depth,
                Access::DEPTH_ATTACHMENT,
                sampled,
                vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            ),
        ];
        let mut ss = ss;
        // SAFETY: guaranteed by the caller; the supersampling images are this
        // renderer's and earlier resolves that sampled them are ordered by the barriers.
        let result = unsafe {
            let scope = begin_pass(d, cmd, &mut profiler, RenderPass::Draw);
            d.cmd_barrier(cmd, &[], &[], &to_attachments);
            let drawn = self.draw_hair(cmd, ss_key, &ss_rendering, big, &params);
            end_pass(d, cmd, &mut profiler, scope);
            drawn.and_then(|_| {
                let scope = begin_pass(d, cmd, &mut profiler, RenderPass::Resolve);
                let resolved = ss.pipeline(host_key).map(|(pipeline, set)| {
                    d.cmd_barrier(cmd, &[attachments], &[], &to_sampled);
                    d.raw.cmd_begin_rendering(cmd, &host_rendering);
                    set_viewport(d, cmd, target.extent);
                    pipeline.bind(cmd, &[*set]);
                    d.raw.cmd_draw(cmd, 3, 1, 0, 0);
                    d.raw.cmd_end_rendering(cmd);
                });
                end_pass(d, cmd, &mut profiler, scope);
                resolved
            })
        };
        self.supersampling = Some(ss);
        result
    }
}

/// A pipeline of tessellation stages that only store (rasterization off), for the
/// geometry passes.
pub(crate) fn capture_pipeline(
    device: &Arc<Device>,
    name: &str,
    stages: &[&crate::vk::shaders::ShaderSource],
    patch_control_points: u32,
    max_sets: u32,
) -> Result<crate::vk::pipeline::GraphicsPipeline> {
    crate::vk::pipeline::GraphicsPipeline::new(
        device,
        &crate::vk::pipeline::GraphicsDesc {
            name,
            stages,
            topology: vk::PrimitiveTopology::PATCH_LIST,
            patch_control_points,
            color_formats: &[],
            depth_format: vk::Format::UNDEFINED,
            samples: vk::SampleCountFlags::TYPE_1,
            depth_test: false,
            depth_write: false,
            blend: crate::vk::pipeline::Blend::None,
            rasterizer_discard: true,
        },
        max_sets,
    )
}

/// Opens a pass: a timestamp scope (with its label) or just a label.
///
/// # Safety
/// `cmd` is recording; with a profiler, its frame was begun.
unsafe fn begin_pass(
    d: &Device,
    cmd: vk::CommandBuffer,
    profiler: &mut Option<&mut GpuProfiler>,
    pass: RenderPass,
) -> Option<crate::ScopeId> {
    // SAFETY: guaranteed by the caller.
    unsafe {
        match profiler.as_deref_mut() {
            Some(p) => Some(p.begin_scope(cmd, pass.label())),
            None => {
                d.cmd_begin_label(cmd, pass.label(), LabelColor::Graphics);
                None
            }
        }
    }
}

/// Closes a pass opened by [`begin_pass`].
///
/// # Safety
/// As for [`begin_pass`], in the same command buffer.
unsafe fn end_pass(
    d: &Device,
    cmd: vk::CommandBuffer,
    profiler: &mut Option<&mut GpuProfiler>,
    scope: Option<crate::ScopeId>,
) {
    // SAFETY: guaranteed by the caller.
    unsafe {
        match (profiler.as_deref_mut(), scope) {
            (Some(p), Some(scope)) => p.end_scope(cmd, scope),
            _ => d.cmd_end_label(cmd),
        }
    }
}

/// Full-extent viewport and scissor.
///
/// # Safety
/// `cmd` is recording inside a rendering instance.
unsafe fn set_viewport(d: &Device, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    // SAFETY: guaranteed by the caller.
    unsafe {
        d.raw.cmd_set_viewport(cmd, 0, &[viewport]);
        d.raw.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
    }
}

impl Renderer {
    /// Builds the Marschner tables for the current material and reads them back
    /// (M indexed by sin θi, sin θo; N by cos φ, cos θd; rows of
    /// [`marschner::TABLE_SIZE`] texels) — for tests and tools (submits and waits).
    pub fn read_marschner_tables(&mut self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let device = self.device.clone();
        let params = self.material.marschner;
        device.submit_once("vkhair marschner tables", |cmd| {
            // SAFETY: a recording command buffer of this device; earlier work completed.
            unsafe { self.marschner.record_update(&device, cmd, &params) };
        })?;
        Ok((self.marschner.read(&device, false)?, self.marschner.read(&device, true)?))
    }
}

impl Detail {
    /// This detail, lowered where `params` allows less.
    fn min_with(self, params: &RenderParams) -> Detail {
        Detail {
            smoothing_level: self.smoothing_level.min(params.smoothing_level),
            hairs_per_key: self.hairs_per_key.min(params.hairs_per_key),
            width_scale: self.width_scale,
        }
    }
}
