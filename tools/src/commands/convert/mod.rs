//! `vkhair convert`: a groom file resampled and/or thinned to key hairs,
//! written as a .hair file or an Alembic .abc file.

use std::path::{Path, PathBuf};

use vkhair::groom::alembic::write::{to_bytes, CurvesObject};
use vkhair::groom::cyhair::HairFile;

use crate::args::input::load;
use crate::destinations::{self, Kind, Output};
use crate::output::CliResult;
use crate::say;

#[derive(clap::Args)]
pub struct ConvertArgs {
    /// Input groom (.hair, .tfx, .usd/.usda/.usdc or .abc).
    input: PathBuf,
    /// Resample every strand to this many points by arc length.
    #[arg(long)]
    points: Option<usize>,
    /// Keep this many strands, spread evenly (key hairs).
    #[arg(long)]
    key_hairs: Option<usize>,
    /// Output file: .hair, or .abc (Alembic: one linear curves object,
    /// widths and colours when the groom has them).
    #[arg(long)]
    out: PathBuf,
    /// Refuse a file with defects instead of repairing it (see `render --strict`).
    #[arg(long)]
    strict: bool,
}

pub fn convert(a: &ConvertArgs) -> CliResult {
    let _made = destinations::check(
        &[&a.input],
        &[Output { flag: "--out", path: &a.out, kind: Kind::File(&["hair", "abc"]) }],
    )?;
    write_converted(&a.input, a.points, a.key_hairs, &a.out, a.strict)
}

fn write_converted(
    input: &Path,
    points: Option<usize>,
    key_hairs: Option<usize>,
    out: &Path,
    strict: bool,
) -> CliResult {
    let (mut groom, _) = load(input, strict)?;
    if let Some(n) = key_hairs {
        groom = groom.select_evenly(n).map_err(crate::args::flag_error)?;
    }
    if let Some(n) = points {
        groom = groom.resampled(n).map_err(crate::args::flag_error)?;
    }
    let s = groom.stats();
    if out.extension().is_some_and(|e| e.eq_ignore_ascii_case("abc")) {
        let object = CurvesObject { name: "groom", groom: &groom, guides: None, root_uvs: None, transform: None };
        vkhair::files::write_atomic(out, &to_bytes(&[object])?)?;
    } else {
        HairFile::new(groom, &format!("from {}", input.file_name().and_then(|n| n.to_str()).unwrap_or("input")))
            .save(out)?;
    }
    say!("wrote {}: {} strands, {} points", out.display(), s.strands, s.points);
    Ok(())
}
