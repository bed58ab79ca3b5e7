//! GPU timings of named passes from timestamp queries.
//!
//! The profiler keeps one slot of queries per frame in flight. Recording frame
//! N into slot `N % frames_in_flight` first reads back what that slot measured
//! for frame `N - frames_in_flight` — which the host has already waited for
//! before reusing the slot's resources — so reading never stalls. Results are
//! read without `WAIT` and with availability bits: a slot whose queries are not
//! available yet yields no report rather than blocking.
//!
//! Every scope also opens a debug-utils label, so RenderDoc/Nsight show the same
//! pass names whether profiling is enabled or not. vkhair's own passes and stages
//! open their scopes through one helper, [`PassScope`], coloured by the kind of
//! work; both timestamps are written at `ALL_COMMANDS`.

use std::cell::RefCell;
use std::sync::Arc;

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::vk::device::Device;

mod report;
mod scope;

use crate::vk::debug::LabelColor;
pub use report::{Clock, PassTiming, ProfileReport};
pub(crate) use scope::PassScope;
use scope::TIMESTAMP_STAGE;

/// Handle of an open scope, returned by [`GpuProfiler::begin_scope`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use = "a scope must be closed with end_scope"]
pub struct ScopeId(Option<u32>);

struct Scope {
    name: String,
    depth: u32,
    begin: u32,
    end: Option<u32>,
}

#[derive(Default)]
struct Slot {
    frame: Option<u64>,
    scopes: Vec<Scope>,
    queries: u32,
    open: u32,
}

/// What recording scopes changes: the slots and the frame being recorded.
/// Behind a `RefCell`, so that vkhair's passes can open scopes through a
/// shared [`Timing`] handle.
struct Recording {
    slots: Vec<Slot>,
    current: Option<usize>,
}

/// Where a vkhair pass writes its timestamps: the frame's profiler, or nowhere
/// (debug labels only). `Copy`, so it is passed by value through every
/// recording function instead of threading a mutable borrow.
#[derive(Clone, Copy, Default)]
pub(crate) struct Timing<'a>(Option<&'a GpuProfiler>);

impl<'a> Timing<'a> {
    /// Timestamps into `profiler` when given.
    pub(crate) fn of(profiler: Option<&'a GpuProfiler>) -> Self {
        Timing(profiler)
    }

    /// The profiler, when there is one.
    pub(crate) fn profiler(self) -> Option<&'a GpuProfiler> {
        self.0
    }
}

/// Timestamp-query profiler for passes recorded into the host's command buffers.
///
/// vkhair's passes and stages open their scopes in the profiler they are given;
/// a host opens its own with [`GpuProfiler::begin_scope`]. Reports come back
/// `frames_in_flight` frames later, or from [`GpuProfiler::drain`]:
///
/// ```
/// use glam::Vec3;
/// use vkhair::headless::Submit;
/// use vkhair::sim::{HairSim, RigidTransform, SimParams, SimStage};
/// use vkhair::{ContextOptions, GpuContext, GpuProfiler, Groom, ValidationLog};
///
/// let log = ValidationLog::new();
/// {
///     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
///     let strand: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.02 * i as f32, 0.0, 0.0)).collect();
///     let head = RigidTransform::default();
///     let mut sim = HairSim::new(&ctx, &Groom::from_strands(&[strand])?, &SimParams::default(), &head)?;
///     let mut profiler = GpuProfiler::new(&ctx, 2, 64)?;
///     let mut result = Ok(());
///     ctx.run_commands("frame 0", |cmd| {
///         // SAFETY: a recording command buffer of the context's device.
///         result = unsafe {
///             let _ = profiler.begin_frame(cmd, 0);
///             let frame = profiler.begin_scope(cmd, "host: frame");
///             let stepped = sim.record_step(cmd, &head, Some(&mut profiler));
///             profiler.end_scope(cmd, frame);
///             stepped
///         };
///     })?;
///     result?;
///     let report = profiler.drain().pop().expect("frame 0 has completed");
///     assert!(report.pass(SimStage::Step.label()).is_some());
///     println!("{report}");
/// }
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
pub struct GpuProfiler {
    device: Arc<Device>,
    pool: vk::QueryPool,
    recording: RefCell<Recording>,
    queries_per_slot: u32,
    enabled: bool,
    period_ns: f64,
    valid_mask: u64,
    latest: Option<ProfileReport>,
    /// Reads device and host clocks together, when calibrated timestamps are enabled
    /// and offer both.
    calibration: Option<ash::ext::calibrated_timestamps::Device>,
}

impl GpuProfiler {
    /// A profiler for `frames_in_flight` frames (1..=16) of at most
    /// `max_scopes` scopes (1..=1024) each.
    pub fn new(ctx: &GpuContext, frames_in_flight: u32, max_scopes: u32) -> Result<Self> {
        Self::from_device(&ctx.device, frames_in_flight, max_scopes)
    }

