//! Pass 4c — motion vectors ([`RenderPass::Motion`]): where a frame's target
//! has a velocity image ([`crate::render::RenderTarget::velocity`]), the
//! screen-space motion of each pixel's hair since the previous frame, for a
//! host's TAA or upscaler.
//!
//! 1. **Which hair** a pixel follows: the transparency pass leaves a depth per
//!    pixel — in the exact mode the depth of the fragment at which its sorted
//!    fragments, composited front to back, first reach
//!    [`MotionParams::threshold`] (`kb_crossing`, written by whichever
//!    composite resolved the pixel), in the fast mode the nearest half-opaque
//!    depth it keeps anyway.
//! 2. **The walk** (`motion_raster.comp`, one invocation a segment): every
//!    segment's pixels and fragments as the compute rasterisers make them
//!    (`strand_segment.glsl`); at each pixel the fragment nearest that depth
//!    gives the motion of its point — this frame's position against the same
//!    point of the same hair in the previous frame (the drawn positions kept
//!    by [`MotionHistory`]), each projected by its frame's camera without the
//!    jitter. The pick is a minimum over (distance, velocity bits): one 64-bit
//!    atomic where the device has them, else two walks of 32-bit ones, to the
//!    same result.
//! 3. **The write** (`motion_write.frag`): over the host's velocity image,
//!    each hair pixel gets its motion (supersampled: of its four drawn pixels,
//!    the nearest hair's); the host's values stay everywhere else.
//!
//! After the frame, the drawn positions are copied for the next one.

use std::sync::Arc;

use ash::vk;
use glam::Mat4;

use super::super::{Camera, MotionDirection, MotionParams, MotionUnits};
use crate::error::{Error, Result};
use crate::gpu_types::GpuMotion;
use crate::render::graph::{FrameGraph, Use};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::Device;
use crate::vk::pipeline::{Blend, ComputePipeline, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::{
    RENDER_MOTION_RASTER_COMP, RENDER_MOTION_RASTER_COMP_INT64, RENDER_MOTION_WRITE_FRAG, RENDER_RESOLVE_VERT,
};

/// Binding of the previous frame's drawn positions (`motion_raster.comp`).
pub(super) const PREVIOUS_BINDING: u32 = 34;
/// Binding of the depth each pixel's motion follows.
pub(super) const DEPTH_BINDING: u32 = 35;
/// Binding of the per-pixel picks (velocity, distance).
pub(super) const KEYS_BINDING: u32 = 36;
/// Binding of the frame's [`GpuMotion`] block.
pub(super) const BLOCK_BINDING: u32 = 37;
/// Bytes a drawn pixel of the picks.
pub(super) const KEY_BYTES: u64 = 8;
/// The velocity formats a target may give.
pub const VELOCITY_FORMATS: [vk::Format; 2] = [vk::Format::R16G16_SFLOAT, vk::Format::R32G32_SFLOAT];

/// What a frame with motion vectors adds to the draw.
pub(in crate::render) struct MotionFrame<'a> {
    /// The host's velocity image (`COLOR_ATTACHMENT_OPTIMAL`) and its format.
    pub velocity: vk::ImageView,
    pub format: vk::Format,
    /// The host's target's extent (the velocity image's).
    pub extent: vk::Extent2D,
    /// Which hair a pixel follows.
    pub threshold: f32,
    /// The previous frame's drawn positions.
    pub previous: &'a Buffer,
    /// The frame's block, written from `block` by the pass.
    pub uniforms: &'a Buffer,
    pub block: GpuMotion,
    /// Opaque frames: the host's depth attachment (view and format) the
    /// write is tested against, `None` where the target has none.
    pub host_depth: Option<(vk::ImageView, vk::Format)>,
    /// The depth runs reversed (near = 1).
    pub reverse_z: bool,
}

/// The camera and the hairs of the latest frame that wrote motion vectors.
#[derive(Debug, Clone, Copy)]
struct Before {
    /// World → clip without jitter.
    view_proj: Mat4,
    /// Hairs drawn and vertices a hair.
    hairs: u32,
    per_hair: u32,
    /// Which hairs those were (see [`HairLayout::order`]).
    order: u64,
}

/// The drawn hairs of a frame as the motion vectors see them.
#[derive(Debug, Clone, Copy)]
pub(super) struct HairLayout {
    /// Hairs drawn.
    pub hairs: u32,
    /// Vertices a hair.
    pub per_hair: u32,
    /// What decides which hair an index is: frames of equal `order` draw the
    /// same hair at the same index (followers: a stable order whatever the
    /// count, so 0; grown hairs: the hairs grown per key, which renumbers them).
    pub order: u64,
}

