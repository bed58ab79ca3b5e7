//! Compute and graphics pipelines whose layouts come from SPIR-V reflection.
//!
//! Descriptor set layouts and the push-constant range are built from what the
//! shaders declare; a compute pipeline knows its workgroup size and takes
//! dispatch sizes in threads. Each pipeline owns a descriptor pool for the
//! sets it hands out.

use std::collections::BTreeMap;
use std::sync::Arc;

use ash::vk;

use super::buffer::Buffer;
use super::device::Device;
use super::reflect::{reflect, Binding, Reflection};
use super::shaders::ShaderSource;
use crate::error::{Error, Result};

/// Layout objects shared by compute and graphics pipelines.
struct Layout {
    device: Arc<Device>,
    set_layouts: Vec<vk::DescriptorSetLayout>,
    raw: vk::PipelineLayout,
    bindings: Vec<(Binding, vk::ShaderStageFlags)>,
    push_constant_size: u32,
    push_stages: vk::ShaderStageFlags,
    pool: vk::DescriptorPool,
}

impl Layout {
    fn new(device: &Arc<Device>, name: &str, reflections: &[Reflection], max_sets: u32) -> Result<Self> {
        let mut merged: BTreeMap<(u32, u32), (Binding, vk::ShaderStageFlags)> = BTreeMap::new();
        let mut push_constant_size = 0;
        let mut push_stages = vk::ShaderStageFlags::empty();
        for r in reflections {
            for b in &r.bindings {
                let entry = merged.entry((b.set, b.binding)).or_insert((b.clone(), vk::ShaderStageFlags::empty()));
                if entry.0.ty != b.ty || entry.0.count != b.count {
                    return Err(Error::Shader {
                        shader: name.to_owned(),
                        reason: format!("set {} binding {} declared differently across stages", b.set, b.binding),
                    });
                }
                entry.1 |= r.stage;
            }
            if r.push_constant_size > 0 {
                push_constant_size = push_constant_size.max(r.push_constant_size);
                push_stages |= r.stage;
            }
        }
        let bindings: Vec<_> = merged.into_values().collect();
        let mut layout = Layout {
            device: device.clone(),
            set_layouts: Vec::new(),
            raw: vk::PipelineLayout::null(),
            bindings,
            push_constant_size,
            push_stages,
            pool: vk::DescriptorPool::null(),
        };
        let set_count = layout.bindings.iter().map(|(b, _)| b.set + 1).max().unwrap_or(0);
        for set in 0..set_count {
            let vk_bindings: Vec<_> = layout
                .bindings
                .iter()
                .filter(|(b, _)| b.set == set)
                .map(|(b, stages)| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.binding)
                        .descriptor_type(b.ty)
                        .descriptor_count(b.count)
                        .stage_flags(*stages)
                })
                .collect();
            let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
            // SAFETY: valid create info; destroyed in Drop.
            let set_layout = unsafe { device.raw.create_descriptor_set_layout(&info, None) }
                .map_err(Error::vk("vkCreateDescriptorSetLayout"))?;
            device.set_name(set_layout, &format!("{name} set {set}"));
            layout.set_layouts.push(set_layout);
        }
        let ranges: Vec<_> = (push_constant_size > 0)
            .then_some(vk::PushConstantRange { stage_flags: push_stages, offset: 0, size: push_constant_size })
            .into_iter()
            .collect();
        let info =
            vk::PipelineLayoutCreateInfo::default().set_layouts(&layout.set_layouts).push_constant_ranges(&ranges);
        // SAFETY: the set layouts are alive; destroyed in Drop.
        layout.raw =
            unsafe { device.raw.create_pipeline_layout(&info, None) }.map_err(Error::vk("vkCreatePipelineLayout"))?;
        device.set_name(layout.raw, &format!("{name} layout"));

        let mut sizes: BTreeMap<i32, u32> = BTreeMap::new();
        for (b, _) in &layout.bindings {
            *sizes.entry(b.ty.as_raw()).or_default() += b.count * max_sets;
        }
        if !sizes.is_empty() && max_sets > 0 {
            let pool_sizes: Vec<_> = sizes
                .into_iter()
                .map(|(ty, n)| vk::DescriptorPoolSize { ty: vk::DescriptorType::from_raw(ty), descriptor_count: n })
                .collect();
            let info =
                vk::DescriptorPoolCreateInfo::default().max_sets(max_sets * set_count.max(1)).pool_sizes(&pool_sizes);
            // SAFETY: valid create info; destroyed in Drop.
            layout.pool = unsafe { device.raw.create_descriptor_pool(&info, None) }
                .map_err(Error::vk("vkCreateDescriptorPool"))?;
            device.set_name(layout.pool, &format!("{name} descriptor pool"));
        }
        Ok(layout)
    }

    fn allocate_set(&self, set: u32, name: &str) -> Result<vk::DescriptorSet> {
        let layout = *self
            .set_layouts
            .get(set as usize)
            .ok_or_else(|| Error::incompatible("descriptor set", format!("{name}: set {set} is not declared")))?;
        let layouts = [layout];
        let info = vk::DescriptorSetAllocateInfo::default().descriptor_pool(self.pool).set_layouts(&layouts);
        // SAFETY: pool and layout belong to this device; sets are freed with the pool.
        let set = unsafe { self.device.raw.allocate_descriptor_sets(&info) }
            .map_err(Error::vk("vkAllocateDescriptorSets"))?[0];
        self.device.set_name(set, name);
        Ok(set)
    }

    /// The entries of `buffers` whose binding the pipeline declares in `set`.
    fn declared<'a>(&self, set: u32, buffers: &[(u32, &'a Buffer)]) -> Vec<(u32, &'a Buffer)> {
        buffers
            .iter()
            .filter(|(binding, _)| self.bindings.iter().any(|(b, _)| b.set == set && b.binding == *binding))
            .copied()
            .collect()
    }

    /// Points storage-image bindings of `set` at views in GENERAL layout.
    fn write_storage_images(&self, target: vk::DescriptorSet, set: u32, images: &[(u32, vk::ImageView)]) -> Result<()> {
        let images: Vec<_> = images.iter().map(|&(binding, view)| (binding, view, vk::Sampler::null())).collect();
        self.write_image_bindings(target, set, vk::DescriptorType::STORAGE_IMAGE, &images)
    }

    /// Points combined image-sampler bindings of `set` at (view, sampler) pairs
    /// in SHADER_READ_ONLY_OPTIMAL.
    fn write_images(
        &self,
        target: vk::DescriptorSet,
        set: u32,
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<()> {
        self.write_image_bindings(target, set, vk::DescriptorType::COMBINED_IMAGE_SAMPLER, images)
    }

    /// Points image bindings of type `ty` of `set` at (view, sampler) pairs: storage
    /// images in GENERAL layout (null samplers), sampled ones in
    /// SHADER_READ_ONLY_OPTIMAL.
    fn write_image_bindings(
        &self,
        target: vk::DescriptorSet,
        set: u32,
        ty: vk::DescriptorType,
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<()> {
        let (layout, what) = match ty {
            vk::DescriptorType::STORAGE_IMAGE => (vk::ImageLayout::GENERAL, "a storage image"),
            _ => (vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, "a sampled image"),
        };
        let infos: Vec<_> = images
            .iter()
            .map(|&(_, image_view, sampler)| [vk::DescriptorImageInfo { sampler, image_view, image_layout: layout }])
            .collect();
        let mut writes = Vec::new();
        for ((binding, _, _), info) in images.iter().zip(&infos) {
            let declared = self.bindings.iter().any(|(b, _)| b.set == set && b.binding == *binding && b.ty == ty);
            if !declared {
                return Err(Error::incompatible(
                    "descriptor binding",
                    format!("set {set} binding {binding} is not {what}"),
                ));
            }
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(target)
                    .dst_binding(*binding)
                    .descriptor_type(ty)
                    .image_info(info),
            );
        }
        // SAFETY: as in write_buffers; views and samplers are alive.
        unsafe { self.device.raw.update_descriptor_sets(&writes, &[]) };
        Ok(())
    }

    /// Allocates descriptor set `set` with buffer and combined image-sampler bindings.
    fn resource_set(
        &self,
        set: u32,
        kind: &str,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<vk::DescriptorSet> {
        let target = self.allocate_set(set, &format!("{kind} set {set}"))?;
        self.write_buffers(target, set, buffers)?;
        self.write_images(target, set, images)?;
        Ok(target)
    }

    /// Points storage/uniform buffer bindings of `set` at whole buffers.
    fn write_buffers(&self, target: vk::DescriptorSet, set: u32, buffers: &[(u32, &Buffer)]) -> Result<()> {
        let infos: Vec<_> = buffers.iter().map(|(_, b)| [b.descriptor()]).collect();
        let mut writes = Vec::new();
        for ((binding, _), info) in buffers.iter().zip(&infos) {
            let (b, _) =
                self.bindings.iter().find(|(b, _)| b.set == set && b.binding == *binding).ok_or_else(|| {
                    Error::incompatible("descriptor binding", format!("set {set} binding {binding} is not declared"))
                })?;
            if !matches!(b.ty, vk::DescriptorType::STORAGE_BUFFER | vk::DescriptorType::UNIFORM_BUFFER) {
                return Err(Error::incompatible(
                    "descriptor binding",
                    format!("set {set} binding {binding} is not a buffer"),
                ));
            }
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(target)
                    .dst_binding(*binding)
                    .descriptor_type(b.ty)
                    .buffer_info(info),
            );
        }
        // SAFETY: the set is not in use by pending GPU work (sets are written once
        // after allocation, before recording) and the buffers are alive.
        unsafe { self.device.raw.update_descriptor_sets(&writes, &[]) };
        Ok(())
    }
}

