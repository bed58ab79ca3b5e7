//! SECOND DEVICE mode: a worker thread owns the simulation device's submissions.
//!
//! The render thread and the worker coordinate as in the seed's two-GPU design,
//! with a mutex and a condition variable instead of events (no busy waiting):
//!
//! - **start**: the render thread queues a job (the heads of this frame's steps);
//! - **end**: the worker records the steps and the copy into hand-off slot
//!   `job % slots`, submits, waits for its own timeline, and publishes the job as
//!   finished with its [`Meta`];
//! - **acknowledge**: once the render thread has taken the slot's contents (copied
//!   the staging bytes, or recorded its copy of the shared memory), it acknowledges
//!   the job; the worker writes a slot again only after its previous job was
//!   acknowledged.
//!
//! Every wait on either side has a deadline, and the worker checks a stop flag
//! between slices of its GPU wait, so dropping either side ends in an error, not
//! a deadlock.

use std::collections::VecDeque;
use std::sync::{mpsc, Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use ash::vk;

use super::mirror::{record_copy, Layout, Meta, Parts};
use super::update::SimUpdate;
use crate::error::{Error, Result};
use crate::profiler::{GpuProfiler, ProfileReport};
use crate::sim::{HairSim, RigidTransform, SimState};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::external::ExternalBuffer;
use crate::vk::submit::CommandRing;

/// How often a blocked worker looks at the stop flag.
const SLICE: Duration = Duration::from_millis(20);

enum Request {
    Step {
        job: u64,
        heads: Vec<RigidTransform>,
    },
    Update(SimUpdate),
    Read(mpsc::Sender<Result<SimState>>),
    #[cfg(test)]
    Panic,
    /// Test only: the simulation device reports `VK_ERROR_DEVICE_LOST`.
    #[cfg(test)]
    DeviceLost,
    /// Test only: the worker is alive but stuck this long.
    #[cfg(test)]
    Stall(Duration),
}

#[derive(Default)]
struct State {
    requests: VecDeque<Request>,
    /// Jobs the worker finished (job ids are 0, 1, ...).
    finished: u64,
    /// Jobs the render thread acknowledged.
    acked: u64,
    /// Meta of the job last finished in each slot.
    metas: Vec<Option<Meta>>,
    report: Option<ProfileReport>,
    failure: Option<String>,
    stop: bool,
    running: bool,
}

struct Shared {
    state: Mutex<State>,
    changed: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Where the worker writes its hand-offs on the simulation device.
pub(crate) enum SimSlots {
    /// Exported memory the rendering device imports.
    External(Vec<ExternalBuffer>),
    /// Host-visible buffers the render thread copies from.
    Staging(Arc<Vec<Buffer>>),
}

/// Everything the worker thread owns.
pub(crate) struct SimSide {
    /// Dropped first: waits for the worker's own submissions.
    pub ring: CommandRing,
    pub sim: HairSim,
    pub slots: SimSlots,
    pub profiler: Option<GpuProfiler>,
    pub device: Arc<Device>,
    pub steps: u64,
}

/// The render thread's handle on the worker.
pub(crate) struct Worker {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    timeout: Duration,
    next_job: u64,
}

impl Worker {
    pub(crate) fn spawn(side: SimSide, slots: usize, timeout: Duration) -> Result<Self> {
        let shared = Arc::new(Shared {
            state: Mutex::new(State { metas: vec![None; slots], running: true, ..State::default() }),
            changed: Condvar::new(),
        });
        let theirs = shared.clone();
        let thread = std::thread::Builder::new()
            .name("vkhair simulation".into())
            .spawn(move || run(side, slots, timeout, &theirs))
            .map_err(|e| Error::SimulationStopped(format!("the worker thread could not start: {e}")))?;
        Ok(Worker { shared, thread: Some(thread), timeout, next_job: 0 })
    }

    /// Start: queues the steps of one job and returns its id.
    pub(crate) fn start(&mut self, heads: &[RigidTransform]) -> Result<u64> {
        let job = self.next_job;
        self.send(Request::Step { job, heads: heads.to_vec() })?;
        self.next_job += 1;
        Ok(job)
    }

    pub(crate) fn update(&self, update: SimUpdate) -> Result<()> {
        self.send(Request::Update(update))
    }

    fn send(&self, request: Request) -> Result<()> {
        let mut state = self.shared.lock();
        check_alive(&state)?;
        state.requests.push_back(request);
        self.shared.changed.notify_all();
        Ok(())
    }

    /// End: waits until `job` is finished and returns its meta.
    pub(crate) fn wait_end(&self, job: u64, slots: usize) -> Result<Meta> {
        let deadline = Instant::now() + self.timeout;
        let mut state = self.shared.lock();
        loop {
            if state.finished > job {
                return state.metas[job as usize % slots]
                    .ok_or_else(|| Error::HandOff(format!("job {job} finished without its meta")));
            }
            check_alive(&state)?;
            let now = Instant::now();
            if now >= deadline {
                return Err(Error::HandOff(format!("simulation job {job} did not finish within {:?}", self.timeout)));
            }
            state = self.shared.changed.wait_timeout(state, deadline - now).unwrap_or_else(|e| e.into_inner()).0;
        }
    }

    /// Acknowledge: the slot of `job` may be written again.
    pub(crate) fn ack(&self, job: u64) {
        let mut state = self.shared.lock();
        state.acked = state.acked.max(job + 1);
        self.shared.changed.notify_all();
    }

    /// Reads the simulation's state on the worker (after every queued job).
    pub(crate) fn read_state(&self) -> Result<SimState> {
        let (tx, rx) = mpsc::channel();
        self.send(Request::Read(tx))?;
        let deadline = self.timeout + self.timeout;
        match rx.recv_timeout(deadline) {
            Ok(result) => result,
            Err(_) => Err(self.failure().unwrap_or_else(|| Error::HandOff("reading the state timed out".into()))),
        }
    }

    fn failure(&self) -> Option<Error> {
        check_alive(&self.shared.lock()).err()
    }

    pub(crate) fn report(&self) -> Option<ProfileReport> {
        self.shared.lock().report.clone()
    }

    #[cfg(test)]
    pub(crate) fn inject_panic(&self) -> Result<()> {
        self.send(Request::Panic)
    }

    #[cfg(test)]
    pub(crate) fn inject_device_loss(&self) -> Result<()> {
        self.send(Request::DeviceLost)
    }

    #[cfg(test)]
    pub(crate) fn inject_stall(&self, how_long: Duration) -> Result<()> {
        self.send(Request::Stall(how_long))
    }

    /// Stops the worker and joins it (its own GPU work is waited for on its thread).
    pub(crate) fn stop(&mut self) {
        {
            let mut state = self.shared.lock();
            state.stop = true;
            self.shared.changed.notify_all();
        }
        if let Some(thread) = self.thread.take() {
            if thread.join().is_err() {
                log::error!("vkhair: the simulation worker panicked");
            }
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.stop();
    }
}

fn check_alive(state: &State) -> Result<()> {
    if let Some(f) = &state.failure {
        return Err(Error::SimulationStopped(f.clone()));
    }
    if state.stop || !state.running {
        return Err(Error::SimulationStopped("the simulation worker has stopped".into()));
    }
    Ok(())
}

/// Marks the worker as gone however its thread ends (panics included).
struct Exit<'a>(&'a Shared);

impl Drop for Exit<'_> {
    fn drop(&mut self) {
        let mut state = self.0.lock();
        state.running = false;
        if std::thread::panicking() && state.failure.is_none() {
            state.failure = Some("the simulation worker panicked".into());
        }
        self.0.changed.notify_all();
    }
}

fn run(mut side: SimSide, slots: usize, timeout: Duration, shared: &Shared) {
    let _exit = Exit(shared);
    loop {
        let request = {
            let mut state = shared.lock();
            loop {
                if state.stop {
                    return;
                }
                if let Some(r) = state.requests.pop_front() {
                    break r;
                }
                state = shared.changed.wait(state).unwrap_or_else(|e| e.into_inner());
            }
        };
        let result = match request {
            Request::Step { job, heads } => step(&mut side, shared, job, &heads, slots, timeout),
            Request::Update(update) => update.apply(&mut side.sim),
            Request::Read(reply) => {
                let _ = reply.send(side.sim.read_state());
                Ok(())
            }
            #[cfg(test)]
            Request::Panic => panic!("injected worker failure"),
            #[cfg(test)]
            Request::Stall(how_long) => {
                std::thread::sleep(how_long);
                Ok(())
            }
            #[cfg(test)]
            Request::DeviceLost => {
                Err(Error::Vulkan { call: "vkQueueSubmit (injected)", result: ash::vk::Result::ERROR_DEVICE_LOST })
            }
        };
        if let Err(e) = result {
            let mut state = shared.lock();
            state.failure = Some(e.to_string());
            shared.changed.notify_all();
            return;
        }
    }
}

/// Runs one job: waits for its slot's previous job to be acknowledged, records and
/// submits the steps and the hand-off copy, waits for them, publishes the result.
fn step(
    side: &mut SimSide,
    shared: &Shared,
    job: u64,
    heads: &[RigidTransform],
    slots: usize,
    timeout: Duration,
) -> Result<()> {
    let slot = job as usize % slots;
    let deadline = Instant::now() + timeout;
    {
        let mut state = shared.lock();
        while job >= slots as u64 && state.acked + slots as u64 <= job {
            if state.stop {
                return Err(Error::SimulationStopped("stopped".into()));
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(Error::HandOff(format!("slot {slot} was not acknowledged in time")));
            }
            state = shared.changed.wait_timeout(state, deadline - now).unwrap_or_else(|e| e.into_inner()).0;
        }
    }
    let SimSide { ring, sim, slots: sim_slots, profiler, device, steps } = side;
    let family = device.graphics.family;
    let layout = Layout::of(sim);
    ring.submit(&[], timeout, |cmd| {
        // SAFETY: `cmd` is recording on the simulation device's graphics family; the
        // slot's previous contents were taken (acknowledged) by the render thread.
        unsafe {
            if let Some(p) = profiler.as_mut() {
                let _ = p.begin_frame(cmd, job);
            }
            for head in heads {
                sim.record_step(cmd, head, profiler.as_mut())?;
            }
            match sim_slots {
                SimSlots::External(buffers) => {
                    let b = buffers[slot].raw();
                    let copy = &[AccessKind::TransferWrite];
                    let acquire = barrier::ownership(b, barrier::NOTHING, copy, vk::QUEUE_FAMILY_EXTERNAL, family);
                    device.cmd_barrier(cmd, &[], &[acquire], &[]);
                    record_copy(device, cmd, Parts::of_sim(sim), Parts::packed(b, layout), layout);
                    let release = barrier::ownership(b, copy, barrier::NOTHING, family, vk::QUEUE_FAMILY_EXTERNAL);
                    device.cmd_barrier(cmd, &[], &[release], &[]);
                }
                SimSlots::Staging(buffers) => {
                    let dst = Parts::packed(buffers[slot].raw(), layout);
                    record_copy(device, cmd, Parts::of_sim(sim), dst, layout);
                    device.cmd_barrier(
                        cmd,
                        &[barrier::memory(&[AccessKind::TransferWrite], &[AccessKind::HostRead])],
                        &[],
                        &[],
                    );
                }
            }
        }
        Ok(())
    })?;
    *steps += heads.len() as u64;
    let stop = || shared.lock().stop;
    ring.timeline.wait_until(ring.submitted(), deadline, SLICE, stop)?;
    let report = profiler.as_mut().and_then(|p| p.drain().pop());
    let meta = Meta::of(sim, *steps);
    let mut state = shared.lock();
    state.metas[slot] = Some(meta);
    state.finished = job + 1;
    if report.is_some() {
        state.report = report;
    }
    shared.changed.notify_all();
    Ok(())
}
