//! Pass 4 with [`Transparency::Exact`](crate::render::Transparency::Exact) and
//! [`Raster::Tiles`](crate::render::Raster::Tiles): vkhair's tiled compute
//! rasteriser. The segments are binned into screen tiles of
//! [`TILE_SIZE`]² pixels and each tile is drawn by one workgroup whose
//! fragments stay in its shared memory: no per-pixel lists, no node pool, no
//! atomics on device memory per fragment.
//!
//! 1. **Count** (`tile_bin.comp`, the build's first dispatch): one invocation
//!    a segment finds the tiles its band reaches and counts itself in each.
//! 2. **Scan** (`tile_scan.comp`, one workgroup): the counts into each tile's
//!    run of one list, and the total.
//! 3. **Fill** (`tile_bin.comp`'s `VKHAIR_TILE_FILL` variant): each segment
//!    writes its index into the runs of the tiles it reaches.
//! 4. **Fine** (`tile_fine.comp`, in the composite's scope, where the list
//!    path resolves): one workgroup a tile, one invocation a pixel; the
//!    tile's segments walk their pixels within it (the same pixels and
//!    fragments as the per-segment rasteriser, `strand_segment.glsl`) into
//!    shared memory, and each invocation sorts its pixel's fragments into its
//!    K-buffer (the same K nearest and tail as the list path's resolve,
//!    `oit_kbuffer.glsl`), composites it and writes the nearest half-opaque
//!    depth.
//!
//! Memory at an extent: per pixel the target's depth copy, the resolved
//! colour and the opaque depth (16 bytes); per tile three words; the list, 4
//! bytes an entry, sized by [`OitParams::tile_entries_per_vertex`] (and at
//! least [`LEAST_ENTRIES_PER_TILE`] a tile). A frame
//! whose segments ask for more entries than the list holds draws the tiles'
//! entries that fit ([`OitStats::tile_entries`](super::OitStats) says how many
//! were asked for), and the list of the frame `frames_in_flight` after it
//! grows to hold them (up to one buffer's range).

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::codes::tile::{FRAGMENTS, SCAN_GROUP, SIZE as TILE_SIZE};
use crate::error::{Error, Result};
use crate::gpu_types::TileCounters;
use crate::render::graph::{FrameGraph, Use};
use crate::render::OitParams;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::{Device, DeviceInfo};
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::{RENDER_TILE_BIN_COMP, RENDER_TILE_BIN_COMP_TILE_FILL, RENDER_TILE_SCAN_COMP};

/// Bindings (`tile_lists.glsl`): the counters, the three per-tile words, the list.
const COUNTERS_BINDING: u32 = 29;
const PER_TILE_BINDINGS: [u32; 3] = [30, 31, 32];
const LIST_BINDING: u32 = 33;
/// Bytes of one list entry (a segment's index).
const ENTRY_BYTES: u64 = 4;
/// Frames whose asked-for entries are kept for the host, one slot each (the
/// most frames in flight, `RenderParams::frames_in_flight`).
const READBACK_SLOTS: u64 = 16;

/// Shared memory of the fine pass's workgroup: the fragments (16 bytes
/// each), a head a pixel and three words (`tile_fine.comp`).
pub(super) const FINE_SHARED_BYTES: u32 = 16 * FRAGMENTS + 4 * TILE_SIZE * TILE_SIZE + 12;

/// Whether a device with `info`'s limits runs the fine pass: an error naming
/// the limit and the way out where its workgroups cannot hold the fragments.
pub(super) fn check_device(info: &DeviceInfo) -> Result<()> {
    check_shared_memory(info.max_compute_shared_memory)
}

/// As [`check_device`], for a device whose workgroups hold `limit` bytes.
fn check_shared_memory(limit: u32) -> Result<()> {
    if limit < FINE_SHARED_BYTES {
        return Err(Error::incompatible(
            "device",
            format!(
                "the tiled rasteriser's workgroups need {FINE_SHARED_BYTES} bytes of shared memory, more than this \
                 device's {limit} (maxComputeSharedMemorySize): draw with Raster::Compute"
            ),
        ));
    }
    Ok(())
}

