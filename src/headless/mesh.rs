//! A lit triangle mesh drawn the way a host draws its own geometry: the head
//! the hair sits on, optionally shadowed by the hair through
//! `glsl/include/shadow.glsl`.

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Quat, Vec3, Vec4};

use super::offscreen::{OFFSCREEN_COLOR, OFFSCREEN_DEPTH};
use crate::context::GpuContext;
use crate::error::Result;
use crate::groom::mesh::TriMesh;
use crate::render::{RenderTarget, Renderer};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::{RENDER_MESH_FRAG, RENDER_MESH_SHADOWED_FRAG, RENDER_MESH_VERT};

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MeshPush {
    mvp: [[f32; 4]; 4],
    rotation: [f32; 4],
    color: [f32; 4],
    light: [f32; 4],
    translation: [f32; 4],
}

/// Every triangle's corners and its flat normal at each.
fn corners(mesh: &TriMesh) -> (Vec<Vec4>, Vec<Vec4>) {
    let mut positions = Vec::with_capacity(mesh.triangles.len() * 3);
    let mut normals = Vec::with_capacity(mesh.triangles.len() * 3);
    for i in 0..mesh.triangles.len() {
        let n = mesh.scaled_normal(i).normalize_or_zero().extend(0.0);
        for p in mesh.corners(i) {
            positions.push(p.extend(1.0));
            normals.push(n);
        }
    }
    (positions, normals)
}

/// Draws a triangle mesh with one directional light (the host's head).
pub struct MeshDrawer {
    device: Arc<Device>,
    pipeline: GraphicsPipeline,
    set: vk::DescriptorSet,
    vertices: u32,
    buffers: [Buffer; 2],
    /// The light whose hair shadow falls on the mesh (shadowed drawers only).
    shadow_light: Option<usize>,
}

impl MeshDrawer {
    /// Uploads `mesh` (flat-shaded: one normal per triangle) for the [`super::Offscreen`]
    /// formats (this submits and waits).
    pub fn new(ctx: &GpuContext, mesh: &TriMesh) -> Result<Self> {
        Self::build(ctx, mesh, None, false)
    }

    /// As [`MeshDrawer::new`], for a reversed depth buffer (near = 1, cleared
    /// to 0, a reverse-Z projection): its depth test passes the greater depth.
    pub fn reverse_z(ctx: &GpuContext, mesh: &TriMesh) -> Result<Self> {
        Self::build(ctx, mesh, None, true)
    }

    /// As [`MeshDrawer::new`], and the hair of `renderer` shadows the mesh from light
    /// `light` (which must cast a deep-opacity-map shadow) the way a host would do
    /// it: `glsl/include/shadow.glsl` with [`Renderer::shadow_uniforms`] and
    /// [`Renderer::shadow_atlas`]. Make it after the renderer's
    /// [`Renderer::set_shadows`]: a later change of the atlas size replaces the
    /// images this drawer reads.
    pub fn with_hair_shadows(ctx: &GpuContext, mesh: &TriMesh, renderer: &Renderer, light: usize) -> Result<Self> {
        Self::build(ctx, mesh, Some((renderer, light)), false)
    }

    /// Replaces the mesh's positions by `mesh`'s, which has the same triangles
    /// (a skinned character's next pose; flat normals recomputed). This submits
    /// and waits: call it between frames, after the last frame that drew the
    /// mesh has completed.
    pub fn update(&self, mesh: &TriMesh) -> Result<()> {
        let (positions, normals) = corners(mesh);
        if positions.len() as u32 != self.vertices {
            return Err(crate::error::Error::incompatible(
                "mesh update",
                format!("{} triangles, the drawer's mesh has {}", mesh.triangles.len(), self.vertices / 3),
            ));
        }
        self.device.upload_pod(&self.buffers[0], &positions)?;
        self.device.upload_pod(&self.buffers[1], &normals)
    }

