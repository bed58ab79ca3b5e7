//! Pass 4 — drawing (`glsl/render/draw.*`): the interpolated hairs as
//! camera-facing ribbons expanded in the geometry stage, shaded with
//! Kajiya-Kay diffuse and two shifted highlights for every light, into the
//! host's color and depth images (dynamic rendering, depth-tested against what
//! the host drew). With a depth image the ribbons are drawn twice in one
//! rendering instance: first depth only (no fragment stage), then shaded with
//! depth writes off and the depth test passing only fragments at the nearest
//! depth, so that hidden layers of hair are not shaded. Pipelines are made on
//! first use for each combination of color format, depth format, sample count
//! and primitive. The pass owns the Marschner lookup tables it samples and
//! rebuilds them when the material's parameters change.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use glam::Vec4;

use super::marschner::{MarschnerParams, MarschnerTables};
use super::pass::RenderPass;
use super::shading::{noise_texels, Camera, HairMaterial, MAX_LIGHTS, NOISE_SIZE};
use super::Primitive;
use crate::error::Result;
use crate::gpu_types::{DrawParams, GpuLight};
use crate::profiler::GpuProfiler;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::shaders::{ShaderSource, RENDER_DRAW_FRAG, RENDER_DRAW_GEOM, RENDER_DRAW_VERT};

/// Formats, sample count and primitive a draw pipeline is made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct TargetKey {
    pub color: vk::Format,
    pub depth: vk::Format,
    pub samples: vk::SampleCountFlags,
    pub primitive: Primitive,
}

/// The draw pass: its pipelines per target, the uniform block it reads, the
/// noise texture and the Marschner tables.
pub(super) struct DrawPass {
    device: Arc<Device>,
    pipelines: HashMap<TargetKey, DrawPipelines>,
    noise: Image,
    sampler: Sampler,
    /// The frame's [`DrawParams`], written by a transfer before the draw.
    params: Buffer,
    /// Marschner lookup tables, rebuilt when their parameters change.
    marschner: MarschnerTables,
}

/// The pipelines of one target: the depth pre-pass (targets with a depth image)
/// and the shading draw, each with its descriptor set.
struct DrawPipelines {
    depth: Option<(GraphicsPipeline, vk::DescriptorSet)>,
    shade: (GraphicsPipeline, vk::DescriptorSet),
}

/// The shading stages' buffers and (view, sampler) images, by binding.
pub(super) type ShadingBindings<'a> = ([(u32, &'a Buffer); 5], [(u32, vk::ImageView, vk::Sampler); 4]);

/// What the draw reads besides its own resources.
pub(super) struct DrawInputs<'a> {
    /// Interpolated hair positions and (tangent, t).
    pub hairs: (&'a Buffer, &'a Buffer),
    /// The frame's shadow uniforms.
    pub shadow_uniforms: &'a Buffer,
    /// The opacity atlas and its sampler.
    pub atlas: (vk::ImageView, vk::Sampler),
    /// Per-cell transmittance of density-volume lights.
    pub transmittance: &'a Buffer,
}

/// Where the draw goes: a rendering instance of images with `key`'s formats.
pub(super) struct DrawTarget<'a> {
    pub key: TargetKey,
    pub rendering: &'a vk::RenderingInfo<'a>,
    pub extent: vk::Extent2D,
}

