//! `simulate --dispatches`: the compute dispatches of the last steps, per
//! kernel and step.

use vkhair::DispatchRecord;

use crate::say;

/// One kernel's dispatches over the logged steps.
#[derive(Default)]
struct Kernel {
    dispatches: u64,
    workgroups: u64,
    largest: u64,
    size: u32,
    trips: u32,
    indirect: bool,
}

/// Prints `log` (the dispatches of `steps` steps) grouped by kernel, in the
/// order each first ran: dispatches and workgroups a step, the largest launch,
/// invocations per workgroup and the most loop trips of an invocation.
pub fn print(log: &[DispatchRecord], steps: usize) {
    let steps = steps.max(1) as u64;
    // In the order each first ran (a step has a few dozen kernels at most).
    let mut kernels: Vec<(&str, Kernel)> = Vec::new();
    for d in log {
        let at = match kernels.iter().position(|(name, _)| *name == d.kernel) {
            Some(at) => at,
            None => {
                kernels.push((d.kernel.as_str(), Kernel::default()));
                kernels.len() - 1
            }
        };
        let k = &mut kernels[at].1;
        k.dispatches += 1;
        k.workgroups += d.workgroups;
        k.largest = k.largest.max(d.workgroups);
        k.size = d.workgroup_size;
        k.trips = k.trips.max(d.loop_trips);
        k.indirect |= d.indirect;
    }
    say!(
        "compute dispatches a step (the last {steps}; * the most an indirect dispatch launches):\n{:<40} {:>10} {:>12} {:>10} {:>6} {:>10}",
        "kernel",
        "dispatches",
        "workgroups",
        "largest",
        "size",
        "loop trips"
    );
    for (name, k) in &kernels {
        say!(
            "{:<40} {:>10} {:>12} {:>10} {:>6} {:>10}",
            name,
            k.dispatches / steps,
            format!("{}{}", k.workgroups / steps, if k.indirect { "*" } else { "" }),
            k.largest,
            k.size,
            k.trips
        );
    }
    let total: u64 = log.len() as u64 / steps;
    say!("{total} dispatches a step");
}
