//! Pass 4 with [`Transparency::Exact`](crate::render::Transparency::Exact) and
//! [`Raster::Compute`](crate::render::Raster::Compute): the fragments made by
//! vkhair's compute rasteriser (`glsl/render/strand_raster.comp`, one
//! invocation a segment, analytic coverage) instead of the ribbons' hardware
//! draw, into the same per-pixel lists (`exact.rs`), composited by the same
//! resolve reading the overflow from a buffer.
//!
//! What the rasteriser adds to the transparency pass's resources, per extent:
//!
//! - **the target's depth**, copied each frame out of the host's depth image
//!   ([`crate::render::RenderTarget::depth_image`]) into a buffer the
//!   rasteriser tests each fragment against: a compute shader cannot read a
//!   depth attachment, and a copy asks of the host only `TRANSFER_SRC` usage
//!   (no sampled view, no layout of its own); none where the frame's depth
//!   was cleared by vkhair (supersampling's own images);
//! - **the overflow sums**, five words a pixel of fixed-point sums added with
//!   integer atomics (`glsl/include/oit_overflow.glsl`) in two planes, where
//!   the hardware build blends the overflow into two float images.

use std::sync::Arc;

use ash::vk;

use super::DrawTarget;
use crate::codes::scene_depth;
use crate::error::{Error, Result};
use crate::render::graph::{FrameGraph, Use};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::rendering::Load;

/// Binding of the target's depth copy (`SceneDepth` in `strand_raster.comp`).
const SCENE_DEPTH_BINDING: u32 = 25;
/// Bindings of the overflow sums' planes (`oit_overflow.glsl`).
const OVERFLOW_BINDINGS: [u32; 2] = [26, 27];
/// Bytes a pixel of the overflow planes: premultiplied rgb, then alpha and absorbance.
const OVERFLOW_PLANE_BYTES: [u64; 2] = [12, 8];

/// The rasteriser's buffers of one extent.
pub(super) struct RasterBuffers {
    /// The target's depth, a 32-bit word a pixel (16-bit depths two a word).
    scene_depth: Buffer,
    /// Fixed-point overflow sums, in two planes (none for the tiled
    /// rasteriser, which keeps every fragment: `tiles.rs`).
    overflow: Option<[Buffer; 2]>,
}

impl RasterBuffers {
    /// The buffers for a target of `extent` on `device`, the overflow sums
    /// `with_overflow`: an error where a plane would exceed one binding's range.
    pub(super) fn new(device: &Arc<Device>, extent: vk::Extent2D, with_overflow: bool) -> Result<Self> {
        let pixels = pixels(extent);
        let plane = |name, bytes: u64| Buffer::storage(device, name, bytes * pixels);
        if !with_overflow {
            return Ok(RasterBuffers { scene_depth: plane("vkhair compute raster scene depth", 4)?, overflow: None });
        }
        let largest = OVERFLOW_PLANE_BYTES[0] * pixels;
        if largest > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::incompatible(
                "render target",
                format!(
                    "the compute rasteriser at {}×{} needs {largest} bytes of per-pixel sums in one buffer, more \
                     than this device's storage buffer range ({} bytes): draw smaller, without supersampling, or \
                     with Raster::Hardware",
                    extent.width, extent.height, device.info.max_storage_buffer_range
                ),
            ));
        }
        Ok(RasterBuffers {
            scene_depth: plane("vkhair compute raster scene depth", 4)?,
            overflow: Some([
                plane("vkhair compute raster overflow colour", OVERFLOW_PLANE_BYTES[0])?,
                plane("vkhair compute raster overflow alpha", OVERFLOW_PLANE_BYTES[1])?,
            ]),
        })
    }

    /// Bytes of the buffers at `extent`, the overflow sums `with_overflow`.
    pub(super) fn memory_bytes(extent: vk::Extent2D, with_overflow: bool) -> u64 {
        let overflow = if with_overflow { OVERFLOW_PLANE_BYTES[0] + OVERFLOW_PLANE_BYTES[1] } else { 0 };
        (4 + overflow) * pixels(extent)
    }

    /// The buffers by binding.
    pub(super) fn bindings(&self) -> Vec<(u32, &Buffer)> {
        let mut out = vec![(SCENE_DEPTH_BINDING, &self.scene_depth)];
        if let Some([colour, alpha]) = &self.overflow {
            out.extend([(OVERFLOW_BINDINGS[0], colour), (OVERFLOW_BINDINGS[1], alpha)]);
        }
        out
    }
}