impl DrawPass {
    pub(super) fn new(device: &Arc<Device>) -> Result<Self> {
        let noise = Image::new(
            device,
            &ImageDesc {
                name: "vkhair hair noise",
                extent: vk::Extent2D { width: NOISE_SIZE, height: NOISE_SIZE },
                format: vk::Format::R8G8_UNORM,
                usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        device.upload_image(&noise, &noise_texels())?;
        let sampler = Sampler::new(device, "vkhair noise sampler", true)?;
        let params = Buffer::uniform(device, "vkhair draw params", std::mem::size_of::<DrawParams>() as u64)?;
        let marschner = MarschnerTables::new(device)?;
        Ok(DrawPass { device: device.clone(), pipelines: HashMap::new(), noise, sampler, params, marschner })
    }

    /// Makes the pipelines and descriptor sets for `key` on first use, bound to
    /// [`DrawPass::shading_bindings`] of `inputs`.
    fn make_pipelines(&mut self, key: TargetKey, inputs: &DrawInputs<'_>) -> Result<()> {
        if self.pipelines.contains_key(&key) {
            return Ok(());
        }
        let (buffers, images) = self.shading_bindings(inputs);
        let color_formats = [key.color];
        let has_depth = key.depth != vk::Format::UNDEFINED;
        // Lines skip the geometry stage: the fragment stage reads the vertex
        // stage's outputs at the same locations.
        let lines = key.primitive == Primitive::Lines;
        let shading: &[&ShaderSource] = if lines {
            &[&RENDER_DRAW_VERT, &RENDER_DRAW_FRAG]
        } else {
            &[&RENDER_DRAW_VERT, &RENDER_DRAW_GEOM, &RENDER_DRAW_FRAG]
        };
        let desc = |name, stages, depth_write, blend| GraphicsDesc {
            name,
            stages,
            topology: vk::PrimitiveTopology::LINE_LIST,
            patch_control_points: 0,
            color_formats: &color_formats,
            depth_format: key.depth,
            samples: key.samples,
            depth_test: has_depth,
            depth_write,
            blend,
            rasterizer_discard: false,
        };
        // The geometry is the same in both: only the hair positions (bindings 1
        // and 2) and the uniform block.
        let depth = if has_depth {
            let stages = &shading[..shading.len() - 1];
            let pipeline =
                GraphicsPipeline::new(&self.device, &desc("vkhair hair depth", stages, true, Blend::NoColor), 1)?;
            let set = pipeline.resource_set(0, &buffers[..3], &[])?;
            Some((pipeline, set))
        } else {
            None
        };
        let pipeline = GraphicsPipeline::new(&self.device, &desc("vkhair hair draw", shading, false, Blend::None), 1)?;
        let set = pipeline.resource_set(0, &buffers, &images)?;
        self.pipelines.insert(key, DrawPipelines { depth, shade: (pipeline, set) });
        Ok(())
    }

    /// Drops every pipeline and set (their resources changed); the caller made sure
    /// no pending work uses them.
    pub(super) fn forget(&mut self) {
        self.pipelines.clear();
    }

    /// Records the draw in its own scope: first `before` (the barriers that make
    /// the target ready), then the Marschner tables' rebuild if `marschner`
    /// changed, the parameter update and one draw of `vertices` line vertices
    /// into `target`.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass;
    /// after `before`, the target's attachments are in attachment layouts with
    /// earlier writes visible; the inputs were written earlier in submission order
    /// with barriers to the draw's stages (the capture and shadow passes leave them so).
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        before: (&[vk::MemoryBarrier2<'_>], &[vk::ImageMemoryBarrier2<'_>]),
        target: &DrawTarget<'_>,
        inputs: &DrawInputs<'_>,
        params: &DrawParams,
        marschner: &MarschnerParams,
        vertices: u32,
        profiler: &mut Option<&mut GpuProfiler>,
    ) -> Result<()> {
        // Made (or found) before anything is recorded: a failure leaves `cmd` as it was.
        self.make_pipelines(target.key, inputs)?;
        let device = self.device.clone();
        let d = &device;
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            let scope = RenderPass::Draw.open(d, cmd, profiler);
            self.record_updates(cmd, before, params, marschner);
            let pipelines = &self.pipelines[&target.key];
            d.raw.cmd_begin_rendering(cmd, target.rendering);
            d.cmd_set_full_viewport(cmd, target.extent);
            // Within one rendering instance, rasterization order puts the depth
            // pre-pass's writes before the shading draw's tests.
            for (pipeline, set) in pipelines.depth.iter().chain([&pipelines.shade]) {
                pipeline.bind(cmd, &[*set]);
                d.raw.cmd_draw(cmd, vertices, 1, 0, 0);
            }
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, profiler);
        }
        Ok(())
    }

    /// The shading stages' buffers and images by binding: this pass's uniform
    /// block (binding 0, first), noise (binding 3, first image) and Marschner
    /// tables, and `inputs`.
    pub(super) fn shading_bindings<'a>(&'a self, inputs: &DrawInputs<'a>) -> ShadingBindings<'a> {
        let sampler = self.marschner.sampler.raw;
        (
            [
                (0, &self.params),
                (1, inputs.hairs.0),
                (2, inputs.hairs.1),
                (6, inputs.shadow_uniforms),
                (8, inputs.transmittance),
            ],
            [
                (3, self.noise.view(), self.sampler.raw),
                (4, self.marschner.m.view(), sampler),
                (5, self.marschner.n.view(), sampler),
                (7, inputs.atlas.0, inputs.atlas.1),
            ],
        )
    }

    /// Records `before` (the barriers that make the target ready), the Marschner
    /// tables' rebuild if `marschner` changed and the update of the uniform block
    /// to `params`, with the barriers that make both visible to the draw's stages.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass;
    /// draws recorded earlier that read the uniform block are ordered before by the
    /// recorded barrier.
    pub(super) unsafe fn record_updates(
        &mut self,
        cmd: vk::CommandBuffer,
        before: (&[vk::MemoryBarrier2<'_>], &[vk::ImageMemoryBarrier2<'_>]),
        params: &DrawParams,
        marschner: &MarschnerParams,
    ) {
        let d = &self.device;
        let before_update = barrier::memory(&[AccessKind::AnyWrite], &[AccessKind::TransferWrite]);
        let updated = barrier::memory(&[AccessKind::TransferWrite], UNIFORM_READERS);
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            d.cmd_barrier(cmd, before.0, &[], before.1);
            // The draw pipeline may sample the Marschner tables: build them first.
            self.marschner.record_update(d, cmd, marschner);
            d.cmd_barrier(cmd, &[before_update], &[], &[]);
            d.raw.cmd_update_buffer(cmd, self.params.raw(), 0, bytemuck::bytes_of(params));
            d.cmd_barrier(cmd, &[updated], &[], &[]);
        }
    }

    /// Builds the Marschner tables for `params` and reads them back (M, then N;
    /// submits and waits).
    pub(super) fn read_marschner_tables(&mut self, params: &MarschnerParams) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let device = self.device.clone();
        device.submit_once("vkhair marschner tables", |cmd| {
            // SAFETY: a recording command buffer of this device; earlier work completed.
            unsafe { self.marschner.record_update(&device, cmd, params) };
        })?;
        Ok((self.marschner.read(&device, false)?, self.marschner.read(&device, true)?))
    }
}

