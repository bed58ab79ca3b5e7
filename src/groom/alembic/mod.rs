//! Alembic grooms: `ICurves` objects of `.abc` files (the Ogawa container),
//! read by a small, strict reader of vkhair's own.
//!
//! What is read, from the first sample of each property (animated files give
//! their first frame):
//!
//! | object / property | use |
//! | --- | --- |
//! | `AbcGeom_Curve_v2` objects, anywhere in the tree | one curve object each |
//! | `.geom/P`, `.geom/nVertices` | the strands (P as 32- or 64-bit floats, 3 per point) |
//! | `.geom/curveBasisAndType` | linear; cubic B-spline, Catmull-Rom or Bézier; non-periodic |
//! | `.geom/width` (else `.arbGeomParams/groom_width`) | per-point thickness (diameter) |
//! | `.arbGeomParams/groom_color` | per-point colour |
//! | `.geom/uv` (else `.arbGeomParams/groom_root_uv`) | per-strand root UV |
//! | `.arbGeomParams/groom_guide` | per-strand guide mark (non-zero: a guide) |
//! | `AbcGeom_Xform_v3` objects (`.xform/.ops`, `.vals`, `.inherits`) | the transform of the objects below them |
//!
//! Geometry parameters may be plain arrays or `.vals` + `.indices`
//! compounds; their scope (`geoScope`: constant, uniform, varying, vertex)
//! says how values map to curves, inferred from the count when absent.
//! Alembic states no unit: the groom is taken as meters, +Y up (Alembic's
//! convention), and `--scale` applies.
//!
//! Refused, with the object and property named: HDF5 archives, unfinished
//! files, periodic curves and the Hermite, power and variable-order bases (or,
//! when repairing, such an object is passed over and said), 16-bit floats and
//! strings where numbers belong, counts that do not add up, any position or
//! length outside the file, more than [`MAX_DEPTH`] levels of objects or
//! [`MAX_OBJECTS`] objects, an object group listed twice (a cycle), more
//! curve points than a groom holds. Objects of other geometry (points, meshes) are
//! passed over and listed in [`AuthoredGroom::skipped`]. The file is read
//! whole, within [`MAX_ABC_BYTES`] (or `VKHAIR_MAX_INPUT_BYTES`).
//!
//! [`write`](mod@write) writes grooms in the same layout (for `vkhair convert` and for
//! tests of files this reader did not see written elsewhere).

mod abc;
mod ogawa;
pub mod write;

use std::path::Path;

use glam::{DMat4, DVec3, Vec2, Vec3};

use self::abc::{meta, Archive, Kind, PropertyHeader, Sample};
use self::ogawa::{malformed, Child};
use super::authored::{assemble, in_object, per_curve, per_point, AuthoredGroom, Basis, Frame, Interpolation};
use super::authored::{RawCurves, Topology, UpAxis, Values};
use super::repair::Load;
use super::{Repairs, MAX_POINTS};
use crate::error::{Error, FileFormat, Result};

/// The largest Alembic file read by default (1 GiB).
pub const MAX_ABC_BYTES: u64 = 1 << 30;
/// The deepest nesting of objects read.
pub const MAX_DEPTH: usize = 256;
/// The most objects read.
pub const MAX_OBJECTS: usize = 1 << 20;
/// The most bytes decoding one file may allocate (2 GiB): group lists, object
/// and property headers with their metadata, values widened to numbers —
/// whatever the file's size, however often it points at the same bytes.
pub const MAX_ABC_DECODED: u64 = 2 << 30;

/// Reads the Alembic file at `path`, refusing any defect (see the module docs).
pub fn open(path: impl AsRef<Path>) -> Result<AuthoredGroom> {
    let path = path.as_ref();
    parse(&read(path)?).map_err(|e| e.in_asset(path))
}

/// Reads the Alembic file at `path`, repairing what can be repaired and
/// passing over objects of curves that are not strands.
pub fn open_repairing(path: impl AsRef<Path>) -> Result<(AuthoredGroom, Repairs)> {
    let path = path.as_ref();
    parse_repairing(&read(path)?).map_err(|e| e.in_asset(path))
}

