//! Compute pipelines: workgroup size from reflection, dispatches in threads.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use ash::vk;

use super::{shader_module, ConstantZero, Layout};
use crate::error::{Error, Result};
use crate::vk::buffer::Buffer;
use crate::vk::counters::DispatchRecord;
use crate::vk::device::Device;
use crate::vk::reflect::reflect;
use crate::vk::shaders::ShaderSource;

/// Workgroups of a dispatch that every device runs (`maxComputeWorkGroupCount`'s
/// minimum): a grid-stride kernel dispatches at most this many and loops over
/// the rest ([`ComputePipeline::grid_stride_threads`]).
pub(crate) const MAX_WORKGROUPS: u32 = 65_535;

/// A compute pipeline, and variants of it with its specialisation constant 0
/// set (see [`ComputePipeline::prepare_variant`]).
///
/// Compiling is the costly part of creating a pipeline (a software device
/// compiles to machine code then): [`ComputePipeline::deferred`] compiles
/// nothing until [`ComputePipeline::prepare`] or a variant asks for it, for a
/// kernel that is only ever bound as variants or only some of the time.
pub(crate) struct ComputePipeline {
    layout: Layout,
    /// The pipeline with every specialisation constant at its default; null
    /// until compiled.
    raw: vk::Pipeline,
    /// Variants by the value of specialisation constant 0; destroyed with the pipeline.
    variants: HashMap<u32, vk::Pipeline>,
    words: &'static [u32],
    full_subgroups: bool,
    workgroup_size: [u32; 3],
    name: String,
    /// Bytes read and written through each buffer descriptor set (for the counters).
    traffic: Mutex<HashMap<vk::DescriptorSet, (u64, u64)>>,
    /// The traffic of the sets bound last.
    bound: Mutex<(u64, u64)>,
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
        let mut pipeline = Self::deferred(device, shader, max_sets, full_subgroups)?;
        pipeline.prepare()?;
        Ok(pipeline)
    }

    /// As [`ComputePipeline::with_full_subgroups`], compiling nothing yet: the
    /// layout and descriptor sets are there, and [`ComputePipeline::prepare`]
    /// (the pipeline itself) or [`ComputePipeline::prepare_variant`] compile
    /// what is bound later.
    pub(crate) fn deferred(
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
        Ok(ComputePipeline {
            layout,
            raw: vk::Pipeline::null(),
            variants: HashMap::new(),
            words: shader.words,
            full_subgroups,
            workgroup_size,
            name: shader.name.to_owned(),
            traffic: Mutex::default(),
            bound: Mutex::default(),
        })
    }

    /// Compiles, unless it is, the pipeline with every specialisation constant
    /// at its default (what [`ComputePipeline::bind`] binds).
    pub(crate) fn prepare(&mut self) -> Result<()> {
        if self.raw == vk::Pipeline::null() {
            self.raw = create(&self.layout, self.words, &self.name, self.full_subgroups, None)?;
        }
        Ok(())
    }

    /// Whether the pipeline itself (not a variant) is compiled.
    #[cfg(test)]
    pub(crate) fn is_prepared(&self) -> bool {
        self.raw != vk::Pipeline::null()
    }

    /// Creates, unless it exists, the variant with specialisation constant 0 set to
    /// `constant` (a `uint`); it shares the layout and descriptor sets of the pipeline.
    pub(crate) fn prepare_variant(&mut self, constant: u32) -> Result<()> {
        if !self.variants.contains_key(&constant) {
            let name = format!("{} [constant 0 = {constant:#x}]", self.name);
            let raw = create(&self.layout, self.words, &name, self.full_subgroups, Some(constant))?;
            self.variants.insert(constant, raw);
        }
        Ok(())
    }

    /// Invocations to dispatch for `threads` items of a grid-stride kernel:
    /// all of them, or as many as [`MAX_WORKGROUPS`] workgroups hold (the
    /// kernel loops over the rest).
    pub(crate) fn grid_stride_threads(&self, threads: u32) -> u32 {
        threads.min(MAX_WORKGROUPS.saturating_mul(self.workgroup_size[0]))
    }

    /// Invocations per workgroup in each dimension.
    pub(crate) fn workgroup_size(&self) -> [u32; 3] {
        self.workgroup_size
    }

    /// Allocates descriptor set `set` and binds those of `buffers` that the shader
    /// declares (stages sharing one binding table each use a subset of it).
    pub(crate) fn declared_buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        self.buffer_set(set, &self.layout.declared(set, buffers))
    }

    /// Points those of `buffers` that the shader declares in set `set` at new buffers,
    /// in an existing descriptor set `target`.
    ///
    /// # Safety
    /// `target` was allocated by this pipeline for set `set`, and no pending or
    /// recording command buffer uses it.
    pub(crate) unsafe fn rewrite_declared(
        &self,
        target: vk::DescriptorSet,
        set: u32,
        buffers: &[(u32, &Buffer)],
    ) -> Result<()> {
        let declared = self.layout.declared(set, buffers);
        self.layout.write_buffers(target, set, &declared)?;
        self.note_traffic(target, set, &declared);
        Ok(())
    }

    /// Points storage buffer `binding` of set `set` in `target` at a range of a
    /// host's buffer (not counted in the traffic estimate).
    ///
    /// # Safety
    /// As [`ComputePipeline::rewrite_declared`], and `info` names a live buffer
    /// of this device with storage usage, its range within the buffer and the
    /// device's limits.
    pub(crate) unsafe fn rewrite_raw_buffer(
        &self,
        target: vk::DescriptorSet,
        set: u32,
        binding: u32,
        info: vk::DescriptorBufferInfo,
    ) -> Result<()> {
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.write_raw_buffer(target, set, binding, info) }
    }

    fn note_traffic(&self, target: vk::DescriptorSet, set: u32, buffers: &[(u32, &Buffer)]) {
        let traffic = self.layout.traffic(set, buffers);
        if let Ok(mut map) = self.traffic.lock() {
            map.insert(target, traffic);
        }
    }

    /// Allocates descriptor set `set` and points its buffer bindings at `buffers`.
    pub(crate) fn buffer_set(&self, set: u32, buffers: &[(u32, &Buffer)]) -> Result<vk::DescriptorSet> {
        let target = self.layout.allocate_set(set, &format!("{} set {set}", self.name))?;
        self.layout.write_buffers(target, set, buffers)?;
        self.note_traffic(target, set, buffers);
        Ok(target)
    }

    /// Allocates descriptor set `set` and binds those of `buffers` and `images`
    /// (combined image-samplers) that the shader declares.
    pub(crate) fn declared_resource_set(
        &self,
        set: u32,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<vk::DescriptorSet> {
        let buffers = self.layout.declared(set, buffers);
        let target = self.layout.resource_set(set, &self.name, &buffers, &self.layout.declared_images(set, images))?;
        self.note_traffic(target, set, &buffers);
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
    /// `cmd` is a recording command buffer of this device, and the pipeline is
    /// compiled (a deferred one prepared: [`ComputePipeline::prepare`]).
    pub(crate) unsafe fn bind(&self, cmd: vk::CommandBuffer, sets: &[vk::DescriptorSet]) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.bind_raw(cmd, self.raw, sets) };
    }

    /// As [`ComputePipeline::bind`], the variant prepared for `constant`; the
    /// pipeline itself (every constant at its default) when there is none.
    ///
    /// # Safety
    /// As [`ComputePipeline::bind`], with the variant or the pipeline compiled.
    pub(crate) unsafe fn bind_variant(&self, cmd: vk::CommandBuffer, constant: u32, sets: &[vk::DescriptorSet]) {
        let raw = self.variants.get(&constant).copied().unwrap_or(self.raw);
        // SAFETY: guaranteed by the caller.
        unsafe { self.bind_raw(cmd, raw, sets) };
    }

    /// Binds `raw` (this pipeline or one of its variants) and `sets`.
    ///
    /// # Safety
    /// As [`ComputePipeline::bind`].
    unsafe fn bind_raw(&self, cmd: vk::CommandBuffer, raw: vk::Pipeline, sets: &[vk::DescriptorSet]) {
        if raw == vk::Pipeline::null() {
            // A broken contract: binding nothing leaves the dispatch to the
            // validation layers rather than binding a null handle.
            log::error!("{}: bound before it was compiled; nothing bound", self.name);
            debug_assert!(false, "{}: bound before it was compiled", self.name);
            return;
        }
        if let (Ok(map), Ok(mut bound)) = (self.traffic.lock(), self.bound.lock()) {
            *bound = sets.iter().filter_map(|s| map.get(s)).fold((0, 0), |a, t| (a.0 + t.0, a.1 + t.1));
        }
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.bind(cmd, vk::PipelineBindPoint::COMPUTE, raw, sets) };
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
        // SAFETY: guaranteed by the caller; the counts cover `threads`.
        unsafe { self.dispatch_groups(cmd, groups, 1) };
    }

    /// Dispatches `groups` workgroups in each dimension, whose invocations go
    /// round their loops at most `loop_trips` times (for the dispatch log; 1
    /// for a kernel whose invocations each take one item).
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound; each count is within the
    /// device's `maxComputeWorkGroupCount`.
    pub(crate) unsafe fn dispatch_groups(&self, cmd: vk::CommandBuffer, groups: [u32; 3], loop_trips: u32) {
        self.count_dispatch(groups, false, loop_trips);
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.device.raw.cmd_dispatch(cmd, groups[0], groups[1], groups[2]) };
    }

    /// Dispatches with the workgroup counts read from `buffer` at `offset` when the
    /// command executes (a `VkDispatchIndirectCommand`), logged as launching at
    /// most `groups` workgroups whose invocations go round their loops at most
    /// `loop_trips` times ([`crate::GpuContext::start_dispatch_log`]).
    ///
    /// # Safety
    /// `cmd` is recording with this pipeline bound; `buffer` has INDIRECT_BUFFER usage,
    /// holds a command at `offset` (a multiple of 4) whose counts stay within the
    /// device limits, and writes to it are made visible to DRAW_INDIRECT reads.
    pub(crate) unsafe fn dispatch_indirect_at_most(
        &self,
        cmd: vk::CommandBuffer,
        buffer: vk::Buffer,
        offset: u64,
        groups: [u32; 3],
        loop_trips: u32,
    ) {
        self.count_dispatch(groups, true, loop_trips);
        // SAFETY: guaranteed by the caller.
        unsafe { self.layout.device.raw.cmd_dispatch_indirect(cmd, buffer, offset) };
    }
}