/// The drawn positions kept from one frame to the next, and the previous
/// frame's camera.
pub(in crate::render) struct MotionHistory {
    device: Arc<Device>,
    /// Drawn positions of the latest frame that wrote motion vectors, one
    /// vec4 a vertex the renderer can draw.
    previous: Buffer,
    /// The frame's [`GpuMotion`] block.
    uniforms: Buffer,
    before: Option<Before>,
}

impl MotionHistory {
    /// Room for `hair_vertices` drawn vertices.
    pub(super) fn new(device: &Arc<Device>, hair_vertices: u64) -> Result<Self> {
        let previous = Buffer::new(
            device,
            &BufferDesc {
                name: "vkhair motion previous positions",
                size: hair_vertices.max(1) * 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: gpu_allocator::MemoryLocation::GpuOnly,
            },
        )?;
        let uniforms = Buffer::new(
            device,
            &BufferDesc {
                name: "vkhair motion block",
                size: std::mem::size_of::<GpuMotion>() as u64,
                usage: vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: gpu_allocator::MemoryLocation::GpuOnly,
            },
        )?;
        Ok(MotionHistory { device: device.clone(), previous, uniforms, before: None })
    }

    /// Forgets the previous frame: the next frame's motion vectors are zero
    /// for every hair (a camera cut, a teleport).
    pub(super) fn reset(&mut self) {
        self.before = None;
    }

    /// The frame's motion for a target of `target` pixels drawn at `drawn`
    /// pixels, seen by `camera`, with `hairs` drawn as transparent strands
    /// (`opaque` `None`) or as opaque ribbons over the host's depth
    /// attachment (`Some` of it, or of `None` without one).
    pub(super) fn frame(
        &self,
        params: &MotionParams,
        (velocity, format): (vk::ImageView, vk::Format),
        (camera, target, drawn): (&Camera, vk::Extent2D, vk::Extent2D),
        (hairs, opaque): (HairLayout, Option<Option<(vk::ImageView, vk::Format)>>),
    ) -> Result<MotionFrame<'_>> {
        if !VELOCITY_FORMATS.contains(&format) {
            return Err(Error::incompatible(
                "render target",
                format!("a velocity image of {format:?}: motion vectors go into R16G16_SFLOAT or R32G32_SFLOAT"),
            ));
        }
        let now = camera.projection * camera.view;
        let (before, kept) = match self.before {
            Some(b) if b.per_hair == hairs.per_hair && b.order == hairs.order => {
                (b.view_proj, b.hairs.min(hairs.hairs))
            }
            Some(b) => (b.view_proj, 0),
            None => (now, 0),
        };
        let half = match params.units {
            MotionUnits::Pixels => [0.5 * target.width as f32, 0.5 * target.height as f32],
            MotionUnits::Ndc => [1.0, 1.0],
        };
        let sign = match params.direction {
            MotionDirection::CurrentMinusPrevious => 1.0,
            MotionDirection::PreviousMinusCurrent => -1.0,
        };
        let samples = (drawn.width / target.width.max(1)).max(1);
        Ok(MotionFrame {
            velocity,
            format,
            host_depth: opaque.flatten(),
            reverse_z: camera.depth_reversed(),
            extent: target,
            threshold: params.threshold,
            previous: &self.previous,
            uniforms: &self.uniforms,
            block: GpuMotion {
                now: now.to_cols_array_2d(),
                before: before.to_cols_array_2d(),
                scale: [
                    half[0] * sign,
                    half[1] * sign,
                    // World size of a target pixel at distance 1.
                    2.0 * (0.5 * camera.fov_y).tan() / target.height.max(1) as f32,
                    0.0,
                ],
                depth: {
                    let p = camera.projection;
                    [p.z_axis.z, p.w_axis.z, p.z_axis.w, p.w_axis.w]
                },
                counts: [kept, samples, u32::from(opaque.is_some()), 0],
            },
        })
    }

    /// Records the copy of the frame's drawn positions (`vertices` of
    /// `positions`) for the next frame's motion, and remembers its camera and
    /// hairs.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render
    /// pass, after the frame's motion walk in submission order.
    pub(super) unsafe fn record_keep(
        &mut self,
        cmd: vk::CommandBuffer,
        positions: &Buffer,
        camera: &Camera,
        hairs: HairLayout,
    ) {
        let bytes = (u64::from(hairs.hairs) * u64::from(hairs.per_hair) * 16).min(self.previous.size());
        // The walk read the previous positions this copy replaces, the
        // interpolation wrote the positions it reads: a graph of its own (the
        // draw's has settled) waits for any earlier use of either.
        let copy = [
            Use::buffer(positions, &[AccessKind::TransferRead]),
            Use::buffer(&self.previous, &[AccessKind::TransferWrite]),
        ];
        // SAFETY: guaranteed by the caller; both buffers hold `bytes`.
        unsafe {
            FrameGraph::new().record(&self.device, cmd, &copy);
            if bytes > 0 {
                let region = vk::BufferCopy { src_offset: 0, dst_offset: 0, size: bytes };
                self.device.raw.cmd_copy_buffer(cmd, positions.raw(), self.previous.raw(), &[region]);
            }
        }
        self.before = Some(Before {
            view_proj: camera.projection * camera.view,
            hairs: hairs.hairs,
            per_hair: hairs.per_hair,
            order: hairs.order,
        });
    }
}