/// Parses Alembic bytes, refusing any defect.
pub fn parse(bytes: &[u8]) -> Result<AuthoredGroom> {
    parse_as(bytes, Load::Strict).map(|(g, _)| g)
}

/// Parses Alembic bytes, repairing what can be repaired.
pub fn parse_repairing(bytes: &[u8]) -> Result<(AuthoredGroom, Repairs)> {
    parse_as(bytes, Load::Repair).map(|(g, r)| (g, r.unwrap_or_default()))
}

fn read(path: &Path) -> Result<Vec<u8>> {
    let bytes = crate::files::read_capped(path, crate::files::input_cap(MAX_ABC_BYTES)?, "an Alembic file")?;
    if bytes.is_empty() {
        // Named as empty, not as an archive cut short: a FIFO nothing wrote to reads so.
        use std::os::unix::fs::FileTypeExt;
        let fifo = std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo());
        let what = if fifo { "a FIFO nothing wrote to: it read as empty" } else { "the file is empty (0 bytes)" };
        return Err(Error::Malformed { format: FileFormat::Alembic, reason: what.into() }.in_asset(path));
    }
    Ok(bytes)
}

fn parse_as(bytes: &[u8], load: Load) -> Result<(AuthoredGroom, Option<Repairs>)> {
    let archive = Archive::open(bytes)?;
    let mut walk = Walk {
        archive: &archive,
        load,
        raw: Vec::new(),
        skipped: Vec::new(),
        objects: 0,
        seen: std::collections::HashSet::new(),
        points: 0,
    };
    walk.objects(&archive.top, "", DMat4::IDENTITY, 0)?;
    if walk.raw.is_empty() {
        let why = if walk.skipped.is_empty() { String::new() } else { format!(" ({})", walk.skipped.join("; ")) };
        return Err(malformed(format!("the archive has no curves object to read as hair{why}")));
    }
    let frame = Frame { format: FileFormat::Alembic, meters_per_unit: 1.0, units_stated: false, up_axis: UpAxis::Y };
    assemble(walk.raw, frame, walk.skipped, load)
}

/// Why an object was not read: passed over when repairing, or a defect.
enum Outcome {
    Skip(String),
    Fail(Error),
}

impl From<Error> for Outcome {
    fn from(e: Error) -> Self {
        Outcome::Fail(e)
    }
}

fn unsupported(reason: String) -> Error {
    Error::Unsupported { format: FileFormat::Alembic, reason }
}

struct Walk<'w, 'a> {
    archive: &'w Archive<'a>,
    load: Load,
    raw: Vec<RawCurves>,
    skipped: Vec<String>,
    objects: usize,
    /// Object group positions read so far.
    seen: std::collections::HashSet<u64>,
    /// Curve points read so far.
    points: usize,
}

impl Walk<'_, '_> {
    /// Reads the objects of `group`, which lie `depth + 1` levels down (the
    /// top object's children at level 1).
    fn objects(&mut self, group: &[Child], path: &str, parent: DMat4, depth: usize) -> Result<()> {
        for (header, at, child) in self.archive.children(group).map_err(|e| in_object(or_root(path), e))? {
            if depth >= MAX_DEPTH {
                return Err(malformed(format!("{path}/{}: objects nest deeper than {MAX_DEPTH} levels", header.name)));
            }
            self.objects += 1;
            if self.objects > MAX_OBJECTS {
                return Err(malformed(format!("more than {MAX_OBJECTS} objects")));
            }
            let here = format!("{path}/{}", header.name);
            // Every object is written once: a group listed again is a cycle or
            // a file made to read one object over and over.
            if at != 0 && !self.seen.insert(at) {
                return Err(malformed(format!("{here}: its group (byte {at}) belongs to another object too")));
            }
            let mut world = parent;
            match meta(&header.metadata, "schema").unwrap_or("") {
                "AbcGeom_Xform_v3" => world = xform(self.archive, &child, parent).map_err(|e| in_object(&here, e))?,
                "AbcGeom_Curve_v2" => match curves(self.archive, &child, world, &here) {
                    Ok(c) => {
                        self.points += c.points.len();
                        if self.points > MAX_POINTS {
                            return Err(Error::TooManyPoints { count: self.points as u64, max: MAX_POINTS as u64 });
                        }
                        self.raw.push(c)
                    }
                    Err(Outcome::Skip(why)) if self.load == Load::Repair => self.skipped.push(format!("{here}: {why}")),
                    Err(Outcome::Skip(why)) => return Err(in_object(&here, unsupported(why))),
                    Err(Outcome::Fail(e)) => return Err(in_object(&here, e)),
                },
                s if s.starts_with("AbcGeom_") => self.skipped.push(format!("{here}: an {s} object, not curves")),
                _ => {}
            }
            self.objects(&child, &here, world, depth + 1)?;
        }
        Ok(())
    }
}

