//! Graphics pipelines for dynamic rendering.

use std::sync::Arc;

use ash::vk;

use super::{shader_module, ConstantZero, Layout};
use crate::error::{Error, Result};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::reflect::reflect;
use crate::vk::shaders::ShaderSource;

/// Fixed-function state of a graphics pipeline (dynamic rendering; viewport and
/// scissor are dynamic).
#[derive(Debug, Clone)]
pub(crate) struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub stages: &'a [&'a ShaderSource],
    pub topology: vk::PrimitiveTopology,
    /// Control points per patch (0 without tessellation).
    pub patch_control_points: u32,
    pub color_formats: &'a [vk::Format],
    pub depth_format: vk::Format,
    pub samples: vk::SampleCountFlags,
    pub depth_test: bool,
    pub depth_write: bool,
    /// The depth buffer is reversed (near = 1): the test passes a fragment at
    /// least as great (`GREATER_OR_EQUAL`), else at most as great.
    pub reverse_z: bool,
    /// Color blending.
    pub blend: Blend,
    /// Discard primitives before rasterization (capture passes that only store).
    pub rasterizer_discard: bool,
}

/// Color blending of a graphics pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Blend {
    /// Overwrite.
    None,
    /// Add (`ONE`, `ONE`): accumulation.
    Additive,
    /// Premultiplied alpha over the destination (`ONE`, `ONE_MINUS_SRC_ALPHA`).
    Premultiplied,
    /// Add the color, keep the larger alpha (opacity layers with z0 in alpha).
    AddColorMaxAlpha,
    /// Write no color at all (depth pre-passes).
    NoColor,
}

/// A graphics pipeline.
pub(crate) struct GraphicsPipeline {
    layout: Layout,
    raw: vk::Pipeline,
}

impl GraphicsPipeline {
    pub(crate) fn new(device: &Arc<Device>, desc: &GraphicsDesc<'_>, max_sets: u32) -> Result<Self> {
        Self::specialised(device, desc, max_sets, None)
    }

    /// As [`GraphicsPipeline::new`], with specialisation constant 0 (a `uint`)
    /// of every stage that declares one set to `constant` when given.
    pub(crate) fn specialised(
        device: &Arc<Device>,
        desc: &GraphicsDesc<'_>,
        max_sets: u32,
        constant: Option<u32>,
    ) -> Result<Self> {
        let reflections = desc.stages.iter().map(|s| reflect(s)).collect::<Result<Vec<_>>>()?;
        let layout = Layout::new(device, desc.name, &reflections, max_sets)?;
        let mut modules = Vec::new();
        for s in desc.stages {
            match shader_module(device, s.words, s.name) {
                Ok(m) => modules.push(m),
                Err(e) => {
                    // SAFETY: modules created above, unused.
                    modules.iter().for_each(|m| unsafe { device.raw.destroy_shader_module(*m, None) });
                    return Err(e);
                }
            }
        }
        let stages: Vec<_> = desc
            .stages
            .iter()
            .zip(&modules)
            .map(|(s, m)| vk::PipelineShaderStageCreateInfo::default().stage(s.stage.flags()).module(*m).name(c"main"))
            .collect();
        let constant = constant.map(ConstantZero::new);
        let specialization = constant.as_ref().map(ConstantZero::info);
        let stages: Vec<_> = match &specialization {
            Some(info) => stages.into_iter().map(|stage| stage.specialization_info(info)).collect(),
            None => stages,
        };
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let tessellation =
            vk::PipelineTessellationStateCreateInfo::default().patch_control_points(desc.patch_control_points);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .rasterizer_discard_enable(desc.rasterizer_discard)
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(desc.samples);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_test)
            .depth_write_enable(desc.depth_write)
            .depth_compare_op(match desc.reverse_z {
                true => vk::CompareOp::GREATER_OR_EQUAL,
                false => vk::CompareOp::LESS_OR_EQUAL,
            });
        let attachment = match desc.blend {
            Blend::None => {
                vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)
            }
            Blend::NoColor => {
                vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::empty())
            }
            Blend::Additive | Blend::Premultiplied => {
                let dst = if desc.blend == Blend::Additive {
                    vk::BlendFactor::ONE
                } else {
                    vk::BlendFactor::ONE_MINUS_SRC_ALPHA
                };
                vk::PipelineColorBlendAttachmentState::default()
                    .blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::ONE)
                    .dst_color_blend_factor(dst)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ONE)
                    .dst_alpha_blend_factor(dst)
                    .alpha_blend_op(vk::BlendOp::ADD)
                    .color_write_mask(vk::ColorComponentFlags::RGBA)
            }
            Blend::AddColorMaxAlpha => vk::PipelineColorBlendAttachmentState::default()
                .blend_enable(true)
                .src_color_blend_factor(vk::BlendFactor::ONE)
                .dst_color_blend_factor(vk::BlendFactor::ONE)
                .color_blend_op(vk::BlendOp::ADD)
                .src_alpha_blend_factor(vk::BlendFactor::ONE)
                .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                .alpha_blend_op(vk::BlendOp::MAX)
                .color_write_mask(vk::ColorComponentFlags::RGBA),
        };
        let attachments = vec![attachment; desc.color_formats.len()];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format);
        let mut info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout.raw)
            .push_next(&mut rendering);
        if desc.patch_control_points > 0 {
            info = info.tessellation_state(&tessellation);
        }
        // SAFETY: every pointer refers to locals alive for the call.
        let result = unsafe { device.raw.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
        // SAFETY: modules are no longer needed once the pipeline exists.
        modules.iter().for_each(|m| unsafe { device.raw.destroy_shader_module(*m, None) });
        let raw = result.map_err(|(_, r)| Error::Vulkan { call: "vkCreateGraphicsPipelines", result: r })?[0];
        device.set_name(raw, desc.name);
        Ok(GraphicsPipeline { layout, raw })
    }

    /// Allocates descriptor set `set` and points its buffer bindings at `buffers`.
    pub(crate) fn buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        self.resource_set(set, buffers, &[])
    }

    /// As [`ComputePipeline::declared_buffer_set`].
    pub(crate) fn declared_buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        self.declared_resource_set(set, buffers, &[])
    }

    /// As [`GraphicsPipeline::resource_set`] with only the entries of `buffers` and
    /// `images` whose binding the pipeline declares in `set`.
    pub(crate) fn declared_resource_set(
        &self,
        set: u32,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<vk::DescriptorSet> {
        self.resource_set(set, &self.layout.declared(set, buffers), &self.layout.declared_images(set, images))
    }

    /// Allocates descriptor set `set` with buffer and combined image-sampler bindings.
    pub(crate) fn resource_set(
        &self,
        set: u32,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<vk::DescriptorSet> {
        self.layout.resource_set(set, "graphics", buffers, images)
    }

    /// Binds the pipeline and descriptor sets (from set 0).
    ///
    /// # Safety
    /// `cmd` is recording inside a dynamic rendering instance compatible with the
    /// pipeline's formats.
    pub(crate) unsafe fn bind(&self, cmd: vk::CommandBuffer, sets: &[vk::DescriptorSet]) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.bind(cmd, vk::PipelineBindPoint::GRAPHICS, self.raw, sets) };
    }

    /// Records push constants; their size must equal the shaders' block.
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound.
    pub(crate) unsafe fn push<P: bytemuck::Pod>(&self, cmd: vk::CommandBuffer, push: &P) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.push(cmd, push) };
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        // SAFETY: pipeline of this device, no longer used by pending work.
        unsafe { self.layout.device.raw.destroy_pipeline(self.raw, None) };
    }
}