/// The walk and the write of one target, bound to its buffers.
pub(super) struct MotionPipelines {
    walk: ComputePipeline,
    walk_set: vk::DescriptorSet,
    /// The walk is the one-pass 64-bit variant.
    int64: bool,
    write: GraphicsPipeline,
    write_set: vk::DescriptorSet,
}

impl MotionPipelines {
    /// The pipelines for a velocity image of `format`, bound to `buffers`
    /// (the draw's and the pass's, by binding) and the shading's `images`;
    /// the write tested against a depth attachment of `depth`'s format (and
    /// convention: reversed) where given.
    pub(super) fn new(
        device: &Arc<Device>,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
        format: vk::Format,
        depth: Option<(vk::Format, bool)>,
    ) -> Result<Self> {
        let int64 = device.int64_atomics.load(std::sync::atomic::Ordering::Relaxed);
        let shader = if int64 { &RENDER_MOTION_RASTER_COMP_INT64 } else { &RENDER_MOTION_RASTER_COMP };
        let walk = ComputePipeline::new(device, shader, 1)?;
        let walk_set = walk.declared_resource_set(0, buffers, images)?;
        let write = GraphicsPipeline::new(
            device,
            &GraphicsDesc {
                name: "vkhair motion vectors write",
                stages: &[&RENDER_RESOLVE_VERT, &RENDER_MOTION_WRITE_FRAG],
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                patch_control_points: 0,
                color_formats: &[format],
                depth_format: depth.map_or(vk::Format::UNDEFINED, |d| d.0),
                samples: vk::SampleCountFlags::TYPE_1,
                depth_test: depth.is_some(),
                depth_write: false,
                reverse_z: depth.is_some_and(|d| d.1),
                blend: Blend::None,
                rasterizer_discard: false,
            },
            1,
        )?;
        let write_set = write.declared_resource_set(0, buffers, &[])?;
        Ok(MotionPipelines { walk, walk_set, int64, write, write_set })
    }

    /// Records the frame's motion vectors: the block, the walk over `segments`
    /// segments and the write into the velocity image, each declared to
    /// `graph`: the walk reads `words.0` (the drawn positions, the pass's
    /// per-pixel words) and reads and writes `words.1` (the picks), the write
    /// reads both. Leaves the write's graphics pipeline bound and the viewport
    /// and scissor set to the velocity image.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render
    /// pass; the velocity image is in `COLOR_ATTACHMENT_OPTIMAL`; the picks
    /// were filled with [`MOTION_NONE`] and the depths to match written
    /// earlier, declared to `graph` like every command on the buffers since it was made.
    pub(super) unsafe fn record(
        &self,
        device: &Device,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        motion: &MotionFrame<'_>,
        (segments, words): (u32, (&[&Buffer], &[&Buffer])),
    ) {
        use AccessKind::*;
        // `vkCmdUpdateBuffer` runs in the clear stage: any transfer write.
        let update = [Use::buffer(motion.uniforms, &[AnyTransferWrite])];
        let walk = [
            vec![Use::buffer(motion.uniforms, &[ComputeUniformRead]), Use::buffer(motion.previous, &[ComputeRead])],
            Use::buffers(words.0.iter().copied(), &[ComputeRead]),
            Use::buffers(words.1.iter().copied(), &[ComputeRead, ComputeWrite]),
        ]
        .concat();
        // The host's velocity and depth images (its clear, its meshes: with
        // supersampling the draw has not used them) and the opaque draw's
        // depth writes, before the write loads and tests them.
        let write = [
            vec![Use::buffer(motion.uniforms, &[FragmentUniformRead]), Use::host_attachments(barrier::ATTACHMENTS)],
            Use::buffers(words.0.iter().copied(), &[FragmentRead]),
            Use::buffers(words.1.iter().copied(), &[FragmentRead]),
        ]
        .concat();
        let color = [rendering::color(motion.velocity, Load::Keep)];
        let depth = motion.host_depth.map(|(view, _)| rendering::depth(view, Load::Keep));
        let info = rendering::info(motion.extent, &color, depth.as_ref());
        let threads = self.walk.grid_stride_threads(segments);
        // SAFETY: guaranteed by the caller.
        unsafe {
            graph.record(device, cmd, &update);
            device.raw.cmd_update_buffer(cmd, motion.uniforms.raw(), 0, bytemuck::bytes_of(&motion.block));
            graph.record(device, cmd, &walk);
            self.walk.bind(cmd, &[self.walk_set]);
            if self.int64 {
                self.walk.dispatch_threads(cmd, [threads, 1, 1]);
            } else {
                for round in 0u32..2 {
                    if round == 1 {
                        graph.record(device, cmd, &walk);
                    }
                    self.walk.push(cmd, &round);
                    self.walk.dispatch_threads(cmd, [threads, 1, 1]);
                }
            }
            graph.record(device, cmd, &write);
            device.raw.cmd_begin_rendering(cmd, &info);
            device.cmd_set_full_viewport(cmd, motion.extent);
            self.write.bind(cmd, &[self.write_set]);
            device.raw.cmd_draw(cmd, 3, 1, 0, 0);
            device.raw.cmd_end_rendering(cmd);
        }
    }
}

