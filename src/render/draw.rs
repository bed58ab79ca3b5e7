//! Pass 3 — drawing (`glsl/render/draw.*`): the interpolated hairs as
//! camera-facing ribbons expanded in the geometry stage, shaded with
//! Kajiya-Kay diffuse and two shifted highlights for every light, into the
//! host's color and depth images (dynamic rendering, depth-tested against what
//! the host drew). Pipelines are made on first use for each combination of
//! color format, depth format and sample count.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;

use super::shading::{noise_texels, NOISE_SIZE};
use crate::error::Result;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::shaders::{RENDER_DRAW_FRAG, RENDER_DRAW_GEOM, RENDER_DRAW_VERT};

/// Formats, sample count and primitive a draw pipeline is made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct TargetKey {
    pub color: vk::Format,
    pub depth: vk::Format,
    pub samples: vk::SampleCountFlags,
    pub primitive: super::Primitive,
}

pub(super) struct DrawPass {
    device: Arc<Device>,
    pipelines: HashMap<TargetKey, (GraphicsPipeline, vk::DescriptorSet)>,
    noise: Image,
    sampler: Sampler,
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
        Ok(DrawPass { device: device.clone(), pipelines: HashMap::new(), noise, sampler })
    }

    /// The pipeline and descriptor set for `key`, made on first use with `buffers`
    /// and `images` (by binding) besides the noise texture.
    pub(super) fn pipeline(
        &mut self,
        key: TargetKey,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<&(GraphicsPipeline, vk::DescriptorSet)> {
        if !self.pipelines.contains_key(&key) {
            let color_formats = [key.color];
            // Lines skip the geometry stage: the fragment stage reads the vertex
            // stage's outputs at the same locations.
            let ribbons: &[&crate::vk::shaders::ShaderSource] =
                &[&RENDER_DRAW_VERT, &RENDER_DRAW_GEOM, &RENDER_DRAW_FRAG];
            let lines: &[&crate::vk::shaders::ShaderSource] = &[&RENDER_DRAW_VERT, &RENDER_DRAW_FRAG];
            let pipeline = GraphicsPipeline::new(
                &self.device,
                &GraphicsDesc {
                    name: "vkhair hair draw",
                    stages: if key.primitive == super::Primitive::Lines { lines } else { ribbons },
                    topology: vk::PrimitiveTopology::LINE_LIST,
                    patch_control_points: 0,
                    color_formats: &color_formats,
                    depth_format: key.depth,
                    samples: key.samples,
                    depth_test: key.depth != vk::Format::UNDEFINED,
                    depth_write: key.depth != vk::Format::UNDEFINED,
                    blend: Blend::None,
                    rasterizer_discard: false,
                },
                1,
            )?;
            let mut all_images = vec![(3, self.noise.view(), self.sampler.raw)];
            all_images.extend_from_slice(images);
            let set = pipeline.resource_set(0, buffers, &all_images)?;
            self.pipelines.insert(key, (pipeline, set));
        }
        Ok(&self.pipelines[&key])
    }

    /// Drops every pipeline and set (their resources changed); the caller made sure
    /// no pending work uses them.
    pub(super) fn forget(&mut self) {
        self.pipelines.clear();
    }
}
