//! Pass 4 — drawing the hair into the host's target, and pass 5, the
//! supersampling resolve ([`super::resolve`]), which [`Renderer::record_draw`]
//! records after it.
//!
//! One frame of pass 4 is a [`DrawFrame`]: the host's command buffer and frame
//! index, the profiler handle, the [`DrawTarget`] (the host's images, or the
//! supersampling images twice their size), what the shading reads and the
//! frame's uniform block. Every mode draws the same ribbons
//! (`glsl/render/ribbon.vert`, two triangles a segment) with the same shading
//! (`hair_shading.glsl`, [`shading::ShadingResources`]) and differs only in
//! where the shading runs (per fragment when opaque; per hair vertex in a
//! compute dispatch, `shade_points.comp`, for the transparent modes, whose
//! fragments only add coverage) and how fragments reach the target, one file
//! each, selected by one value a frame, the [`DrawMethod`] (`method.rs`) that
//! [`super::Transparency`] and the resolved [`Raster`] make together:
//!
//! - [`DrawMethod::Opaque`] ([`super::Transparency::Off`]) — `opaque.rs`: a
//!   depth pre-pass and a shaded draw of the nearest layer;
//! - [`DrawMethod::HardwareLists`], [`DrawMethod::ComputeLists`],
//!   [`DrawMethod::Tiles`] ([`super::Transparency::Exact`]) — `transparent/`
//!   with `exact.rs` (per-pixel fragment lists, the nearest sorted, built by
//!   the hardware raster pipeline or `raster.rs`) or `tiles.rs`;
//! - [`DrawMethod::Weighted`] ([`super::Transparency::Fast`]) — `transparent/`
//!   with `fast.rs`: weighted blended sums.

mod exact;
mod fast;
mod method;
mod motion;
mod opaque;
mod opaque_motion;
mod raster;
mod ribbons;
mod shading;
mod tiles;
mod transparent;

use std::sync::Arc;

use ash::vk;

pub use exact::OitPool;
pub(super) use method::DrawMethod;
pub use transparent::OitStats;

use super::marschner::MarschnerParams;
use super::shading::{Camera, HairMaterial, ShadingMode, MAX_LIGHTS};
use super::shadow::ShadowParams;
use super::{OitParams, Primitive, Raster, RenderTarget, Renderer};
use crate::error::{Error, Result};
use crate::gpu_types::{DrawParams, GpuLight};
use crate::profiler::{GpuProfiler, Timing};
use crate::render::graph::{FrameGraph, Use};
use crate::vk::barrier;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::ShaderSource;
pub(super) use motion::MotionHistory;
pub use motion::VELOCITY_FORMATS;
use motion::{HairLayout, MotionFrame};
use opaque::OpaquePipelines;
use opaque_motion::OpaqueMotion;
use ribbons::RibbonIndices;
use shading::ShadingResources;
use transparent::TransparentPass;

/// A transparency mode's fragment stages: the build's and the composite's
/// (`exact` and `fast` give theirs, `transparent` builds the pass from them).
pub(super) struct ModeShaders {
    pub build: &'static ShaderSource,
    pub composite: &'static ShaderSource,
    /// A compute resolve recorded before the composite, when the mode has one.
    pub resolve: Option<&'static ShaderSource>,
}

impl ModeShaders {
    /// The name the mode's pipelines are kept under: the resolve's, else the
    /// composite's (each names the mode and its K).
    pub fn key(&self) -> &'static str {
        self.resolve.map_or(self.composite.name, |r| r.name)
    }
}

/// Formats, sample count and primitive a draw pipeline is made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct TargetKey {
    pub color: vk::Format,
    pub depth: vk::Format,
    pub samples: vk::SampleCountFlags,
    pub primitive: Primitive,
    /// The depth is reversed (near = 1; [`super::Camera::depth_reversed`]).
    pub reverse_z: bool,
}