/// A drawn pixel's picks before the walk: none (`MOTION_NONE` in `motion.glsl`).
pub(super) const MOTION_NONE: u32 = u32::MAX;

/// The per-pixel words of one drawn extent: the picks, and in the exact mode
/// the depths to match (the fast mode matches the nearest half-opaque depth
/// the transparency pass keeps anyway).
pub(super) struct MotionBuffers {
    keys: Buffer,
    depth: Option<Buffer>,
}

impl MotionBuffers {
    /// The words for `extent` drawn pixels, the depths `exact`.
    pub(super) fn new(device: &Arc<Device>, extent: vk::Extent2D, exact: bool) -> Result<Self> {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        Ok(MotionBuffers {
            keys: Self::keys_buffer(device, extent)?,
            depth: match exact {
                true => Some(Buffer::storage(device, "vkhair motion depths", 4 * pixels)?),
                false => None,
            },
        })
    }

    /// The picks of `extent` drawn pixels: an error where one binding's range cannot hold them.
    pub(super) fn keys_buffer(device: &Arc<Device>, extent: vk::Extent2D) -> Result<Buffer> {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        let keys = KEY_BYTES * pixels;
        if keys > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::incompatible(
                "render target",
                format!(
                    "motion vectors at {}×{} drawn pixels need {keys} bytes of per-pixel words, more than this \
                     device's storage buffer range ({} bytes): draw smaller or without supersampling",
                    extent.width, extent.height, device.info.max_storage_buffer_range
                ),
            ));
        }
        Buffer::storage(device, "vkhair motion picks", keys)
    }

    /// The buffers by binding: the depths to match are `fallback` (the fast
    /// mode's nearest half-opaque depths) where the mode keeps none of its own.
    pub(super) fn bindings<'a>(&'a self, fallback: &'a Buffer) -> [(u32, &'a Buffer); 2] {
        [(KEYS_BINDING, &self.keys), (DEPTH_BINDING, self.depth.as_ref().unwrap_or(fallback))]
    }

    /// The picks and the depths to match (what [`MotionBuffers::record_clear`] fills).
    pub(super) fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        std::iter::once(&self.keys).chain(&self.depth)
    }

    /// Records the fills that start a frame: no picks, no depth to match.
    /// Transfer writes: the caller's barriers order them.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// earlier uses of the buffers are ordered before by the caller's barrier.
    pub(super) unsafe fn record_clear(&self, device: &Device, cmd: vk::CommandBuffer) {
        // SAFETY: guaranteed by the caller.
        unsafe {
            device.raw.cmd_fill_buffer(cmd, self.keys.raw(), 0, vk::WHOLE_SIZE, MOTION_NONE);
            if let Some(depth) = &self.depth {
                device.raw.cmd_fill_buffer(cmd, depth.raw(), 0, vk::WHOLE_SIZE, crate::codes::sentinel::OIT_END);
            }
        }
    }
}

#[cfg(test)]
mod tests;