impl Drop for Layout {
    fn drop(&mut self) {
        // SAFETY: objects of this device, no longer used by pending work.
        unsafe {
            self.device.raw.destroy_descriptor_pool(self.pool, None);
            self.device.raw.destroy_pipeline_layout(self.raw, None);
            for l in &self.set_layouts {
                self.device.raw.destroy_descriptor_set_layout(*l, None);
            }
        }
    }
}

fn shader_module(device: &Device, shader: &ShaderSource) -> Result<vk::ShaderModule> {
    let info = vk::ShaderModuleCreateInfo::default().code(shader.words);
    // SAFETY: the words are SPIR-V validated by spirv-val at build time.
    let module = unsafe { device.raw.create_shader_module(&info, None) }.map_err(Error::vk("vkCreateShaderModule"))?;
    device.set_name(module, shader.name);
    Ok(module)
}

/// A compute pipeline.
pub(crate) struct ComputePipeline {
    layout: Layout,
    raw: vk::Pipeline,
    workgroup_size: [u32; 3],
    name: String,
}

impl ComputePipeline {
    /// Creates the pipeline; `max_sets` descriptor sets (of each set index) can be allocated.
    pub(crate) fn new(device: &Arc<Device>, shader: &ShaderSource, max_sets: u32) -> Result<Self> {
        Self::with_full_subgroups(device, shader, max_sets, false)
    }

