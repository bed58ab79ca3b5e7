//! The viewer's skinning pass, as a host with a skinned character has one: a
//! compute shader deforms the character's mesh by its joints' matrices
//! (linear blend skinning, four joints a vertex) into two buffers that live on
//! the GPU only:
//!
//! - the skinned vertices (xyzw, world), one slot per simulation step of a
//!   frame: vkhair reads the key hairs' roots from them
//!   (`HairSim::bind_scalp_source`, `set_scalp_offset` per step), so the hair
//!   rides the same skin the viewer draws;
//! - the triangles the viewer draws (position and flat normal per corner) at
//!   the frame's shown time.
//!
//! Joint matrices go through a host-visible buffer, one region per frame in
//! flight (written after that frame's fence).

use std::sync::Mutex;

use ash::vk;
use glam::Mat4;
use gpu_allocator::vulkan::{Allocation, Allocator};
use gpu_allocator::MemoryLocation;
use vkhair::character::Character;
use vkhair::{ash, gpu_allocator};

use crate::hair::FRAMES_IN_FLIGHT;
use crate::host::{allocate, compile, BoxError, Memory};

/// Most simulation steps a frame records (the viewer's `FixedStepDriver`'s).
pub const MAX_STEPS: u32 = 2;

/// Bytes of one skinned vertex in the steps' slots (xyzw).
pub const SKINNED_STRIDE: u64 = 16;

/// Bytes of one drawn corner: position and normal.
pub const DRAW_STRIDE: u64 = 24;