    fn build(ctx: &GpuContext, mesh: &TriMesh, shadows: Option<(&Renderer, usize)>, reverse_z: bool) -> Result<Self> {
        let device = ctx.device.clone();
        let (positions, normals) = corners(mesh);
        let storage = |name: &str, data: &[Vec4]| -> Result<Buffer> {
            let b = Buffer::storage(&device, name, (data.len() * 16) as u64)?;
            device.upload_pod(&b, data)?;
            Ok(b)
        };
        let buffers = [storage("mesh positions", &positions)?, storage("mesh normals", &normals)?];
        let color_formats = [OFFSCREEN_COLOR];
        let pipeline = GraphicsPipeline::new(
            &device,
            &GraphicsDesc {
                name: "mesh",
                stages: &[
                    &RENDER_MESH_VERT,
                    if shadows.is_some() { &RENDER_MESH_SHADOWED_FRAG } else { &RENDER_MESH_FRAG },
                ],
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                patch_control_points: 0,
                color_formats: &color_formats,
                depth_format: OFFSCREEN_DEPTH,
                samples: vk::SampleCountFlags::TYPE_1,
                depth_test: true,
                depth_write: true,
                reverse_z,
                blend: Blend::None,
                rasterizer_discard: false,
            },
            1,
        )?;
        let set = match shadows {
            Some((renderer, _)) => {
                let (view, sampler) = renderer.shadow_atlas();
                pipeline.resource_set(
                    0,
                    &[(0, &buffers[0]), (1, &buffers[1]), (2, renderer.shadow_uniform_buffer())],
                    &[(3, view, sampler)],
                )?
            }
            None => pipeline.buffer_set(0, &[(0, &buffers[0]), (1, &buffers[1])])?,
        };
        Ok(MeshDrawer {
            device,
            pipeline,
            set,
            vertices: positions.len() as u32,
            buffers,
            shadow_light: shadows.map(|(_, light)| light),
        })
    }

    /// Records the mesh placed by `model` (rotation + translation) into `target`,
    /// seen through `view_proj`, lit from `light_direction` (direction of travel).
    ///
    /// # Safety
    /// As for [`super::Offscreen::record_clear`], after it; `target` is an [`super::Offscreen`]'s.
    /// A drawer made [`MeshDrawer::with_hair_shadows`] reads the renderer's shadow
    /// atlas and uniforms: they are still the ones it was made with (no
    /// `set_shadows` that changed the atlas size since), and the renderer's
    /// `record_shadows` for this frame was recorded before.
    pub unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        target: &RenderTarget,
        view_proj: Mat4,
        model: (Quat, Vec3),
        albedo: Vec3,
        light_direction: Vec3,
    ) {
        let d = &self.device;
        let m = Mat4::from_rotation_translation(model.0, model.1);
        let push = MeshPush {
            mvp: (view_proj * m).to_cols_array_2d(),
            rotation: model.0.to_array(),
            color: albedo.extend(1.0).to_array(),
            light: light_direction.extend(0.15).to_array(),
            translation: model.1.extend(self.shadow_light.map_or(-1.0, |l| l as f32)).to_array(),
        };
        let written = barrier::memory(&[AccessKind::ColorAttachmentWrite], barrier::COLOR_ATTACHMENT);
        let depth_written = barrier::memory(barrier::DEPTH_ATTACHMENT, barrier::DEPTH_ATTACHMENT);
        let color = [rendering::color(target.color, Load::Keep)];
        let depth = rendering::depth(target.depth, Load::Keep);
        let rendering = rendering::info(target.extent, &color, Some(&depth));
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_barrier(cmd, &[written, depth_written], &[], &[]);
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.cmd_set_full_viewport(cmd, target.extent);
            self.pipeline.bind(cmd, &[self.set]);
            self.pipeline.push(cmd, &push);
            d.raw.cmd_draw(cmd, self.vertices, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
        }
    }
}