    /// As [`ComputePipeline::new`]; with `full_subgroups` (only when the device has
    /// `computeFullSubgroups` enabled) every subgroup of a workgroup is full.
    pub(crate) fn with_full_subgroups(
        device: &Arc<Device>,
        shader: &ShaderSource,
        max_sets: u32,
        full_subgroups: bool,
    ) -> Result<Self> {
        if full_subgroups && !device.full_subgroups {
            return Err(Error::MissingRequirement("computeFullSubgroups".into()));
        }
        let reflection = reflect(shader)?;
        let workgroup_size = reflection
            .workgroup_size
            .ok_or_else(|| Error::Shader { shader: shader.name.to_owned(), reason: "not a compute shader".into() })?;
        let layout = Layout::new(device, shader.name, &[reflection], max_sets)?;
        let module = shader_module(device, shader)?;
        let flags = if full_subgroups {
            vk::PipelineShaderStageCreateFlags::REQUIRE_FULL_SUBGROUPS
        } else {
            vk::PipelineShaderStageCreateFlags::empty()
        };
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .flags(flags)
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout.raw);
        // SAFETY: module and layout are alive; the module is destroyed right after.
        let result = unsafe { device.raw.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) };
        // SAFETY: the module is no longer needed once the pipeline exists.
        unsafe { device.raw.destroy_shader_module(module, None) };
        let raw = result.map_err(|(_, r)| Error::Vulkan { call: "vkCreateComputePipelines", result: r })?[0];
        device.set_name(raw, shader.name);
        Ok(ComputePipeline { layout, raw, workgroup_size, name: shader.name.to_owned() })
    }

    #[cfg(test)]
    pub(crate) fn workgroup_size(&self) -> [u32; 3] {
        self.workgroup_size
    }

    /// Allocates descriptor set `set` and binds those of `buffers` that the shader
    /// declares (stages sharing one binding table each use a subset of it).
    pub(crate) fn declared_buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        self.buffer_set(set, &self.layout.declared(set, buffers))
    }

    /// Allocates descriptor set `set` and points its buffer bindings at `buffers`.
    pub(crate) fn buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        let target = self.layout.allocate_set(set, &format!("{} set {set}", self.name))?;
        self.layout.write_buffers(target, set, buffers)?;
        Ok(target)
    }

    /// Allocates descriptor set `set` with buffer and combined image-sampler bindings.
    #[cfg(test)]
    pub(crate) fn resource_set(
        &self,
        set: u32,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<vk::DescriptorSet> {
        self.layout.resource_set(set, &self.name, buffers, images)
    }

    /// Allocates descriptor set `set` and points its storage-image bindings at views
    /// (in GENERAL layout when dispatched).
    pub(crate) fn storage_image_set(&self, set: u32, images: &[(u32, vk::ImageView)]) -> Result<vk::DescriptorSet> {
        let target = self.layout.allocate_set(set, &format!("{} set {set}", self.name))?;
        self.layout.write_storage_images(target, set, images)?;
        Ok(target)
    }

    /// Binds the pipeline and the descriptor sets (from set 0).
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device.
    pub(crate) unsafe fn bind(&self, cmd: vk::CommandBuffer, sets: &[vk::DescriptorSet]) {
        let d = &self.layout.device.raw;
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.raw);
            if !sets.is_empty() {
                d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout.raw, 0, sets, &[]);
            }
        }
    }

    /// Records push constants; their size must equal the shader's block.
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound.
    pub(crate) unsafe fn push<P: bytemuck::Pod>(&self, cmd: vk::CommandBuffer, push: &P) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.push(cmd, push) };
    }

    /// Dispatches enough workgroups to cover `threads` invocations in each dimension.
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound.
    pub(crate) unsafe fn dispatch_threads(&self, cmd: vk::CommandBuffer, threads: [u32; 3]) {
        let groups = [0, 1, 2].map(|i| threads[i].div_ceil(self.workgroup_size[i]));
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.device.raw.cmd_dispatch(cmd, groups[0], groups[1], groups[2]) };
    }

    /// Dispatches with the workgroup counts read from `buffer` at `offset` when the
    /// command executes (a `VkDispatchIndirectCommand`).
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound; `buffer` has INDIRECT_BUFFER usage,
    /// holds a command at `offset` (a multiple of 4) whose counts stay within the
    /// device limits, and writes to it are made visible to DRAW_INDIRECT reads.
    pub(crate) unsafe fn dispatch_indirect(&self, cmd: vk::CommandBuffer, buffer: vk::Buffer, offset: u64) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.device.raw.cmd_dispatch_indirect(cmd, buffer, offset) };
    }
}

