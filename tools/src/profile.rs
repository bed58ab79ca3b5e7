//! The run's GPU profile as a user takes it home: a per-pass table (mean, p95,
//! share), a Chrome trace (Perfetto, `chrome://tracing`) and a JSON summary,
//! all three from the same reports.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use vkhair::files::write_atomic;
use vkhair::{Clock, ProfileReport};

use crate::destinations::{Kind, Output};
use crate::output::Error;
use crate::say;

/// One pass's GPU time per report (nanoseconds) on one track.
struct PassStats {
    track: String,
    name: String,
    depth: u32,
    samples: Vec<f64>,
    /// Times the pass was recorded (a pass may run several times per sample).
    events: usize,
}

/// A pass's statistics: mean and p95 per sample, share of its track's total.
struct Row<'a> {
    pass: &'a PassStats,
    mean_ns: f64,
    p95_ns: f64,
    share: f64,
}

/// A Chrome trace event of the "complete" kind.
struct Span {
    track: String,
    name: String,
    start_ns: f64,
    duration_ns: f64,
}

/// Everything measured in a run.
pub struct Profile {
    /// What one sample is of: "frame" or "step".
    unit: &'static str,
    passes: Vec<PassStats>,
    spans: Vec<Span>,
    /// Whether every GPU report was on the host's clock (calibrated timestamps).
    host_clock: Option<bool>,
    reports: usize,
}

/// `CLOCK_MONOTONIC` now, nanoseconds: the host clock calibrated GPU timestamps use.
pub fn host_now_ns() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `t` is a valid timespec to write; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
    t.tv_sec as f64 * 1e9 + t.tv_nsec as f64
}

/// The nearest-rank percentile of sorted samples (the smallest sample that at
/// least `percent` % of them do not exceed); `None` when there are none.
pub fn percentile<T: Copy>(sorted: &[T], percent: usize) -> Option<T> {
    let rank = (sorted.len() * percent).div_ceil(100).max(1);
    sorted.get(rank - 1).copied()
}

/// `--trace` and `--json`, the same for `render` and `simulate`.
#[derive(clap::Args)]
pub struct ProfileArgs {
    /// Write the GPU passes (one track per queue or device) and the CPU spans as
    /// a Chrome trace (opens in Perfetto and chrome://tracing).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Write the run's summary (device, scene, counts, per-pass statistics) as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
}

impl ProfileArgs {
    /// The outputs these flags name, for [`crate::destinations::check`].
    pub fn outputs(&self) -> Vec<Output<'_>> {
        [("--trace", &self.trace), ("--json", &self.json)]
            .into_iter()
            .filter_map(|(flag, path)| path.as_deref().map(|path| Output { flag, path, kind: Kind::File(&["json"]) }))
            .collect()
    }

    /// Writes the files asked for from `profile`, the summary with `context`
    /// (made only when it is asked for), saying where each went.
    pub fn write(&self, profile: &Profile, context: impl FnOnce() -> Value) -> Result<(), Error> {
        if let Some(path) = &self.trace {
            profile.write_trace(path)?;
            say!("wrote the GPU trace to {} (open it in Perfetto or chrome://tracing)", path.display());
        }
        if let Some(path) = &self.json {
            profile.write_summary(path, context())?;
            say!("wrote the run's summary to {}", path.display());
        }
        Ok(())
    }
}

impl Profile {
    /// An empty profile whose table is per `unit` ("frame", "step").
    pub fn new(unit: &'static str) -> Profile {
        Profile { unit, passes: Vec::new(), spans: Vec::new(), host_clock: None, reports: 0 }
    }

    /// Adds a report of `units` frames or steps on `track` (a queue or device):
    /// each pass counts as one sample of its time per unit.
    pub fn add(&mut self, report: &ProfileReport, track: &str, units: usize) {
        self.reports += 1;
        let per = units.max(1) as f64;
        let on_host = report.clock == Clock::HostMonotonic;
        self.host_clock = Some(self.host_clock.unwrap_or(true) && on_host);
        for (name, ns) in report.totals_by_name() {
            let depth = report.passes.iter().find(|p| p.name == name).map_or(0, |p| p.depth);
            let events = report.passes.iter().filter(|p| p.name == name).count();
            match self.passes.iter_mut().find(|p| p.track == track && p.name == name) {
                Some(p) => {
                    p.samples.push(ns / per);
                    p.events += events;
                }
                None => {
                    let samples = vec![ns / per];
                    self.passes.push(PassStats { track: track.to_owned(), name, depth, samples, events });
                }
            }
        }
        for p in &report.passes {
            self.spans.push(Span {
                track: format!("GPU: {track}"),
                name: p.name.clone(),
                start_ns: p.start_ns,
                duration_ns: p.nanoseconds,
            });
        }
    }

    /// Adds a CPU span (host clock, nanoseconds).
    pub fn add_cpu_span(&mut self, name: &str, start_ns: f64, end_ns: f64) {
        self.spans.push(Span {
            track: "CPU: main thread".into(),
            name: name.to_owned(),
            start_ns,
            duration_ns: end_ns - start_ns,
        });
    }

