//! `vkhair inspect`: counts, lengths, bounds and point statistics of a groom
//! file; for USD and Alembic also its curve objects, guides, units and axis;
//! with `--drawn`, the hairs `render` roots over the scalp its strands' roots
//! cover and how evenly they cover it.

use std::path::PathBuf;

use serde_json::json;
use vkhair::groom::authored::UpAxis;

use vkhair::render::{scalp_coverage, ScalpCoverage, ScalpHairParams};
use vkhair::sim::{RigidTransform, SimParams, SimState};

use crate::args::input::{check_scale, load_with_defaults, Loaded};
use crate::output::{CliResult, Error};
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
    /// Also report the hairs `render` draws over the scalp the strands' roots
    /// cover (each strand a key hair): their count at the density, the mean
    /// spacing of their roots and the largest disk of the scalp with no root
    /// in it, at full detail and at a quarter of the hairs (level of detail).
    #[arg(long)]
    drawn: bool,
    /// With --drawn: multiply positions by this to make meters (0.01: Blender
    /// units → m) [default: 1].
    #[arg(long)]
    scale: Option<f32>,
    /// With --drawn: drawn hairs per cm² [default: 150, `[scalp] density`'s default].
    #[arg(long)]
    density: Option<f32>,
}

/// Most strands `--drawn` takes as key hairs (`render`'s: a larger file is
/// drawn as followers of its guides, not over the scalp).
const MOST_KEY_HAIRS: usize = 4096;

/// Points each key hair is resampled to for `--drawn` (only roots matter).
const DRAWN_POINTS: usize = 4;

pub fn inspect(a: &InspectArgs) -> CliResult {
    for (flag, given) in [("--scale", a.scale.is_some()), ("--density", a.density.is_some())] {
        if given && !a.drawn {
            return Err(format!("{flag} needs --drawn (it sets how the hairs over the scalp are counted)").into());
        }
    }
    let loaded = load_with_defaults(&a.file, a.strict)?;
    let drawn = if a.drawn { Some(drawn(a, &loaded.groom)?) } else { None };
    if a.json {
        let mut r = report(&loaded);
        r["drawn"] = drawn.as_ref().map_or(serde_json::Value::Null, Drawn::json);
        say!("{r}");
    } else {
        print_table(&a.file, &loaded);
        if let Some(d) = &drawn {
            d.print();
        }
    }
    Ok(())
}

/// What `--drawn` reports: the hairs over the scalp at full detail and at a
/// quarter of them.
struct Drawn {
    density: f32,
    full: ScalpCoverage,
    quarter: ScalpCoverage,
}

/// The hairs `render` roots over the scalp `groom`'s roots cover.
fn drawn(a: &InspectArgs, groom: &vkhair::Groom) -> Result<Drawn, Error> {
    let scale = a.scale.unwrap_or(1.0);
    check_scale(scale)?;
    let params =
        ScalpHairParams { density: a.density.unwrap_or(ScalpHairParams::default().density), ..Default::default() };
    params.validate().map_err(|e| format!("--density: {e}"))?;
    if groom.strand_count() > MOST_KEY_HAIRS {
        return Err(format!(
            "--drawn: {} strands are more than the {MOST_KEY_HAIRS} key hairs `render` roots hairs over the scalp \
             from; it draws such a file's strands as followers of its guides",
            groom.strand_count()
        )
        .into());
    }
    let keys = groom.scaled(scale)?.resampled(DRAWN_POINTS)?;
    let rest = SimState::from_groom(&keys, &SimParams::default(), &RigidTransform::default())?;
    let full = scalp_coverage(&rest, &params, 1.0)?;
    let quarter = scalp_coverage(&rest, &params, 0.25)?;
    Ok(Drawn { density: params.density, full, quarter })
}

impl Drawn {
    fn print(&self) {
        let (f, q) = (&self.full, &self.quarter);
        say!(
            "drawn hairs        {} over the scalp the strands' roots cover: {} per cm² over {:.1} cm², a root every {:.2} mm",
            f.hairs,
            self.density,
            f.area_cm2,
            f.spacing * 1e3
        );
        say!(
            "scalp coverage     largest root-free disk {:.2} mm, {:.2} × the spacing; a quarter of the hairs (level of \
             detail): {:.2} × theirs",
            f.largest_gap * 1e3,
            f.gap_ratio(),
            q.gap_ratio()
        );
    }

    fn json(&self) -> serde_json::Value {
        let one = |c: &ScalpCoverage| json!({ "hairs": c.hairs, "spacing_m": c.spacing, "largest_gap_m": c.largest_gap, "gap_ratio": c.gap_ratio() });
        json!({
            "density_per_cm2": self.density,
            "scalp_area_cm2": self.full.area_cm2,
            "full": one(&self.full),
            "quarter": one(&self.quarter),
        })
    }
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