    pub(crate) fn from_device(device: &Arc<Device>, frames_in_flight: u32, max_scopes: u32) -> Result<Self> {
        if !(1..=16).contains(&frames_in_flight) {
            return Err(Error::param("frames_in_flight", frames_in_flight, "1..=16"));
        }
        if !(1..=1024).contains(&max_scopes) {
            return Err(Error::param("max_scopes", max_scopes, "1..=1024"));
        }
        let device = device.clone();
        if device.info.timestamp_valid_bits == 0 {
            return Err(Error::MissingRequirement("timestamps on the graphics queue family".into()));
        }
        let queries_per_slot = 2 * max_scopes;
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(queries_per_slot * frames_in_flight);
        // SAFETY: valid create info; destroyed in Drop.
        let pool = unsafe { device.raw.create_query_pool(&info, None) }.map_err(Error::vk("vkCreateQueryPool"))?;
        device.set_name(pool, "vkhair timestamps");
        let bits = device.info.timestamp_valid_bits;
        let calibration = calibration(&device);
        Ok(GpuProfiler {
            calibration,
            pool,
            recording: RefCell::new(Recording {
                slots: (0..frames_in_flight).map(|_| Slot::default()).collect(),
                current: None,
            }),
            queries_per_slot,
            enabled: true,
            period_ns: f64::from(device.info.timestamp_period),
            valid_mask: if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 },
            latest: None,
            device,
        })
    }

    /// Turns timestamp writing on or off from the next frame on (labels stay).
    pub fn set_enabled(&mut self, enabled: bool) {
        self.enabled = enabled;
    }

    /// Whether timestamps are written.
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// The most recent report read back.
    pub fn latest(&self) -> Option<&ProfileReport> {
        self.latest.as_ref()
    }

    /// Starts recording frame `frame` into `cmd`: returns the report of the frame
    /// that last used this slot (frame − frames_in_flight) when its results are
    /// available, then resets the slot's queries in `cmd`.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of the context's device, outside a render
    /// pass, submitted to the graphics queue family; the command buffer that recorded
    /// frame `frame − frames_in_flight` has completed (the usual frames-in-flight wait).
    pub unsafe fn begin_frame(&mut self, cmd: vk::CommandBuffer, frame: u64) -> Option<ProfileReport> {
        let index = (frame % self.recording.get_mut().slots.len() as u64) as usize;
        let report = self.read_slot(index);
        if report.is_some() {
            self.latest.clone_from(&report);
        }
        let first = index as u32 * self.queries_per_slot;
        // SAFETY: guaranteed by the caller; the range lies within the pool.
        unsafe { self.device.raw.cmd_reset_query_pool(cmd, self.pool, first, self.queries_per_slot) };
        let recording = self.recording.get_mut();
        recording.slots[index] = Slot { frame: Some(frame), ..Slot::default() };
        recording.current = Some(index);
        report
    }

    /// Opens a named pass: a debug label and, when enabled, a begin timestamp.
    /// Scopes beyond `max_scopes` in a frame get a label only.
    ///
    /// # Safety
    /// As for [`GpuProfiler::begin_frame`], after it was called for this frame.
    pub unsafe fn begin_scope(&mut self, cmd: vk::CommandBuffer, name: &str) -> ScopeId {
        // SAFETY: guaranteed by the caller.
        unsafe { self.begin_scope_as(cmd, name, LabelColor::Host) }
    }

    /// [`GpuProfiler::begin_scope`] for a pass of a known kind: the label's colour
    /// follows `kind`.
    ///
    /// # Safety
    /// As for [`GpuProfiler::begin_scope`].
    pub(crate) unsafe fn begin_scope_as(&self, cmd: vk::CommandBuffer, name: &str, kind: LabelColor) -> ScopeId {
        // SAFETY: guaranteed by the caller.
        unsafe { self.device.cmd_begin_label(cmd, name, kind) };
        let mut recording = self.recording.borrow_mut();
        let Some(index) = recording.current.filter(|_| self.enabled) else { return ScopeId(None) };
        let first = index as u32 * self.queries_per_slot;
        let slot = &mut recording.slots[index];
        if slot.queries + 2 > self.queries_per_slot {
            slot.open += 1;
            return ScopeId(None);
        }
        let query = slot.queries;
        slot.queries += 2;
        slot.scopes.push(Scope { name: name.to_owned(), depth: slot.open, begin: query, end: None });
        slot.open += 1;
        // SAFETY: guaranteed by the caller; the query was reset in begin_frame.
        unsafe { self.device.raw.cmd_write_timestamp2(cmd, TIMESTAMP_STAGE, self.pool, first + query) };
        ScopeId(Some(slot.scopes.len() as u32 - 1))
    }

    /// Closes the pass opened by `scope`.
    ///
    /// # Safety
    /// As for [`GpuProfiler::begin_scope`], in the same command buffer.
    pub unsafe fn end_scope(&mut self, cmd: vk::CommandBuffer, scope: ScopeId) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.end_scope_shared(cmd, scope) }
    }

    /// [`GpuProfiler::end_scope`] through a shared reference (vkhair's passes).
    ///
    /// # Safety
    /// As for [`GpuProfiler::end_scope`].
    pub(crate) unsafe fn end_scope_shared(&self, cmd: vk::CommandBuffer, scope: ScopeId) {
        let mut recording = self.recording.borrow_mut();
        if let Some(index) = recording.current {
            let first = index as u32 * self.queries_per_slot;
            let slot = &mut recording.slots[index];
            slot.open = slot.open.saturating_sub(1);
            if let Some(s) = scope.0.and_then(|i| slot.scopes.get_mut(i as usize)) {
                let query = s.begin + 1;
                s.end = Some(query);
                // SAFETY: guaranteed by the caller; the query was reset in begin_frame.
                unsafe { self.device.raw.cmd_write_timestamp2(cmd, TIMESTAMP_STAGE, self.pool, first + query) };
            }
        }
        // SAFETY: guaranteed by the caller (matching begin_scope).
        unsafe { self.device.cmd_end_label(cmd) };
    }

    /// Reads back every slot whose frame is complete, newest last; for a host that
    /// has waited for all its frames (end of a run).
    pub fn drain(&mut self) -> Vec<ProfileReport> {
        let slots = &self.recording.get_mut().slots;
        let mut order: Vec<usize> = (0..slots.len()).filter(|&i| slots[i].frame.is_some()).collect();
        order.sort_by_key(|&i| slots[i].frame);
        let reports: Vec<_> = order.into_iter().filter_map(|i| self.read_slot(i)).collect();
        let recording = self.recording.get_mut();
        recording.slots.iter_mut().for_each(|slot| *slot = Slot::default());
        recording.current = None;
        if let Some(last) = reports.last() {
            self.latest = Some(last.clone());
        }
        reports
    }

    fn read_slot(&self, index: usize) -> Option<ProfileReport> {
        let recording = self.recording.borrow();
        let slot = &recording.slots[index];
        let frame = slot.frame?;
        if slot.queries == 0 {
            return None;
        }
        let first = index as u32 * self.queries_per_slot;
        // Pairs of (value, availability).
        let mut data = vec![[0u64; 2]; slot.queries as usize];
        // SAFETY: the range lies within the pool; no WAIT flag, so this never blocks.
        let result = unsafe {
            self.device.raw.get_query_pool_results(
                self.pool,
                first,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WITH_AVAILABILITY,
            )
        };
        match result {
            Ok(()) | Err(vk::Result::NOT_READY) => {}
            Err(e) => {
                log::warn!("reading timestamps failed: {e}");
                return None;
            }
        }
        // Device time "now" against the host clock, to place the passes on it.
        let now = self.calibration.as_ref().and_then(|c| {
            let infos = [vk::TimeDomainEXT::DEVICE, vk::TimeDomainEXT::CLOCK_MONOTONIC]
                .map(|d| vk::CalibratedTimestampInfoEXT::default().time_domain(d));
            // SAFETY: both domains were reported calibrateable for this device.
            unsafe { c.get_calibrated_timestamps(&infos) }.ok().map(|(t, _)| (t[0], t[1]))
        });
        let mut passes = Vec::new();
        for s in &slot.scopes {
            let end = s.end?;
            let (b, e) = (data[s.begin as usize], data[end as usize]);
            if b[1] == 0 || e[1] == 0 {
                return None;
            }
            let ticks = e[0].wrapping_sub(b[0]) & self.valid_mask;
            let start_ns = match now {
                Some((device_now, host_now)) => {
                    let ago = device_now.wrapping_sub(b[0]) & self.valid_mask;
                    host_now as f64 - ago as f64 * self.period_ns
                }
                None => (b[0] & self.valid_mask) as f64 * self.period_ns,
            };
            passes.push(PassTiming {
                name: s.name.clone(),
                depth: s.depth,
                nanoseconds: ticks as f64 * self.period_ns,
                start_ns,
            });
        }
        let clock = if now.is_some() { Clock::HostMonotonic } else { Clock::Device };
        Some(ProfileReport { frame, passes, clock })
    }
}

/// The calibrated-timestamps loader when the extension is enabled and both the
/// device and the host's monotonic clock can be read together.
fn calibration(device: &Device) -> Option<ash::ext::calibrated_timestamps::Device> {
    if !device.extensions.calibrated_timestamps {
        return None;
    }
    let instance_fns = ash::ext::calibrated_timestamps::Instance::new(&device.entry, &device.instance);
    // SAFETY: the physical device belongs to the instance.
    let domains = unsafe { instance_fns.get_physical_device_calibrateable_time_domains(device.physical) }.ok()?;
    let wanted = [vk::TimeDomainEXT::DEVICE, vk::TimeDomainEXT::CLOCK_MONOTONIC];
    wanted
        .iter()
        .all(|d| domains.contains(d))
        .then(|| ash::ext::calibrated_timestamps::Device::new(&device.instance, &device.raw))
}

impl Drop for GpuProfiler {
    fn drop(&mut self) {
        // SAFETY: the pool belongs to this device; the host has finished the frames
        // that wrote it before dropping the profiler.
        unsafe { self.device.raw.destroy_query_pool(self.pool, None) };
    }
}
