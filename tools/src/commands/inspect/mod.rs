//! `vkhair inspect`: counts, lengths, bounds and point statistics of a groom
//! file; for USD and Alembic also its curve objects, guides, units and axis.

use std::path::PathBuf;

use serde_json::json;
use vkhair::groom::authored::UpAxis;

use crate::args::input::{load_with_defaults, Loaded};
use crate::output::CliResult;
use crate::say;

#[derive(clap::Args)]
pub struct InspectArgs {
    /// The groom file (.hair, .tfx, .usd/.usda/.usdc or .abc).
    file: PathBuf,
    /// Refuse a file with defects instead of repairing it (see `render --strict`).
    #[arg(long)]
    strict: bool,
    /// Print the numbers as one JSON object instead of a table (for scripts).
    #[arg(long)]
    json: bool,
}

pub fn inspect(a: &InspectArgs) -> CliResult {
    let loaded = load_with_defaults(&a.file, a.strict)?;
    if a.json {
        say!("{}", report(&loaded));
    } else {
        print_table(&a.file, &loaded);
    }
    Ok(())
}

/// Guides and followers: the file's own guide marks, else none marked.
fn guides(l: &Loaded) -> Option<usize> {
    l.authored.as_ref().and_then(|a| a.guides.as_ref()).map(|g| g.iter().filter(|&&g| g).count())
}

fn report(l: &Loaded) -> serde_json::Value {
    let s = l.groom.stats();
    let guides = guides(l);
    let a = l.authored.as_ref();
    json!({
        "format": l.kind,
        "strands": s.strands,
        "points": s.points,
        "guides_marked": guides,
        "followers": guides.map(|g| s.strands - g),
        "points_per_strand": { "min": s.points_per_strand.0, "mean": s.points_per_strand.1, "max": s.points_per_strand.2 },
        "strand_length": { "min": s.strand_length.0, "mean": s.strand_length.1, "max": s.strand_length.2 },
        "bounds": { "min": s.bounds.0.to_array(), "max": s.bounds.1.to_array() },
        "attributes": {
            "thickness": s.has_thickness,
            "transparency": s.has_transparency,
            "colors": s.has_colors,
            "root_uvs": a.is_some_and(|a| a.root_uvs.is_some()),
            "guide_marks": guides.is_some(),
        },
        "curve_objects": a.map(|a| a.objects.iter().map(|o| json!({
            "path": o.path, "curves": o.curves, "basis": o.basis.to_string(),
        })).collect::<Vec<_>>()),
        "meters_per_unit": a.map(|a| a.meters_per_unit.0),
        "units_stated": a.map(|a| a.meters_per_unit.1),
        "up_axis": a.map(|a| if a.up_axis == UpAxis::Z { "Z" } else { "Y" }),
        "skipped": a.map(|a| a.skipped.clone()),
    })
}

fn print_table(path: &std::path::Path, l: &Loaded) {
    let s = l.groom.stats();
    say!("{}: {}", path.display(), l.kind);
    say!("strands            {}", s.strands);
    say!("points             {}", s.points);
    if let Some(a) = &l.authored {
        match guides(l) {
            Some(g) => say!("guides             {g} marked by the file (groom_guide), {} followers", s.strands - g),
            None => say!("guides             none marked by the file"),
        }
        let (k, stated) = a.meters_per_unit;
        let unit = if stated {
            format!("{k} m per unit (stated)")
        } else {
            "not stated by the format: taken as meters (--scale changes it)".into()
        };
        say!("units              {unit}; lengths below in meters");
        let up = if a.up_axis == UpAxis::Z { "Z up in the file, turned to Y up" } else { "Y up" };
        say!("axes               {up}");
    }
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
    let uvs = l.authored.as_ref().is_some_and(|a| a.root_uvs.is_some());
    say!(
        "attributes         thickness {}  transparency {}  colors {}  root UVs {}",
        yes(s.has_thickness),
        yes(s.has_transparency),
        yes(s.has_colors),
        yes(uvs)
    );
    for note in l.authored.iter().flat_map(|a| &a.skipped) {
        say!("not read           {note}");
    }
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}
