//! Universal Scene Description grooms: `BasisCurves` prims of `.usda`, `.usdc`
//! and `.usd` stages, read with the `openusd` crate (composition included).
//!
//! What is read, per `BasisCurves` prim the stage's default traversal reaches
//! (active, loaded, defined, not abstract):
//!
//! | property | use |
//! | --- | --- |
//! | `curveVertexCounts`, `points` | the strands, with the prim's composed transform (its `xformOp`s and its ancestors') |
//! | `type`, `basis`, `wrap` | linear; cubic B-spline, Catmull-Rom or Bézier; non-periodic or pinned (see [`super::authored`]) |
//! | `widths` (else `primvars:groom_width`) | per-point thickness (diameter), scaled like the points |
//! | `primvars:displayColor` (else `primvars:groom_color`) | per-point colour |
//! | `primvars:groom_root_uv` (else `primvars:st`) | per-strand root UV |
//! | `primvars:groom_guide` | per-strand guide mark (non-zero: a guide) |
//!
//! Primvars honour their `interpolation` (`constant`, `uniform`, `varying`,
//! `vertex`) and `:indices`. Values and transforms are read at the earliest
//! time: an attribute's first time sample, else its default. The stage's `metersPerUnit` (USD's fallback 0.01 when not
//! authored) and `upAxis` (fallback Y) are honoured: the groom comes out in
//! meters, +Y up.
//!
//! Refused, with the prim and property named: periodic curves (loops, not
//! strands rooted at one end) and the Hermite and power bases — or, when
//! repairing, such a prim is passed over and [`AuthoredGroom::skipped`] says
//! so; `NurbsCurves` and `HermiteCurves` prims are always passed over that
//! way; mismatched counts, a missing `points`, values of the wrong type.
//! Prims of other types (meshes, cameras, materials) are not read. A stage
//! without any `BasisCurves` prim is refused. The root file must be a regular
//! file within [`MAX_USD_BYTES`] (or `VKHAIR_MAX_INPUT_BYTES`).

use std::path::Path;

use glam::{DMat4, DVec3, Vec2, Vec3};
use openusd::schemas::geom::Xformable;
use openusd::sdf;
use openusd::usd::{Prim, PrimPredicate, SchemaBase, SchemaKind, Stage, TimeCode};

use super::authored::{
    assemble, in_object, per_curve, per_point, AuthoredGroom, Basis, Frame, Interpolation, RawCurves, Topology, UpAxis,
    Values,
};
use super::repair::Load;
use super::Repairs;
use crate::error::{Error, FileFormat, Result};

/// The largest USD root file read by default (1 GiB).
pub const MAX_USD_BYTES: u64 = 1 << 30;

/// Reads the USD stage at `path`, refusing any defect (see the module docs).
pub fn open(path: impl AsRef<Path>) -> Result<AuthoredGroom> {
    open_as(path.as_ref(), Load::Strict).map(|(g, _)| g)
}

/// Reads the USD stage at `path`, repairing what can be repaired (see
/// [`super::Groom::repaired`]) and passing over prims of curves that are not
/// strands.
pub fn open_repairing(path: impl AsRef<Path>) -> Result<(AuthoredGroom, Repairs)> {
    open_as(path.as_ref(), Load::Repair).map(|(g, r)| (g, r.unwrap_or_default()))
}

fn open_as(path: &Path, load: Load) -> Result<(AuthoredGroom, Option<Repairs>)> {
    let cap = crate::files::input_cap(MAX_USD_BYTES)?;
    super::usd_layers::check_layers(path, cap)?;
    let text = path.to_str().ok_or_else(|| Error::Asset {
        path: path.into(),
        source: Box::new(unsupported("the path is not UTF-8 text".into())),
    })?;
    // The crate is young: a panic inside it on a malformed file is reported as
    // the file's defect, silently, rather than taking the host down.
    let read = crate::files::read_guarded(|| read_stage(text, load))
        .unwrap_or_else(|what| Err(malformed(format!("the USD reader stopped: {what}"))));
    let (raw, frame, skipped) = read.map_err(|e| e.in_asset(path))?;
    assemble(raw, frame, skipped, load).map_err(|e| e.in_asset(path))
}

pub use super::usd_layers::MAX_USD_LAYERS;

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

fn unsupported(reason: String) -> Error {
    Error::Unsupported { format: FileFormat::Usd, reason }
}

/// An `openusd` error as a malformed-file error.
fn usd_error(e: anyhow::Error) -> Error {
    malformed(format!("{e:#}"))
}

type Read = (Vec<RawCurves>, Frame, Vec<String>);