/// Fraction of a band of `n` hair widths that `n` hairs placed at random across
/// it cover: 1 − (1 − 1/n)^n (1 for one hair, toward 1 − 1/e for many).
pub(super) fn band_density(n: f32) -> f32 {
    let n = n.max(1.0);
    1.0 - (1.0 - 1.0 / n).powf(n)
}

/// Stages that read the draw's uniform block.
const UNIFORM_READERS: &[AccessKind] =
    &[AccessKind::VertexUniformRead, AccessKind::GeometryUniformRead, AccessKind::FragmentUniformRead];

/// The draw's uniform block for `hairs` hairs of `per_hair` vertices with
/// `material`, `lights` and the width factor of the frame's detail, seen by
/// `camera` into a target of `extent`; `transparent` strands are drawn with
/// their coverage (no least width).
pub(super) fn draw_params(
    transparent: bool,
    material: &HairMaterial,
    lights: &[GpuLight],
    width_scale: f32,
    (hairs, per_hair): (u32, u32),
    camera: &Camera,
    extent: vk::Extent2D,
) -> DrawParams {
    let m = material;
    let mut gpu_lights = [GpuLight::default(); MAX_LIGHTS];
    gpu_lights[..lights.len()].copy_from_slice(lights);
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
        widths: [m.root_width * width_scale, m.tip_width * width_scale, m.least_pixel_width, 0.0],
        coverage: [
            if transparent { 1.0 } else { 0.0 },
            m.opacity,
            m.represented_hairs,
            band_density(m.represented_hairs),
        ],
        counts: [hairs, per_hair, lights.len() as u32, m.shading.code()],
        lights: gpu_lights,
    }
}