/// Tiles across and down a target of `extent`.
pub(super) fn grid(extent: vk::Extent2D) -> [u32; 2] {
    [extent.width.div_ceil(TILE_SIZE), extent.height.div_ceil(TILE_SIZE)]
}

/// Least entries of the list a tile of the target: few hairs drawn large (a
/// close-up of a small groom at 4K) reach many tiles a segment, and the
/// per-segment share alone would not hold their first frame.
pub(super) const LEAST_ENTRIES_PER_TILE: u64 = 256;

/// Entries of the list for a renderer drawing at most `vertices` hair
/// vertices with `params` at `extent`, at least `demand` (what an earlier
/// frame asked for), within one buffer on a device with `info`'s limits.
pub(super) fn capacity(
    info: &DeviceInfo,
    params: &OitParams,
    (vertices, extent): (u64, vk::Extent2D),
    demand: u64,
) -> u64 {
    let wanted = (vertices as f64 * f64::from(params.tile_entries_per_vertex)).ceil() as u64;
    let [x, y] = grid(extent);
    let least = LEAST_ENTRIES_PER_TILE * u64::from(x) * u64::from(y);
    let most = (u64::from(info.max_storage_buffer_range).min(info.max_memory_allocation_size) / ENTRY_BYTES)
        .min(u64::from(u32::MAX));
    wanted.max(least).max(demand).clamp(1, most)
}

/// The bins of one extent: the counters (host-visible), the per-tile words,
/// the list, and per frame slot a copy of what the frame asked for (so that a
/// later frame reads a completed frame's, never one the GPU may be writing).
pub(super) struct TileBins {
    counters: Buffer,
    readback: Buffer,
    /// The frames recorded with these bins, newest last, with the slot each
    /// copied its count into (at most READBACK_SLOTS of them).
    recorded: std::sync::Mutex<std::collections::VecDeque<(u64, u64)>>,
    per_tile: [Buffer; 3],
    list: Buffer,
    grid: [u32; 2],
    capacity: u64,
}

impl TileBins {
    /// The bins for a target of `extent` holding `capacity` entries.
    pub(super) fn new(device: &Arc<Device>, extent: vk::Extent2D, capacity: u64) -> Result<Self> {
        let grid = grid(extent);
        let tiles = u64::from(grid[0]) * u64::from(grid[1]);
        let host = |name, size, usage| {
            let mut buffer =
                Buffer::new(device, &BufferDesc { name, size, usage, location: MemoryLocation::GpuToCpu })?;
            // Zeroed: read before any frame wrote it, it asks for nothing.
            if let Some(bytes) = buffer.mapped_mut() {
                bytes.fill(0);
            }
            Ok::<_, Error>(buffer)
        };
        let counters = host(
            "vkhair tile counters",
            std::mem::size_of::<TileCounters>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
        )?;
        let readback = host("vkhair tile entries asked", 4 * READBACK_SLOTS, vk::BufferUsageFlags::TRANSFER_DST)?;
        let word = |name| Buffer::storage(device, name, 4 * tiles);
        Ok(TileBins {
            counters,
            readback,
            recorded: std::sync::Mutex::default(),
            per_tile: [word("vkhair tile counts")?, word("vkhair tile starts")?, word("vkhair tile cursors")?],
            list: Buffer::storage(device, "vkhair tile list", ENTRY_BYTES * capacity)?,
            grid,
            capacity,
        })
    }

    /// Bytes of the bins at `extent` holding `capacity` entries.
    pub(super) fn memory_bytes(extent: vk::Extent2D, capacity: u64) -> u64 {
        let [x, y] = grid(extent);
        std::mem::size_of::<TileCounters>() as u64
            + 4 * READBACK_SLOTS
            + 12 * u64::from(x) * u64::from(y)
            + ENTRY_BYTES * capacity
    }

