//! Where the simulation runs relative to rendering: the [`FrameScheduler`].
//!
//! Three modes ([`ScheduleMode`]), chosen automatically from what the devices
//! offer and overridable through [`SchedulerOptions::mode`]:
//!
//! 1. **SINGLE QUEUE** — the simulation steps are recorded into the host's
//!    command buffer, in order with rendering (one queue, e.g. lavapipe).
//! 2. **ASYNC COMPUTE** — vkhair submits the steps to a second queue of the
//!    rendering device (another family, or a second queue of the graphics
//!    family); the host's frame waits on a timeline semaphore that
//!    [`FrameScheduler::record_frame`] returns. Buffers are shared between the
//!    families with `CONCURRENT` sharing rather than ownership transfers: the
//!    state crosses queues every frame, and concurrent sharing needs no
//!    release/acquire pair on both queues for each of the simulation's buffers.
//! 3. **SECOND DEVICE** — the simulation lives on a second logical device (another
//!    GPU, or a second device of the same GPU). A worker thread owns its
//!    submissions (start / end / acknowledge, see `worker.rs`); the positions and
//!    density reach the rendering device through memory shared with
//!    `VK_KHR_external_memory_fd` when both devices can share it
//!    ([`HandOff::ExternalMemory`], no host copy), else through host-visible
//!    staging buffers ([`HandOff::HostStaging`]).
//!
//! Each frame ends with one **hand-off**: the latest state is copied into the
//! scheduler's **mirror** on the rendering device, the buffers that
//! [`FrameScheduler::key_hairs`] shows the renderer. With [`Pipelining::Latency`]
//! frame N shows the state after frame N's steps; with [`Pipelining::Throughput`]
//! it shows the state after frame N−1's steps, so frame N's steps (on another queue
//! or device) run while frame N renders. All modes show the same state for the
//! same pipelining choice: SINGLE QUEUE copies before its steps for throughput.
//!
//! ## The host's side
//!
//! Call [`FrameScheduler::record_frame`] once per frame, with the heads of the
//! steps a [`crate::sim::FixedStepDriver`] planned, into the frame's command
//! buffer before the renderer's passes; submit that command buffer waiting on
//! [`FrameSync::waits`]. Frames in flight follow the usual contract: when recording
//! frame N, the host has waited for frame N − `frames_in_flight` to complete. vkhair
//! never submits to the host's graphics queue from these calls, never waits on it,
//! and its teardown waits only for its own submissions.

mod async_compute;
mod control;
mod mirror;
mod mode;
mod options;
mod update;
mod worker;

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::groom::Groom;
use crate::profiler::{GpuProfiler, PassScope, ProfileReport, Timing};
use crate::sim::{Collider, HairSim, KeyHairs, RigidTransform, SimParams, SimState};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::external::{self, ExternalBuffer};
use crate::vk::submit::CommandRing;
use async_compute::{AsyncSim, Pending};
use mirror::{slot_buffer, Layout, Meta, Mirror, Parts};
use worker::{SimSide, SimSlots, Worker};

use mode::{choose_mode, unavailable};
pub use options::{FrameSync, HandOff, Pipelining, ScheduleMode, SchedulerOptions, SemaphoreWait};

/// The rendering side of SECOND DEVICE hand-off slots.
enum RenderSlots {
    /// The rendering device's imports of the simulation device's exports.
    External(Vec<ExternalBuffer>),
    /// The simulation device's host-visible copies and the rendering device's
    /// upload buffers.
    Staging { readback: Arc<Vec<Buffer>>, upload: Vec<Buffer> },
}

enum Backend {
    Local { sim: Box<HairSim>, steps: u64 },
    Async { sim: Box<AsyncSim>, pending: Option<Pending> },
    Remote { worker: Worker, slots: RenderSlots, pending: Option<u64> },
    Stopped(String),
}

