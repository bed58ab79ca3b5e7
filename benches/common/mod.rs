//! Shared by the benchmarks with a criterion group and a summary table.

use criterion::Criterion;

/// Runs the criterion group `benches` unless `-- summary` or `-- quick` is given,
/// then `summary`, told whether `-- quick` asked for fewer measurements.
pub fn criterion_then_summary(benches: fn(), summary: impl FnOnce(bool)) {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "quick");
    if !args.iter().any(|a| a == "summary" || a == "quick") {
        benches();
        Criterion::default().configure_from_args().final_summary();
    }
    summary(quick);
}