fn read_stage(path: &str, load: Load) -> Result<Read> {
    let stage = Stage::open(path).map_err(usd_error)?;
    let frame = stage_frame(&stage)?;
    let mut paths = Vec::new();
    // Into instances too: an instanceable prim's curves are the groom's as
    // much as any (the default traversal stops at it, and they were dropped).
    stage.traverse(PrimPredicate::DEFAULT_PROXIES, |p| paths.push(p.clone())).map_err(usd_error)?;
    // What the library dropped while composing (an arc it could not follow,
    // a layer it could not use) is an error, never a stage read without it.
    let errors = stage.composition_errors();
    if let Some(first) = errors.first() {
        let more = match errors.len() {
            1 => String::new(),
            n => format!(" (and {} more)", n - 1),
        };
        return Err(malformed(format!("the USD library could not compose the stage: {first}{more}")));
    }
    let (mut raw, mut skipped) = (Vec::new(), Vec::new());
    for p in paths {
        let prim = stage.prim(p.clone());
        let ty = prim.type_name().map_err(usd_error)?;
        match ty.as_ref().map(|t| t.as_str()) {
            Some("BasisCurves") => match read_curves(&prim) {
                Ok(curves) => raw.push(curves),
                Err(Skip(reason)) if load == Load::Repair => skipped.push(format!("{}: {reason}", p.as_str())),
                Err(Skip(reason)) => return Err(in_object(p.as_str(), unsupported(reason))),
                Err(Fail(e)) => return Err(in_object(p.as_str(), e)),
            },
            Some(t @ ("NurbsCurves" | "HermiteCurves")) => {
                skipped.push(format!("{}: {t} prims are not read (BasisCurves are)", p.as_str()))
            }
            _ => {}
        }
    }
    if raw.is_empty() {
        let why = if skipped.is_empty() { String::new() } else { format!(" ({})", skipped.join("; ")) };
        return Err(malformed(format!("the stage has no BasisCurves prim to read as hair{why}")));
    }
    Ok((raw, frame, skipped))
}

/// The stage's unit and up axis, with USD's fallbacks.
fn stage_frame(stage: &Stage) -> Result<Frame> {
    let mpu = stage.stage_metadata("metersPerUnit").map_err(usd_error)?;
    let (meters_per_unit, units_stated) = match mpu {
        None => (0.01, false),
        Some(v) => match v {
            sdf::Value::Double(d) => (d, true),
            sdf::Value::Float(f) => (f64::from(f), true),
            other => return Err(malformed(format!("metersPerUnit is {other:?}, not a number"))),
        },
    };
    if !(meters_per_unit.is_finite() && meters_per_unit > 0.0) {
        return Err(malformed(format!("metersPerUnit is {meters_per_unit}; it must be a finite number above 0")));
    }
    let up_axis = match stage.stage_metadata("upAxis").map_err(usd_error)? {
        None => UpAxis::Y,
        Some(v) => match token(&v).as_deref() {
            Some("Y") => UpAxis::Y,
            Some("Z") => UpAxis::Z,
            _ => return Err(malformed(format!("upAxis is {v:?}; USD allows \"Y\" or \"Z\""))),
        },
    };
    Ok(Frame { format: FileFormat::Usd, meters_per_unit, units_stated: true, up_axis })
        .map(|f| Frame { units_stated, ..f })
}

fn token(v: &sdf::Value) -> Option<String> {
    match v {
        sdf::Value::Token(t) => Some(t.as_str().to_owned()),
        sdf::Value::String(s) => Some(s.clone()),
        _ => None,
    }
}

/// Why a prim was not read: passed over when repairing, or a real defect.
enum Outcome {
    Skip(String),
    Fail(Error),
}
use Outcome::{Fail, Skip};

impl From<Error> for Outcome {
    fn from(e: Error) -> Self {
        Fail(e)
    }
}

/// Any prim as an `Xformable`, to compose its `xformOp`s.
struct AnyXformable(Prim);

impl SchemaBase for AnyXformable {
    const KIND: SchemaKind = SchemaKind::AbstractTyped;
    fn prim(&self) -> &Prim {
        &self.0
    }
}
impl openusd::schemas::geom::Imageable for AnyXformable {}
impl Xformable for AnyXformable {}

/// The prim's local-to-world transform at its first time sample (column vectors).
fn world_transform(prim: &Prim) -> Result<DMat4> {
    let mut world = DMat4::IDENTITY;
    let mut at = Some(prim.path().clone());
    while let Some(path) = at {
        if path.as_str() == "/" {
            break;
        }
        let x = AnyXformable(prim.stage().prim(path.clone()));
        let m = x.local_to_parent_transform(TimeCode::EARLIEST).map_err(usd_error)?;
        // USD's row-major matrix acting on row vectors, read as columns, is
        // glam's matrix acting on column vectors; the parent applies after.
        world = DMat4::from_cols_array(&m.0) * world;
        if x.resets_xform_stack().map_err(usd_error)? {
            break;
        }
        at = path.parent();
    }
    if !world.is_finite() {
        return Err(malformed("the prim's transform is not finite".into()));
    }
    Ok(world)
}

