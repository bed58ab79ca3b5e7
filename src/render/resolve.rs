//! Pass 5 (optional) — supersampling (`glsl/render/resolve.*`): the hair is drawn
//! at twice the target's size into the renderer's own color and depth images,
//! then resolved into the host's target with a 5-tap filter as premultiplied
//! coverage, writing the nearest hair depth so the host's depth test still
//! applies (see the shader for the filter).
//!
//! The pass owns the images for the current target size; when the size changes,
//! the old images are retired and freed once the frames that used them are
//! `frames_in_flight` behind.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;

use super::draw::{DrawTarget, TargetKey};
use super::graph::{FrameGraph, Use};
use super::pass::RenderPass;
use super::Primitive;
use crate::error::Result;
use crate::profiler::Timing;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::{RENDER_RESOLVE_FRAG, RENDER_RESOLVE_FRAG_REVERSE_Z, RENDER_RESOLVE_VERT};

/// Color format of the supersampled hair image (linear, with coverage in alpha).
const SUPERSAMPLED_COLOR: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Depth format of the supersampled hair image.
const SUPERSAMPLED_DEPTH: vk::Format = vk::Format::D32_SFLOAT;

/// Images twice the host target's size and the resolve pipelines reading them.
pub(super) struct Supersampling {
    device: Arc<Device>,
    /// Size of the host's target these images are twice as large as.
    pub target_extent: vk::Extent2D,
    color: Image,
    depth: Image,
    linear: Sampler,
    nearest: Sampler,
    pipelines: HashMap<TargetKey, (GraphicsPipeline, vk::DescriptorSet)>,
}

