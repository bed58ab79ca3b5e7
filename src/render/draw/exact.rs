//! Pass 4 with [`Transparency::Exact`](crate::render::Transparency::Exact):
//! per-pixel fragment lists (`glsl/render/oit_build.frag`,
//! `oit_resolve.frag`). Every hair fragment is pushed onto its pixel's list
//! from a pool of [`OitParams::fragments_per_pixel`] nodes per pixel; the
//! composite sorts the [`OitParams::sorted_fragments`] nearest exactly and
//! blends the rest, and the pool's overflow (added to the weighted sums
//! instead, `fast.rs`), as an order-independent tail behind them.

use std::sync::Arc;

use ash::vk;

use super::ModeShaders;
use crate::codes::sentinel::OIT_END;
use crate::error::Result;
use crate::render::OitParams;
use crate::render::Raster;
use crate::vk::buffer::Buffer;
use crate::vk::device::{Device, DeviceInfo};
use crate::vk::shaders::{
    ShaderSource, RENDER_OIT_BUILD_FRAG, RENDER_OIT_RESOLVED_FRAG, RENDER_OIT_RESOLVE_COMP,
    RENDER_OIT_RESOLVE_COMP_SORT_16, RENDER_OIT_RESOLVE_COMP_SORT_4, RENDER_OIT_RESOLVE_COMP_SORT_8,
    RENDER_OIT_RESOLVE_FRAG, RENDER_OIT_RESOLVE_FRAG_SORT_16, RENDER_OIT_RESOLVE_FRAG_SORT_4,
    RENDER_OIT_RESOLVE_FRAG_SORT_8, RENDER_TILE_FINE_COMP, RENDER_TILE_FINE_COMP_SORT_16, RENDER_TILE_FINE_COMP_SORT_4,
    RENDER_TILE_FINE_COMP_SORT_8,
};

/// The build's and the composite's stages for `sorted` (K) fragments sorted
/// per pixel: the resolve variant with the smallest arrays that hold K. After
/// the hardware build, the composite's fragment stage resolves each pixel and
/// reads the overflow from the build's images; after the compute rasteriser
/// (`raster.rs`, whose build is a compute pipeline of its own), a compute
/// dispatch resolves every pixel with its overflow sums
/// (`oit_resolve.comp`) and the composite's fragment stage only blends the
/// result (`oit_resolved.frag`).
pub(super) fn shaders(sorted: u32, raster: Raster) -> ModeShaders {
    let pick = |variants: [&'static ShaderSource; 4]| match sorted {
        0..=4 => variants[0],
        5..=8 => variants[1],
        9..=16 => variants[2],
        _ => variants[3],
    };
    match raster {
        // The fine pass rasterises and resolves each tile (tiles.rs); the
        // build's dispatches are the bins' own.
        Raster::Tiles => ModeShaders {
            build: &RENDER_OIT_BUILD_FRAG,
            composite: &RENDER_OIT_RESOLVED_FRAG,
            resolve: Some(pick([
                &RENDER_TILE_FINE_COMP_SORT_4,
                &RENDER_TILE_FINE_COMP_SORT_8,
                &RENDER_TILE_FINE_COMP_SORT_16,
                &RENDER_TILE_FINE_COMP,
            ])),
        },
        Raster::Compute => ModeShaders {
            build: &RENDER_OIT_BUILD_FRAG,
            composite: &RENDER_OIT_RESOLVED_FRAG,
            resolve: Some(pick([
                &RENDER_OIT_RESOLVE_COMP_SORT_4,
                &RENDER_OIT_RESOLVE_COMP_SORT_8,
                &RENDER_OIT_RESOLVE_COMP_SORT_16,
                &RENDER_OIT_RESOLVE_COMP,
            ])),
        },
        _ => ModeShaders {
            build: &RENDER_OIT_BUILD_FRAG,
            composite: pick([
                &RENDER_OIT_RESOLVE_FRAG_SORT_4,
                &RENDER_OIT_RESOLVE_FRAG_SORT_8,
                &RENDER_OIT_RESOLVE_FRAG_SORT_16,
                &RENDER_OIT_RESOLVE_FRAG,
            ]),
            resolve: None,
        },
    }
}

/// Bytes of one stored fragment (colour and alpha as half floats, depth, next).
const NODE_BYTES: u64 = 16;

/// The pool's storage-buffer bindings (`OitNodes0`..`OitNodes7` in
/// `glsl/include/oit.glsl`), in the order of the pool's buffers: a pool larger
/// than one buffer's range is split over up to this many buffers.
const POOL_BINDINGS: [u32; 8] = [11, 13, 14, 15, 16, 17, 18, 19];

