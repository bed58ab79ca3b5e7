//! Reading the groom a user gives: `.hair`, `.tfx`, USD (`.usd`, `.usda`,
//! `.usdc`) or Alembic (`.abc`), repaired unless `--strict` (with a warning
//! that counts what was dropped), scaled and resampled.

use std::path::{Path, PathBuf};

use glam::Vec3;
use vkhair::groom::authored::{AuthoredGroom, CurveObject, UpAxis};
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::{alembic, guides, usd, Groom, Repairs};

use super::texture::Texture;

use crate::output::Error;
use crate::say_err;

/// The groom and character mesh a user gives `render` and `simulate`.
#[derive(clap::Args, Clone, Debug)]
pub struct InputArgs {
    /// Groom file (.hair, .tfx, .usd/.usda/.usdc or .abc) instead of the
    /// `thesis` scene (its groom, head and colliders); it holds its authored
    /// style (a shape constraint over the whole strand and a sag-free rest
    /// state) unless --config says otherwise. A USD stage's metersPerUnit and
    /// upAxis are honoured (meters, Y up); Alembic states no unit and is taken
    /// as meters.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Character mesh (OBJ, the groom's units and frame): the strands collide with
    /// its signed distance field; `render` draws it and frames the camera by it.
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// Do not collide with the --obj mesh (`render` still draws it, `simulate`
    /// still counts the points inside it).
    #[arg(long)]
    pub no_mesh_collider: bool,
    /// Multiply input positions (groom and mesh) by this (0.01: Blender units →
    /// m; 1e-6..=1e6) [default: 1].
    #[arg(long)]
    pub scale: Option<f32>,
    /// Resample input strands to this many points (2..=64) [default: 16].
    #[arg(long)]
    pub points: Option<usize>,
    /// Refuse an --input file with defects (zero-length segments, NaN or infinite
    /// values, strands of fewer than two points) instead of dropping them with a
    /// warning.
    #[arg(long)]
    pub strict: bool,
    /// Skinned, animated glTF character (.glb or .gltf, meters): key hairs are
    /// grown on its head (the joint that dominates the top of the mesh, or
    /// --head-joint), or read from --input (in the character's bind pose, as
    /// `vkhair grow --scalp gltf` writes them, each root on its mesh), their
    /// roots bound to the skinned mesh; a capsule per bone and the head's
    /// distance field keep them out of the body.
    #[arg(long)]
    pub gltf: Option<PathBuf>,
    /// The --gltf animation, by name or index [default: the first].
    #[arg(long)]
    pub animation: Option<String>,
    /// The --gltf joint the hair grows on, by name [default: found by weights].
    #[arg(long)]
    pub head_joint: Option<String>,
    /// Simulate this many strands of a dense --input groom as guides — a
    /// count, or a share below 1 such as 0.05 — and draw every strand of the
    /// file as a follower of them; `all` simulates every strand as a key hair.
    /// [default: the strands the file marks as guides (groom_guide), else
    /// every strand up to 4096 strands, else 5 % of them (at least 64)]
    #[arg(long)]
    pub guides: Option<String>,
    /// Colour each strand of a dense groom drawn as followers from this PNG
    /// (sRGB), sampled at the strand's root UV (the file's st, groom_root_uv
    /// or uv) [default: the file's own colours (displayColor, groom_color),
    /// else the material's]
    #[arg(long)]
    pub scalp_texture: Option<PathBuf>,
}

/// A groom with more strands than this is dense: without --guides or guide
/// marks, 5 % of its strands (at least 64) are simulated as guides.
pub const DENSE_STRANDS: usize = 4096;

/// A dense groom drawn as followers of some of its strands.
pub struct Dense {
    /// Every strand of the file, scaled, in the file's order (not resampled).
    pub groom: Groom,
    /// The strands simulated as guides (indices into `groom`, ascending).
    pub guides: Vec<usize>,
    /// How they were chosen, for the run's header.
    pub chosen_by: &'static str,
    /// Points per drawn follower: the file's median per strand, 4..=64.
    pub points: usize,
    /// Each strand's own albedo at the root and the tip (the file's order).
    pub colors: Option<Vec<[Vec3; 2]>>,
    /// Where the colours come from, for the run's header.
    pub colors_from: &'static str,
    /// Each strand's width at the root and the tip as a factor of the
    /// groom's median there (the file's thickness), 0..=10.
    pub width_factors: Option<Vec<[f32; 2]>>,
}

