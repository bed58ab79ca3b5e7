//! Headless helpers standing in for a host: an offscreen color + depth target
//! and a simple lit mesh drawer (the head). Tools, tests and examples use them;
//! a real host draws into its own images.

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Quat, Vec3, Vec4};

use super::RenderTarget;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;
use crate::vk::barrier::{self, Access};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc};
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::shaders::{RENDER_MESH_FRAG, RENDER_MESH_SHADOWED_FRAG, RENDER_MESH_VERT};

/// Color format of [`Offscreen`] (shading is linear; the target encodes sRGB).
pub const OFFSCREEN_COLOR: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth format of [`Offscreen`].
pub const OFFSCREEN_DEPTH: vk::Format = vk::Format::D32_SFLOAT;

/// An offscreen single-sample color + depth target.
pub struct Offscreen {
    device: Arc<Device>,
    color: Image,
    depth: Image,
}

impl Offscreen {
    /// A `width` × `height` target (1..=8192 each).
    pub fn new(ctx: &GpuContext, width: u32, height: u32) -> Result<Self> {
        if !(1..=8192).contains(&width) || !(1..=8192).contains(&height) {
            return Err(Error::param("extent", format!("{width}×{height} is outside 1..=8192")));
        }
        let device = ctx.device.clone();
        let extent = vk::Extent2D { width, height };
        let color = Image::new(
            &device,
            &ImageDesc {
                name: "offscreen color",
                extent,
                format: OFFSCREEN_COLOR,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::SAMPLED,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        let depth = Image::new(
            &device,
            &ImageDesc {
                name: "offscreen depth",
                extent,
                format: OFFSCREEN_DEPTH,
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::DEPTH,
            },
        )?;
        Ok(Offscreen { device, color, depth })
    }

    /// The target for [`super::Renderer::record_draw`] and [`MeshDrawer::record`].
    pub fn target(&self) -> RenderTarget {
        RenderTarget {
            color: self.color.view(),
            color_format: OFFSCREEN_COLOR,
            depth: self.depth.view(),
            depth_format: OFFSCREEN_DEPTH,
            extent: self.color.extent,
            samples: vk::SampleCountFlags::TYPE_1,
        }
    }

    /// Records a clear of color (to `rgb`, linear) and depth (to 1), leaving both in
    /// attachment layouts. Earlier contents are discarded.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of the context's device, outside a render
    /// pass; earlier work on this target was submitted before it on the same queue.
    pub unsafe fn record_clear(&self, cmd: vk::CommandBuffer, rgb: Vec3) {
        let d = &self.device;
        let to_color = barrier::image(
            &self.color,
            Access::ANY,
            Access::COLOR_ATTACHMENT_WRITE,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        );
        let to_depth = barrier::image(
            &self.depth,
            Access::ANY,
            Access::DEPTH_ATTACHMENT,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        );
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(self.color.view())
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [rgb.x, rgb.y, rgb.z, 1.0] } })];
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(self.depth.view())
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } });
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent: self.color.extent })
            .layer_count(1)
            .color_attachments(&color)
            .depth_attachment(&depth);
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_barrier(cmd, &[], &[], &[to_color, to_depth]);
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.raw.cmd_end_rendering(cmd);
        }
    }

    /// Reads the color image back as sRGB-encoded RGBA8 rows, top to bottom
    /// (this submits and waits).
    pub fn read_rgba8(&self) -> Result<Vec<u8>> {
        self.device.readback_image(&self.color, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, 4)
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.color.extent.width, self.color.extent.height)
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MeshPush {
    mvp: [[f32; 4]; 4],
    rotation: [f32; 4],
    color: [f32; 4],
    light: [f32; 4],
    translation: [f32; 4],
}

/// Draws a triangle mesh with one directional light (the host's head).
pub struct MeshDrawer {
    device: Arc<Device>,
    pipeline: GraphicsPipeline,
    set: vk::DescriptorSet,
    vertices: u32,
    _buffers: [Buffer; 2],
    /// The light whose hair shadow falls on the mesh (shadowed drawers only).
    shadow_light: Option<usize>,
}

impl MeshDrawer {
    /// Uploads `mesh` (flat-shaded: one normal per triangle) for the [`Offscreen`]
    /// formats (this submits and waits).
    pub fn new(ctx: &GpuContext, mesh: &TriMesh) -> Result<Self> {
        Self::build(ctx, mesh, None)
    }

    /// As [`MeshDrawer::new`], and the hair of `renderer` shadows the mesh from light
    /// `light` (which must cast a deep-opacity-map shadow) the way a host would do
    /// it: `glsl/include/shadow.glsl` with [`super::Renderer::shadow_uniforms`] and
    /// [`super::Renderer::shadow_atlas`]. Make it after the renderer's
    /// [`super::Renderer::set_shadows`]: a later change of the atlas size replaces the
    /// images this drawer reads.
    pub fn with_hair_shadows(
        ctx: &GpuContext,
        mesh: &TriMesh,
        renderer: &super::Renderer,
        light: usize,
    ) -> Result<Self> {
        Self::build(ctx, mesh, Some((renderer, light)))
    }

    fn build(ctx: &GpuContext, mesh: &TriMesh, shadows: Option<(&super::Renderer, usize)>) -> Result<Self> {
        let device = ctx.device.clone();
        let mut positions = Vec::with_capacity(mesh.triangles.len() * 3);
        let mut normals = Vec::with_capacity(mesh.triangles.len() * 3);
        for i in 0..mesh.triangles.len() {
            let n = mesh.scaled_normal(i).normalize_or_zero().extend(0.0);
            for p in mesh.corners(i) {
                positions.push(p.extend(1.0));
                normals.push(n);
            }
        }
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
            _buffers: buffers,
            shadow_light: shadows.map(|(_, light)| light),
        })
    }

    /// Records the mesh placed by `model` (rotation + translation) into `target`,
    /// seen through `view_proj`, lit from `light_direction` (direction of travel).
    ///
    /// # Safety
    /// As for [`Offscreen::record_clear`], after it; `target` is an [`Offscreen`]'s.
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
        let written = barrier::memory(
            Access {
                stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
            },
            Access::COLOR_ATTACHMENT_WRITE,
        );
        let depth_written = barrier::memory(Access::DEPTH_ATTACHMENT, Access::DEPTH_ATTACHMENT);
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(target.color)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(target.depth)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE);
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: target.extent };
        let rendering = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&color)
            .depth_attachment(&depth);
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_barrier(cmd, &[written, depth_written], &[], &[]);
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.raw.cmd_set_viewport(
                cmd,
                0,
                &[vk::Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: target.extent.width as f32,
                    height: target.extent.height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }],
            );
            d.raw.cmd_set_scissor(cmd, 0, &[area]);
            self.pipeline.bind(cmd, &[self.set]);
            self.pipeline.push(cmd, &push);
            d.raw.cmd_draw(cmd, self.vertices, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
        }
    }
}
