//! The rendering side's copy of the key-hair state, and the copies that pack a
//! simulation's latest state into a hand-off buffer and unpack it again.
//!
//! A hand-off buffer holds the positions (vec4 per particle), the positions
//! before the latest step (the same size) and, when the volume stage is on, the
//! density cells (vec4 per cell).

use std::sync::Arc;

use ash::vk;

use crate::error::Result;
use crate::sim::{HairSim, KeyHairs, RigidTransform, SimState, VolumeGrid};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::Device;

/// What travels with a hand-off besides the buffer contents.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Meta {
    /// Steps the simulation has run in all.
    pub steps: u64,
    pub head: RigidTransform,
    pub grid: Option<VolumeGrid>,
}

impl Meta {
    pub(crate) fn of(sim: &HairSim, steps: u64) -> Meta {
        Meta { steps, head: sim.head(), grid: sim.volume_grid() }
    }
}

/// Byte sizes of the parts of a hand-off (the positions before the latest step
/// are as large as the positions).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    pub positions: u64,
    pub density: u64,
}

impl Layout {
    pub(crate) fn of(sim: &HairSim) -> Layout {
        let (positions, density) = sim.latest_buffers();
        Layout { positions: positions.size(), density: density.map_or(0, Buffer::size) }
    }

    pub(crate) fn total(&self) -> u64 {
        2 * self.positions + self.density
    }
}

/// Stages and accesses that read the mirror after a hand-off (the renderer's
/// passes and the host's own copies).
const READERS: &[AccessKind] = &[
    AccessKind::VertexRead,
    AccessKind::TessellationRead,
    AccessKind::FragmentRead,
    AccessKind::ComputeRead,
    AccessKind::TransferRead,
];

/// Before a copy: every earlier write is visible to it and every earlier access of
/// its destination is done.
fn before_copy() -> vk::MemoryBarrier2<'static> {
    barrier::memory(&[AccessKind::AnyWrite], &[AccessKind::TransferRead, AccessKind::TransferWrite])
}

/// Where the parts of a state are: (buffer, byte offset) of the positions, of
/// the positions before the latest step and, with the volume stage, of the
/// density cells.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Parts {
    positions: (vk::Buffer, u64),
    before: (vk::Buffer, u64),
    density: Option<(vk::Buffer, u64)>,
}

impl Parts {
    /// A simulation's latest state.
    pub(crate) fn of_sim(sim: &HairSim) -> Parts {
        let (positions, density) = sim.latest_buffers();
        let before = (sim.previous_positions_buffer(), 0);
        Parts { positions: (positions.raw(), 0), before, density: density.map(|d| (d.raw(), 0)) }
    }

    /// A hand-off buffer laid out as `layout`.
    pub(crate) fn packed(buffer: vk::Buffer, layout: Layout) -> Parts {
        Parts {
            positions: (buffer, 0),
            before: (buffer, layout.positions),
            density: (layout.density > 0).then_some((buffer, 2 * layout.positions)),
        }
    }
}

/// Records the copy of both parts from `src` to `dst`, after a barrier from every
/// earlier write and access.
///
/// # Safety
/// `cmd` is recording outside a render pass; all buffers belong to its device, with
/// `TRANSFER_SRC`/`TRANSFER_DST` usage and room for `layout` at their offsets.
pub(crate) unsafe fn record_copy(device: &Device, cmd: vk::CommandBuffer, src: Parts, dst: Parts, layout: Layout) {
    let copy = |(from, src_offset): (vk::Buffer, u64), (to, dst_offset): (vk::Buffer, u64), size: u64| {
        let region = vk::BufferCopy { src_offset, dst_offset, size };
        // SAFETY: guaranteed by the caller.
        unsafe { device.raw.cmd_copy_buffer(cmd, from, to, &[region]) };
    };
    // SAFETY: guaranteed by the caller.
    unsafe { device.cmd_barrier(cmd, &[before_copy()], &[], &[]) };
    copy(src.positions, dst.positions, layout.positions);
    copy(src.before, dst.before, layout.positions);
    if let (Some(from), Some(to)) = (src.density, dst.density) {
        copy(from, to, layout.density);
    }
}