/// Runs a [`HairSim`] in one of the [`ScheduleMode`]s and hands its state to the
/// rendering device every frame (see the module docs).
///
/// Dropping it stops the worker thread (SECOND DEVICE) and waits for vkhair's own
/// submissions only; the host's frames that used its buffers or waited on its
/// semaphores must have completed, as for any resource of a frame in flight.
///
/// Each frame, [`FrameScheduler::record_frame`] runs the steps a
/// [`crate::sim::FixedStepDriver`] planned and hands the state to the renderer,
/// which reads [`FrameScheduler::key_hairs`]; the host's submission waits on the
/// returned [`FrameSync`]:
///
/// ```
/// use glam::Vec3;
/// use vkhair::headless::Submit;
/// use vkhair::schedule::{FrameScheduler, SchedulerOptions};
/// use vkhair::sim::{FixedStepDriver, RigidTransform, SimParams};
/// use vkhair::{ContextOptions, GpuContext, Groom, ValidationLog};
///
/// let log = ValidationLog::new();
/// {
///     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
///     let strand: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.02 * i as f32, 0.0, 0.0)).collect();
///     let groom = Groom::from_strands(&[strand])?;
///     let head = RigidTransform::default();
///     let options = SchedulerOptions::default();
///     let mut scheduler = FrameScheduler::new(&ctx, &groom, &SimParams::default(), &head, &[], &options)?;
///     println!("simulation: {:?}, because {}", scheduler.mode(), scheduler.reason());
///     let mut driver = FixedStepDriver::new(1.0 / 60.0, 4)?;
///     for _ in 0..3 {
///         let heads = vec![head; driver.advance(1.0 / 60.0).steps as usize];
///         // SAFETY: a recording command buffer of the rendering device; the
///         // previous frame completed (run_frame waits).
///         ctx.run_frame("frame", |cmd| unsafe { scheduler.record_frame(cmd, &heads, None) })?;
///     }
///     let shown = scheduler.read_shown_positions()?;
///     assert!(shown[5].y < 0.0, "the renderer sees the simulated tip");
/// }
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
pub struct FrameScheduler {
    backend: Backend,
    mirror: Mirror,
    mode: ScheduleMode,
    hand_off: Option<HandOff>,
    reason: String,
    pipelining: Pipelining,
    slots: usize,
    frames: u64,
    sim_device: Option<GpuContext>,
    /// Head and body colliders set, checked together against what a sub-step
    /// holds before anything is sent to a worker.
    colliders: (usize, usize),
    /// The scalp skinned from bone matrices, when bound (to check bones against).
    scalp: Option<crate::sim::scalp::Scalp>,
    /// The bones a skinned mesh collider follows, when one is set (to check bones against).
    mesh_joints: Option<Vec<u32>>,
}

impl std::fmt::Debug for FrameScheduler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameScheduler")
            .field("mode", &self.mode)
            .field("hand_off", &self.hand_off)
            .field("pipelining", &self.pipelining)
            .field("frames", &self.frames)
            .finish()
    }
}