impl InputArgs {
    /// Options that need others and values out of range, as errors that say so.
    pub fn check(&self) -> Result<(), String> {
        if self.gltf.is_some() {
            if self.obj.is_some() {
                return Err("--gltf brings its own mesh: --obj cannot go with it".into());
            }
            let given = [("--scale", self.scale.is_some()), ("--strict", self.strict)];
            if let Some((flag, _)) = given.iter().find(|(_, g)| *g).filter(|_| self.input.is_none()) {
                return Err(format!("{flag} needs --input (without it the hair is grown on the --gltf character)"));
            }
        } else if let Some(flag) =
            [("--animation", self.animation.is_some()), ("--head-joint", self.head_joint.is_some())]
                .iter()
                .find_map(|(f, g)| g.then_some(f))
        {
            return Err(format!("{flag} needs --gltf"));
        } else if self.input.is_none() {
            let given = [
                ("--obj", self.obj.is_some()),
                ("--scale", self.scale.is_some()),
                ("--points", self.points.is_some()),
                ("--strict", self.strict),
            ];
            if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
                return Err(format!(
                    "{flag} needs --input (the thesis scene brings its own groom, head and colliders)"
                ));
            }
        }
        if self.no_mesh_collider && self.obj.is_none() {
            return Err("--no-mesh-collider needs --obj (there is no mesh to collide with)".into());
        }
        if let Some(scale) = self.scale {
            check_scale(scale)?;
        }
        if let Some(points) = self.points {
            if !(2..=64).contains(&points) {
                return Err(format!("--points must be 2..=64 (got {points})"));
            }
        }
        if let Some(g) = &self.guides {
            if self.input.is_none() {
                return Err("--guides needs --input (a dense groom to choose guides from)".into());
            }
            guide_request(g)?;
        }
        if self.scalp_texture.is_some() && self.input.is_none() {
            return Err("--scalp-texture needs --input (a dense groom with root UVs)".into());
        }
        Ok(())
    }

    /// The files these flags read.
    pub fn files(&self) -> Vec<&Path> {
        [self.input.as_deref(), self.obj.as_deref(), self.gltf.as_deref(), self.scalp_texture.as_deref()]
            .into_iter()
            .flatten()
            .collect()
    }

    /// The --scale factor.
    pub fn scale(&self) -> f32 {
        self.scale.unwrap_or(1.0)
    }

    /// The --input groom's key hairs (scaled, resampled to --points) and, for
    /// a dense groom, the whole groom and the guides among it that the key
    /// hairs are (see --guides).
    pub fn groom_and_guides(&self, path: &Path) -> Result<(Scaled, Option<Dense>), Error> {
        let mut loaded = load_with_defaults(path, self.strict)?;
        let (marks, root_uvs) = loaded.authored.take().map(|a| (a.guides, a.root_uvs)).unwrap_or_default();
        let (groom, thickness) = loaded.scaled(self.scale())?;
        let points = self.points.unwrap_or(16);
        let n = groom.strand_count();
        let request = self.guides.as_deref().map(guide_request).transpose()?;
        let key_hairs_only = |groom: Groom| -> Result<(Scaled, Option<Dense>), Error> {
            if self.scalp_texture.is_some() {
                return Err("--scalp-texture colours the strands of a dense groom drawn as followers of guides; this \
                            one is simulated strand by strand (give --guides)"
                    .into());
            }
            Ok((Scaled { groom: groom.resampled(points)?, thickness }, None))
        };
        let (guides, chosen_by) = match (request, marks) {
            (Some(Guides::All), _) => return key_hairs_only(groom),
            (Some(Guides::Count(c)), _) => (guides::spread(&groom, c.min(n))?, "--guides, spread over the roots"),
            (Some(Guides::Share(f)), _) => {
                let c = ((n as f64 * f).round() as usize).clamp(1, n);
                (guides::spread(&groom, c)?, "--guides, spread over the roots")
            }
            (None, Some(marks)) => (guides::marked(&marks)?, "marked by the file (groom_guide)"),
            (None, None) if n > DENSE_STRANDS => {
                (guides::spread(&groom, (n / 20).max(64))?, "5 % of a dense groom, spread over the roots")
            }
            (None, None) => return key_hairs_only(groom),
        };
        let (colors, colors_from) = match &self.scalp_texture {
            Some(texture) => {
                let uvs = root_uvs.ok_or_else(|| {
                    format!(
                        "--scalp-texture: {} has no root UVs (primvars:st or groom_root_uv in USD, uv or \
                         groom_root_uv in Alembic)",
                        path.display()
                    )
                })?;
                let t = Texture::open(texture)?;
                (Some(uvs.iter().map(|&uv| [t.sample(uv); 2]).collect()), "the scalp texture at the root UVs")
            }
            None => match groom.end_colors() {
                Some(c) => {
                    let clamp = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
                    (Some(c.into_iter().map(|[r, t]| [clamp(r), clamp(t)]).collect()), "the file's")
                }
                None => (None, "the material's"),
            },
        };
        let keys = groom.select(&guides)?.resampled(points)?;
        let mut per_strand: Vec<usize> = (0..n).map(|s| groom.strand_len(s)).collect();
        per_strand.sort_unstable();
        let follower_points = per_strand[n / 2].clamp(4, 64);
        let width_factors = width_factors(&groom);
        let dense = Dense { groom, guides, chosen_by, points: follower_points, colors, colors_from, width_factors };
        Ok((Scaled { groom: keys, thickness }, Some(dense)))
    }

    /// Whether the strands collide with the --obj mesh.
    pub fn colliding(&self) -> bool {
        self.input.is_some() && self.obj.is_some() && !self.no_mesh_collider
    }
}