fn or_root(path: &str) -> &str {
    if path.is_empty() {
        "/"
    } else {
        path
    }
}

/// A property of `props` by name.
fn find<'p>(props: &'p [(PropertyHeader, Child)], name: &str) -> Option<&'p (PropertyHeader, Child)> {
    props.iter().find(|(h, _)| h.name == name)
}

/// The properties of the compound `name` in `props` (none when absent).
fn compound(a: &Archive<'_>, props: &[(PropertyHeader, Child)], name: &str) -> Result<Vec<(PropertyHeader, Child)>> {
    match find(props, name) {
        Some((h, c)) if h.kind == Kind::Compound => a.properties(&a.file.group_of(*c, name)?),
        Some(_) => Err(malformed(format!("{name} is not a compound property"))),
        None => Ok(Vec::new()),
    }
}

/// The first sample of `name` as numbers, checked to have `extent` values per element.
fn numbers(a: &Archive<'_>, props: &[(PropertyHeader, Child)], name: &str, extent: usize) -> Result<Option<Vec<f64>>> {
    let Some((h, c)) = find(props, name) else { return Ok(None) };
    let Some(sample) = a.first_sample(h, *c)? else { return Ok(None) };
    checked(a, name, sample, extent).map(Some)
}

fn checked(a: &Archive<'_>, name: &str, sample: Sample<'_>, extent: usize) -> Result<Vec<f64>> {
    if sample.extent != extent {
        return Err(malformed(format!("{name} has {} values per element; {extent} belong there", sample.extent)));
    }
    a.file.charge((sample.len() as u64).saturating_mul(8), name)?;
    sample.numbers().ok_or_else(|| malformed(format!("{name} holds {:?} values, not numbers", sample.pod)))
}

/// The object's transform in the world: its `.xform` ops composed, after its
/// parent's unless it does not inherit.
fn xform(a: &Archive<'_>, object: &[Child], parent: DMat4) -> Result<DMat4> {
    let props = a.object_properties(object)?;
    let x = compound(a, &props, ".xform")?;
    let ops: Vec<u8> = match find(&x, ".ops") {
        Some((h, c)) => match a.first_sample(h, *c)? {
            Some(s) => checked(a, ".xform/.ops", s, s.extent)?.into_iter().map(|v| v as u8).collect(),
            None => Vec::new(),
        },
        None => Vec::new(),
    };
    let vals: Vec<f64> = match find(&x, ".vals") {
        Some((h, c)) => match a.first_sample(h, *c)? {
            Some(s) => checked(a, ".xform/.vals", s, s.extent)?,
            None => Vec::new(),
        },
        None => Vec::new(),
    };
    let inherits = numbers(a, &x, ".inherits", 1)?.and_then(|v| v.first().copied()).is_none_or(|v| v != 0.0);
    let mut local = DMat4::IDENTITY;
    let mut at = 0usize;
    for (i, &op) in ops.iter().enumerate() {
        let n = match op >> 4 {
            0 | 1 => 3,
            2 => 4,
            3 => 16,
            4..=6 => 1,
            t => return Err(malformed(format!(".xform/.ops: op {i} has type {t}"))),
        };
        let v = vals
            .get(at..at + n)
            .ok_or_else(|| malformed(format!(".xform/.vals has {} values; its ops need more", vals.len())))?;
        at += n;
        let axis =
            |x: DVec3| x.try_normalize().ok_or_else(|| malformed(format!(".xform: op {i} rotates about a zero axis")));
        let m = match op >> 4 {
            0 => DMat4::from_scale(DVec3::new(v[0], v[1], v[2])),
            1 => DMat4::from_translation(DVec3::new(v[0], v[1], v[2])),
            2 => DMat4::from_axis_angle(axis(DVec3::new(v[0], v[1], v[2]))?, v[3].to_radians()),
            3 => DMat4::from_cols_array(v.try_into().map_err(|_| malformed(".xform: a matrix of the wrong size"))?),
            4 => DMat4::from_rotation_x(v[0].to_radians()),
            5 => DMat4::from_rotation_y(v[0].to_radians()),
            _ => DMat4::from_rotation_z(v[0].to_radians()),
        };
        // The first op is outermost (Alembic composes row vectors).
        local *= m;
    }
    let world = if inherits { parent * local } else { local };
    if !world.is_finite() {
        return Err(malformed(".xform: the transform is not finite"));
    }
    Ok(world)
}