impl FrameScheduler {
    /// Creates the simulation of `groom` (as [`HairSim::new`], with `colliders`) on
    /// the device the mode needs and the hand-off buffers on `render`. This submits
    /// uploads and waits for them. Forcing a mode the devices cannot run is an
    /// [`Error::ModeUnavailable`] naming what is missing.
    pub fn new(
        render: &GpuContext,
        groom: &Groom,
        params: &SimParams,
        head: &RigidTransform,
        colliders: &[Collider],
        options: &SchedulerOptions,
    ) -> Result<Self> {
        if !(1..=8).contains(&options.frames_in_flight) {
            return Err(Error::param("frames_in_flight", options.frames_in_flight, "1..=8"));
        }
        if options.timeout.is_zero() {
            return Err(Error::param("timeout", format!("{:?}", options.timeout), "longer than zero"));
        }
        let slots = options.frames_in_flight as usize + 1;
        let (mode, reason) = choose_mode(render, options)?;
        let device = render.device.clone();
        let sim_ctx = match mode {
            ScheduleMode::SecondDevice => {
                options.sim_device.clone().ok_or_else(|| unavailable(mode, "no sim_device given"))?
            }
            _ => render.clone(),
        };
        let mut sim = HairSim::new(&sim_ctx, groom, params, head)?;
        sim.set_colliders(colliders)?;
        let initial = sim.read_state()?;
        let layout = Layout::of(&sim);
        let mirror = Mirror::new(&device, &initial, Meta::of(&sim, 0), layout)?;
        let mut hand_off = None;
        let backend = match mode {
            ScheduleMode::SingleQueue => Backend::Local { sim: Box::new(sim), steps: 0 },
            ScheduleMode::AsyncCompute => {
                let queue = match device.compute {
                    Some(q) => q,
                    None => device.graphics,
                };
                let sim = AsyncSim::new(sim, queue, slots, options.profile, options.timeout)?;
                Backend::Async { sim: Box::new(sim), pending: None }
            }
            ScheduleMode::SecondDevice => {
                let sim_device = sim_ctx.device.clone();
                let can_share = external::compatible(&sim_device, &device);
                let chosen = match options.hand_off {
                    Some(HandOff::ExternalMemory) if !can_share => return Err(unavailable(
                        mode,
                        "external memory needs VK_KHR_external_memory_fd on both devices and equal device/driver UUIDs",
                    )),
                    Some(h) => h,
                    None if can_share => HandOff::ExternalMemory,
                    None => HandOff::HostStaging,
                };
                hand_off = Some(chosen);
                let (sim_slots, render_slots) = make_slots(&sim_device, &device, chosen, layout, slots)?;
                let profiler = match options.profile && sim_device.info.timestamp_valid_bits > 0 {
                    true => Some(GpuProfiler::from_device(&sim_device, 1, 1024)?),
                    false => None,
                };
                let ring = CommandRing::new(&sim_device, sim_device.graphics, 2, "vkhair simulation device")?;
                let side = SimSide { ring, sim, slots: sim_slots, profiler, device: sim_device, steps: 0 };
                let worker = Worker::spawn(side, slots, options.timeout)?;
                Backend::Remote { worker, slots: render_slots, pending: None }
            }
        };
        log::info!("vkhair: simulation scheduled as {} ({reason})", mode.name());
        Ok(FrameScheduler {
            backend,
            mirror,
            mode,
            hand_off,
            reason,
            pipelining: options.pipelining,
            slots,
            frames: 0,
            sim_device: (mode == ScheduleMode::SecondDevice).then_some(sim_ctx),
            colliders: (colliders.len(), 0),
            scalp: None,
            mesh_joints: None,
        })
    }

    /// The mode in use.
    pub fn mode(&self) -> ScheduleMode {
        self.mode
    }

    /// Why the mode was chosen (e.g. "no second queue: ...").
    pub fn reason(&self) -> &str {
        &self.reason
    }

    /// The hand-off of SECOND DEVICE mode.
    pub fn hand_off(&self) -> Option<HandOff> {
        self.hand_off
    }

    /// The pipelining choice.
    pub fn pipelining(&self) -> Pipelining {
        self.pipelining
    }

    /// The simulation device of SECOND DEVICE mode.
    pub fn sim_device(&self) -> Option<&GpuContext> {
        self.sim_device.as_ref()
    }