const SHADER: &str = r#"#version 460
layout(local_size_x = 64) in;
struct Vertex { vec4 position; uvec4 joints; vec4 weights; };
layout(std430, set = 0, binding = 0) readonly buffer Bind { Vertex vertices[]; };
layout(std430, set = 0, binding = 1) readonly buffer Corners { uint corners[]; };
layout(std430, set = 0, binding = 2) readonly buffer Bones { mat4 bones[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Skinned { vec4 skinned[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Drawn { float drawn[]; };
// mode 0: vertex i into skinned[first_out + i]; mode 1: triangle i into drawn.
layout(push_constant) uniform Push { uint mode; uint count; uint first_bone; uint first_out; } pc;

vec3 skin(uint v) {
    Vertex x = vertices[v];
    mat4 m = bones[pc.first_bone + x.joints.x] * x.weights.x + bones[pc.first_bone + x.joints.y] * x.weights.y
           + bones[pc.first_bone + x.joints.z] * x.weights.z + bones[pc.first_bone + x.joints.w] * x.weights.w;
    return (m * vec4(x.position.xyz, 1.0)).xyz;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    if (pc.mode == 0u) {
        skinned[pc.first_out + i] = vec4(skin(i), 1.0);
        return;
    }
    vec3 p[3] = vec3[3](skin(corners[3u * i]), skin(corners[3u * i + 1u]), skin(corners[3u * i + 2u]));
    vec3 n = cross(p[1] - p[0], p[2] - p[0]);
    n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    for (uint k = 0u; k < 3u; k++) {
        uint o = (3u * i + k) * 6u;
        drawn[o] = p[k].x; drawn[o + 1u] = p[k].y; drawn[o + 2u] = p[k].z;
        drawn[o + 3u] = n.x; drawn[o + 4u] = n.y; drawn[o + 5u] = n.z;
    }
}
"#;

/// A buffer of the skinning pass with its memory.
struct SkinBuffer {
    buffer: vk::Buffer,
    memory: Memory,
    size: u64,
}

/// The skinning pass (see the module docs).
pub struct GpuSkin {
    device: ash::Device,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    bind: SkinBuffer,
    corners: SkinBuffer,
    bones: SkinBuffer,
    skinned: SkinBuffer,
    drawn: SkinBuffer,
    vertices: u32,
    triangles: u32,
    joints: u32,
}

/// Bone regions a frame in flight has: one per step, one for the drawn mesh.
const BONE_SLOTS: u32 = MAX_STEPS + 1;

impl GpuSkin {
    /// The pass for `character` on `device`.
    pub fn new(device: &ash::Device, allocator: &Mutex<Allocator>, character: &Character) -> Result<GpuSkin, BoxError> {
        let vertices = u32::try_from(character.positions.len())?;
        let triangles = u32::try_from(character.triangles.len())?;
        let joints = u32::try_from(character.skeleton.joints.len())?;
        let mut bind: Vec<u8> = Vec::with_capacity(character.positions.len() * 48);
        for (p, (j, w)) in character.positions.iter().zip(&character.weights) {
            bind.extend_from_slice(bytemuck::cast_slice(&p.extend(1.0).to_array()));
            bind.extend_from_slice(bytemuck::cast_slice(&j.map(u32::from)));
            bind.extend_from_slice(bytemuck::cast_slice(w));
        }
        let corners: Vec<u32> = character.triangles.iter().flatten().copied().collect();
        let bind = filled(device, allocator, "viewer skin bind pose", &bind)?;
        let corners = filled(device, allocator, "viewer skin triangles", bytemuck::cast_slice(&corners))?;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut skin = GpuSkin {
            device: device.clone(),
            pipeline: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            bind,
            corners,
            bones: buffer(
                device,
                allocator,
                "viewer skin joint matrices",
                u64::from(FRAMES_IN_FLIGHT * BONE_SLOTS * joints) * 64,
                storage,
                MemoryLocation::CpuToGpu,
            )?,
            skinned: buffer(
                device,
                allocator,
                "viewer skinned vertices",
                u64::from(MAX_STEPS * vertices) * SKINNED_STRIDE,
                storage,
                MemoryLocation::GpuOnly,
            )?,
            drawn: buffer(
                device,
                allocator,
                "viewer skinned triangles",
                u64::from(3 * triangles) * DRAW_STRIDE,
                storage | vk::BufferUsageFlags::VERTEX_BUFFER,
                MemoryLocation::GpuOnly,
            )?,
            vertices,
            triangles,
            joints,
        };
        skin.make_pipeline()?;
        Ok(skin)
    }

    /// The skinned vertices' buffer, its size, and the bytes of one step's slot.
    pub fn skinned(&self) -> (vk::Buffer, u64, u64) {
        (self.skinned.buffer, self.skinned.size, u64::from(self.vertices) * SKINNED_STRIDE)
    }

    /// The drawn triangles' vertex buffer and its vertex count.
    pub fn drawn(&self) -> (vk::Buffer, u32) {
        (self.drawn.buffer, 3 * self.triangles)
    }

    /// Writes the joints' skinning matrices of frame slot `frame_slot`: one set
    /// per step (`steps`, at most [`MAX_STEPS`]) and the drawn mesh's.
    /// The frame slot's previous frame has completed.
    pub fn write_bones(&mut self, frame_slot: u32, steps: &[Vec<Mat4>], drawn: &[Mat4]) -> Result<(), BoxError> {
        if steps.len() > MAX_STEPS as usize {
            return Err(format!("{} steps in one frame: the skinning pass holds {MAX_STEPS}", steps.len()).into());
        }
        for (k, bones) in steps.iter().map(Vec::as_slice).chain([drawn]).enumerate() {
            let slot = if k == steps.len() { MAX_STEPS } else { k as u32 };
            if bones.len() != self.joints as usize {
                return Err(format!("{} joint matrices for {} joints", bones.len(), self.joints).into());
            }
            let offset = u64::from((frame_slot * BONE_SLOTS + slot) * self.joints) * 64;
            let flat: Vec<f32> = bones.iter().flat_map(|m| m.to_cols_array()).collect();
            write(&mut self.bones, offset, bytemuck::cast_slice(&flat))?;
        }
        Ok(())
    }

    /// Records the pass for frame slot `frame_slot`: `steps` slots of skinned
    /// vertices and the drawn triangles, with the barriers that order them
    /// after the previous frame's reads (vkhair's steps, the host's draw) and
    /// before this frame's (vkhair's steps order their own reads; the draw's
    /// vertex reads are ordered here). Leaves the compute pipeline bound.
    ///
    /// # Safety
    /// `cmd` records for the device's queue, outside rendering; the bones were
    /// written by [`GpuSkin::write_bones`] for this frame slot.
    pub unsafe fn record(&self, cmd: vk::CommandBuffer, frame_slot: u32, steps: u32) {
        let d = &self.device;
        let before = vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT)
            .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
            .dst_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE);
        let after = vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
            .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT)
            .dst_access_mask(vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::VERTEX_ATTRIBUTE_READ);
        let first_bone = |slot: u32| (frame_slot * BONE_SLOTS + slot) * self.joints;
        // SAFETY: guaranteed by the caller; every object here is alive.
        unsafe {
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&[before]));
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.set], &[]);
            for k in 0..steps.min(MAX_STEPS) {
                self.dispatch(cmd, [0, self.vertices, first_bone(k), k * self.vertices]);
            }
            self.dispatch(cmd, [1, self.triangles, first_bone(MAX_STEPS), 0]);
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&[after]));
        }
    }

    /// One dispatch over `push[1]` items.
    unsafe fn dispatch(&self, cmd: vk::CommandBuffer, push: [u32; 4]) {
        // SAFETY: guaranteed by `record`'s caller.
        unsafe {
            self.device.cmd_push_constants(
                cmd,
                self.layout,
                vk::ShaderStageFlags::COMPUTE,
                0,
                bytemuck::cast_slice(&push),
            );
            self.device.cmd_dispatch(cmd, push[1].div_ceil(64), 1, 1);
        }
    }

    /// The pipeline, its layout and the one descriptor set over the buffers.
    fn make_pipeline(&mut self) -> Result<(), BoxError> {
        let d = &self.device;
        let code = compile(SHADER, shaderc::ShaderKind::Compute, "skin.comp")?;
        let bindings: Vec<_> = (0..5)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let push = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::COMPUTE, offset: 0, size: 16 }];
        let sizes = [vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: 5 }];
        // SAFETY: valid create infos; each object is destroyed in `destroy`
        // (the shader module below, once the pipeline exists).
        unsafe {
            self.set_layout = d.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )?;
            let set_layouts = [self.set_layout];
            self.layout = d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts).push_constant_ranges(&push),
                None,
            )?;
            self.pool = d.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes),
                None,
            )?;
            self.set = d.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default().descriptor_pool(self.pool).set_layouts(&set_layouts),
            )?[0];
            let infos: Vec<[vk::DescriptorBufferInfo; 1]> =
                [&self.bind, &self.corners, &self.bones, &self.skinned, &self.drawn]
                    .iter()
                    .map(|b| [vk::DescriptorBufferInfo { buffer: b.buffer, offset: 0, range: vk::WHOLE_SIZE }])
                    .collect();
            let writes: Vec<_> = infos
                .iter()
                .enumerate()
                .map(|(b, info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(self.set)
                        .dst_binding(b as u32)
                        .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                        .buffer_info(info)
                })
                .collect();
            d.update_descriptor_sets(&writes, &[]);
            let module = d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None)?;
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(c"main");
            let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(self.layout);
            let created = d.create_compute_pipelines(vk::PipelineCache::null(), &[info], None);
            d.destroy_shader_module(module, None);
            self.pipeline = created.map_err(|(_, e)| e)?[0];
        }
        Ok(())
    }

    /// Destroys everything (no pending work uses it).
    pub fn destroy(&mut self, allocator: &Mutex<Allocator>) {
        let d = &self.device;
        // SAFETY: the caller waited for the device; null handles are ignored.
        unsafe {
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            for b in [&mut self.bind, &mut self.corners, &mut self.bones, &mut self.skinned, &mut self.drawn] {
                d.destroy_buffer(b.buffer, None);
                b.memory.free(allocator);
            }
        }
    }
}