/// The rendering device's copy of the latest handed-off state: positions and the
/// positions before the latest step double buffered (a hand-off writes the half
/// the previous frame did not read) and the density cells.
pub(crate) struct Mirror {
    device: Arc<Device>,
    rest: SimState,
    halves: [Buffer; 2],
    before: [Buffer; 2],
    density: Option<Buffer>,
    current: usize,
    meta: Meta,
    layout: Layout,
}

impl Mirror {
    /// A mirror on `device` holding `initial` (uploaded now; this submits and waits).
    pub(crate) fn new(device: &Arc<Device>, initial: &SimState, meta: Meta, layout: Layout) -> Result<Self> {
        let halves = |what: &str| -> Result<[Buffer; 2]> {
            let half = |i: usize| Buffer::storage(device, &format!("vkhair hand-off {what} {i}"), layout.positions);
            Ok([half(0)?, half(1)?])
        };
        let (halves, before) = (halves("positions")?, halves("positions before")?);
        for h in halves.iter().chain(&before) {
            device.upload_pod(h, &initial.positions)?;
        }
        let density = match layout.density {
            0 => None,
            bytes => {
                let b = Buffer::storage(device, "vkhair hand-off density", bytes)?;
                device.upload(&b, 0, &vec![0u8; bytes as usize])?;
                Some(b)
            }
        };
        Ok(Mirror { device: device.clone(), rest: initial.clone(), halves, before, density, current: 0, meta, layout })
    }

    pub(crate) fn device(&self) -> &Arc<Device> {
        &self.device
    }

    pub(crate) fn layout(&self) -> Layout {
        self.layout
    }

    pub(crate) fn meta(&self) -> Meta {
        self.meta
    }

    /// The state as a renderer reads it.
    pub(crate) fn key_hairs(&self) -> KeyHairs<'_> {
        KeyHairs {
            device: &self.device,
            rest: &self.rest,
            halves: [&self.halves[0], &self.halves[1]],
            current: self.current,
            before: [&self.before[0], &self.before[1]],
            alpha: 1.0,
            head: self.meta.head,
            volume: self.meta.grid.zip(self.density.as_ref()),
            bounds: None,
        }
    }

    /// Records the copy of `src` (a simulation's latest state or a hand-off buffer,
    /// on the mirror's device) into the mirror, then a barrier to the readers.
    ///
    /// # Safety
    /// `cmd` is recording on the mirror's device outside a render pass; `src` lies in
    /// buffers of that device with `TRANSFER_SRC` usage, whose contents are ready
    /// when the command runs (earlier work in submission order, the caller's
    /// semaphores or acquire barriers).
    pub(crate) unsafe fn record_update(&mut self, cmd: vk::CommandBuffer, src: Parts, meta: Meta) {
        let next = 1 - self.current;
        let dst = Parts {
            positions: (self.halves[next].raw(), 0),
            before: (self.before[next].raw(), 0),
            density: self.density.as_ref().map(|d| (d.raw(), 0)),
        };
        let d = &self.device;
        // SAFETY: guaranteed by the caller.
        unsafe {
            record_copy(d, cmd, src, dst, self.layout);
            d.cmd_barrier(cmd, &[barrier::memory(&[AccessKind::TransferWrite], READERS)], &[], &[]);
        }
        self.current = next;
        self.meta = meta;
    }

    /// Reads the mirrored positions back (this submits and waits on the mirror's
    /// device).
    pub(crate) fn read_positions(&self) -> Result<Vec<glam::Vec4>> {
        self.device.readback_pod(&self.halves[self.current], self.rest.positions.len())
    }
}

/// A hand-off buffer on one device.
pub(crate) fn slot_buffer(
    device: &Arc<Device>,
    name: &str,
    layout: Layout,
    location: gpu_allocator::MemoryLocation,
) -> Result<Buffer> {
    Buffer::new(
        device,
        &BufferDesc {
            name,
            size: layout.total(),
            usage: vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
            location,
        },
    )
}