impl Layout {
    /// # Safety
    /// `cmd` is recording with a pipeline of this layout bound.
    unsafe fn push<P: bytemuck::Pod>(&self, cmd: vk::CommandBuffer, push: &P) {
        let bytes = bytemuck::bytes_of(push);
        if self.push_constant_size == 0 {
            return;
        }
        assert_eq!(
            bytes.len() as u32,
            self.push_constant_size,
            "push-constant struct size differs from the shader's block"
        );
        // SAFETY: guaranteed by the caller; size matches the declared range.
        unsafe { self.device.raw.cmd_push_constants(cmd, self.raw, self.push_stages, 0, bytes) };
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: pipeline of this device, no longer used by pending work.
        unsafe { self.layout.device.raw.destroy_pipeline(self.raw, None) };
    }
}

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
}

/// A graphics pipeline.
pub(crate) struct GraphicsPipeline {
    layout: Layout,
    raw: vk::Pipeline,
}

impl GraphicsPipeline {
    pub(crate) fn new(device: &Arc<Device>, desc: &GraphicsDesc<'_>, max_sets: u32) -> Result<Self> {
        let reflections = desc.stages.iter().map(|s| reflect(s)).collect::<Result<Vec<_>>>()?;
        let layout = Layout::new(device, desc.name, &reflections, max_sets)?;
        let mut modules = Vec::new();
        for s in desc.stages {
            match shader_module(device, s) {
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
            .depth_compare_op(vk::CompareOp::LESS_OR_EQUAL);
        let attachment = match desc.blend {
            Blend::None => {
                vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA)
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
        self.buffer_set(set, &self.layout.declared(set, buffers))
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
        let d = &self.layout.device.raw;
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.raw);
            if !sets.is_empty() {
                d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.layout.raw, 0, sets, &[]);
            }
        }
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
