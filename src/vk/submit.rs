//! Submissions the crate makes on its own behalf (the simulation on an async
//! compute queue or a second device): a timeline semaphore and a ring of
//! command buffers, each reused only after the timeline shows its previous
//! submission complete.

use std::sync::Arc;
use std::time::{Duration, Instant};

use ash::vk;

use super::barrier::{self, AccessKind};
use super::device::{Device, Queue};
use crate::error::{Error, Result};

/// A timeline semaphore of one device.
pub(crate) struct Timeline {
    device: Arc<Device>,
    raw: vk::Semaphore,
}

impl Timeline {
    pub(crate) fn new(device: &Arc<Device>, name: &str) -> Result<Self> {
        let mut kind = vk::SemaphoreTypeCreateInfo::default().semaphore_type(vk::SemaphoreType::TIMELINE);
        let info = vk::SemaphoreCreateInfo::default().push_next(&mut kind);
        // SAFETY: valid create info; destroyed in Drop.
        let raw = unsafe { device.raw.create_semaphore(&info, None) }.map_err(Error::vk("vkCreateSemaphore"))?;
        device.set_name(raw, name);
        Ok(Timeline { device: device.clone(), raw })
    }

    pub(crate) fn raw(&self) -> vk::Semaphore {
        self.raw
    }

    /// Blocks (without spinning) until the timeline reaches `value` or `timeout`
    /// passes; returns whether it was reached.
    pub(crate) fn wait(&self, value: u64, timeout: Duration) -> Result<bool> {
        let semaphores = [self.raw];
        let values = [value];
        let info = vk::SemaphoreWaitInfo::default().semaphores(&semaphores).values(&values);
        // SAFETY: the semaphore belongs to this device.
        match unsafe { self.device.raw.wait_semaphores(&info, timeout.as_nanos().min(u128::from(u64::MAX)) as u64) } {
            Ok(()) => Ok(true),
            Err(vk::Result::TIMEOUT) => Ok(false),
            Err(e) => Err(Error::Vulkan { call: "vkWaitSemaphores", result: e }),
        }
    }

    /// Waits for `value` in slices of `slice`, giving up with an error when
    /// `stop()` says so or `deadline` passes.
    pub(crate) fn wait_until(
        &self,
        value: u64,
        deadline: Instant,
        slice: Duration,
        stop: impl Fn() -> bool,
    ) -> Result<()> {
        loop {
            if self.wait(value, slice)? {
                return Ok(());
            }
            if stop() || Instant::now() >= deadline {
                return Err(Error::HandOff(format!("GPU work did not reach timeline value {value} in time")));
            }
        }
    }
}

impl Drop for Timeline {
    fn drop(&mut self) {
        // SAFETY: the owner waited for every submission that uses the semaphore.
        unsafe { self.device.raw.destroy_semaphore(self.raw, None) };
    }
}

/// A semaphore wait of a submission.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wait {
    pub semaphore: vk::Semaphore,
    pub value: u64,
    pub stage: vk::PipelineStageFlags2,
}

/// A ring of command buffers for one queue, ordered by a timeline.
pub(crate) struct CommandRing {
    device: Arc<Device>,
    queue: Queue,
    pool: vk::CommandPool,
    buffers: Vec<vk::CommandBuffer>,
    /// The timeline each submission signals (value = submission count).
    pub timeline: Timeline,
    submitted: u64,
}

impl CommandRing {
    pub(crate) fn new(device: &Arc<Device>, queue: Queue, count: u32, name: &str) -> Result<Self> {
        let timeline = Timeline::new(device, &format!("{name} timeline"))?;
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue.family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid create info; destroyed in Drop.
        let pool = unsafe { device.raw.create_command_pool(&info, None) }.map_err(Error::vk("vkCreateCommandPool"))?;
        device.set_name(pool, &format!("{name} pool"));
        let mut ring = CommandRing { device: device.clone(), queue, pool, buffers: Vec::new(), timeline, submitted: 0 };
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(count);
        // SAFETY: the pool belongs to this device.
        ring.buffers =
            unsafe { device.raw.allocate_command_buffers(&alloc) }.map_err(Error::vk("vkAllocateCommandBuffers"))?;
        for (i, &cmd) in ring.buffers.iter().enumerate() {
            device.set_name(cmd, &format!("{name} {i}"));
        }
        Ok(ring)
    }

    /// Submissions made so far (the timeline value the latest one signals).
    pub(crate) fn submitted(&self) -> u64 {
        self.submitted
    }

    /// Records `record` into the next command buffer and submits it after `waits`;
    /// it signals the timeline with the new submission count, which is returned.
    /// Waits (up to `timeout`) for the buffer's previous submission first.
    pub(crate) fn submit(
        &mut self,
        waits: &[Wait],
        timeout: Duration,
        record: impl FnOnce(vk::CommandBuffer) -> Result<()>,
    ) -> Result<u64> {
        let n = self.buffers.len() as u64;
        let index = (self.submitted % n) as usize;
        let cmd = self.buffers[index];
        if self.submitted >= n {
            let previous = self.submitted + 1 - n;
            if !self.timeline.wait(previous, timeout)? {
                return Err(Error::HandOff(format!("submission {previous} did not complete in time")));
            }
        }
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        let d = &self.device;
        // SAFETY: the buffer's previous submission completed (checked above).
        unsafe {
            d.raw
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .map_err(Error::vk("vkResetCommandBuffer"))?;
            d.raw.begin_command_buffer(cmd, &begin).map_err(Error::vk("vkBeginCommandBuffer"))?;
            d.cmd_barrier(cmd, &[barrier::memory(&[AccessKind::AnyWrite], barrier::ANY)], &[], &[]);
        }
        let recorded = record(cmd);
        // SAFETY: as above; ended even when recording failed, so the pool stays usable.
        let ended = unsafe {
            d.cmd_barrier(cmd, &[barrier::memory(&[AccessKind::AnyWrite], barrier::ANY)], &[], &[]);
            d.raw.end_command_buffer(cmd)
        };
        recorded?;
        ended.map_err(Error::vk("vkEndCommandBuffer"))?;
        let value = self.submitted + 1;
        let wait_infos: Vec<_> = waits
            .iter()
            .map(|w| vk::SemaphoreSubmitInfo::default().semaphore(w.semaphore).value(w.value).stage_mask(w.stage))
            .collect();
        let signal = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.timeline.raw())
            .value(value)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default()
            .wait_semaphore_infos(&wait_infos)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signal);
        {
            let _lock = d.lock_submit();
            // SAFETY: queue access is serialised by the device's submit lock; the
            // command buffer is executable.
            unsafe { d.raw.queue_submit2(self.queue.raw, &[submit], vk::Fence::null()) }
                .map_err(Error::vk("vkQueueSubmit2"))?;
        }
        self.submitted = value;
        Ok(value)
    }

    /// Waits (up to `timeout`) until every submission completed.
    pub(crate) fn wait_all(&self, timeout: Duration) -> Result<bool> {
        self.timeline.wait(self.submitted, timeout)
    }
}

impl Drop for CommandRing {
    fn drop(&mut self) {
        // Only this ring's own work is waited for.
        if !matches!(self.wait_all(Duration::from_secs(60)), Ok(true)) {
            log::error!("vkhair: own submissions did not finish before teardown; waiting for the device");
            // SAFETY: the device belongs to this record; a last resort before destroying.
            let _ = unsafe { self.device.raw.device_wait_idle() };
        }
        // SAFETY: every submission from the pool completed (waited above).
        unsafe { self.device.raw.destroy_command_pool(self.pool, None) };
    }
}