fn pixels(extent: vk::Extent2D) -> u64 {
    u64::from(extent.width) * u64::from(extent.height)
}

/// Where the rasteriser's depth test reads the target's depth.
#[derive(Debug, Clone, Copy)]
pub(super) enum DepthSource {
    /// Nothing to test against: no depth attachment, or one vkhair clears.
    None,
    /// The host's depth image (`image`, its depth aspect in `format`), copied
    /// each frame; `code` is its encoding (`codes::scene_depth`).
    Copy { image: vk::Image, code: u32 },
}

impl DepthSource {
    /// The source for `target`: the error names what the host must give.
    pub(super) fn of(target: &DrawTarget) -> Result<Self> {
        let Some((_, Load::Keep)) = target.depth else {
            return Ok(DepthSource::None);
        };
        let Some(image) = target.depth_image else {
            return Err(Error::incompatible(
                "render target",
                "the compute rasteriser tests hair against the target's depth and needs its image: set \
                 RenderTarget::depth_image (created with TRANSFER_SRC usage), or draw with Raster::Hardware",
            ));
        };
        // Depth-only formats: the copy moves the image's one aspect to
        // TRANSFER_SRC_OPTIMAL and back (a stencil aspect would need its own
        // layouts, separateDepthStencilLayouts).
        let code = match target.key.depth {
            vk::Format::D32_SFLOAT => scene_depth::FLOAT32,
            vk::Format::X8_D24_UNORM_PACK32 => scene_depth::UNORM24,
            vk::Format::D16_UNORM => scene_depth::UNORM16,
            other => {
                return Err(Error::incompatible(
                    "render target",
                    format!(
                        "the compute rasteriser reads depth-only targets (D32_SFLOAT, X8_D24_UNORM_PACK32, \
                         D16_UNORM), not {other:?}: draw with Raster::Hardware"
                    ),
                ))
            }
        };
        Ok(DepthSource::Copy { image, code })
    }

    /// The encoding the rasteriser reads (`OitCounters::scene_depth`).
    pub(super) fn code(self) -> u32 {
        match self {
            DepthSource::None => scene_depth::NONE,
            DepthSource::Copy { code, .. } => code,
        }
    }
}

impl RasterBuffers {
    /// The buffers: the depth copy and the overflow sums.
    pub(super) fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        std::iter::once(&self.scene_depth).chain(self.overflow.iter().flatten())
    }

    /// What [`RasterBuffers::record_inputs`] fills (transfer writes the
    /// caller declares): the overflow sums.
    pub(super) fn cleared(&self) -> impl Iterator<Item = &Buffer> {
        self.overflow.iter().flatten()
    }

    /// Records the overflow sums zeroed ([`RasterBuffers::cleared`]) and the
    /// copy of the target's depth (if any) into the buffer the rasteriser
    /// reads: the host's image from `DEPTH_ATTACHMENT_OPTIMAL` to
    /// `TRANSFER_SRC_OPTIMAL`, copied, and back for the composite's depth test
    /// and write, the copy declared to `graph`.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// `source`'s image is `extent` large (or larger), in
    /// `DEPTH_ATTACHMENT_OPTIMAL`; the fills of the sums were declared to
    /// `graph`, like every earlier command on the buffers since it was made.
    pub(super) unsafe fn record_inputs(
        &self,
        device: &Device,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        source: DepthSource,
        extent: vk::Extent2D,
    ) {
        // SAFETY: guaranteed by the caller.
        unsafe {
            for plane in self.overflow.iter().flatten() {
                device.raw.cmd_fill_buffer(cmd, plane.raw(), 0, vk::WHOLE_SIZE, 0);
            }
        }
        let DepthSource::Copy { image, .. } = source else {
            return;
        };
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::DEPTH,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        let attachment = vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL;
        let source = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        let copy = [
            Use::subresources(image, range, &[AccessKind::TransferRead], (source, attachment)),
            Use::buffer(&self.scene_depth, &[AccessKind::TransferWrite]),
        ];
        let back = [Use::subresources(image, range, barrier::DEPTH_ATTACHMENT, (attachment, attachment))];
        let region = vk::BufferImageCopy {
            buffer_offset: 0,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::DEPTH,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D { width: extent.width, height: extent.height, depth: 1 },
        };
        // SAFETY: guaranteed by the caller; the buffer holds a word a pixel.
        unsafe {
            graph.record(device, cmd, &copy);
            device.raw.cmd_copy_image_to_buffer(cmd, image, source, self.scene_depth.raw(), &[region]);
            graph.record(device, cmd, &back);
        }
    }
}