/// Where a frame's hair goes: images with `key`'s formats, how each
/// attachment's earlier contents are loaded the first time the frame uses it,
/// and the frame graph's uses of them as attachments.
#[derive(Clone)]
pub(super) struct DrawTarget {
    pub key: TargetKey,
    pub extent: vk::Extent2D,
    pub color: (vk::ImageView, Load),
    pub depth: Option<(vk::ImageView, Load)>,
    /// The image behind a kept depth attachment, for the compute rasteriser's
    /// copy ([`RenderTarget::depth_image`]); `None` when not given.
    pub depth_image: Option<vk::Image>,
    /// The attachments as the draw uses them ([`FrameGraph`] declarations).
    pub uses: Vec<Use>,
}

impl DrawTarget {
    /// The colour attachment as the frame first uses it.
    fn color_attachment(&self) -> [vk::RenderingAttachmentInfo<'static>; 1] {
        [rendering::color(self.color.0, self.color.1)]
    }

    /// The depth attachment as the frame first uses it.
    fn depth_attachment(&self) -> Option<vk::RenderingAttachmentInfo<'static>> {
        self.depth.map(|(view, load)| rendering::depth(view, load))
    }

    /// The depth attachment once the frame has used it (its contents kept).
    fn depth_kept(&self) -> Option<vk::RenderingAttachmentInfo<'static>> {
        self.depth.map(|(view, _)| rendering::depth(view, Load::Keep))
    }
}

/// What the draw reads besides its own resources.
pub(super) struct DrawInputs<'a> {
    /// Interpolated hair positions and (tangent, t).
    pub hairs: (&'a Buffer, &'a Buffer),
    /// The frame's shadow uniforms.
    pub shadow_uniforms: &'a Buffer,
    /// The opacity atlas and its sampler.
    pub atlas: (vk::ImageView, vk::Sampler),
    /// The opacity atlas as the draw samples it.
    pub atlas_use: Use,
    /// Per-cell transmittance of density-volume lights.
    pub transmittance: &'a Buffer,
    /// Per hair its own albedo at the root and the tip (read when the draw
    /// parameters say the hairs have them).
    pub looks: &'a Buffer,
}

/// One frame of pass 4: everything its modes record with and into.
pub(super) struct DrawFrame<'a> {
    /// The host's command buffer, recording outside a render pass.
    pub cmd: vk::CommandBuffer,
    /// The host's frame index.
    pub frame: u64,
    /// Where the pass's timestamps go.
    pub timing: Timing<'a>,
    /// Where the hair goes.
    pub target: DrawTarget,
    /// What the shading reads besides the pass's own resources.
    pub inputs: DrawInputs<'a>,
    /// The frame's uniform block.
    pub params: DrawParams,
    /// The Marschner tables' parameters (rebuilt when they change).
    pub marschner: MarschnerParams,
    /// Segments of the frame's hairs: a ribbon or a line each.
    pub segments: u32,
    /// The optional parts of the shading the frame needs
    /// ([`crate::codes::shading_features`]): the shading pipelines are
    /// specialised to them.
    pub features: u32,
    /// The motion vectors, where the host's target has a velocity image.
    pub motion: Option<MotionFrame<'a>>,
}

impl DrawFrame<'_> {
    /// The format of the frame's velocity image (`UNDEFINED` for none).
    fn velocity_format(&self) -> vk::Format {
        self.motion.as_ref().map_or(vk::Format::UNDEFINED, |m| m.format)
    }
}

/// Pass 4: the shading every mode shares, the opaque pipelines and the
/// transparency modes' resources.
pub(super) struct DrawPass {
    shading: ShadingResources,
    ribbons: RibbonIndices,
    opaque: OpaquePipelines,
    /// Motion vectors of opaque frames (the transparent pass has its own).
    opaque_motion: OpaqueMotion,
    transparent: TransparentPass,
}

impl DrawPass {
    /// The pass for a renderer drawing at most `hair_vertices` hair vertices.
    pub(super) fn new(device: &Arc<Device>, hair_vertices: u64) -> Result<Self> {
        Ok(DrawPass {
            shading: ShadingResources::new(device)?,
            ribbons: RibbonIndices::new(device)?,
            opaque: OpaquePipelines::new(device),
            opaque_motion: OpaqueMotion::new(device),
            transparent: TransparentPass::new(device, hair_vertices)?,
        })
    }