    /// The state the latest recorded frame shows, for [`crate::render::Renderer`]
    /// (create the renderer from it, and pass it to each frame's passes).
    pub fn key_hairs(&self) -> KeyHairs<'_> {
        self.mirror.key_hairs()
    }

    /// Simulation steps behind the state the latest recorded frame shows.
    pub fn shown_steps(&self) -> u64 {
        self.mirror.meta().steps
    }

    /// Records frame `frame`'s part into the host's `cmd`: runs one step per entry
    /// of `heads` (the head transform at the end of each step; none is fine) where
    /// the mode runs them, and the hand-off into [`FrameScheduler::key_hairs`] for
    /// the [`Pipelining`] choice. With a profiler, SINGLE QUEUE steps and the
    /// hand-off get timestamp scopes in it.
    ///
    /// # Safety
    /// `cmd` is a command buffer of the rendering context's device in the recording
    /// state, outside a render pass, for the graphics queue family; it is submitted
    /// with the returned [`FrameSync`]'s waits, after the calls of earlier frames'
    /// command buffers. When recording, the host has waited for the frame recorded
    /// `frames_in_flight` calls ago. The profiler, if any, had `begin_frame` called
    /// for this frame.
    pub unsafe fn record_frame(
        &mut self,
        cmd: vk::CommandBuffer,
        heads: &[RigidTransform],
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<FrameSync> {
        heads.iter().try_for_each(RigidTransform::validate)?;
        let latency = self.pipelining == Pipelining::Latency;
        let mut sync = FrameSync::default();
        let label = "vkhair hand-off";
        let device = self.mirror.device().clone();
        match &mut self.backend {
            Backend::Stopped(why) => return Err(Error::SimulationStopped(why.clone())),
            Backend::Local { sim, steps } => {
                // SAFETY: guaranteed by the caller; the simulation lives on this device.
                unsafe {
                    if !latency {
                        let meta = Meta::of(sim, *steps);
                        scoped(&device, Timing::of(profiler.as_deref()), cmd, label, |_| {
                            self.mirror.record_update(cmd, Parts::of_sim(sim), meta)
                        });
                    }
                    for head in heads {
                        sim.record_step(cmd, head, profiler.as_deref_mut())?;
                        *steps += 1;
                    }
                    if latency {
                        let meta = Meta::of(sim, *steps);
                        scoped(&device, Timing::of(profiler.as_deref()), cmd, label, |_| {
                            self.mirror.record_update(cmd, Parts::of_sim(sim), meta)
                        });
                    }
                }
            }
            Backend::Async { sim, pending } => {
                let take = match latency {
                    true => Some(sim.submit(heads)?),
                    false => pending.replace(sim.submit(heads)?),
                };
                if let Some(p) = take {
                    let (parts, wait) = sim.take(&p);
                    // SAFETY: guaranteed by the caller; the slot is ready once the
                    // returned wait is satisfied.
                    unsafe {
                        scoped(&device, Timing::of(profiler.as_deref()), cmd, label, |_| {
                            self.mirror.record_update(cmd, parts, p.meta)
                        })
                    };
                    sync.waits.push(SemaphoreWait { semaphore: wait.semaphore, value: wait.value, stage: wait.stage });
                }
            }
            Backend::Remote { worker, slots, pending } => {
                // Latency takes this frame's job, throughput the previous frame's.
                let take = match latency {
                    true => Some(worker.start(heads)?),
                    false => pending.take(),
                };
                if let Some(job) = take {
                    let meta = worker.wait_end(job, self.slots)?;
                    // SAFETY: guaranteed by the caller; the job is finished.
                    unsafe {
                        consume(&mut self.mirror, slots, cmd, job, self.slots, meta, Timing::of(profiler.as_deref()))?
                    };
                    worker.ack(job);
                }
                if !latency {
                    *pending = Some(worker.start(heads)?);
                }
            }
        }
        self.frames += 1;
        Ok(sync)
    }

    /// The latest simulation state (waits for vkhair's own simulation work; this
    /// submits readbacks on the simulation device and waits for them).
    pub fn read_state(&self) -> Result<SimState> {
        match &self.backend {
            Backend::Local { sim, .. } => sim.read_state(),
            Backend::Async { sim, .. } => {
                sim.wait_idle()?;
                sim.sim.read_state()
            }
            Backend::Remote { worker, .. } => worker.read_state(),
            Backend::Stopped(why) => Err(Error::SimulationStopped(why.clone())),
        }
    }

    /// The positions the latest recorded frame shows (this submits a readback on the
    /// rendering device and waits for it; the host's frames must be complete).
    pub fn read_shown_positions(&self) -> Result<Vec<glam::Vec4>> {
        self.mirror.read_positions()
    }

    /// The timestamp profile of vkhair's latest simulation submission whose results
    /// are available (ASYNC COMPUTE and SECOND DEVICE with
    /// [`SchedulerOptions::profile`]; SINGLE QUEUE steps are profiled in the host's
    /// profiler). Place it next to the render profile with
    /// [`ProfileReport::overlap_ns`].
    pub fn sim_profile(&self) -> Option<ProfileReport> {
        match &self.backend {
            Backend::Async { sim, .. } => sim.report(),
            Backend::Remote { worker, .. } => worker.report(),
            _ => None,
        }
    }

    #[cfg(test)]
    fn inject_worker_panic(&self) -> Result<()> {
        match &self.backend {
            Backend::Remote { worker, .. } => worker.inject_panic(),
            _ => Ok(()),
        }
    }

    #[cfg(test)]
    fn inject_worker_stall(&self, how_long: std::time::Duration) -> Result<()> {
        match &self.backend {
            Backend::Remote { worker, .. } => worker.inject_stall(how_long),
            _ => Ok(()),
        }
    }

    #[cfg(test)]
    fn inject_sim_device_loss(&self) -> Result<()> {
        match &self.backend {
            Backend::Remote { worker, .. } => worker.inject_device_loss(),
            _ => Ok(()),
        }
    }
}

