//! `vkhair plot`: a benchmark CSV as a PNG chart (see `chart.rs` for the CSVs
//! it reads).

use std::path::PathBuf;

use crate::chart::plot_file;
use crate::destinations::{self, Kind, Output};
use crate::output::CliResult;

#[derive(clap::Args)]
pub struct PlotArgs {
    /// CSV written by `cargo bench --features bench --bench render` or `--bench volume`, or the
    /// scaling.csv or transparency.csv of `vkhair bench`.
    #[arg(default_value = "target/vkhair-bench/render.csv")]
    csv: PathBuf,
    /// Output PNG (default: the CSV's path with a .png extension).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn plot(a: &PlotArgs) -> CliResult {
    let out = a.out.clone().unwrap_or_else(|| a.csv.with_extension("png"));
    let _made = destinations::check(&[&a.csv], &[Output { flag: "--out", path: &out, kind: Kind::File(&["png"]) }])?;
    plot_file(&a.csv, &out)
}