    /// Drops every pipeline and set (the draw's inputs changed); the caller made
    /// sure no pending work uses them.
    pub(super) fn forget(&mut self) {
        self.opaque.forget();
        self.opaque_motion.forget();
        self.transparent.forget();
    }

    /// Records `frame` by `method` (`oit` its transparency parameters).
    ///
    /// # Safety
    /// `frame.cmd` is a recording command buffer of this device outside a render
    /// pass; the target's attachments are in the layouts `frame.target.uses`
    /// name as their rest; every earlier command on the resources since `graph`
    /// was made was declared to it; the frames `frames_in_flight` before
    /// `frame.frame` completed.
    unsafe fn record(
        &mut self,
        frame: &DrawFrame<'_>,
        graph: &mut FrameGraph,
        method: DrawMethod,
        oit: &OitParams,
    ) -> Result<()> {
        // SAFETY: guaranteed by the caller.
        unsafe {
            match method {
                DrawMethod::Opaque => self
                    .opaque
                    .record(frame, graph, &mut self.shading, &self.ribbons)
                    .and_then(|_| self.opaque_motion.record(frame, graph, &self.shading)),
                _ => self.transparent.record(frame, graph, (method, oit), &mut self.shading, &self.ribbons),
            }
        }
    }

    /// Builds the Marschner tables for `params` and reads them back (M, then N;
    /// submits and waits).
    pub(super) fn read_marschner_tables(
        &mut self,
        params: &MarschnerParams,
    ) -> Result<(Vec<glam::Vec4>, Vec<glam::Vec4>)> {
        self.shading.read_marschner_tables(params)
    }
}

