//! Pass 4 with transparency (`glsl/render/oit_*`, [`Transparency`]): the hair
//! as transparent strands composited over the target.
//!
//! 1. **Build** (in the [`RenderPass::Draw`] scope): the ribbons of the draw
//!    pass's vertex and geometry stages, with their true width and a coverage
//!    per fragment, depth-tested against the target's depth (not written). Every
//!    surviving fragment is shaded once and either pushed onto its pixel's list
//!    (exact: a node from a pool of [`OitParams::fragments_per_pixel`] per pixel;
//!    beyond it, counted and added to two accumulation images instead) or added
//!    to two accumulation images (fast: weighted blended). Both keep the nearest
//!    depth of a fragment at least half opaque.
//! 2. **Composite** ([`RenderPass::Composite`]): one full-screen triangle blends
//!    each pixel's hair over the target as premultiplied colour (exact: the
//!    [`OitParams::sorted_fragments`] nearest sorted, the rest and the pool's
//!    overflow an order-independent tail behind them), then a second one writes that nearest
//!    half-opaque depth into the target's depth where it is nearer, so later
//!    host passes see the hair.
//!
//! The pass owns the lists, the accumulation images and their pipelines for the
//! current extent and mode; when either changes, the old ones are retired and
//! freed once the frames that used them are `frames_in_flight` behind.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::draw::{DrawInputs, DrawPass, TargetKey};
use super::marschner::MarschnerParams;
use super::pass::RenderPass;
use super::{OitParams, Transparency};
use crate::error::{Error, Result};
use crate::gpu_types::{DrawParams, OitCounters};
use crate::profiler::GpuProfiler;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::{
    ShaderSource, RENDER_DRAW_VERT, RENDER_OIT_BUILD_FRAG, RENDER_OIT_DEPTH_FRAG, RENDER_OIT_GEOM,
    RENDER_OIT_RESOLVE_FRAG, RENDER_OIT_WEIGHTED_FRAG, RENDER_OIT_WEIGHTED_RESOLVE_FRAG, RENDER_RESOLVE_VERT,
};

/// Format of the weighted colour and weight sums (fast mode; the exact mode's
/// overflow: weight 1).
const WEIGHTED_SUM: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Format of the absorbance sum (fast mode; the exact mode's overflow).
const ABSORBANCE: vk::Format = vk::Format::R32_SFLOAT;
/// Bytes of one stored fragment (colour and alpha as half floats, depth, next).
const NODE_BYTES: u64 = 16;
/// The "no node" / "no depth" word the lists and the opaque depths are cleared to.
const END: u32 = crate::codes::sentinel::OIT_END;

/// What the last exact-mode frame stored, read by
/// [`super::Renderer::transparency_stats`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OitStats {
    /// Hair fragments that passed the depth test.
    pub fragments: u64,
    /// Of those, the ones stored in the pool.
    pub stored: u64,
    /// The ones the full pool could not store: composited unsorted, in the
    /// order-independent tail behind the sorted ones (not dropped).
    pub overflowed: u64,
    /// Fragments the pool holds.
    pub capacity: u64,
}

/// The pipelines of one target and their descriptor sets.
struct OitPipelines {
    build: (GraphicsPipeline, vk::DescriptorSet),
    composite: (GraphicsPipeline, vk::DescriptorSet),
    depth: Option<(GraphicsPipeline, vk::DescriptorSet)>,
}

/// The buffers and images of one extent and mode, and the pipelines bound to them.
struct OitResources {
    extent: vk::Extent2D,
    mode: Transparency,
    capacity: u32,
    /// Per pixel: the nearest half-opaque depth.
    opaque: Buffer,
    /// Exact mode: per pixel the newest node of its list, and the node pool.
    lists: Option<(Buffer, Buffer)>,
    /// Weighted sums and absorbance (fast mode; the exact mode's overflow).
    sums: (Image, Image),
    pipelines: HashMap<TargetKey, OitPipelines>,
}

/// Where the transparent hair goes: a target with `key`'s formats, its colour
/// and depth attachments loaded as their first use in the frame needs.
pub(super) struct OitTarget<'a> {
    pub key: TargetKey,
    pub extent: vk::Extent2D,
    pub color: (vk::ImageView, Load),
    pub depth: Option<(vk::ImageView, Load)>,
    /// Barriers that make the target ready for the build.
    pub before: (&'a [vk::MemoryBarrier2<'a>], &'a [vk::ImageMemoryBarrier2<'a>]),
}

