//! `vkhair inspect`: counts, lengths, bounds and point statistics of a groom file.

use std::path::{Path, PathBuf};

use crate::args::input::load;
use crate::output::CliResult;
use crate::say;

#[derive(clap::Args)]
pub struct InspectArgs {
    /// The groom file (.hair or .tfx).
    file: PathBuf,
    /// Refuse a file with defects instead of repairing it (see `render --strict`).
    #[arg(long)]
    strict: bool,
}

pub fn inspect(a: &InspectArgs) -> CliResult {
    print_stats(&a.file, a.strict)
}

fn print_stats(path: &Path, strict: bool) -> CliResult {
    let (groom, kind) = load(path, strict)?;
    let s = groom.stats();
    say!("{}: {kind}", path.display());
    say!("strands            {}", s.strands);
    say!("points             {}", s.points);
    say!(
        "points per strand  min {}  mean {:.2}  max {}",
        s.points_per_strand.0,
        s.points_per_strand.1,
        s.points_per_strand.2
    );
    say!(
        "strand length      min {:.4}  mean {:.4}  max {:.4}",
        s.strand_length.0,
        s.strand_length.1,
        s.strand_length.2
    );
    say!("segment length     min {:.5}  max {:.5}", s.segment_length.0, s.segment_length.1);
    say!("bounds             {:.4} .. {:.4}  (size {:.4})", s.bounds.0, s.bounds.1, s.bounds.1 - s.bounds.0);
    say!(
        "attributes         thickness {}  transparency {}  colors {}",
        yes(s.has_thickness),
        yes(s.has_transparency),
        yes(s.has_colors)
    );
    Ok(())
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}