    /// Each pass's statistics, in order of first appearance.
    fn rows(&self) -> Vec<Row<'_>> {
        let total = |track: &str| -> f64 {
            self.passes.iter().filter(|p| p.track == track && p.depth == 0).map(|p| mean(&p.samples)).sum()
        };
        self.passes
            .iter()
            .map(|p| {
                let mut sorted = p.samples.clone();
                sorted.sort_by(f64::total_cmp);
                let mean_ns = mean(&p.samples);
                let t = total(&p.track);
                Row {
                    pass: p,
                    mean_ns,
                    p95_ns: percentile(&sorted, 95).unwrap_or(0.0),
                    share: if t > 0.0 { mean_ns / t } else { 0.0 },
                }
            })
            .collect()
    }

    /// The per-pass table on standard output, one block per track, with each
    /// track's total (the sum of its top-level passes' means).
    pub fn print_table(&self) {
        let rows = self.rows();
        let mut tracks: Vec<&str> = Vec::new();
        for p in &self.passes {
            if !tracks.contains(&p.track.as_str()) {
                tracks.push(&p.track);
            }
        }
        for track in tracks {
            say!(
                "{:<46} {:>9} {:>9} {:>7}",
                format!("GPU pass ({track}), per {}", self.unit),
                "mean ms",
                "p95 ms",
                "share"
            );
            let mut total = 0.0;
            for row in rows.iter().filter(|r| r.pass.track == track) {
                let p = row.pass;
                if p.depth == 0 {
                    total += row.mean_ns;
                }
                let label = format!("{}{}", "  ".repeat(p.depth as usize), p.name);
                say!("{label:<46} {:>9.3} {:>9.3} {:>6.1}%", row.mean_ns / 1e6, row.p95_ns / 1e6, 100.0 * row.share);
            }
            say!("{:<46} {:>9.3}", "total", total / 1e6);
        }
    }

    /// Writes the trace: Chrome trace events, one thread per track, times in µs
    /// (the GPU's on the host clock when every report was calibrated; CPU spans
    /// are on the host clock too).
    pub fn write_trace(&self, path: &Path) -> Result<(), Error> {
        let mut tracks: Vec<&str> = Vec::new();
        for s in &self.spans {
            if !tracks.contains(&s.track.as_str()) {
                tracks.push(&s.track);
            }
        }
        let mut events: Vec<Value> = tracks
            .iter()
            .enumerate()
            .map(|(tid, name)| json!({"ph": "M", "name": "thread_name", "pid": 1, "tid": tid, "args": {"name": name}}))
            .collect();
        events.push(json!({"ph": "M", "name": "process_name", "pid": 1, "args": {"name": "vkhair"}}));
        for s in &self.spans {
            let tid = tracks.iter().position(|t| *t == s.track).unwrap_or(0);
            events.push(json!({
                "ph": "X", "pid": 1, "tid": tid, "name": s.name, "cat": "vkhair",
                "ts": s.start_ns / 1e3, "dur": s.duration_ns / 1e3,
            }));
        }
        let clock = if self.host_clock == Some(true) { "host CLOCK_MONOTONIC (calibrated)" } else { "device" };
        let trace = json!({"traceEvents": events, "displayTimeUnit": "ms", "otherData": {"gpu_clock": clock}});
        write_atomic(path, serde_json::to_string(&trace)?.as_bytes())?;
        Ok(())
    }

    /// The run's summary for dashboards: `context` (device, scene, counts) plus
    /// the per-pass statistics.
    pub fn write_summary(&self, path: &Path, context: Value) -> Result<(), Error> {
        let passes: Vec<Value> = self
            .rows()
            .into_iter()
            .map(|r| {
                let p = r.pass;
                json!({
                    "track": p.track, "name": p.name, "depth": p.depth, "mean_ms": r.mean_ns / 1e6,
                    "p95_ms": r.p95_ns / 1e6, "share": r.share, "events": p.events,
                })
            })
            .collect();
        let summary = json!({
            "run": context,
            "reports": self.reports,
            "per": self.unit,
            "passes": passes,
            "peak_resident_bytes": peak_resident_bytes(),
        });
        write_atomic(path, serde_json::to_string_pretty(&summary)?.as_bytes())?;
        Ok(())
    }
}

/// The process's peak resident memory so far, bytes (`getrusage`).
pub fn peak_resident_bytes() -> u64 {
    // SAFETY: an all-zero rusage is a valid value for getrusage to overwrite.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `usage` is a valid rusage to write; RUSAGE_SELF always exists.
    let ok = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } == 0;
    if ok {
        u64::try_from(usage.ru_maxrss).unwrap_or(0) * 1024 // Linux: kilobytes
    } else {
        0
    }
}

fn mean(samples: &[f64]) -> f64 {
    if samples.is_empty() {
        0.0
    } else {
        samples.iter().sum::<f64>() / samples.len() as f64
    }
}