/// A buffer of `size` bytes bound to new memory at `location`.
fn buffer(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    size: u64,
    usage: vk::BufferUsageFlags,
    location: MemoryLocation,
) -> Result<SkinBuffer, BoxError> {
    let info = vk::BufferCreateInfo::default().size(size.max(4)).usage(usage);
    // SAFETY: valid create info; destroyed in `GpuSkin::destroy`.
    let buffer = unsafe { device.create_buffer(&info, None) }?;
    // SAFETY: the buffer is alive.
    let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
    let memory: Allocation = allocate(allocator, name, requirements, location, true)?;
    // SAFETY: memory allocated for this buffer.
    unsafe { device.bind_buffer_memory(buffer, memory.memory(), memory.offset()) }?;
    Ok(SkinBuffer { buffer, memory: Memory(Some(memory)), size: size.max(4) })
}

/// A host-visible storage buffer holding `bytes`.
fn filled(
    device: &ash::Device,
    allocator: &Mutex<Allocator>,
    name: &str,
    bytes: &[u8],
) -> Result<SkinBuffer, BoxError> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let mut b = buffer(device, allocator, name, bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    write(&mut b, 0, bytes)?;
    Ok(b)
}

/// Copies `bytes` into a host-visible buffer at `offset`.
fn write(b: &mut SkinBuffer, offset: u64, bytes: &[u8]) -> Result<(), BoxError> {
    let mapped = b.memory.0.as_mut().and_then(|m| m.mapped_slice_mut()).ok_or("skin memory is not mapped")?;
    let range = offset as usize..offset as usize + bytes.len();
    mapped.get_mut(range).ok_or("write past the skin buffer")?.copy_from_slice(bytes);
    Ok(())
}
