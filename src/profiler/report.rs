//! What the profiler reads back: per-pass GPU timings of one frame.

/// GPU time of one named pass.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    /// Pass name (the same string as its debug label).
    pub name: String,
    /// Nesting depth (0 for top-level passes).
    pub depth: u32,
    /// GPU time in nanoseconds.
    pub nanoseconds: f64,
    /// When the pass began, nanoseconds on the report's [`Clock`].
    pub start_ns: f64,
}

impl PassTiming {
    /// When the pass ended, nanoseconds on the report's [`Clock`].
    pub fn end_ns(&self) -> f64 {
        self.start_ns + self.nanoseconds
    }
}

/// The clock that [`PassTiming::start_ns`] counts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// The device's own timestamp counter (comparable only with reports of the same
    /// device).
    Device,
    /// The host's `CLOCK_MONOTONIC`, through `VK_EXT_calibrated_timestamps`:
    /// comparable across devices and with `std::time::Instant`-style host clocks.
    HostMonotonic,
}

/// Per-pass GPU timings of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileReport {
    /// The host's frame index these timings belong to.
    pub frame: u64,
    /// Passes in the order they were recorded.
    pub passes: Vec<PassTiming>,
    /// The clock of the passes' start times.
    pub clock: Clock,
}

impl ProfileReport {
    /// Sum of the top-level passes, nanoseconds.
    pub fn total_nanoseconds(&self) -> f64 {
        self.passes.iter().filter(|p| p.depth == 0).map(|p| p.nanoseconds).sum()
    }

    /// Total time per pass name (passes recorded several times are added up), in
    /// order of first appearance, nanoseconds.
    pub fn totals_by_name(&self) -> Vec<(String, f64)> {
        let mut totals: Vec<(String, f64)> = Vec::new();
        for p in &self.passes {
            match totals.iter_mut().find(|(n, _)| *n == p.name) {
                Some((_, t)) => *t += p.nanoseconds,
                None => totals.push((p.name.clone(), p.nanoseconds)),
            }
        }
        totals
    }

    /// The time of the first pass with this name, nanoseconds.
    pub fn pass(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|p| p.name == name).map(|p| p.nanoseconds)
    }

    /// The interval from the first top-level pass's start to the last one's end,
    /// nanoseconds on [`ProfileReport::clock`] (`None` without passes).
    pub fn span(&self) -> Option<(f64, f64)> {
        let top = self.passes.iter().filter(|p| p.depth == 0);
        let start = top.clone().map(|p| p.start_ns).reduce(f64::min)?;
        let end = top.map(PassTiming::end_ns).reduce(f64::max)?;
        Some((start, end))
    }

    /// How long the top-level passes of `self` and `other` ran at the same time,
    /// nanoseconds: the overlap of a simulation profile with a render profile. `None`
    /// when the two are on different clocks that cannot be compared.
    pub fn overlap_ns(&self, other: &ProfileReport) -> Option<f64> {
        if self.clock != other.clock || self.clock == Clock::Device {
            return None;
        }
        Some(overlap(&top_intervals(self), &top_intervals(other)))
    }
}

/// The top-level passes' intervals, sorted and merged.
fn top_intervals(report: &ProfileReport) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> =
        report.passes.iter().filter(|p| p.depth == 0).map(|p| (p.start_ns, p.end_ns())).collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (s, e) in v {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    merged
}

/// Total length of the intersection of two sorted, disjoint interval lists.
fn overlap(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let (mut i, mut j, mut total) = (0, 0, 0.0);
    while i < a.len() && j < b.len() {
        let (s, e) = (a[i].0.max(b[j].0), a[i].1.min(b[j].1));
        if e > s {
            total += e - s;
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    total
}

impl std::fmt::Display for ProfileReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let width = self.passes.iter().map(|p| p.name.len() + 2 * p.depth as usize).max().unwrap_or(4).max(4);
        writeln!(f, "{:<width$}  {:>10}", "pass", "GPU ms")?;
        for p in &self.passes {
            let name = format!("{}{}", "  ".repeat(p.depth as usize), p.name);
            writeln!(f, "{name:<width$}  {:>10.3}", p.nanoseconds / 1e6)?;
        }
        write!(f, "{:<width$}  {:>10.3}", "total", self.total_nanoseconds() / 1e6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(clock: Clock, passes: &[(u32, f64, f64)]) -> ProfileReport {
        let passes = passes
            .iter()
            .map(|&(depth, start_ns, nanoseconds)| PassTiming { name: "p".into(), depth, nanoseconds, start_ns })
            .collect();
        ProfileReport { frame: 0, passes, clock }
    }

    /// Overlap counts time where top-level passes of both reports run, merging each
    /// report's own overlapping passes first and ignoring nested ones.
    #[test]
    fn overlap_of_two_profiles() {
        let sim = report(Clock::HostMonotonic, &[(0, 0.0, 10.0), (1, 2.0, 50.0), (0, 5.0, 10.0), (0, 30.0, 10.0)]);
        let render = report(Clock::HostMonotonic, &[(0, 12.0, 22.0), (0, 100.0, 1.0)]);
        // sim covers [0, 15] ∪ [30, 40]; render [12, 34] ∪ [100, 101]: 3 + 4.
        assert_eq!(sim.overlap_ns(&render), Some(7.0));
        assert_eq!(render.overlap_ns(&sim), Some(7.0));
        assert_eq!(sim.span(), Some((0.0, 40.0)));
        let device = report(Clock::Device, &[(0, 0.0, 10.0)]);
        assert_eq!(device.overlap_ns(&device), None);
        assert_eq!(sim.overlap_ns(&device), None);
        let apart = report(Clock::HostMonotonic, &[(0, 40.0, 5.0)]);
        assert_eq!(sim.overlap_ns(&apart), Some(0.0));
    }
}