/// Records `f` inside the hand-off's scope (a timestamp scope with a profiler,
/// else a debug label).
///
/// # Safety
/// `cmd` is a recording command buffer of `device`; the profiler contract is the
/// caller's.
unsafe fn scoped(
    device: &Device,
    timing: Timing<'_>,
    cmd: vk::CommandBuffer,
    name: &str,
    f: impl FnOnce(vk::CommandBuffer),
) {
    // SAFETY: guaranteed by the caller.
    unsafe { PassScope::record(device, cmd, timing, name, LabelColor::Transfer, || f(cmd)) }
}

/// Takes a finished SECOND DEVICE job's slot into the mirror.
///
/// # Safety
/// `cmd` is recording on the mirror's device; the job is finished and not yet
/// acknowledged.
unsafe fn consume(
    mirror: &mut Mirror,
    slots: &mut RenderSlots,
    cmd: vk::CommandBuffer,
    job: u64,
    count: usize,
    meta: Meta,
    timing: Timing<'_>,
) -> Result<()> {
    let slot = job as usize % count;
    let layout = mirror.layout();
    if let RenderSlots::Staging { readback, upload } = slots {
        let bytes = layout.total() as usize;
        match (readback[slot].mapped(), upload[slot].mapped_mut()) {
            (Some(src), Some(dst)) => dst[..bytes].copy_from_slice(&src[..bytes]),
            _ => return Err(Error::HandOff("staging memory could not be mapped".into())),
        }
    }
    // SAFETY: guaranteed by the caller.
    unsafe {
        let device = mirror.device().clone();
        scoped(&device, timing, cmd, "vkhair hand-off", |cmd| match slots {
            RenderSlots::External(buffers) => {
                let b = buffers[slot].raw();
                let family = mirror.device().graphics.family;
                let read = &[AccessKind::TransferRead];
                let d = mirror.device().clone();
                d.cmd_barrier(
                    cmd,
                    &[],
                    &[barrier::ownership(b, barrier::NOTHING, read, vk::QUEUE_FAMILY_EXTERNAL, family)],
                    &[],
                );
                mirror.record_update(cmd, Parts::packed(b, layout), meta);
                d.cmd_barrier(
                    cmd,
                    &[],
                    &[barrier::ownership(b, read, barrier::NOTHING, family, vk::QUEUE_FAMILY_EXTERNAL)],
                    &[],
                );
            }
            RenderSlots::Staging { upload, .. } => {
                mirror.record_update(cmd, Parts::packed(upload[slot].raw(), layout), meta)
            }
        });
    }
    Ok(())
}

/// The hand-off slots of SECOND DEVICE mode on both devices.
fn make_slots(
    sim: &Arc<crate::vk::device::Device>,
    render: &Arc<crate::vk::device::Device>,
    hand_off: HandOff,
    layout: Layout,
    count: usize,
) -> Result<(SimSlots, RenderSlots)> {
    match hand_off {
        HandOff::ExternalMemory => {
            let mut exported = Vec::new();
            let mut imported = Vec::new();
            for i in 0..count {
                let e = ExternalBuffer::export(sim, &format!("vkhair shared slot {i}"), layout.total())?;
                let fd = e.export_fd()?;
                imported.push(ExternalBuffer::import(render, &format!("vkhair shared slot {i} (imported)"), &e, fd)?);
                exported.push(e);
            }
            Ok((SimSlots::External(exported), RenderSlots::External(imported)))
        }
        HandOff::HostStaging => {
            let readback = (0..count)
                .map(|i| slot_buffer(sim, &format!("vkhair staging slot {i}"), layout, MemoryLocation::GpuToCpu))
                .collect::<Result<Vec<_>>>()?;
            let upload = (0..count)
                .map(|i| slot_buffer(render, &format!("vkhair upload slot {i}"), layout, MemoryLocation::CpuToGpu))
                .collect::<Result<Vec<_>>>()?;
            let readback = Arc::new(readback);
            Ok((SimSlots::Staging(readback.clone()), RenderSlots::Staging { readback, upload }))
        }
    }
}

#[cfg(test)]
mod tests;