/// Passes 4–5: the draw and the resolve.
impl Renderer {
    /// Records the draw pass for the host's frame `frame`: the hairs prepared by
    /// [`Renderer::record_prepare`] into the host's `target`, seen by `camera`. The
    /// color (and depth) image is loaded, drawn into with depth test and write
    /// against what the host drew, and stored. With [`super::RenderParams::supersampling`],
    /// the hair is drawn at twice the size into the renderer's own images and
    /// resolved into `target` (depth tested, not written). When the target's size
    /// changes, the images of the old size are kept until `frame` is
    /// [`super::RenderParams::frames_in_flight`] frames later. Viewport and scissor are
    /// left set to the full target and one of vkhair's pipelines bound, and,
    /// when ribbons were drawn, vkhair's 16-bit index buffer of their corners;
    /// vkhair binds no vertex buffers, so the host's stay bound, and the host
    /// binds its own pipeline and index buffer and pushes its constants again
    /// afterwards (`tests/viewer.rs` draws from its vertex buffers after the
    /// hair relying on this).
    ///
    /// With [`super::RenderParams::transparency`] on, the hair is composited over
    /// the target's colour instead (see `render/draw/transparent/`): each
    /// fragment depth-tested against the target's depth, and the depth of the
    /// nearest fragment at least half opaque written where it is nearer (not
    /// with supersampling, whose resolve leaves the host's depth as it was); the
    /// target must then be single-sample.
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
        profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        if target.extent.width == 0 || target.extent.height == 0 {
            return Err(Error::param(
                "render target extent",
                format!("{:?}", target.extent),
                "non-zero width and height",
            ));
        }
        if self.last_frame.is_some_and(|last| frame < last) {
            return Err(Error::incompatible(
                "frame",
                format!("{frame} is before the previous frame {:?}", self.last_frame),
            ));
        }
        self.last_frame = Some(frame);
        self.resolve.collect_retired(frame, self.params.frames_in_flight);
        self.draw.transparent.collect_retired(frame, self.params.frames_in_flight);
        self.draw.opaque_motion.collect_retired(frame, self.params.frames_in_flight);
        let finite = camera.view.is_finite() && camera.projection.is_finite() && camera.fov_y.is_finite();
        if !finite {
            return Err(Error::param(
                "camera",
                "a non-finite matrix or field of view",
                "finite view, projection and field of view",
            ));
        }
        if !camera.jitter.is_finite() || camera.jitter.abs().max_element() > 1.0 {
            return Err(Error::param("camera jitter", camera.jitter, "finite, within ±1 pixel on each axis"));
        }
        let has_depth = target.depth_format != vk::Format::UNDEFINED;
        let reverse_z = camera.depth_reversed();
        let host = DrawTarget {
            key: TargetKey {
                color: target.color_format,
                depth: target.depth_format,
                samples: target.samples,
                primitive: self.params.primitive,
                reverse_z,
            },
            extent: target.extent,
            color: (target.color, Load::Keep),
            depth: has_depth.then_some((target.depth, Load::Keep)),
            depth_image: (has_depth && target.depth_image != vk::Image::null()).then_some(target.depth_image),
            // The host's earlier writes (its head, its clear) are unknown to the
            // graph: the first use waits for any.
            uses: vec![Use::host_attachments(barrier::ATTACHMENTS)],
        };
        // With supersampling, the hair goes into the renderer's own images first.
        let mut images = match self.params.supersampling {
            true => Some(self.resolve.take(frame, target.extent)?),
            false => None,
        };
        let drawn = match &images {
            Some(images) => images.draw_target(self.params.primitive, reverse_z),
            None => host.clone(),
        };
        let method = self.draw_method();
        let hairs = self.hair_layout();
        let motion = match target.velocity == vk::ImageView::null() {
            true => None,
            false if target.samples != vk::SampleCountFlags::TYPE_1 => {
                return Err(Error::incompatible(
                    "render target",
                    "motion vectors go into a single-sample target (a multisampled host resolves first, or \
                     draws the hair supersampled)",
                ));
            }
            false => {
                if self.motion.is_none() {
                    self.motion = Some(MotionHistory::new(&self.device, self.interpolate.hairs().0.size() / 16)?);
                }
                let history = self.motion.as_ref().ok_or_else(|| Error::incompatible("motion", "no history"))?;
                let images = (target.velocity, target.velocity_format);
                // Opaque hair is tested against the host's depth when written
                // (the walk's nearest ribbon may lie behind the host's meshes).
                let opaque = match method {
                    DrawMethod::Opaque => Some(has_depth.then_some((target.depth, target.depth_format))),
                    _ => None,
                };
                Some(history.frame(
                    &self.params.motion,
                    images,
                    (camera, target.extent, drawn.extent),
                    (hairs, opaque),
                )?)
            }
        };
        let frame = DrawFrame {
            cmd,
            frame,
            timing: Timing::of(profiler.as_deref()),
            params: own_looks(
                draw_params(
                    method != DrawMethod::Opaque,
                    &self.material,
                    &self.lights,
                    StrandFootprint {
                        width_scale: self.detail.width_scale,
                        hairs: self.strand_hairs(),
                        spacing: self.strand_spacing(),
                    },
                    self.hair_counts(),
                    (camera, target.extent),
                    drawn.extent,
                ),
                self.interpolate.looks().1,
            ),
            segments: self.draw_segments(),
            features: shading_features(&self.material, self.shadows.params()),
            target: drawn,
            inputs: DrawInputs {
                hairs: self.interpolate.hairs(),
                shadow_uniforms: self.shadows.uniforms(),
                atlas: self.shadows.atlas(),
                atlas_use: self.shadows.atlas_use(),
                transmittance: self.shadows.transmittance(),
                looks: self.interpolate.looks().0,
            },
            marschner: self.material.marschner,
            motion,
        };
        let mut graph = FrameGraph::new();
        // SAFETY: guaranteed by the caller; the supersampling images are this
        // renderer's and earlier resolves that sampled them are ordered by the
        // graph's first uses.
        let result = unsafe {
            let drawn = self.draw.record(&frame, &mut graph, method, &self.params.oit);
            let resolved = match &mut images {
                Some(images) => drawn.and_then(|_| self.resolve.record(cmd, &mut graph, images, &host, frame.timing)),
                None => drawn,
            };
            graph.settle(&self.device, cmd);
            resolved
        };
        if let Some(images) = images {
            self.resolve.restore(images);
        }
        let wrote_motion = frame.motion.is_some();
        drop(frame);
        if let (Ok(()), true, Some(history)) = (&result, wrote_motion, self.motion.as_mut()) {
            // SAFETY: guaranteed by the caller; recorded after the frame's walk.
            unsafe { history.record_keep(cmd, self.interpolate.hairs().0, camera, hairs) };
        }
        result
    }

    /// Forgets the previous frame for motion vectors: the next frame's are
    /// zero for every hair, whatever moved (for a camera cut or a teleport,
    /// where the motion since the last frame means nothing to a TAA history).
    pub fn reset_motion(&mut self) {
        if let Some(history) = &mut self.motion {
            history.reset();
        }
    }

    /// The drawn hairs of the frame as the motion vectors see them.
    fn hair_layout(&self) -> HairLayout {
        let (hairs, per_hair) = self.hair_counts();
        // Followers keep one stable order; grown hairs are numbered by the
        // hairs grown per key (and the mode that grows them).
        let order = match self.followers {
            Some(_) => 0,
            None => {
                (u64::from(self.params.interpolation == super::InterpolationMode::Barycentric) << 32)
                    | (u64::from(self.detail.hairs_per_key) + 1)
            }
        };
        HairLayout { hairs, per_hair, order }
    }

    /// The rasteriser the current parameters draw with on this device:
    /// [`RenderParams::raster`](super::RenderParams::raster) resolved for the
    /// device's type in the exact mode ([`Raster::resolve`]), and
    /// [`Raster::Hardware`] in the other modes, which draw only through the
    /// hardware raster pipeline.
    pub fn raster(&self) -> Raster {
        self.draw_method().raster()
    }

    /// How the current parameters draw on this device: the transparency mode
    /// with [`RenderParams::raster`](super::RenderParams::raster) resolved.
    pub(super) fn draw_method(&self) -> DrawMethod {
        let raster = self.params.raster.resolve(self.device.info.device_type);
        DrawMethod::of(self.params.transparency, raster)
    }

    /// Sets of size-dependent images waiting for their frames to complete
    /// (supersampling images and transparency lists).
    pub fn retired_image_sets(&self) -> usize {
        self.resolve.retired_count() + self.draw.transparent.retired_count() + self.draw.opaque_motion.retired_count()
    }

    /// The extent the hair is drawn at for a target of `extent`: twice each
    /// side with supersampling.
    fn drawn_extent(&self, extent: vk::Extent2D) -> vk::Extent2D {
        let scale = if self.params.supersampling { 2 } else { 1 };
        vk::Extent2D { width: extent.width.saturating_mul(scale), height: extent.height.saturating_mul(scale) }
    }

    /// What the latest frame drawn with [`super::Transparency::Exact`] stored: fragments
    /// offered, stored, and overflowed because the pool was full (those are
    /// composited unsorted behind the stored ones). Read from
    /// host-visible memory: valid once that frame's commands completed and before
    /// the next frame's are submitted. `None` unless the latest frame drawn with
    /// transparency was an exact-mode frame.
    pub fn transparency_stats(&self) -> Option<OitStats> {
        self.draw.transparent.stats()
    }

    /// GPU memory the transparency mode of the current parameters needs for a
    /// target of `extent` (the supersampled extent where supersampling is on), bytes.
    pub fn transparency_memory(&self, extent: vk::Extent2D) -> u64 {
        let drawn = self.drawn_extent(extent);
        self.draw.transparent.memory_bytes(&self.device.info, self.draw_method(), &self.params.oit, drawn)
    }

    /// The exact mode's fragment pool for a target of `extent` (the
    /// supersampled extent where supersampling is on) on this device: what
    /// [`OitParams::fragments_per_pixel`] asks for and what the device's buffers
    /// hold ([`OitPool::is_capped`] when fewer). `None` unless the current mode
    /// is [`super::Transparency::Exact`] with per-pixel lists (the tiled rasteriser,
    /// [`Raster::Tiles`], keeps none).
    pub fn transparency_pool(&self, extent: vk::Extent2D) -> Option<OitPool> {
        if !self.draw_method().lists() {
            return None;
        }
        Some(OitPool::plan(&self.device.info, &self.params.oit, self.drawn_extent(extent)))
    }
}