/// Each strand's thickness at its root and tip over the groom's median there
/// (see [`Groom::end_thickness`]), 0..=10; 1 where the median is 0.
fn width_factors(groom: &Groom) -> Option<Vec<[f32; 2]>> {
    let t = groom.thickness()?;
    let (root, tip) = groom.end_thickness()?;
    let factor = |v: f32, median: f32| if median > 0.0 { (v / median).clamp(0.0, 10.0) } else { 1.0 };
    Some(
        (0..groom.strand_count())
            .map(|s| {
                let r = groom.strand_range(s);
                [factor(t[r.start], root), factor(t[r.end - 1], tip)]
            })
            .collect(),
    )
}

/// What --guides asks for.
enum Guides {
    All,
    Count(usize),
    Share(f64),
}

fn guide_request(g: &str) -> Result<Guides, String> {
    if g == "all" {
        return Ok(Guides::All);
    }
    if let Ok(n) = g.parse::<usize>() {
        return if n >= 1 { Ok(Guides::Count(n)) } else { Err("--guides must be at least 1".into()) };
    }
    match g.parse::<f64>() {
        Ok(f) if f > 0.0 && f < 1.0 => Ok(Guides::Share(f)),
        _ => Err(format!("--guides takes a count (1 or more), a share between 0 and 1, or `all` (got {g})")),
    }
}

/// The groom in `path` and a description of its format. Defects that can be
/// repaired are (with a warning on stderr) unless `strict`; then the file is
/// refused with the defect named.
pub fn load(path: &Path, strict: bool) -> Result<(Groom, String), Error> {
    load_with_defaults(path, strict).map(|l| (l.groom, l.kind))
}

/// A groom file read: the groom, what kind of file it was, and what a USD or
/// Alembic file says beyond its strands.
pub struct Loaded {
    /// The groom (the file's units; USD and Alembic: meters, Y up).
    pub groom: Groom,
    /// The format, as `inspect` names it.
    pub kind: String,
    /// A cyHair header's thickness (see [`load_with_defaults`]).
    header_thickness: Option<f32>,
    /// What a USD or Alembic file says beyond its strands.
    pub authored: Option<Authored>,
}

impl Loaded {
    /// The groom with its lengths multiplied by `scale`, and the root and tip
    /// thickness it gives its strands (see [`Scaled::thickness`]).
    fn scaled(self, scale: f32) -> Result<(Groom, Option<(f32, f32)>), Error> {
        let groom = self.groom.scaled(scale)?;
        let thickness = groom.end_thickness().or(self.header_thickness.map(|t| (t * scale, t * scale)));
        Ok((groom, thickness))
    }
}