/// A geometry parameter's first sample: its values (indices applied), `extent`
/// per element, and its declared scope.
struct Param {
    values: Vec<f64>,
    scope: Option<Interpolation>,
    name: &'static str,
}

/// The geometry parameter `name` of `props`: a plain array or scalar, or a
/// compound of `.vals` and `.indices`.
fn geom_param(
    a: &Archive<'_>,
    props: &[(PropertyHeader, Child)],
    name: &'static str,
    extent: usize,
) -> Result<Option<Param>> {
    let Some((h, c)) = find(props, name) else { return Ok(None) };
    let mut scope = scope_of(&h.metadata);
    if h.kind != Kind::Compound {
        let values = a.first_sample(h, *c)?.map(|s| checked(a, name, s, extent)).transpose()?;
        return Ok(values.map(|values| Param { values, scope, name }));
    }
    let inner = a.properties(&a.file.group_of(*c, name)?)?;
    let Some(vals) = numbers(a, &inner, ".vals", extent).map_err(|e| in_object(name, e))? else { return Ok(None) };
    scope = scope.or_else(|| find(&inner, ".vals").and_then(|(h, _)| scope_of(&h.metadata)));
    let values = match numbers(a, &inner, ".indices", 1).map_err(|e| in_object(name, e))? {
        None => vals,
        Some(indices) => {
            let mut out = Vec::with_capacity(indices.len().saturating_mul(extent));
            for &i in &indices {
                let i = if i >= 0.0 && i.fract() == 0.0 { i as usize } else { usize::MAX / 2 };
                let v = vals.get(i.saturating_mul(extent)..i.saturating_add(1).saturating_mul(extent)).ok_or_else(
                    || malformed(format!("{name}/.indices points past its {} values", vals.len() / extent)),
                )?;
                out.extend_from_slice(v);
            }
            out
        }
    };
    Ok(Some(Param { values, scope, name }))
}

/// A `geoScope` as an interpolation (face-varying taken as varying on curves).
fn scope_of(metadata: &str) -> Option<Interpolation> {
    match meta(metadata, "geoScope")? {
        "con" => Some(Interpolation::Constant),
        "uni" => Some(Interpolation::Uniform),
        "var" | "fvr" => Some(Interpolation::Varying),
        "vtx" => Some(Interpolation::Vertex),
        _ => None,
    }
}

impl Param {
    /// Elements of `extent` values each, with the declared scope or, when
    /// none is, the one their count matches.
    fn elements<T>(self, extent: usize, topology: &Topology<'_>, make: impl Fn(&[f64]) -> T) -> Result<Values<T>> {
        let elements: Vec<T> = self.values.chunks_exact(extent).map(make).collect();
        let points: usize = topology.counts.iter().map(|&n| n as usize).sum();
        let scope = match self.scope {
            Some(s) => s,
            None if elements.len() == 1 => Interpolation::Constant,
            None if elements.len() == topology.counts.len() => Interpolation::Uniform,
            None if elements.len() == points => Interpolation::Vertex,
            None => {
                return Err(malformed(format!(
                    "{} has {} values and no geoScope; it matches neither the {} curves nor the {points} points",
                    self.name,
                    elements.len(),
                    topology.counts.len()
                )))
            }
        };
        Ok((elements, scope))
    }
}

