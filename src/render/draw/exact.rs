//! Pass 4 with [`Transparency::Exact`](crate::render::Transparency::Exact):
//! per-pixel fragment lists (`glsl/render/oit_build.frag`,
//! `oit_resolve.frag`). Every hair fragment is pushed onto its pixel's list
//! from a pool of [`OitParams::fragments_per_pixel`] nodes per pixel; the
//! composite sorts the [`OitParams::sorted_fragments`] nearest exactly and
//! blends the rest, and the pool's overflow (added to the weighted sums
//! instead, `fast.rs`), as an order-independent tail behind them.

use std::sync::Arc;

use ash::vk;

use super::transparent::ModeShaders;
use crate::codes::sentinel::OIT_END;
use crate::error::{Error, Result};
use crate::render::OitParams;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::shaders::{RENDER_OIT_BUILD_FRAG, RENDER_OIT_RESOLVE_FRAG};

/// The build's and the composite's fragment stages.
pub(super) const SHADERS: ModeShaders =
    ModeShaders { build: &RENDER_OIT_BUILD_FRAG, composite: &RENDER_OIT_RESOLVE_FRAG };

/// Bytes of one stored fragment (colour and alpha as half floats, depth, next).
const NODE_BYTES: u64 = 16;

/// Nodes in the pool at `extent`.
pub(super) fn pool_capacity(params: &OitParams, extent: vk::Extent2D) -> u64 {
    let pixels = f64::from(extent.width) * f64::from(extent.height);
    ((pixels * f64::from(params.fragments_per_pixel)).ceil() as u64).max(1)
}

/// The lists: per pixel the newest node of its list, and the node pool.
pub(super) struct Lists {
    heads: Buffer,
    nodes: Buffer,
    /// Nodes in the pool.
    pub capacity: u32,
}

impl Lists {
    /// The lists for `extent`; an error naming `fragments_per_pixel` when the
    /// pool exceeds what one storage buffer of the device can address.
    pub(super) fn new(device: &Arc<Device>, params: &OitParams, extent: vk::Extent2D) -> Result<Self> {
        let capacity = pool_capacity(params, extent);
        let node_bytes = capacity * NODE_BYTES;
        if capacity > u64::from(u32::MAX) || node_bytes > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::param(
                "oit.fragments_per_pixel",
                params.fragments_per_pixel,
                format!(
                    "a pool of at most {} bytes at {}×{} (this one needs {node_bytes})",
                    device.info.max_storage_buffer_range, extent.width, extent.height
                ),
            ));
        }
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        Ok(Lists {
            heads: Buffer::storage(device, "vkhair transparency heads", 4 * pixels)?,
            nodes: Buffer::storage(device, "vkhair transparency nodes", node_bytes)?,
            capacity: capacity as u32,
        })
    }

    /// Bytes of the heads and the pool at `extent`.
    pub(super) fn memory_bytes(params: &OitParams, extent: vk::Extent2D) -> u64 {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        4 * pixels + NODE_BYTES * pool_capacity(params, extent)
    }

    /// The heads and the pool by binding.
    pub(super) fn bindings(&self) -> [(u32, &Buffer); 2] {
        [(10, &self.heads), (11, &self.nodes)]
    }

    /// Records every list emptied (transfer writes).
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// earlier reads of the heads are ordered before by the caller's barrier.
    pub(super) unsafe fn record_clear(&self, device: &Device, cmd: vk::CommandBuffer) {
        // SAFETY: guaranteed by the caller.
        unsafe { device.raw.cmd_fill_buffer(cmd, self.heads.raw(), 0, vk::WHOLE_SIZE, OIT_END) };
    }
}