/// An attribute's value at the stage's earliest time: its first time sample,
/// else its default (USD's resolution at a time); a blocked value counts as
/// none. The transforms are read at the same time.
fn value(prim: &Prim, name: &str) -> Result<Option<sdf::Value>> {
    let attr = prim.attribute(name);
    let v = match attr.get_at::<sdf::Value>(TimeCode::EARLIEST).map_err(usd_error)? {
        Some(v) => Some(v),
        None => attr.get::<sdf::Value>().map_err(usd_error)?,
    };
    Ok(v.filter(|v| !matches!(v, sdf::Value::ValueBlock | sdf::Value::None)))
}

/// A token-valued attribute, `fallback` when not authored.
fn token_attr(prim: &Prim, name: &str, fallback: &str) -> Result<String> {
    match value(prim, name)? {
        None => Ok(fallback.to_owned()),
        Some(v) => token(&v).ok_or_else(|| malformed(format!("{name} is {v:?}, not a token"))),
    }
}

/// The attribute's `interpolation` metadata, `fallback` when not authored.
fn interpolation(prim: &Prim, name: &str, fallback: Interpolation) -> Result<Interpolation> {
    let v = prim.attribute(name).get_metadata::<sdf::Value>("interpolation").map_err(usd_error)?;
    let Some(v) = v else { return Ok(fallback) };
    match token(&v).as_deref() {
        Some("constant") => Ok(Interpolation::Constant),
        Some("uniform") => Ok(Interpolation::Uniform),
        // Face-varying is varying on curves.
        Some("varying" | "faceVarying") => Ok(Interpolation::Varying),
        Some("vertex") => Ok(Interpolation::Vertex),
        _ => {
            Err(malformed(format!("{name} has interpolation {v:?}; curves take constant, uniform, varying or vertex")))
        }
    }
}

fn floats(v: sdf::Value) -> Option<Vec<f32>> {
    match v {
        sdf::Value::FloatVec(v) => Some(v),
        sdf::Value::DoubleVec(v) => Some(v.into_iter().map(|x| x as f32).collect()),
        sdf::Value::Float(x) => Some(vec![x]),
        sdf::Value::Double(x) => Some(vec![x as f32]),
        _ => None,
    }
}

fn vec3s(v: sdf::Value) -> Option<Vec<DVec3>> {
    match v {
        sdf::Value::Vec3fVec(v) => {
            Some(v.into_iter().map(|p| DVec3::new(p.x.into(), p.y.into(), p.z.into())).collect())
        }
        sdf::Value::Vec3dVec(v) => Some(v.into_iter().map(|p| DVec3::new(p.x, p.y, p.z)).collect()),
        sdf::Value::Vec3f(p) => Some(vec![DVec3::new(p.x.into(), p.y.into(), p.z.into())]),
        _ => None,
    }
}

fn vec2s(v: sdf::Value) -> Option<Vec<Vec2>> {
    match v {
        sdf::Value::Vec2fVec(v) => Some(v.into_iter().map(|p| Vec2::new(p.x, p.y)).collect()),
        sdf::Value::Vec2dVec(v) => Some(v.into_iter().map(|p| Vec2::new(p.x as f32, p.y as f32)).collect()),
        _ => None,
    }
}

fn flags(v: sdf::Value) -> Option<Vec<bool>> {
    match v {
        sdf::Value::IntVec(v) => Some(v.into_iter().map(|x| x != 0).collect()),
        sdf::Value::BoolVec(v) => Some(v),
        sdf::Value::FloatVec(v) => Some(v.into_iter().map(|x| x != 0.0).collect()),
        sdf::Value::Int(x) => Some(vec![x != 0]),
        sdf::Value::Bool(x) => Some(vec![x]),
        _ => None,
    }
}

/// A primvar (or plain attribute) `name` decoded by `decode`, its `:indices`
/// applied: `(values, interpolation)`, or `None` when not authored.
fn primvar<T: Copy>(
    prim: &Prim,
    name: &str,
    fallback: Interpolation,
    what: &str,
    decode: fn(sdf::Value) -> Option<Vec<T>>,
) -> Result<Option<Values<T>>> {
    let Some(v) = value(prim, name)? else { return Ok(None) };
    let shown = format!("{v:?}");
    let values = decode(v).ok_or_else(|| {
        malformed(format!("{name} holds {}…, not {what}", shown.chars().take(40).collect::<String>()))
    })?;
    let values = match value(prim, &format!("{name}:indices"))? {
        None => values,
        Some(sdf::Value::IntVec(indices)) => indices
            .iter()
            .map(|&i| usize::try_from(i).ok().and_then(|i| values.get(i).copied()))
            .collect::<Option<Vec<T>>>()
            .ok_or_else(|| malformed(format!("{name}:indices points past its {} values", values.len())))?,
        Some(other) => return Err(malformed(format!("{name}:indices is {other:?}, not int[]"))),
    };
    Ok(Some((values, interpolation(prim, name, fallback)?)))
}