/// The first of two geometry parameters present.
fn either(
    a: &Archive<'_>,
    first: (&[(PropertyHeader, Child)], &'static str),
    second: (&[(PropertyHeader, Child)], &'static str),
    extent: usize,
) -> Result<Option<Param>> {
    match geom_param(a, first.0, first.1, extent)? {
        Some(p) => Ok(Some(p)),
        None => geom_param(a, second.0, second.1, extent),
    }
}

/// A curves object's strands and attributes.
fn curves(a: &Archive<'_>, object: &[Child], world: DMat4, path: &str) -> std::result::Result<RawCurves, Outcome> {
    let props = a.object_properties(object)?;
    let geom = compound(a, &props, ".geom")?;
    let arb = compound(a, &geom, ".arbGeomParams")?;
    let (kind, wrap, basis) = match numbers(a, &geom, "curveBasisAndType", 4)? {
        Some(v) if v.len() == 4 => (v[0] as u8, v[1] as u8, v[2] as u8),
        Some(v) => return Err(malformed(format!("curveBasisAndType has {} values, not 4", v.len())).into()),
        None => return Err(malformed("it has no curveBasisAndType").into()),
    };
    let basis = match (kind, basis) {
        (1, _) => Basis::Linear,
        (0, 1) => Basis::Bezier,
        (0, 2) => Basis::Bspline,
        (0, 3) => Basis::CatmullRom,
        (0, 4) => return Err(Outcome::Skip("the Hermite basis is not read".into())),
        (0, 5) => return Err(Outcome::Skip("the power basis is not read".into())),
        (0, b) => return Err(malformed(format!("a cubic curve with basis {b}")).into()),
        (2, _) => return Err(Outcome::Skip("variable-order (NURBS) curves are not read".into())),
        (t, _) => return Err(malformed(format!("curve type {t}")).into()),
    };
    match wrap {
        0 => {}
        1 => return Err(Outcome::Skip("periodic curves are loops, not strands rooted at one end".into())),
        w => return Err(malformed(format!("curve periodicity {w}")).into()),
    }
    let counts = numbers(a, &geom, "nVertices", 1)?.ok_or_else(|| malformed("it has no nVertices"))?;
    let counts = counts
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            (n >= 0.0 && n <= f64::from(u32::MAX))
                .then_some(n as u32)
                .ok_or_else(|| malformed(format!("nVertices: curve {i} has {n} points")))
        })
        .collect::<Result<Vec<u32>>>()?;
    let p = numbers(a, &geom, "P", 3)?.ok_or_else(|| malformed("it has no P"))?;
    let total: u64 = counts.iter().map(|&n| u64::from(n)).sum();
    if total != (p.len() / 3) as u64 {
        return Err(malformed(format!("nVertices add up to {total} points but P holds {}", p.len() / 3)).into());
    }
    let points = p.chunks_exact(3).map(|c| world.transform_point3(DVec3::new(c[0], c[1], c[2]))).collect();
    let topology = Topology { counts: &counts, basis, pinned: false };
    let width_scale = world.determinant().abs().cbrt() as f32;
    let widths = match either(a, (&geom, "width"), (&arb, "groom_width"), 1)? {
        Some(w) => {
            let name = w.name;
            let w = w.elements(1, &topology, |v| v[0] as f32 * width_scale)?;
            Some(per_point(name, w, &topology)?)
        }
        None => None,
    };
    let colors = match geom_param(a, &arb, "groom_color", 3)? {
        Some(c) => Some(per_point(
            "groom_color",
            c.elements(3, &topology, |v| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))?,
            &topology,
        )?),
        None => None,
    };
    let root_uvs = match either(a, (&geom, "uv"), (&arb, "groom_root_uv"), 2)? {
        Some(uv) => {
            let name = uv.name;
            Some(per_curve(name, uv.elements(2, &topology, |v| Vec2::new(v[0] as f32, v[1] as f32))?, &topology)?)
        }
        None => None,
    };
    let guides = match geom_param(a, &arb, "groom_guide", 1)? {
        Some(g) => Some(per_curve("groom_guide", g.elements(1, &topology, |v| v[0] != 0.0)?, &topology)?),
        None => None,
    };
    Ok(RawCurves { path: path.to_owned(), basis, counts, points, widths, colors, guides, root_uvs })
}
