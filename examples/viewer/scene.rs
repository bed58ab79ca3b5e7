//! What the viewer draws itself: the head mesh before the hair and a floor
//! after it (as a host's later passes would be), lit by one fixed light, with
//! its own pipeline (dynamic viewport and scissor) and vertex buffer.

use std::sync::Mutex;

use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::vulkan::{Allocation, Allocator};
use gpu_allocator::MemoryLocation;
use vkhair::groom::mesh::TriMesh;
use vkhair::{ash, gpu_allocator};

use crate::host::{
    allocate, graphics_pipeline, BoxError, Memory, PipelineDesc, MESH_VERTEX_ATTRIBUTES, MESH_VERTEX_BINDINGS,
};
use crate::swapchain::DEPTH;

const VERT: &str = r#"#version 460
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(push_constant) uniform Push { mat4 view_projection; vec4 color; } pc;
layout(location = 0) out vec3 v_normal;
void main() {
    v_normal = normal;
    gl_Position = pc.view_projection * vec4(position, 1.0);
}
"#;

const FRAG: &str = r#"#version 460
layout(location = 0) in vec3 v_normal;
layout(push_constant) uniform Push { mat4 view_projection; vec4 color; } pc;
layout(location = 0) out vec4 color;
void main() {
    float l = max(dot(normalize(v_normal), normalize(vec3(-0.4, 0.6, 0.7))), 0.0);
    color = vec4(pc.color.rgb * (0.3 + 0.7 * l), 1.0);
}
"#;

/// The head's and the floor's colours (linear).
const HEAD_COLOR: [f32; 4] = [0.45, 0.30, 0.24, 1.0];
const FLOOR_COLOR: [f32; 4] = [0.12, 0.12, 0.13, 1.0];

/// The viewer's own geometry and the pipeline that draws it.
pub struct HostScene {
    device: ash::Device,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    buffer: vk::Buffer,
    memory: Memory,
    /// Vertex ranges (first, count) of the head and the floor.
    head: (u32, u32),
    floor: (u32, u32),
}

impl HostScene {
    /// The head `mesh` and a floor square of half side `floor_half` at height
    /// `floor_y` under `center`, drawn into `color_format` with [`DEPTH`].
    pub fn new(
        device: &ash::Device,
        allocator: &Mutex<Allocator>,
        color_format: vk::Format,
        mesh: &TriMesh,
        (center, floor_y, floor_half): (Vec3, f32, f32),
    ) -> Result<HostScene, BoxError> {
        let mut vertices: Vec<f32> = Vec::new();
        for t in 0..mesh.triangles.len() {
            let n = mesh.scaled_normal(t).normalize_or_zero();
            for p in mesh.corners(t) {
                vertices.extend_from_slice(&[p.x, p.y, p.z, n.x, n.y, n.z]);
            }
        }
        let head = (0, (vertices.len() / 6) as u32);
        let (x0, x1, z0, z1) =
            (center.x - floor_half, center.x + floor_half, center.z - floor_half, center.z + floor_half);
        for [x, z] in [[x0, z0], [x0, z1], [x1, z1], [x0, z0], [x1, z1], [x1, z0]] {
            vertices.extend_from_slice(&[x, floor_y, z, 0.0, 1.0, 0.0]);
        }
        let floor = (head.1, 6);
        let size = (vertices.len() * 4) as u64;
        let info = vk::BufferCreateInfo::default().size(size).usage(vk::BufferUsageFlags::VERTEX_BUFFER);
        // SAFETY: valid create info; destroyed in `destroy`.
        let buffer = unsafe { device.create_buffer(&info, None) }?;
        // SAFETY: the buffer is alive.
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
        let mut memory: Allocation =
            allocate(allocator, "viewer scene vertices", requirements, MemoryLocation::CpuToGpu, true)?;
        // SAFETY: memory allocated for this buffer.
        unsafe { device.bind_buffer_memory(buffer, memory.memory(), memory.offset()) }?;
        memory.mapped_slice_mut().ok_or("vertex memory is not mapped")?[..size as usize]
            .copy_from_slice(bytemuck::cast_slice(&vertices));
        let (pipeline, layout) = pipeline(device, color_format)?;
        Ok(HostScene { device: device.clone(), pipeline, layout, buffer, memory: Memory(Some(memory)), head, floor })
    }

