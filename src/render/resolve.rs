//! Pass 4 (optional) — supersampling (`glsl/render/resolve.*`): the hair is drawn
//! at twice the target's size into the renderer's own color and depth images,
//! then resolved into the host's target with a 5-tap filter as premultiplied
//! coverage, writing the nearest hair depth so the host's depth test still
//! applies (see the shader for the filter).

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;

use super::draw::TargetKey;
use crate::error::Result;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::shaders::{RENDER_RESOLVE_FRAG, RENDER_RESOLVE_VERT};

/// Color format of the supersampled hair image (linear, with coverage in alpha).
pub(super) const SUPERSAMPLED_COLOR: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Depth format of the supersampled hair image.
pub(super) const SUPERSAMPLED_DEPTH: vk::Format = vk::Format::D32_SFLOAT;

pub(super) struct Supersampling {
    device: Arc<Device>,
    /// Size of the host's target these images are twice as large as.
    pub target_extent: vk::Extent2D,
    pub color: Image,
    pub depth: Image,
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
    pub(super) fn pipeline(&mut self, key: TargetKey) -> Result<&(GraphicsPipeline, vk::DescriptorSet)> {
        if !self.pipelines.contains_key(&key) {
            let color_formats = [key.color];
            let pipeline = GraphicsPipeline::new(
                &self.device,
                &GraphicsDesc {
                    name: "vkhair supersampling resolve",
                    stages: &[&RENDER_RESOLVE_VERT, &RENDER_RESOLVE_FRAG],
                    topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                    patch_control_points: 0,
                    color_formats: &color_formats,
                    depth_format: key.depth,
                    samples: key.samples,
                    depth_test: key.depth != vk::Format::UNDEFINED,
                    depth_write: false,
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