/// How the frame's drawn strands stand for the real hairs.
#[derive(Debug, Clone, Copy)]
pub(super) struct StrandFootprint {
    /// Width factor of opaque ribbons at the frame's detail.
    pub width_scale: f32,
    /// Real hairs each drawn strand stands for (transparent bands).
    pub hairs: f32,
    /// Spacing of the drawn strands at the root and at the tip, m.
    pub spacing: (f32, f32),
}

/// The optional parts of the shading ([`crate::codes::shading_features`]) a
/// frame with `material` and `shadows` runs.
fn shading_features(material: &HairMaterial, shadows: &ShadowParams) -> u32 {
    use crate::codes::shading_features::{DENSITY_VOLUME, MARSCHNER};
    let marschner = if material.shading == ShadingMode::Marschner { MARSCHNER } else { 0 };
    let volume = if shadows.volume_casters() > 0 { DENSITY_VOLUME } else { 0 };
    marschner | volume
}

/// `params` for hairs drawn in their own albedo (`own`) or the material's.
fn own_looks(mut params: DrawParams, own: bool) -> DrawParams {
    params.widths[3] = if own { 1.0 } else { 0.0 };
    params
}

/// The draw's uniform block for `hairs` hairs of `per_hair` vertices with
/// `material`, `lights` and the frame's strand `footprint`, seen by `camera`
/// (jittered by pixels of the host's target, of `target_extent`) into an
/// image of `extent`; `transparent` strands are drawn with their
/// coverage (no least width, bands standing for the footprint's hairs),
/// opaque ones at the footprint's width factor.
pub(super) fn draw_params(
    transparent: bool,
    material: &HairMaterial,
    lights: &[GpuLight],
    footprint: StrandFootprint,
    (hairs, per_hair): (u32, u32),
    (camera, target_extent): (&Camera, vk::Extent2D),
    extent: vk::Extent2D,
) -> DrawParams {
    let m = material;
    // Transparent bands stand for the hairs level of detail leaves out; opaque
    // ribbons widen instead.
    let width_scale = if transparent { 1.0 } else { footprint.width_scale };
    let mut gpu_lights = [GpuLight::default(); MAX_LIGHTS];
    gpu_lights[..lights.len()].copy_from_slice(lights);
    // World size of one pixel at distance 1.
    let pixel = 2.0 * (0.5 * camera.fov_y).tan() / extent.height.max(1) as f32;
    DrawParams {
        view_proj: (camera.jittered_projection((target_extent.width, target_extent.height)) * camera.view)
            .to_cols_array_2d(),
        camera: camera.position().extend(pixel).to_array(),
        root_color: m.root_color.extend(m.ambient).to_array(),
        tip_color: m.tip_color.extend(m.diffuse_wrap).to_array(),
        primary: m.primary_color.extend(m.primary_exponent).to_array(),
        secondary: m.secondary_color.extend(m.secondary_exponent).to_array(),
        shifts: [m.primary_shift, m.secondary_shift, m.shift_jitter, m.highlight_breakup],
        widths: [m.root_width * width_scale, m.tip_width * width_scale, m.least_pixel_width, 0.0],
        coverage: [if transparent { 1.0 } else { 0.0 }, m.opacity, footprint.hairs, 0.0],
        band: [footprint.spacing.0, footprint.spacing.1, 0.0, 0.0],
        counts: [hairs, per_hair, lights.len() as u32, m.shading.code()],
        lights: gpu_lights,
    }
}
