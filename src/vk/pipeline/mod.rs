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
use super::reflect::{Binding, Reflection};
use crate::error::{Error, Result};

mod compute;
mod graphics;

pub(crate) use compute::ComputePipeline;
pub(crate) use graphics::{Blend, GraphicsDesc, GraphicsPipeline};

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
                entry.0.reads |= b.reads;
                entry.0.writes |= b.writes;
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

    /// Whether the pipeline declares `binding` in `set`.
    fn declares(&self, set: u32, binding: u32) -> bool {
        self.bindings.iter().any(|(b, _)| b.set == set && b.binding == binding)
    }

    /// The entries of `buffers` whose binding the pipeline declares in `set`.
    fn declared<'a>(&self, set: u32, buffers: &[(u32, &'a Buffer)]) -> Vec<(u32, &'a Buffer)> {
        buffers.iter().filter(|(binding, _)| self.declares(set, *binding)).copied().collect()
    }

    /// The entries of `images` (combined image-samplers) whose binding the
    /// pipeline declares in `set`.
    fn declared_images(
        &self,
        set: u32,
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Vec<(u32, vk::ImageView, vk::Sampler)> {
        images.iter().filter(|(binding, _, _)| self.declares(set, *binding)).copied().collect()
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

    /// Bytes a dispatch reads and writes through `buffers` bound to `set`, each
    /// counted whole (see [`crate::RecordedWork`]).
    fn traffic(&self, set: u32, buffers: &[(u32, &Buffer)]) -> (u64, u64) {
        let mut traffic = (0, 0);
        for (binding, buffer) in buffers {
            if let Some((b, _)) = self.bindings.iter().find(|(b, _)| b.set == set && b.binding == *binding) {
                traffic.0 += if b.reads { buffer.size() } else { 0 };
                traffic.1 += if b.writes { buffer.size() } else { 0 };
            }
        }
        traffic
    }

    /// Points storage buffer binding `binding` of `set` at a range of a buffer
    /// this crate does not own (a host's).
    ///
    /// # Safety
    /// `target` was allocated for `set` and is not in use by pending GPU work;
    /// `info` names a live buffer of this device with storage usage, its range
    /// within the buffer and the device's limits.
    unsafe fn write_raw_buffer(
        &self,
        target: vk::DescriptorSet,
        set: u32,
        binding: u32,
        info: vk::DescriptorBufferInfo,
    ) -> Result<()> {
        let declared = self.bindings.iter().find(|(b, _)| b.set == set && b.binding == binding);
        if declared.is_none_or(|(b, _)| b.ty != vk::DescriptorType::STORAGE_BUFFER) {
            return Err(Error::incompatible(
                "descriptor binding",
                format!("set {set} binding {binding} is not a declared storage buffer"),
            ));
        }
        let infos = [info];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(target)
            .dst_binding(binding)
            .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
            .buffer_info(&infos);
        // SAFETY: guaranteed by the caller.
        unsafe { self.device.raw.update_descriptor_sets(&[write], &[]) };
        Ok(())
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

/// Specialisation constant 0 (a `uint`) of a pipeline's stages; a stage that
/// declares none ignores it.
struct ConstantZero {
    entries: [vk::SpecializationMapEntry; 1],
    data: [u8; 4],
}

impl ConstantZero {
    fn new(value: u32) -> Self {
        ConstantZero {
            entries: [vk::SpecializationMapEntry { constant_id: 0, offset: 0, size: 4 }],
            data: value.to_ne_bytes(),
        }
    }

    fn info(&self) -> vk::SpecializationInfo<'_> {
        vk::SpecializationInfo::default().map_entries(&self.entries).data(&self.data)
    }
}

fn shader_module(device: &Device, words: &[u32], name: &str) -> Result<vk::ShaderModule> {
    let info = vk::ShaderModuleCreateInfo::default().code(words);
    // SAFETY: the words are SPIR-V validated by spirv-val at build time.
    let module = unsafe { device.raw.create_shader_module(&info, None) }.map_err(Error::vk("vkCreateShaderModule"))?;
    device.set_name(module, name);
    Ok(module)
}

impl Layout {
    /// Binds `pipeline` (of this layout) at `point` and `sets` from set 0.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device (inside a compatible
    /// rendering instance for graphics pipelines).
    unsafe fn bind(
        &self,
        cmd: vk::CommandBuffer,
        point: vk::PipelineBindPoint,
        pipeline: vk::Pipeline,
        sets: &[vk::DescriptorSet],
    ) {
        let d = &self.device.raw;
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_bind_pipeline(cmd, point, pipeline);
            if !sets.is_empty() {
                d.cmd_bind_descriptor_sets(cmd, point, self.raw, 0, sets, &[]);
            }
        }
    }

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