impl Supersampling {
    pub(super) fn new(device: &Arc<Device>, target_extent: vk::Extent2D) -> Result<Self> {
        let extent = vk::Extent2D { width: target_extent.width * 2, height: target_extent.height * 2 };
        let color = Image::new(
            device,
            &ImageDesc {
                name: "vkhair supersampled hair",
                extent,
                format: SUPERSAMPLED_COLOR,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        let depth = Image::new(
            device,
            &ImageDesc {
                name: "vkhair supersampled depth",
                extent,
                format: SUPERSAMPLED_DEPTH,
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::DEPTH,
            },
        )?;
        Ok(Supersampling {
            device: device.clone(),
            target_extent,
            color,
            depth,
            linear: Sampler::new(device, "vkhair resolve linear", false)?,
            nearest: Sampler::nearest(device, "vkhair resolve nearest")?,
            pipelines: HashMap::new(),
        })
    }

    /// The resolve pipeline for the host's target formats, made on first use.
    fn pipeline(&mut self, key: TargetKey) -> Result<&(GraphicsPipeline, vk::DescriptorSet)> {
        if !self.pipelines.contains_key(&key) {
            let color_formats = [key.color];
            let pipeline = GraphicsPipeline::new(
                &self.device,
                &GraphicsDesc {
                    name: "vkhair supersampling resolve",
                    stages: &[
                        &RENDER_RESOLVE_VERT,
                        if key.reverse_z { &RENDER_RESOLVE_FRAG_REVERSE_Z } else { &RENDER_RESOLVE_FRAG },
                    ],
                    topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                    patch_control_points: 0,
                    color_formats: &color_formats,
                    depth_format: key.depth,
                    samples: key.samples,
                    depth_test: key.depth != vk::Format::UNDEFINED,
                    depth_write: false,
                    reverse_z: key.reverse_z,
                    blend: Blend::Premultiplied,
                    rasterizer_discard: false,
                },
                1,
            )?;
            let set = pipeline.resource_set(
                0,
                &[],
                &[(0, self.color.view(), self.linear.raw), (1, self.depth.view(), self.nearest.raw)],
            )?;
            self.pipelines.insert(key, (pipeline, set));
        }
        Ok(&self.pipelines[&key])
    }
}

impl Supersampling {
    /// The extent the hair is drawn at: twice the target's.
    fn extent(&self) -> vk::Extent2D {
        self.color.extent
    }

    /// Where the frame's hair is drawn: these images, colour cleared to
    /// transparent and depth to the convention's far (1, or 0 reversed), after the barriers that make them attachments.
    pub(super) fn draw_target(&self, primitive: Primitive, reverse_z: bool) -> DrawTarget {
        DrawTarget {
            key: TargetKey {
                color: SUPERSAMPLED_COLOR,
                depth: SUPERSAMPLED_DEPTH,
                samples: vk::SampleCountFlags::TYPE_1,
                primitive,
                reverse_z,
            },
            extent: self.extent(),
            color: (self.color.view(), Load::color([0.0; 4])),
            // Cleared to the far depth of the convention.
            depth: Some((self.depth.view(), Load::depth(if reverse_z { 0.0 } else { 1.0 }))),
            depth_image: None,
            uses: self.attachment_uses().to_vec(),
        }
    }

    /// Both images as the draw's attachments (their contents discarded:
    /// cleared by the draw's first rendering instance).
    fn attachment_uses(&self) -> [Use; 2] {
        let color = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        let depth = vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL;
        [
            Use::image(&self.color, barrier::COLOR_ATTACHMENT, color, SAMPLED).discarding(),
            Use::image(&self.depth, barrier::DEPTH_ATTACHMENT, depth, SAMPLED).discarding(),
        ]
    }

    /// Both images as the resolve samples them (their layout at rest).
    fn sampled_uses(&self) -> [Use; 2] {
        [&self.color, &self.depth].map(|i| Use::image(i, &[AccessKind::FragmentSampledRead], SAMPLED, SAMPLED))
    }
}

/// The layout the supersampling images rest in: sampled by the resolve.
const SAMPLED: vk::ImageLayout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;

/// The resolve pass: the supersampling images of the current target size and
/// those of earlier sizes still in use by frames in flight.
pub(super) struct ResolvePass {
    device: Arc<Device>,
    current: Option<Supersampling>,
    /// Images of earlier target sizes with the last frame that used them.
    retired: Vec<(u64, Supersampling)>,
}

impl ResolvePass {
    pub(super) fn new(device: &Arc<Device>) -> Self {
        ResolvePass { device: device.clone(), current: None, retired: Vec::new() }
    }

    /// Frees retired images whose last frame is `frames_in_flight` frames before
    /// `frame`.
    pub(super) fn collect_retired(&mut self, frame: u64, frames_in_flight: u32) {
        let keep = u64::from(frames_in_flight);
        self.retired.retain(|(last, _)| last.saturating_add(keep) > frame);
    }

    /// Sets of images waiting for their frames to complete.
    pub(super) fn retired_count(&self) -> usize {
        self.retired.len()
    }

    /// Takes the images for a target of `extent` in frame `frame` (made on first
    /// use; the images of another size are retired). Give them back with
    /// [`ResolvePass::restore`].
    pub(super) fn take(&mut self, frame: u64, extent: vk::Extent2D) -> Result<Supersampling> {
        if let Some(old) = self.current.take_if(|s| s.target_extent != extent) {
            // Frames up to the previous one may still be using the old images.
            self.retired.push((frame.saturating_sub(1), old));
        }
        match self.current.take() {
            Some(images) => Ok(images),
            None => Supersampling::new(&self.device, extent),
        }
    }

    /// Gives the images taken by [`ResolvePass::take`] back.
    pub(super) fn restore(&mut self, images: Supersampling) {
        self.current = Some(images);
    }

    /// Records the resolve of `images` into the host's `target` in its own scope,
    /// declaring both to `graph`.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass,
    /// after the draw into `images`; the host's attachments are in attachment
    /// layouts.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        images: &mut Supersampling,
        target: &DrawTarget,
        timing: Timing<'_>,
    ) -> Result<()> {
        let d = &self.device;
        let uses = [&images.sampled_uses()[..], &target.uses].concat();
        let color = [rendering::color(target.color.0, target.color.1)];
        let depth = target.depth.map(|(view, load)| rendering::depth(view, load));
        let info = rendering::info(target.extent, &color, depth.as_ref());
        // Made (or found) before anything is recorded: a failure leaves `cmd` as it was.
        let (pipeline, set) = images.pipeline(target.key)?;
        // SAFETY: guaranteed by the caller; the images are this pass's.
        unsafe {
            let scope = RenderPass::Resolve.open(d, cmd, timing);
            graph.record(d, cmd, &uses);
            d.raw.cmd_begin_rendering(cmd, &info);
            d.cmd_set_full_viewport(cmd, target.extent);
            pipeline.bind(cmd, &[*set]);
            d.raw.cmd_draw(cmd, 3, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, timing);
        }
        Ok(())
    }
}
