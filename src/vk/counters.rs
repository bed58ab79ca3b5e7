//! Counts of the work vkhair records: dispatches, pipeline barriers and the
//! bytes of the buffers each dispatch binds.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

/// Work recorded by vkhair on one device since it was created, counted as it is
/// recorded (a command buffer recorded and never submitted still counts). Take
/// two readings and subtract them to count one step or frame.
///
/// Bytes are those of the whole buffers a compute dispatch binds, read when the
/// shader reads the binding and written when it writes it (from the SPIR-V's
/// `NonWritable`/`NonReadable` decorations): the traffic of a kernel that touches
/// every element of its buffers once, an upper estimate for one that touches
/// part of them (a multigrid level of a larger buffer). Graphics passes are not
/// counted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RecordedWork {
    /// Compute dispatches (direct and indirect).
    pub dispatches: u64,
    /// `vkCmdPipelineBarrier2` calls.
    pub barriers: u64,
    /// Bytes of the buffers the dispatches read.
    pub bytes_read: u64,
    /// Bytes of the buffers the dispatches write.
    pub bytes_written: u64,
}

impl std::ops::Sub for RecordedWork {
    type Output = RecordedWork;

    /// The work recorded between two readings (saturating).
    fn sub(self, earlier: RecordedWork) -> RecordedWork {
        RecordedWork {
            dispatches: self.dispatches.saturating_sub(earlier.dispatches),
            barriers: self.barriers.saturating_sub(earlier.barriers),
            bytes_read: self.bytes_read.saturating_sub(earlier.bytes_read),
            bytes_written: self.bytes_written.saturating_sub(earlier.bytes_written),
        }
    }
}

/// One compute dispatch as recorded ([`crate::GpuContext::take_dispatch_log`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DispatchRecord {
    /// The kernel: its shader's name (`sim/volume/scatter.comp`).
    pub kernel: String,
    /// Workgroups it launches; for an indirect dispatch, the most it can (the
    /// count the recorder uploaded, which the GPU may lower to zero).
    pub workgroups: u64,
    /// Invocations per workgroup.
    pub workgroup_size: u32,
    /// Whether the GPU reads its workgroup count from a buffer.
    pub indirect: bool,
    /// The most times one invocation goes round a loop over data (cells or
    /// items it shares with others, iterations of a solve), as its recorder
    /// states it; 1 for a kernel whose invocations each take one item.
    pub loop_trips: u32,
}

/// The device's running counts.
#[derive(Debug, Default)]
pub(crate) struct Counters {
    dispatches: AtomicU64,
    barriers: AtomicU64,
    bytes_read: AtomicU64,
    bytes_written: AtomicU64,
    /// Whether a log is kept: read by every dispatch, so that recording
    /// without a log takes no lock.
    logging: AtomicBool,
    /// Every dispatch while a log is kept.
    log: Mutex<Option<Vec<DispatchRecord>>>,
}

impl Counters {
    pub(crate) fn barrier(&self) {
        self.barriers.fetch_add(1, Ordering::Relaxed);
    }

    /// One dispatch reading and writing `traffic` (bytes read, bytes written).
    pub(crate) fn dispatch(&self, traffic: (u64, u64)) {
        self.dispatches.fetch_add(1, Ordering::Relaxed);
        self.bytes_read.fetch_add(traffic.0, Ordering::Relaxed);
        self.bytes_written.fetch_add(traffic.1, Ordering::Relaxed);
    }

    /// Keeps `record` when a log is kept.
    pub(crate) fn log_dispatch(&self, record: impl FnOnce() -> DispatchRecord) {
        if !self.logging.load(Ordering::Relaxed) {
            return;
        }
        if let Ok(mut log) = self.log.lock() {
            if let Some(log) = log.as_mut() {
                log.push(record());
            }
        }
    }

    /// Starts (or restarts, emptied) the dispatch log.
    pub(crate) fn start_log(&self) {
        if let Ok(mut log) = self.log.lock() {
            *log = Some(Vec::new());
            self.logging.store(true, Ordering::Relaxed);
        }
    }

    /// The dispatches logged since [`Counters::start_log`]; the log stops.
    pub(crate) fn take_log(&self) -> Vec<DispatchRecord> {
        self.logging.store(false, Ordering::Relaxed);
        self.log.lock().ok().and_then(|mut log| log.take()).unwrap_or_default()
    }

    pub(crate) fn read(&self) -> RecordedWork {
        RecordedWork {
            dispatches: self.dispatches.load(Ordering::Relaxed),
            barriers: self.barriers.load(Ordering::Relaxed),
            bytes_read: self.bytes_read.load(Ordering::Relaxed),
            bytes_written: self.bytes_written.load(Ordering::Relaxed),
        }
    }
}