/// [`AuthoredGroom`] without its groom.
pub struct Authored {
    /// Per-strand guide marks, when the file has them.
    pub guides: Option<Vec<bool>>,
    /// Per-strand root UVs, when the file has them.
    pub root_uvs: Option<Vec<glam::Vec2>>,
    /// The curve objects read.
    pub objects: Vec<CurveObject>,
    /// Meters per file unit, and whether the file states it.
    pub meters_per_unit: (f64, bool),
    /// The file's up axis.
    pub up_axis: UpAxis,
    /// What was passed over.
    pub skipped: Vec<String>,
}

/// The file's format by its extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    CyHair,
    TressFx,
    Usd,
    Alembic,
}

fn format_of(path: &Path) -> Format {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("tfx") => Format::TressFx,
        Some("usd" | "usda" | "usdc") => Format::Usd,
        Some("abc") => Format::Alembic,
        _ => Format::CyHair,
    }
}

/// Splits a USD or Alembic read into the groom and the rest.
fn authored(g: AuthoredGroom, format: &str, path: &Path) -> (Groom, String, Authored) {
    let objects: Vec<String> = g
        .objects
        .iter()
        .map(|o| format!("{} ({} {} curve{})", o.path, o.curves, o.basis, if o.curves == 1 { "" } else { "s" }))
        .collect();
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let kind = format!("{format} (.{ext}), {} curve objects: {}", objects.len(), objects.join(", "));
    let rest = Authored {
        guides: g.guides,
        root_uvs: g.root_uvs,
        objects: g.objects,
        meters_per_unit: (g.meters_per_unit, g.units_stated),
        up_axis: g.up_axis,
        skipped: g.skipped,
    };
    (g.groom, kind, rest)
}

/// The cyHair format's default thickness: a file that leaves it unchanged and has
/// no thickness array says nothing about its strands' thickness.
const CYHAIR_DEFAULT_THICKNESS: f32 = 1.0;

/// `--scale`'s value checked: a finite number above 0.
pub fn check_scale(scale: f32) -> Result<(), String> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("--scale must be a finite number above 0 (got {scale})"));
    }
    // A unit conversion, not a way to the edge of f32 (1e30 overflowed the
    // groom's bounds, 1e-30 made every segment zero-length).
    if !(MIN_SCALE..=MAX_SCALE).contains(&scale) {
        return Err(format!("--scale must be within {MIN_SCALE:e}..={MAX_SCALE:e} (got {scale:e})"));
    }
    Ok(())
}

/// The smallest and largest `--scale`: from micrometres to kilometres.
pub const MIN_SCALE: f32 = 1e-6;
/// See [`MIN_SCALE`].
pub const MAX_SCALE: f32 = 1e6;

/// [`load`], and the thickness a cyHair file gives every point in its header when
/// it has no thickness array and the header says something other than the
/// format's default.
pub fn load_with_defaults(path: &Path, strict: bool) -> Result<Loaded, Error> {
    let format = format_of(path);
    let refused = |e: vkhair::Error| -> Error {
        match e {
            vkhair::Error::Asset { .. } if strict => {
                format!("{e} (--strict: without it, vkhair drops such segments, strands, curve objects or thickness and says so)")
                    .into()
            }
            e => e.into(),
        }
    };
    let mut extra = None;
    let (groom, kind, repairs, header_thickness) = if format == Format::TressFx {
        let (f, repairs) = if strict {
            (TfxFile::open(path).map_err(refused)?, Repairs::default())
        } else {
            TfxFile::open_repairing(path)?
        };
        let kind = format!("TressFX {} (.tfx)", f.version);
        (f.groom, kind, repairs, None)
    } else if matches!(format, Format::Usd | Format::Alembic) {
        let (g, repairs) = match (format, strict) {
            (Format::Usd, true) => (usd::open(path).map_err(refused)?, Repairs::default()),
            (Format::Usd, false) => usd::open_repairing(path)?,
            (_, true) => (alembic::open(path).map_err(refused)?, Repairs::default()),
            (_, false) => alembic::open_repairing(path)?,
        };
        let name = if format == Format::Usd { "USD" } else { "Alembic" };
        let (groom, kind, rest) = authored(g, name, path);
        for note in &rest.skipped {
            say_err!("vkhair: warning: {}: not read: {note}", path.display());
        }
        extra = Some(rest);
        (groom, kind, repairs, None)
    } else {
        let (f, repairs) = if strict {
            (HairFile::open(path).map_err(refused)?, Repairs::default())
        } else {
            HairFile::open_repairing(path)?
        };
        let info = f.info_str();
        let kind =
            format!("cyHair (.hair){}", if info.is_empty() { String::new() } else { format!(", info \"{info}\"") });
        let header = f.defaults.thickness;
        let header_thickness = (f.groom.thickness().is_none() && header != CYHAIR_DEFAULT_THICKNESS).then_some(header);
        (f.groom, kind, repairs, header_thickness)
    };
    if !repairs.is_empty() {
        say_err!(
            "vkhair: warning: {}: {repairs}; {} strands remain (--strict refuses such a file instead)",
            path.display(),
            groom.strand_count()
        );
    }
    Ok(Loaded { groom, kind, header_thickness, authored: extra })
}