    /// Entries the list holds.
    pub(super) fn capacity(&self) -> u64 {
        self.capacity
    }

    /// Tiles across and down.
    pub(super) fn grid(&self) -> [u32; 2] {
        self.grid
    }

    /// Entries asked for by the newest frame recorded with these bins that
    /// is `done` or older (so completed when `done` is), from its own copy;
    /// `None` where no such frame is among the last few recorded.
    pub(super) fn entries_asked_by(&self, done: u64) -> Option<u64> {
        let slot = {
            let recorded = self.recorded.lock().ok()?;
            recorded.iter().rev().find(|(frame, _)| *frame <= done)?.1
        };
        let at = (4 * slot) as usize;
        let bytes = self.readback.mapped()?.get(at..at + 4)?;
        Some(u64::from(u32::from_le_bytes(bytes.try_into().ok()?)))
    }

    /// Entries the latest frame's segments asked for, read from host-visible
    /// memory: valid once that frame completed and before the next one is
    /// submitted (as [`super::OitStats`]).
    pub(super) fn entries_asked(&self) -> Option<u64> {
        let bytes = self.counters.mapped()?;
        let counters: TileCounters = bytemuck::pod_read_unaligned(bytes.get(..std::mem::size_of::<TileCounters>())?);
        Some(u64::from(counters.entries))
    }

    /// The bins' buffers by binding.
    pub(super) fn bindings(&self) -> [(u32, &Buffer); 5] {
        [
            (COUNTERS_BINDING, &self.counters),
            (PER_TILE_BINDINGS[0], &self.per_tile[0]),
            (PER_TILE_BINDINGS[1], &self.per_tile[1]),
            (PER_TILE_BINDINGS[2], &self.per_tile[2]),
            (LIST_BINDING, &self.list),
        ]
    }

    /// The buffers the build and the fine pass use: the counters, the
    /// per-tile words and the list.
    pub(super) fn buffers(&self) -> [&Buffer; 5] {
        [&self.counters, &self.per_tile[0], &self.per_tile[1], &self.per_tile[2], &self.list]
    }

    /// What [`TileBins::record_clear`] writes: the counters and the counts.
    pub(super) fn cleared(&self) -> [&Buffer; 2] {
        [&self.counters, &self.per_tile[0]]
    }

    /// Records the counts zeroed and the counters set for the frame (transfer
    /// writes of [`TileBins::cleared`], which the caller declares).
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// earlier uses of the bins are ordered before by the caller's barrier.
    pub(super) unsafe fn record_clear(&self, device: &Device, cmd: vk::CommandBuffer) {
        let counters = TileCounters {
            entries: 0,
            // The plan keeps it within a word.
            capacity: self.capacity.min(u64::from(u32::MAX)) as u32,
            tiles_x: self.grid[0],
            tiles_y: self.grid[1],
        };
        // SAFETY: guaranteed by the caller.
        unsafe {
            device.raw.cmd_fill_buffer(cmd, self.per_tile[0].raw(), 0, vk::WHOLE_SIZE, 0);
            device.raw.cmd_update_buffer(cmd, self.counters.raw(), 0, bytemuck::bytes_of(&counters));
        }
    }
}