/// The first of `names` the prim has, decoded (see [`primvar`]).
fn first_of<T: Copy>(
    prim: &Prim,
    names: [&'static str; 2],
    fallback: Interpolation,
    what: &str,
    decode: fn(sdf::Value) -> Option<Vec<T>>,
) -> Result<Option<(&'static str, Values<T>)>> {
    for name in names {
        if let Some(v) = primvar(prim, name, fallback, what, decode)? {
            return Ok(Some((name, v)));
        }
    }
    Ok(None)
}

fn read_curves(prim: &Prim) -> std::result::Result<RawCurves, Outcome> {
    let ty = token_attr(prim, "type", "cubic")?;
    let basis_token = token_attr(prim, "basis", "bezier")?;
    let wrap = token_attr(prim, "wrap", "nonperiodic")?;
    let basis = match (ty.as_str(), basis_token.as_str()) {
        ("linear", _) => Basis::Linear,
        ("cubic", "bspline") => Basis::Bspline,
        ("cubic", "catmullRom") => Basis::CatmullRom,
        ("cubic", "bezier") => Basis::Bezier,
        ("cubic", b) => return Err(Skip(format!("the {b} basis is not read (bspline, catmullRom and bezier are)"))),
        (t, _) => return Err(Fail(malformed(format!("type is \"{t}\"; BasisCurves are linear or cubic")))),
    };
    match wrap.as_str() {
        "nonperiodic" | "pinned" => {}
        "periodic" => return Err(Skip("periodic curves are loops, not strands rooted at one end".into())),
        w => return Err(Fail(malformed(format!("wrap is \"{w}\"; USD allows nonperiodic, periodic or pinned")))),
    }
    let counts = match value(prim, "curveVertexCounts")? {
        Some(sdf::Value::IntVec(c)) => c,
        Some(other) => return Err(Fail(malformed(format!("curveVertexCounts is {other:?}, not int[]")))),
        None => return Err(Fail(malformed("it has no curveVertexCounts".into()))),
    };
    let counts = counts
        .iter()
        .enumerate()
        .map(|(i, &n)| u32::try_from(n).map_err(|_| malformed(format!("curve {i} has {n} vertices"))))
        .collect::<Result<Vec<u32>>>()?;
    let Some(points) = value(prim, "points")? else {
        return Err(Fail(malformed("it has no points".into())));
    };
    let points = vec3s(points).ok_or_else(|| malformed("points is not point3f[] or point3d[]".into()))?;
    let total: u64 = counts.iter().map(|&n| u64::from(n)).sum();
    if total != points.len() as u64 {
        return Err(Fail(malformed(format!(
            "curveVertexCounts add up to {total} points but points holds {}",
            points.len()
        ))));
    }
    let world = world_transform(prim)?;
    let width_scale = world.determinant().abs().cbrt() as f32;
    let points = points.into_iter().map(|p| world.transform_point3(p)).collect();
    let topology = Topology { counts: &counts, basis, pinned: wrap == "pinned" };
    let widths = first_of(prim, ["widths", "primvars:groom_width"], Interpolation::Vertex, "widths (float[])", floats)?
        .map(|(name, v)| per_point(name, v, &topology))
        .transpose()?
        .map(|w| w.into_iter().map(|w| w * width_scale).collect());
    let color_names = ["primvars:displayColor", "primvars:groom_color"];
    let colors = first_of(prim, color_names, Interpolation::Constant, "colours (color3f[])", vec3s)?
        .map(|(name, (v, i))| {
            per_point(name, (v.into_iter().map(|c| c.as_vec3()).collect::<Vec<Vec3>>(), i), &topology)
        })
        .transpose()?;
    let uv_names = ["primvars:groom_root_uv", "primvars:st"];
    let root_uvs = first_of(prim, uv_names, Interpolation::Constant, "texture coordinates (float2[])", vec2s)?
        .map(|(name, v)| per_curve(name, v, &topology))
        .transpose()?;
    let guides = primvar(prim, "primvars:groom_guide", Interpolation::Constant, "guide marks (int[])", flags)?
        .map(|v| per_curve("primvars:groom_guide", v, &topology))
        .transpose()?;
    Ok(RawCurves { path: prim.path().as_str().to_owned(), basis, counts, points, widths, colors, guides, root_uvs })
}
