//! ASYNC COMPUTE mode: the simulation is submitted by vkhair to a second queue of
//! the rendering device and handed over through a ring of same-device slots,
//! ordered by a timeline semaphore the host's frame waits on.

use std::time::Duration;

use ash::vk;

use super::mirror::{record_copy, slot_buffer, Layout, Meta, Parts};
use crate::error::Result;
use crate::profiler::{GpuProfiler, ProfileReport};
use crate::sim::{HairSim, RigidTransform};
use crate::vk::buffer::Buffer;
use crate::vk::device::Queue;
use crate::vk::submit::{CommandRing, Wait};

/// A finished-or-pending hand-off: the timeline value that completes it, its slot
/// and what it holds.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pending {
    pub value: u64,
    pub slot: usize,
    pub meta: Meta,
}

pub(crate) struct AsyncSim {
    /// Dropped first: waits for vkhair's own submissions.
    ring: CommandRing,
    pub sim: HairSim,
    slots: Vec<Buffer>,
    profiler: Option<GpuProfiler>,
    report: Option<ProfileReport>,
    steps: u64,
    timeout: Duration,
}

impl AsyncSim {
    pub(crate) fn new(sim: HairSim, queue: Queue, slots: usize, profile: bool, timeout: Duration) -> Result<Self> {
        let device = sim.device().clone();
        let layout = Layout::of(&sim);
        let ring = CommandRing::new(&device, queue, slots as u32, "vkhair async simulation")?;
        let slots = (0..slots)
            .map(|i| {
                slot_buffer(
                    &device,
                    &format!("vkhair hand-off slot {i}"),
                    layout,
                    gpu_allocator::MemoryLocation::GpuOnly,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        // SAFETY: the physical device belongs to the instance.
        let families = unsafe { device.instance.get_physical_device_queue_family_properties(device.physical) };
        let timestamps = families.get(queue.family as usize).is_some_and(|f| f.timestamp_valid_bits > 0);
        let profiler = match profile && timestamps {
            true => Some(GpuProfiler::from_device(&device, slots.len() as u32, 1024)?),
            false => None,
        };
        Ok(AsyncSim { ring, sim, slots, profiler, report: None, steps: 0, timeout })
    }

    /// Submits the steps for `heads` and the copy into the next slot.
    pub(crate) fn submit(&mut self, heads: &[RigidTransform]) -> Result<Pending> {
        let job = self.ring.submitted();
        let slot = (job % self.slots.len() as u64) as usize;
        let AsyncSim { ring, sim, slots, profiler, report, .. } = self;
        let device = sim.device().clone();
        let value = ring.submit(&[], self.timeout, |cmd| {
            // SAFETY: `cmd` is recording for the simulation queue; the slot's previous
            // readers finished (the host's frames-in-flight contract, see the module docs).
            unsafe {
                if let Some(p) = profiler.as_mut() {
                    if let Some(r) = p.begin_frame(cmd, job) {
                        *report = Some(r);
                    }
                }
                for head in heads {
                    sim.record_step(cmd, head, profiler.as_mut())?;
                }
                let layout = Layout::of(sim);
                record_copy(&device, cmd, Parts::of_sim(sim), Parts::packed(slots[slot].raw(), layout), layout);
            }
            Ok(())
        })?;
        self.steps += heads.len() as u64;
        Ok(Pending { value, slot, meta: Meta::of(&self.sim, self.steps) })
    }

    /// The slot of a hand-off and the wait the host's frame needs for it.
    pub(crate) fn take(&self, pending: &Pending) -> (Parts, Wait) {
        let wait =
            Wait { semaphore: self.ring.timeline.raw(), value: pending.value, stage: vk::PipelineStageFlags2::COPY };
        (Parts::packed(self.slots[pending.slot].raw(), Layout::of(&self.sim)), wait)
    }

    /// Waits until every submission completed.
    pub(crate) fn wait_idle(&self) -> Result<()> {
        match self.ring.wait_all(self.timeout)? {
            true => Ok(()),
            false => Err(crate::error::Error::HandOff("the async simulation did not finish in time".into())),
        }
    }

    pub(crate) fn report(&self) -> Option<ProfileReport> {
        self.report.clone()
    }
}
