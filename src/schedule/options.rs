//! The scheduler's choices and what a frame hands the host.

use std::time::Duration;

use ash::vk;

use crate::context::GpuContext;

/// Where the simulation runs (with the `clap` feature, a command-line value:
/// `single`, `async`, `second-device`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ScheduleMode {
    /// Recorded into the host's command buffer, in order with rendering.
    #[cfg_attr(feature = "clap", value(name = "single"))]
    SingleQueue,
    /// Submitted by vkhair to a second queue of the rendering device.
    #[cfg_attr(feature = "clap", value(name = "async"))]
    AsyncCompute,
    /// On a second logical device, driven by a worker thread.
    SecondDevice,
}

impl ScheduleMode {
    /// The mode's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            ScheduleMode::SingleQueue => "single queue",
            ScheduleMode::AsyncCompute => "async compute",
            ScheduleMode::SecondDevice => "second device",
        }
    }
}

/// How SECOND DEVICE mode moves the state to the rendering device (with the
/// `clap` feature, a command-line value: `external`, `staging`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum HandOff {
    /// Memory exported by the simulation device and imported by the rendering
    /// device (`VK_KHR_external_memory_fd`): no host copy.
    #[cfg_attr(feature = "clap", value(name = "external"))]
    ExternalMemory,
    /// Host-visible buffers on both devices, copied by the render thread.
    #[cfg_attr(feature = "clap", value(name = "staging"))]
    HostStaging,
}

/// Which simulation step a frame shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pipelining {
    /// Frame N shows the state after its own steps (rendering waits for them).
    Latency,
    /// Frame N shows the state after frame N−1's steps while frame N's run.
    Throughput,
}

/// How a [`FrameScheduler`](super::FrameScheduler) is set up.
#[derive(Debug, Clone)]
pub struct SchedulerOptions {
    /// The mode to use; `None` chooses: SECOND DEVICE when `sim_device` is given,
    /// else ASYNC COMPUTE when the rendering context has a second queue, else SINGLE
    /// QUEUE. Default: `None`.
    pub mode: Option<ScheduleMode>,
    /// Which step a frame shows. Default: [`Pipelining::Throughput`].
    pub pipelining: Pipelining,
    /// Frames the host keeps in flight (1..=8): the scheduler keeps one more
    /// hand-off slot than this. Default: 2.
    pub frames_in_flight: u32,
    /// The simulation device for SECOND DEVICE mode. Default: `None`.
    pub sim_device: Option<GpuContext>,
    /// How SECOND DEVICE mode hands the state over; `None`: external memory when
    /// both devices can share it, else host staging. Default: `None`.
    pub hand_off: Option<HandOff>,
    /// Lets ASYNC COMPUTE submit to the rendering context's graphics queue when it
    /// has no second queue: nothing overlaps, but the semaphore hand-off runs on any
    /// device (tests). The host must not submit to that queue concurrently with
    /// [`FrameScheduler::record_frame`](super::FrameScheduler::record_frame). Default: `false`.
    pub async_on_graphics_queue: bool,
    /// Timestamp profiles of vkhair's own simulation submissions (ASYNC COMPUTE and
    /// SECOND DEVICE; see [`FrameScheduler::sim_profile`](super::FrameScheduler::sim_profile)). Default: `true`.
    pub profile: bool,
    /// Longest wait for the simulation side before an error. Default: 10 s.
    pub timeout: Duration,
}

impl Default for SchedulerOptions {
    fn default() -> Self {
        SchedulerOptions {
            mode: None,
            pipelining: Pipelining::Throughput,
            frames_in_flight: 2,
            sim_device: None,
            hand_off: None,
            async_on_graphics_queue: false,
            profile: true,
            timeout: Duration::from_secs(10),
        }
    }
}

/// A timeline-semaphore wait the host's submission of a frame must include.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SemaphoreWait {
    /// A timeline semaphore of the rendering device.
    pub semaphore: vk::Semaphore,
    /// The value to wait for.
    pub value: u64,
    /// The stages that must wait (the hand-off copy).
    pub stage: vk::PipelineStageFlags2,
}

/// What the host's submission of a frame must do for vkhair.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[must_use = "the host's submission must wait on these semaphores"]
pub struct FrameSync {
    /// Semaphores to wait on (ASYNC COMPUTE; empty otherwise).
    pub waits: Vec<SemaphoreWait>,
}

impl FrameSync {
    /// The waits as `VkSemaphoreSubmitInfo`s for `vkQueueSubmit2`.
    pub fn wait_infos(&self) -> Vec<vk::SemaphoreSubmitInfo<'static>> {
        self.waits
            .iter()
            .map(|w| vk::SemaphoreSubmitInfo::default().semaphore(w.semaphore).value(w.value).stage_mask(w.stage))
            .collect()
    }
}