/// The exact mode's fragment pool for one extent on one device: what
/// [`OitParams::fragments_per_pixel`] asks for and what the device holds.
///
/// The pool is split over up to 8 storage buffers, each at most the device's
/// `maxStorageBufferRange` and `maxMemoryAllocationSize`; where even 8 cannot
/// hold the request, the pool holds what they can and the fragments beyond it
/// join the order-independent tail (counted in [`OitStats::overflowed`](super::OitStats)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OitPool {
    /// Pixels the lists cover (of the drawn extent: twice each side with supersampling).
    pub pixels: u64,
    /// Nodes `fragments_per_pixel` asks for at the extent.
    pub requested: u64,
    /// Nodes the pool holds: `requested`, or fewer where the device's buffers
    /// cannot hold them.
    pub capacity: u64,
    /// Buffers the pool is split over (1..=8).
    pub buffers: u32,
    /// Nodes in each buffer (the last may hold fewer).
    pub nodes_per_buffer: u64,
}

impl OitPool {
    /// The pool for `params` at `extent` on a device with `info`'s limits.
    pub(crate) fn plan(info: &DeviceInfo, params: &OitParams, extent: vk::Extent2D) -> Self {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        let requested = ((pixels as f64 * f64::from(params.fragments_per_pixel)).ceil() as u64).max(1);
        let mut buffer_bytes = u64::from(info.max_storage_buffer_range).min(info.max_memory_allocation_size);
        if params.max_buffer_bytes != 0 {
            buffer_bytes = buffer_bytes.min(u64::from(params.max_buffer_bytes));
        }
        let most_per_buffer = (buffer_bytes / NODE_BYTES).clamp(1, u64::from(u32::MAX));
        // Node indices stay below the end-of-list marker.
        let most = (most_per_buffer * POOL_BINDINGS.len() as u64).min(u64::from(OIT_END) - 1);
        let capacity = requested.min(most);
        let buffers = capacity.div_ceil(most_per_buffer);
        OitPool { pixels, requested, capacity, buffers: buffers as u32, nodes_per_buffer: capacity.div_ceil(buffers) }
    }

    /// Bytes of the pool's buffers.
    pub fn bytes(&self) -> u64 {
        self.capacity * NODE_BYTES
    }

    /// Bytes the requested pool would take.
    pub fn requested_bytes(&self) -> u64 {
        self.requested * NODE_BYTES
    }

    /// Fragments per pixel the pool holds (the requested
    /// [`OitParams::fragments_per_pixel`] unless the device held fewer).
    pub fn fragments_per_pixel(&self) -> f64 {
        self.capacity as f64 / self.pixels.max(1) as f64
    }

    /// Whether the device held fewer nodes than requested.
    pub fn is_capped(&self) -> bool {
        self.capacity < self.requested
    }
}

/// The lists: per pixel the newest node of its list, and the node pool.
pub(super) struct Lists {
    heads: Buffer,
    nodes: Vec<Buffer>,
    pub pool: OitPool,
}

impl Lists {
    /// The lists of `pool`, a head per pixel it covers.
    pub(super) fn new(device: &Arc<Device>, pool: OitPool) -> Result<Self> {
        let mut nodes = Vec::with_capacity(pool.buffers as usize);
        for i in 0..u64::from(pool.buffers) {
            let count = pool.nodes_per_buffer.min(pool.capacity - i * pool.nodes_per_buffer);
            nodes.push(Buffer::storage(device, &format!("vkhair transparency nodes {i}"), count * NODE_BYTES)?);
        }
        Ok(Lists { heads: Buffer::storage(device, "vkhair transparency heads", 4 * pool.pixels)?, nodes, pool })
    }

    /// Bytes of the heads and the pool.
    pub(super) fn memory_bytes(pool: &OitPool) -> u64 {
        4 * pool.pixels + pool.bytes()
    }

    /// The heads and the pool's buffers by binding; bindings past the pool's
    /// buffers name its first one (never addressed).
    pub(super) fn bindings(&self) -> Vec<(u32, &Buffer)> {
        let mut out = vec![(10, &self.heads)];
        for (i, binding) in POOL_BINDINGS.iter().enumerate() {
            if let Some(buffer) = self.nodes.get(i).or(self.nodes.first()) {
                out.push((*binding, buffer));
            }
        }
        out
    }

    /// Every buffer of the lists: the heads and the pool's.
    pub(super) fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        std::iter::once(&self.heads).chain(&self.nodes)
    }

    /// What [`Lists::record_clear`] fills: the heads.
    pub(super) fn cleared(&self) -> &Buffer {
        &self.heads
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
