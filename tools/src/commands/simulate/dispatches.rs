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
    let mut order: Vec<&str> = Vec::new();
    let mut kernels: std::collections::HashMap<&str, Kernel> = std::collections::HashMap::new();
    for d in log {
        let k = kernels.entry(d.kernel.as_str()).or_insert_with(|| {
            order.push(d.kernel.as_str());
            Kernel::default()
        });
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
    for name in order {
        let k = &kernels[name];
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