    /// Records the head inside the caller's rendering (color attachment of the
    /// format given at creation, depth [`DEPTH`]): binds the pipeline and the
    /// vertex buffer, sets viewport and scissor to `extent`. With `body` (a
    /// vertex buffer of positions and normals and its vertex count: a skinned
    /// character), draws that instead of the head, then binds its own buffer
    /// again for the floor.
    ///
    /// # Safety
    /// `cmd` is recording inside such a rendering; `body`'s buffer is alive
    /// and its vertices written before this draw (barrier included).
    pub unsafe fn record_head(
        &self,
        cmd: vk::CommandBuffer,
        extent: vk::Extent2D,
        view_projection: Mat4,
        body: Option<(vk::Buffer, u32)>,
    ) {
        let d = &self.device;
        let viewport = crate::host::full_viewport(extent);
        // SAFETY: guaranteed by the caller; every object here is alive.
        unsafe {
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
            if let Some((buffer, count)) = body {
                d.cmd_bind_vertex_buffers(cmd, 0, &[buffer], &[0]);
                self.draw(cmd, (0, count), HEAD_COLOR, view_projection);
            }
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.buffer], &[0]);
            if body.is_none() {
                self.draw(cmd, self.head, HEAD_COLOR, view_projection);
            }
        }
    }

    /// [`HostScene::record_head`] for a crowd: the head mesh placed by each
    /// of `heads` (its frame in the world) and, with `body` (a skinned
    /// character's vertex buffer and count, and its places), that body at each
    /// place; leaves the scene's own vertex buffer bound.
    ///
    /// # Safety
    /// As for [`HostScene::record_head`].
    pub unsafe fn record_crowd(
        &self,
        cmd: vk::CommandBuffer,
        extent: vk::Extent2D,
        view_projection: Mat4,
        heads: &[Mat4],
        body: Option<((vk::Buffer, u32), &[Mat4])>,
    ) {
        let d = &self.device;
        let viewport = crate::host::full_viewport(extent);
        // SAFETY: guaranteed by the caller; every object here is alive.
        unsafe {
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
            if let Some(((buffer, count), places)) = body {
                d.cmd_bind_vertex_buffers(cmd, 0, &[buffer], &[0]);
                for place in places {
                    self.draw(cmd, (0, count), HEAD_COLOR, view_projection * *place);
                }
            }
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.buffer], &[0]);
            for head in heads {
                self.draw(cmd, self.head, HEAD_COLOR, view_projection * *head);
            }
        }
    }

    /// Records the floor after vkhair's hair, inside the caller's rendering of
    /// the same attachments, relying on what vkhair documents about the state it
    /// leaves: the vertex buffer bound by [`HostScene::record_head`] is still
    /// bound (vkhair binds no vertex buffer), and the viewport and scissor are the full
    /// target (`Renderer::record_draw` leaves them so). Only the pipeline and
    /// the push constants are the host's to set again.
    ///
    /// # Safety
    /// As for [`HostScene::record_head`], after it and after `record_draw` in the
    /// same command buffer.
    pub unsafe fn record_floor(&self, cmd: vk::CommandBuffer, view_projection: Mat4) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.draw(cmd, self.floor, FLOOR_COLOR, view_projection) }
    }

    /// Binds the pipeline, pushes the constants and draws `(first, count)`.
    unsafe fn draw(&self, cmd: vk::CommandBuffer, (first, count): (u32, u32), color: [f32; 4], view_projection: Mat4) {
        let d = &self.device;
        let mut push = [0f32; 20];
        push[..16].copy_from_slice(&view_projection.to_cols_array());
        push[16..].copy_from_slice(&color);
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        // SAFETY: guaranteed by the callers.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_push_constants(cmd, self.layout, stages, 0, bytemuck::cast_slice(&push));
            d.cmd_draw(cmd, count, 1, first, 0);
        }
    }

    /// Destroys everything (no pending work uses it).
    pub fn destroy(&mut self, allocator: &Mutex<Allocator>) {
        // SAFETY: the caller waited for the device.
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
            self.device.destroy_buffer(self.buffer, None);
        }
        self.memory.free(allocator);
    }
}

/// The mesh pipeline for `color_format` and [`DEPTH`].
fn pipeline(device: &ash::Device, color_format: vk::Format) -> Result<(vk::Pipeline, vk::PipelineLayout), BoxError> {
    let stages_flags = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
    let push = [vk::PushConstantRange { stage_flags: stages_flags, offset: 0, size: 80 }];
    // SAFETY: valid create info; destroyed by `HostScene::destroy`.
    let layout = unsafe {
        device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push), None)
    }?;
    let desc = PipelineDesc {
        vert: VERT,
        frag: FRAG,
        names: ("scene.vert", "scene.frag"),
        vertex_input: vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&MESH_VERTEX_BINDINGS)
            .vertex_attribute_descriptions(&MESH_VERTEX_ATTRIBUTES),
        cull: vk::CullModeFlags::NONE,
        colors: &[color_format],
        depth: Some(DEPTH),
        viewport: None,
    };
    Ok((graphics_pipeline(device, layout, &desc)?, layout))
}