/// The transparency pass: the per-frame counters, the resources of the current
/// extent and mode, and those of earlier ones still used by frames in flight.
pub(super) struct OitPass {
    device: Arc<Device>,
    /// [`OitCounters`], host-visible so the host reads what a frame stored.
    counters: Buffer,
    nearest: Sampler,
    current: Option<OitResources>,
    retired: Vec<(u64, OitResources)>,
}

impl OitPass {
    pub(super) fn new(device: &Arc<Device>) -> Result<Self> {
        let counters = Buffer::new(
            device,
            &BufferDesc {
                name: "vkhair transparency counters",
                size: std::mem::size_of::<OitCounters>() as u64,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        Ok(OitPass {
            device: device.clone(),
            counters,
            nearest: Sampler::nearest(device, "vkhair transparency sums")?,
            current: None,
            retired: Vec::new(),
        })
    }

    /// Bytes of GPU memory the exact or fast mode needs at `extent`.
    pub(super) fn memory_bytes(mode: Transparency, params: &OitParams, extent: vk::Extent2D) -> u64 {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        // Both: the counters, a depth word per pixel, the RGBA32F sums and the
        // R32F absorbance.
        let shared = std::mem::size_of::<OitCounters>() as u64 + (4 + 16 + 4) * pixels;
        match mode {
            Transparency::Off => 0,
            // A head word per pixel and the node pool.
            Transparency::Exact => shared + 4 * pixels + NODE_BYTES * pool_capacity(params, extent),
            Transparency::Fast => shared,
        }
    }

    /// Drops every pipeline and set (the draw's inputs changed); the caller made
    /// sure no pending work uses them.
    pub(super) fn forget(&mut self) {
        if let Some(current) = &mut self.current {
            current.pipelines.clear();
        }
    }

    /// Frees retired resources whose last frame is `frames_in_flight` frames before `frame`.
    pub(super) fn collect_retired(&mut self, frame: u64, frames_in_flight: u32) {
        let keep = u64::from(frames_in_flight);
        self.retired.retain(|(last, _)| last.saturating_add(keep) > frame);
    }

    /// Sets of resources waiting for their frames to complete.
    pub(super) fn retired_count(&self) -> usize {
        self.retired.len()
    }

    /// What the latest exact-mode frame stored, read from host-visible memory:
    /// valid once that frame completed and before the next one is submitted.
    pub(super) fn stats(&self) -> Option<OitStats> {
        // The current resources are those of the latest transparent frame.
        if self.current.as_ref()?.mode != Transparency::Exact {
            return None;
        }
        let bytes = self.counters.mapped()?;
        let counters: OitCounters = bytemuck::pod_read_unaligned(bytes.get(..std::mem::size_of::<OitCounters>())?);
        let stored = counters.used.min(counters.capacity);
        Some(OitStats {
            fragments: u64::from(counters.used),
            stored: u64::from(stored),
            overflowed: u64::from(counters.used - stored),
            capacity: u64::from(counters.capacity),
        })
    }
}

/// Nodes in the exact mode's pool at `extent`.
fn pool_capacity(params: &OitParams, extent: vk::Extent2D) -> u64 {
    let pixels = f64::from(extent.width) * f64::from(extent.height);
    ((pixels * f64::from(params.fragments_per_pixel)).ceil() as u64).max(1)
}

/// Resources: made for an extent and mode, kept while they stay.
impl OitPass {
    /// Makes the resources for `mode` at `extent` the current ones (retiring others).
    fn prepare(&mut self, frame: u64, mode: Transparency, params: &OitParams, extent: vk::Extent2D) -> Result<()> {
        let capacity = pool_capacity(params, extent);
        let fits = |r: &OitResources| r.extent == extent && r.mode == mode && u64::from(r.capacity) == capacity;
        if let Some(old) = self.current.take_if(|r| !fits(r)) {
            // Frames up to the previous one may still be using them.
            self.retired.push((frame.saturating_sub(1), old));
        }
        if self.current.is_some() {
            return Ok(());
        }
        let d = &self.device;
        let node_bytes = capacity * NODE_BYTES;
        if capacity > u64::from(u32::MAX) || node_bytes > u64::from(d.info.max_storage_buffer_range) {
            return Err(Error::param(
                "oit.fragments_per_pixel",
                params.fragments_per_pixel,
                format!(
                    "a pool of at most {} bytes at {}×{} (this one needs {node_bytes})",
                    d.info.max_storage_buffer_range, extent.width, extent.height
                ),
            ));
        }
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        let opaque = Buffer::storage(d, "vkhair transparency opaque depth", 4 * pixels)?;
        let lists = match mode {
            Transparency::Exact => Some((
                Buffer::storage(d, "vkhair transparency heads", 4 * pixels)?,
                Buffer::storage(d, "vkhair transparency nodes", node_bytes)?,
            )),
            _ => None,
        };
        let image = |name, format| {
            Image::new(
                d,
                &ImageDesc {
                    name,
                    extent,
                    format,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
                    samples: vk::SampleCountFlags::TYPE_1,
                    aspect: vk::ImageAspectFlags::COLOR,
                },
            )
        };
        let sums = (
            image("vkhair transparency weighted sums", WEIGHTED_SUM)?,
            image("vkhair transparency absorbance", ABSORBANCE)?,
        );
        self.current = Some(OitResources {
            extent,
            mode,
            capacity: capacity as u32,
            opaque,
            lists,
            sums,
            pipelines: HashMap::new(),
        });
        Ok(())
    }

    /// Makes the pipelines for `key` on first use, bound to the draw's shading
    /// inputs and the current resources.
    fn make_pipelines(&mut self, key: TargetKey, draw: &DrawPass, inputs: &DrawInputs<'_>) -> Result<()> {
        let Some(res) = self.current.as_mut() else {
            return Err(Error::incompatible("transparency", "pipelines requested before the resources"));
        };
        if res.pipelines.contains_key(&key) {
            return Ok(());
        }
        let d = &self.device;
        let exact = res.mode == Transparency::Exact;
        let has_depth = key.depth != vk::Format::UNDEFINED;
        let weighted_formats = [WEIGHTED_SUM, ABSORBANCE];
        let target_formats = [key.color];
        let desc = |name, stages, colors, depth_test, depth_write, blend| GraphicsDesc {
            name,
            stages,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            patch_control_points: 0,
            color_formats: colors,
            depth_format: key.depth,
            samples: vk::SampleCountFlags::TYPE_1,
            depth_test,
            depth_write,
            blend,
            rasterizer_discard: false,
        };
        let mut ours = vec![(9, &self.counters), (12, &res.opaque)];
        if let Some((heads, nodes)) = &res.lists {
            ours.extend([(10, heads), (11, nodes)]);
        }
        let (shading_buffers, shading_images) = draw.shading_bindings(inputs);
        let mut buffers = shading_buffers.to_vec();
        buffers.extend_from_slice(&ours);

        let build_frag: &ShaderSource = if exact { &RENDER_OIT_BUILD_FRAG } else { &RENDER_OIT_WEIGHTED_FRAG };
        let build_stages = [&RENDER_DRAW_VERT, &RENDER_OIT_GEOM, build_frag];
        let build = GraphicsPipeline::new(
            d,
            &GraphicsDesc {
                topology: vk::PrimitiveTopology::LINE_LIST,
                ..desc(
                    "vkhair hair transparency build",
                    &build_stages,
                    &weighted_formats,
                    has_depth,
                    false,
                    Blend::Additive,
                )
            },
            1,
        )?;
        let build_set = build.declared_resource_set(0, &buffers, &shading_images)?;

        let composite_frag: &ShaderSource =
            if exact { &RENDER_OIT_RESOLVE_FRAG } else { &RENDER_OIT_WEIGHTED_RESOLVE_FRAG };
        let composite_stages = [&RENDER_RESOLVE_VERT, composite_frag];
        let composite = GraphicsPipeline::new(
            d,
            &desc(
                "vkhair hair transparency composite",
                &composite_stages,
                &target_formats,
                false,
                false,
                Blend::Premultiplied,
            ),
            1,
        )?;
        let (sum, absorbance) = &res.sums;
        let sums = [(0, sum.view(), self.nearest.raw), (1, absorbance.view(), self.nearest.raw)];
        let composite_set = composite.declared_resource_set(0, &ours, &sums)?;

        let depth = if has_depth {
            let pipeline = GraphicsPipeline::new(
                d,
                &desc(
                    "vkhair hair transparency depth",
                    &[&RENDER_RESOLVE_VERT, &RENDER_OIT_DEPTH_FRAG],
                    &target_formats,
                    true,
                    true,
                    Blend::NoColor,
                ),
                1,
            )?;
            let set = pipeline.declared_resource_set(0, &ours, &[])?;
            Some((pipeline, set))
        } else {
            None
        };
        res.pipelines
            .insert(key, OitPipelines { build: (build, build_set), composite: (composite, composite_set), depth });
        Ok(())
    }
}

/// Recording.
impl OitPass {
    /// Records the build in the draw's scope and the composite in its own, into
    /// `target`, for the host's frame `frame`.
    ///
    /// # Safety
    /// As for [`DrawPass::record`]; `target`'s attachments are in attachment layouts
    /// after `target.before`; frames `frames_in_flight` before `frame` completed.
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        (mode, params): (Transparency, &OitParams),
        draw: &mut DrawPass,
        target: &OitTarget<'_>,
        inputs: &DrawInputs<'_>,
        (draw_params, marschner): (&DrawParams, &MarschnerParams),
        vertices: u32,
        profiler: &mut Option<&mut GpuProfiler>,
    ) -> Result<()> {
        if target.key.samples != vk::SampleCountFlags::TYPE_1 {
            return Err(Error::incompatible(
                "render target",
                "transparent hair needs a single-sample target (use supersampling for more samples)",
            ));
        }
        // Made (or found) before anything is recorded: a failure leaves `cmd` as it was.
        self.prepare(frame, mode, params, target.extent)?;
        self.make_pipelines(target.key, draw, inputs)?;
        let Some(res) = self.current.as_ref() else {
            return Err(Error::incompatible("transparency", "no resources after preparing them"));
        };
        let pipelines = &res.pipelines[&target.key];
        let d = &*self.device;
        let counters = OitCounters {
            used: 0,
            capacity: res.capacity,
            width: target.extent.width,
            sorted: params.sorted_fragments,
        };
        let storage = &[AccessKind::FragmentRead, AccessKind::FragmentWrite];
        // The previous frame's composite read the lists (and the host read the counters).
        let to_clear = barrier::memory(storage, &[AccessKind::TransferWrite]);
        let cleared = barrier::memory(&[AccessKind::TransferWrite], storage);
        let built = barrier::memory(&[AccessKind::FragmentWrite], &[AccessKind::FragmentRead]);
        let depth_order = barrier::memory(barrier::ATTACHMENTS, barrier::ATTACHMENTS);
        let to_host = barrier::memory(&[AccessKind::FragmentWrite], &[AccessKind::HostRead]);
        let sampled = &[AccessKind::FragmentSampledRead];
        let (to_sums, from_sums): (Vec<_>, Vec<_>) = [&res.sums.0, &res.sums.1]
            .into_iter()
            .map(|image| {
                (
                    barrier::image(
                        image,
                        sampled,
                        barrier::COLOR_ATTACHMENT,
                        vk::ImageLayout::UNDEFINED,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    ),
                    barrier::image(
                        image,
                        barrier::COLOR_ATTACHMENT,
                        sampled,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    ),
                )
            })
            .unzip();
        let sums = [&res.sums.0, &res.sums.1].map(|i| rendering::color(i.view(), Load::color([0.0; 4])));
        let depth_first = target.depth.map(|(view, load)| rendering::depth(view, load));
        let depth_again = target.depth.map(|(view, _)| rendering::depth(view, Load::Keep));
        let build_rendering = rendering::info(target.extent, &sums, depth_first.as_ref());
        let color = [rendering::color(target.color.0, target.color.1)];
        let composite_rendering = rendering::info(target.extent, &color, depth_again.as_ref());
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            let scope = RenderPass::Draw.open(d, cmd, profiler);
            draw.record_updates(cmd, target.before, draw_params, marschner);
            d.cmd_barrier(cmd, &[to_clear], &[], &to_sums);
            if let Some((heads, _)) = &res.lists {
                d.raw.cmd_fill_buffer(cmd, heads.raw(), 0, vk::WHOLE_SIZE, END);
            }
            d.raw.cmd_fill_buffer(cmd, res.opaque.raw(), 0, vk::WHOLE_SIZE, END);
            d.raw.cmd_update_buffer(cmd, self.counters.raw(), 0, bytemuck::bytes_of(&counters));
            d.cmd_barrier(cmd, &[cleared], &[], &[]);
            d.raw.cmd_begin_rendering(cmd, &build_rendering);
            d.cmd_set_full_viewport(cmd, target.extent);
            pipelines.build.0.bind(cmd, &[pipelines.build.1]);
            d.raw.cmd_draw(cmd, vertices, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, profiler);

            let scope = RenderPass::Composite.open(d, cmd, profiler);
            d.cmd_barrier(cmd, &[built, depth_order], &[], &from_sums);
            d.raw.cmd_begin_rendering(cmd, &composite_rendering);
            d.cmd_set_full_viewport(cmd, target.extent);
            for (pipeline, set) in [&pipelines.composite].into_iter().chain(&pipelines.depth) {
                pipeline.bind(cmd, &[*set]);
                d.raw.cmd_draw(cmd, 3, 1, 0, 0);
            }
            d.raw.cmd_end_rendering(cmd);
            d.cmd_barrier(cmd, &[to_host], &[], &[]);
            scope.close(d, cmd, profiler);
        }
        Ok(())
    }
}