impl TileBins {
    /// Records the copy of what frame `frame` asked for into its slot, after
    /// the scan wrote it, then makes it visible to the host, each declared to `graph`.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass,
    /// after this frame's scan; every earlier command on the bins since
    /// `graph` was made was declared to it.
    pub(super) unsafe fn record_readback(
        &self,
        device: &Device,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        frame: u64,
    ) {
        // A slot the frames in flight do not use: the one after the newest's,
        // the oldest of READBACK_SLOTS.
        let slot = match self.recorded.lock() {
            Ok(mut recorded) => {
                let slot = recorded.back().map_or(0, |(_, newest)| (newest + 1) % READBACK_SLOTS);
                recorded.push_back((frame, slot));
                if recorded.len() > READBACK_SLOTS as usize {
                    recorded.pop_front();
                }
                slot
            }
            Err(_) => return,
        };
        let copy = [
            Use::buffer(&self.counters, &[AccessKind::TransferRead]),
            Use::buffer(&self.readback, &[AccessKind::TransferWrite]),
        ];
        let region = vk::BufferCopy { src_offset: 0, dst_offset: 4 * slot, size: 4 };
        // SAFETY: guaranteed by the caller; both ranges lie in their buffers.
        unsafe {
            graph.record(device, cmd, &copy);
            device.raw.cmd_copy_buffer(cmd, self.counters.raw(), self.readback.raw(), &[region]);
            graph.record(device, cmd, &[Use::buffer(&self.readback, &[AccessKind::HostRead])]);
        }
    }
}

/// The build's three dispatches (count, scan, fill) and their descriptor sets.
pub(super) struct BinPipelines {
    count: (ComputePipeline, vk::DescriptorSet),
    scan: (ComputePipeline, vk::DescriptorSet),
    fill: (ComputePipeline, vk::DescriptorSet),
}

impl BinPipelines {
    /// The pipelines, their sets bound to `buffers` and `images` (the
    /// transparency pass's table, the bins' included).
    pub(super) fn new(
        device: &Arc<Device>,
        buffers: &[(u32, &Buffer)],
        images: &[(u32, vk::ImageView, vk::Sampler)],
    ) -> Result<Self> {
        let make = |shader| -> Result<(ComputePipeline, vk::DescriptorSet)> {
            let pipeline = ComputePipeline::new(device, shader, 1)?;
            let set = pipeline.declared_resource_set(0, buffers, images)?;
            Ok((pipeline, set))
        };
        Ok(BinPipelines {
            count: make(&RENDER_TILE_BIN_COMP)?,
            scan: make(&RENDER_TILE_SCAN_COMP)?,
            fill: make(&RENDER_TILE_BIN_COMP_TILE_FILL)?,
        })
    }

    /// Records the count, the scan and the fill of `segments` segments into
    /// `bins`, each declaring to `graph` that it reads and writes the bins,
    /// the count also the build's other uses `first` (the frame's inputs, the
    /// per-pixel buffers).
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// the bins are the ones the pipelines were made with; every earlier
    /// command on them since `graph` was made was declared to it.
    pub(super) unsafe fn record(
        &self,
        device: &Device,
        cmd: vk::CommandBuffer,
        (graph, bins, first): (&mut FrameGraph, &TileBins, &[Use]),
        segments: u32,
    ) {
        let uses = Use::buffers(bins.buffers(), &[AccessKind::ComputeRead, AccessKind::ComputeWrite]);
        let threads = self.count.0.grid_stride_threads(segments);
        // SAFETY: guaranteed by the caller.
        unsafe {
            let passes = [(&self.count, threads), (&self.scan, SCAN_GROUP), (&self.fill, threads)];
            for (i, (pass, groups)) in passes.into_iter().enumerate() {
                let declared = if i == 0 { [first, &uses].concat() } else { uses.clone() };
                graph.record(device, cmd, &declared);
                pass.0.bind(cmd, &[pass.1]);
                pass.0.dispatch_threads(cmd, [groups, 1, 1]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device at Vulkan's least shared memory (16 KiB) is refused naming the
    /// way out; the 48 KiB most desktop devices offer holds the fine pass.
    #[test]
    fn the_fine_pass_needs_its_shared_memory() {
        let err = check_shared_memory(16_384).expect_err("16 KiB").to_string();
        assert!(err.contains("17420 bytes") && err.contains("Raster::Compute"), "{err}");
        check_shared_memory(49_152).expect("48 KiB");
        check_shared_memory(FINE_SHARED_BYTES).expect("exactly enough");
    }
}