/// A groom read, scaled and resampled, with what it says about its strands' width.
pub struct Scaled {
    /// The groom (scaled, resampled; attributes kept).
    pub groom: Groom,
    /// Root and tip thickness (diameters, after scaling) when the file gives it:
    /// the medians over the strands of a per-point thickness array, else a cyHair
    /// header's default thickness when it is not the format's default of 1.
    pub thickness: Option<(f32, f32)>,
}

/// The groom in `path` (see [`load`]) with its lengths (positions and thickness)
/// multiplied by `scale` and every strand resampled to `points` points.
pub fn load_scaled(path: &Path, strict: bool, scale: f32, points: usize) -> Result<Scaled, Error> {
    let (groom, thickness) = load_with_defaults(path, strict)?.scaled(scale)?;
    Ok(Scaled { groom: groom.resampled(points)?, thickness })
}

/// Plausible strand diameters, meters: from a fine human hair's 5 µm to a 2 mm
/// strand standing for a clump. A groom's thickness outside is not used.
const PLAUSIBLE_WIDTH: std::ops::RangeInclusive<f32> = 5e-6..=2e-3;

/// The root and tip width to draw strands at, in the scene's units, from the
/// `thickness` the groom file gives (see [`Scaled::thickness`]) for a scene
/// drawn `k` times as wide as a head in meters: `None` (with a warning saying
/// why when there was a thickness) when it has none or an implausible one,
/// checked as meters after dividing by `k`. A tip thinner than the plausible
/// least (tapered to a point) is kept.
pub fn strand_widths(thickness: Option<(f32, f32)>, k: f32) -> Option<(f32, f32)> {
    let (root, tip) = thickness?;
    let (root_m, tip_m) = (root / k, tip / k);
    let fits = PLAUSIBLE_WIDTH.contains(&root_m) && (0.0..=*PLAUSIBLE_WIDTH.end()).contains(&tip_m);
    if !fits {
        say_err!(
            "vkhair: warning: the groom's thickness ({root_m:e} m at the root, {tip_m:e} m at the tip after --scale) \
             is not a hair's ({:e}..={:e} m); drawing vkhair's default widths instead (set material.root_width \
             and tip_width in --config, or fix --scale)",
            PLAUSIBLE_WIDTH.start(),
            PLAUSIBLE_WIDTH.end()
        );
        return None;
    }
    Some((root, tip))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn width_factors_are_each_strands_thickness_over_the_median() {
        let strand = |x: f32| vec![Vec3::new(x, 0.0, 0.0), Vec3::new(x, -0.1, 0.0)];
        let positions: Vec<Vec3> = [0.0, 0.01, 0.02].into_iter().flat_map(strand).collect();
        // Roots 50, 100, 200 µm (median 100); tips 10, 20, 20 (median 20); a
        // root 200 × the median is clamped to 10.
        let thickness = vec![50e-6, 10e-6, 100e-6, 20e-6, 20e-3, 20e-6];
        let attributes = vkhair::groom::Attributes { thickness: Some(thickness), ..Default::default() };
        let groom = Groom::with_attributes(positions, &[2, 2, 2], attributes).expect("groom");
        let f = width_factors(&groom).expect("factors");
        let want = [[0.5, 0.5], [1.0, 1.0], [10.0, 1.0]];
        for (got, want) in f.iter().zip(want) {
            assert!((got[0] - want[0]).abs() < 1e-5 && (got[1] - want[1]).abs() < 1e-5, "{got:?} against {want:?}");
        }
        let bare = Groom::new(vec![Vec3::ZERO, Vec3::X], &[2]).expect("groom");
        assert!(width_factors(&bare).is_none());
    }
}