impl ComputePipeline {
    fn count_dispatch(&self, groups: [u32; 3], indirect: bool, loop_trips: u32) {
        let traffic = self.bound.lock().map_or((0, 0), |b| *b);
        let counters = &self.layout.device.counters;
        counters.dispatch(traffic);
        counters.log_dispatch(|| DispatchRecord {
            kernel: self.name.clone(),
            workgroups: groups.iter().map(|&g| u64::from(g)).product(),
            workgroup_size: self.workgroup_size.iter().product(),
            indirect,
            loop_trips,
        });
    }
}

/// Creates a compute pipeline of `words` with `layout`, specialisation constant 0
/// set to `constant` when given.
fn create(
    layout: &Layout,
    words: &'static [u32],
    name: &str,
    full_subgroups: bool,
    constant: Option<u32>,
) -> Result<vk::Pipeline> {
    let device = &layout.device;
    let module = shader_module(device, words, name)?;
    let flags = if full_subgroups {
        vk::PipelineShaderStageCreateFlags::REQUIRE_FULL_SUBGROUPS
    } else {
        vk::PipelineShaderStageCreateFlags::empty()
    };
    let constant = constant.map(ConstantZero::new);
    let specialization = constant.as_ref().map(ConstantZero::info);
    let mut stage = vk::PipelineShaderStageCreateInfo::default()
        .flags(flags)
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(c"main");
    if let Some(info) = &specialization {
        stage = stage.specialization_info(info);
    }
    let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout.raw);
    // SAFETY: module and layout are alive; the module is destroyed right after.
    let result = unsafe { device.raw.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) };
    // SAFETY: the module is no longer needed once the pipeline exists.
    unsafe { device.raw.destroy_shader_module(module, None) };
    let raw = result.map_err(|(_, r)| Error::Vulkan { call: "vkCreateComputePipelines", result: r })?[0];
    device.set_name(raw, name);
    Ok(raw)
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        let compiled = std::iter::once(self.raw).filter(|raw| *raw != vk::Pipeline::null());
        for raw in compiled.chain(self.variants.values().copied()) {
            // SAFETY: pipelines of this device, no longer used by pending work.
            unsafe { self.layout.device.raw.destroy_pipeline(raw, None) };
        }
    }
}
