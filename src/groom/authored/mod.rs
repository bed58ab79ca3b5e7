//! Curves as artists' tools write them (USD, Alembic), on their way to a [`Groom`].
//!
//! The readers ([`super::usd`], [`super::alembic`]) each hand this module one
//! set of raw curves per curve object, in the file's units and axes with the
//! object's transform applied, which it turns into one [`AuthoredGroom`]:
//!
//! 1. cubic Bézier strands become the points on the curve at each segment's
//!    thirds (a strand keeps its point count and passes through its ends);
//!    linear, B-spline and Catmull-Rom strands keep their points (vkhair's
//!    tessellation smooths every strand as a B-spline of its points), except
//!    that a B-spline's end point repeated to pin the curve to it (as groom
//!    exporters write them: three or more equal points at the root or the
//!    tip) is kept once;
//! 2. lengths become meters (the file's unit) and a Z-up file turns to Y up
//!    (`(x, y, z)` → `(x, z, −y)`), widths scaled like lengths;
//! 3. the strands of every object are concatenated in file order, then checked
//!    strictly or repaired ([`Groom::repaired`]) as for `.hair` files; per-strand
//!    attributes follow the strands kept, and an error names the object with the
//!    strand counted within it.
//!
//! Attributes: a per-point width (diameter) becomes the groom's thickness, a
//! colour its per-point colours; where only some objects have one, the
//! attribute is dropped and [`AuthoredGroom::skipped`] says so.

use glam::{DVec3, Vec2, Vec3};

use super::repair::Load;
use super::{Attributes, Groom, Repairs, MAX_POINTS, MAX_STRANDS};
use crate::error::{Error, Result};

mod locate;
pub(crate) use locate::in_object;
use locate::{locate, object_of, strand_of_point};

/// The axis a file calls up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    /// +Y up (vkhair's own frame).
    Y,
    /// +Z up (turned to Y up on import).
    Z,
}

/// How a curve's points make its shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// A polyline through the points.
    Linear,
    /// A cubic B-spline with the points as control points.
    Bspline,
    /// A cubic Catmull-Rom spline through the points.
    CatmullRom,
    /// Cubic Bézier segments of four points sharing their ends (3k + 1 points).
    Bezier,
}

impl std::fmt::Display for Basis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Basis::Linear => "linear",
            Basis::Bspline => "cubic B-spline",
            Basis::CatmullRom => "cubic Catmull-Rom",
            Basis::Bezier => "cubic Bézier",
        })
    }
}

/// One curve object as a reader found it: the file's units and axes, the
/// object's transform applied, attributes already one per point or per strand.
#[derive(Debug, Clone)]
pub(crate) struct RawCurves {
    /// The prim or object path.
    pub path: String,
    /// The curves' basis.
    pub basis: Basis,
    /// Points per curve.
    pub counts: Vec<u32>,
    /// Every curve's points, curve after curve.
    pub points: Vec<DVec3>,
    /// Per-point width (diameter), in the points' units.
    pub widths: Option<Vec<f32>>,
    /// Per-point linear RGB colour.
    pub colors: Option<Vec<Vec3>>,
    /// Per-curve guide mark.
    pub guides: Option<Vec<bool>>,
    /// Per-curve root UV.
    pub root_uvs: Option<Vec<Vec2>>,
}

/// One curve object of the file, as read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CurveObject {
    /// The prim or object path.
    pub path: String,
    /// Curves it holds (before any repair).
    pub curves: usize,
    /// Their basis.
    pub basis: Basis,
}

/// A groom read from a USD or Alembic file.
#[derive(Debug, Clone, PartialEq)]
pub struct AuthoredGroom {
    /// Every strand of every curve object, in file order, in meters with +Y
    /// up; thickness from the widths, colours from the file's colours.
    pub groom: Groom,
    /// Per strand: whether the file marks it a guide (`groom_guide`); `None`
    /// when the file marks none.
    pub guides: Option<Vec<bool>>,
    /// Per strand: its root's texture coordinate, when the file has one.
    pub root_uvs: Option<Vec<Vec2>>,
    /// The curve objects read, in file order.
    pub objects: Vec<CurveObject>,
    /// Meters per file unit: what the file states (USD's `metersPerUnit`), or
    /// 1 for a format that states none (Alembic) — see `units_stated`.
    pub meters_per_unit: f64,
    /// Whether the file states its unit.
    pub units_stated: bool,
    /// The file's up axis (the groom is turned to +Y up already).
    pub up_axis: UpAxis,
    /// What the reader passed over and why (objects of other kinds of curve,
    /// attributes only some objects have).
    pub skipped: Vec<String>,
}

impl AuthoredGroom {
    /// Strands the file marks as guides (0 when it marks none).
    pub fn guide_count(&self) -> usize {
        self.guides.as_ref().map_or(0, |g| g.iter().filter(|&&g| g).count())
    }
}

/// A file's unit and axis, as its reader found them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    /// The format (for its errors).
    pub format: crate::error::FileFormat,
    /// Meters per unit.
    pub meters_per_unit: f64,
    /// Whether the file states it.
    pub units_stated: bool,
    /// The up axis.
    pub up_axis: UpAxis,
}

/// `values` for each point of curves of `counts` points: `values` gives one
/// value per curve and `per_point` spreads it; for a reader's uniform values.
pub(crate) fn per_point_from_curves<T: Copy>(values: &[T], counts: &[u32]) -> Vec<T> {
    values.iter().zip(counts).flat_map(|(&v, &n)| std::iter::repeat_n(v, n as usize)).collect()
}

/// Per-point values from `values` given at `k` evenly spaced places along each
/// curve (`per_curve(n)` of them for a curve of `n` points, e.g. USD's
/// `varying` values at segment ends), linearly interpolated; `None` when the
/// lengths do not add up.
pub(crate) fn per_point_from_spaced<T>(values: &[T], counts: &[u32], per_curve: impl Fn(u32) -> u32) -> Option<Vec<T>>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let needed: u64 = counts.iter().map(|&n| u64::from(per_curve(n))).sum();
    if needed != values.len() as u64 {
        return None;
    }
    let mut out = Vec::with_capacity(counts.iter().map(|&n| n as usize).sum());
    let mut at = 0usize;
    for &n in counts {
        let k = per_curve(n) as usize;
        let spaced = &values[at..at + k];
        at += k;
        for i in 0..n as usize {
            if k < 2 || n < 2 {
                out.push(*spaced.first()?);
                continue;
            }
            let u = i as f32 / (n - 1) as f32 * (k - 1) as f32;
            let j = (u.floor() as usize).min(k - 2);
            let f = u - j as f32;
            out.push(spaced[j] * (1.0 - f) + spaced[j + 1] * f);
        }
    }
    Some(out)
}

/// The points on a cubic Bézier strand at each segment's thirds, and its end:
/// as many points as control points. `None` unless `points.len()` is 3k + 1.
fn bezier_samples(points: &[DVec3]) -> Option<Vec<DVec3>> {
    if points.len() < 4 || !(points.len() - 1).is_multiple_of(3) {
        return None;
    }
    let mut out = Vec::with_capacity(points.len());
    for seg in points.windows(4).step_by(3) {
        for t in [0.0, 1.0 / 3.0, 2.0 / 3.0] {
            let s = 1.0 - t;
            out.push(
                seg[0] * (s * s * s) + seg[1] * (3.0 * s * s * t) + seg[2] * (3.0 * s * t * t) + seg[3] * (t * t * t),
            );
        }
    }
    out.push(*points.last()?);
    Some(out)
}

/// Keeps once each point a B-spline curve repeats at its root or tip (with its
/// per-point attributes), as exporters pin a B-spline to its ends.
fn collapse_pinned_ends(o: &mut RawCurves) {
    let mut keep = Vec::with_capacity(o.points.len());
    let mut at = 0usize;
    for n in o.counts.iter_mut() {
        let p = &o.points[at..at + *n as usize];
        // A run of three or more equal points at an end is the exporter's
        // pinning; a shorter one is a zero-length segment for the checks.
        let mut first = 0;
        while first + 2 < p.len() && p[first + 1] == p[first] {
            first += 1;
        }
        if first < 2 {
            first = 0;
        }
        let mut last = p.len().saturating_sub(1);
        while last > first + 1 && p[last - 1] == p[last] {
            last -= 1;
        }
        if p.len().saturating_sub(1) - last < 2 {
            last = p.len().saturating_sub(1);
        }
        if p.len() < 2 {
            first = 0;
            last = p.len().saturating_sub(1);
        }
        keep.extend((at + first..=at + last).take(p.len()));
        at += *n as usize;
        *n = if p.is_empty() { 0 } else { (last - first + 1) as u32 };
    }
    if keep.len() == o.points.len() {
        return;
    }
    o.points = keep.iter().map(|&i| o.points[i]).collect();
    if let Some(w) = &mut o.widths {
        *w = keep.iter().map(|&i| w[i]).collect();
    }
    if let Some(c) = &mut o.colors {
        *c = keep.iter().map(|&i| c[i]).collect();
    }
}

/// How a primvar's values map onto the curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Interpolation {
    /// One value for every curve.
    Constant,
    /// One value per curve.
    Uniform,
    /// One value per segment end (see [`Topology::varying`]).
    Varying,
    /// One value per point.
    Vertex,
}

/// A primvar's values and how they map onto the curves.
pub(crate) type Values<T> = (Vec<T>, Interpolation);

/// The curves' shape from the prim's own counts and basis.
pub(crate) struct Topology<'a> {
    /// Points per curve.
    pub counts: &'a [u32],
    /// The basis.
    pub basis: Basis,
    /// Whether the curves are pinned (a value at every point's segment end).
    pub pinned: bool,
}

impl Topology<'_> {
    /// `varying` values on a curve of `n` points: one per segment end.
    pub(crate) fn varying(&self, n: u32) -> u32 {
        match self.basis {
            Basis::Bspline | Basis::CatmullRom if self.pinned => n,
            Basis::Linear => n,
            Basis::Bspline | Basis::CatmullRom => n.saturating_sub(2),
            Basis::Bezier => n.saturating_sub(1) / 3 + 1,
        }
    }
}

/// Refuses a curve that a primvar of `interp` gives no value of its own: one
/// of no points, or a cubic curve too short for varying values.
fn check_valued(name: &'static str, interp: Interpolation, topology: &Topology<'_>) -> Result<()> {
    let empty = |n: u32| n == 0 || (interp == Interpolation::Varying && topology.varying(n) == 0);
    match topology.counts.iter().position(|&n| empty(n)) {
        Some(c) => Err(Error::param(
            name,
            format!("curve {c} of {} points", topology.counts[c]),
            "curves with a value of their own (at least one point; a cubic curve's varying values need four)",
        )),
        None => Ok(()),
    }
}

/// Per-point values of a primvar on `topology`'s curves.
pub(crate) fn per_point<T>(name: &'static str, (values, interp): Values<T>, topology: &Topology<'_>) -> Result<Vec<T>>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let counts = topology.counts;
    let points: usize = counts.iter().map(|&n| n as usize).sum();
    let expected = match interp {
        Interpolation::Constant => 1,
        Interpolation::Uniform => counts.len(),
        Interpolation::Vertex => points,
        Interpolation::Varying => counts.iter().map(|&n| topology.varying(n) as usize).sum(),
    };
    if values.len() != expected {
        return Err(Error::AttributeLength { what: name, expected, actual: values.len() });
    }
    check_valued(name, interp, topology)?;
    Ok(match interp {
        Interpolation::Constant => vec![values[0]; points],
        Interpolation::Uniform => per_point_from_curves(&values, counts),
        Interpolation::Vertex => values,
        Interpolation::Varying => per_point_from_spaced(&values, counts, |n| topology.varying(n))
            .ok_or(Error::AttributeLength { what: name, expected, actual: expected })?,
    })
}

/// Per-curve values of a primvar (a vertex or varying primvar gives each
/// curve its root's value).
pub(crate) fn per_curve<T: Copy>(
    name: &'static str,
    (values, interp): Values<T>,
    topology: &Topology<'_>,
) -> Result<Vec<T>> {
    let counts = topology.counts;
    let mut starts = Vec::with_capacity(counts.len());
    let mut at = 0usize;
    for &n in counts {
        starts.push(at);
        at += match interp {
            Interpolation::Varying => topology.varying(n) as usize,
            _ => n as usize,
        };
    }
    let expected = match interp {
        Interpolation::Constant => 1,
        Interpolation::Uniform => counts.len(),
        Interpolation::Vertex | Interpolation::Varying => at,
    };
    if values.len() != expected {
        return Err(Error::AttributeLength { what: name, expected, actual: values.len() });
    }
    check_valued(name, interp, topology)?;
    Ok(match interp {
        Interpolation::Constant => vec![values[0]; counts.len()],
        Interpolation::Uniform => values,
        Interpolation::Vertex | Interpolation::Varying => starts.iter().map(|&s| values[s]).collect(),
    })
}

/// The groom of `objects` (see the module docs), strict or repairing.
pub(crate) fn assemble(
    mut objects: Vec<RawCurves>,
    frame: Frame,
    mut skipped: Vec<String>,
    load: Load,
) -> Result<(AuthoredGroom, Option<Repairs>)> {
    if objects.is_empty() {
        return Err(Error::EmptyGroom);
    }
    let strands: u64 = objects.iter().map(|o| o.counts.len() as u64).sum();
    if strands > MAX_STRANDS as u64 {
        return Err(Error::TooManyStrands { count: strands, max: MAX_STRANDS as u64 });
    }
    if strands == 0 {
        // (Not "nothing left after repairing": there was nothing to repair.)
        let paths: Vec<&str> = objects.iter().map(|o| o.path.as_str()).collect();
        return Err(Error::Malformed {
            format: frame.format,
            reason: format!("its curve objects hold no curves ({}: no curve vertex counts)", paths.join(", ")),
        });
    }
    let points: u64 = objects.iter().map(|o| o.points.len() as u64).sum();
    if points > MAX_POINTS as u64 {
        return Err(Error::TooManyPoints { count: points, max: MAX_POINTS as u64 });
    }
    for o in &mut objects {
        let total: u64 = o.counts.iter().map(|&n| u64::from(n)).sum();
        if total != o.points.len() as u64 {
            return Err(in_object(
                &o.path,
                Error::AttributeLength {
                    what: "points (curve vertex counts)",
                    expected: total as usize,
                    actual: o.points.len(),
                },
            ));
        }
        if o.basis == Basis::Bspline {
            collapse_pinned_ends(o);
        }
        if o.basis == Basis::Bezier {
            let mut at = 0usize;
            let mut resampled = Vec::with_capacity(o.points.len());
            for (curve, &n) in o.counts.iter().enumerate() {
                let strand = &o.points[at..at + n as usize];
                at += n as usize;
                match bezier_samples(strand) {
                    Some(s) => resampled.extend(s),
                    // Fewer than four or not 3k + 1: left as a polyline, so that
                    // the checks below refuse or repair a 0- or 1-point curve as
                    // they do in every format.
                    None if n < 4 => resampled.extend_from_slice(strand),
                    None => {
                        return Err(in_object(
                            &o.path,
                            Error::Malformed {
                                format: frame.format,
                                reason: format!("Bézier curve {curve} has {n} points; a Bézier curve has 3k + 1"),
                            },
                        ))
                    }
                }
            }
            o.points = resampled;
        }
    }
    let k = frame.meters_per_unit;
    let to_y_up = |p: DVec3| match frame.up_axis {
        UpAxis::Y => p,
        UpAxis::Z => DVec3::new(p.x, p.z, -p.y),
    };
    let mut object_starts = Vec::with_capacity(objects.len());
    let (mut positions, mut counts) = (Vec::with_capacity(points as usize), Vec::with_capacity(strands as usize));
    for o in &objects {
        object_starts.push(counts.len());
        positions.extend(o.points.iter().map(|&p| (to_y_up(p) * k).as_vec3()));
        counts.extend_from_slice(&o.counts);
    }
    // Whatever the transforms and units did: a finite point farther than
    // MAX_COORDINATE_M from the origin is refused, named (non-finite ones are
    // the groom check's) — judged in double precision, before a point past
    // f32's range would become an infinity.
    let far = objects
        .iter()
        .flat_map(|o| o.points.iter())
        .map(|&p| to_y_up(p) * k)
        .position(|q| q.is_finite() && q.abs().max_element() > f64::from(MAX_COORDINATE_M));
    if let Some(i) = far {
        let (strand, first) = strand_of_point(&counts, i).unwrap_or((0, 0));
        let (object, local) = object_of(&object_starts, strand);
        let p = objects.iter().flat_map(|o| o.points.iter()).nth(i).map_or(DVec3::ZERO, |&p| to_y_up(p) * k);
        let reason = format!(
            "strand {local} point {} lies at ({:e}, {:e}, {:e}) m after its transforms and the stage's units: \
             a groom lies within {MAX_COORDINATE_M:e} m of the origin",
            i - first,
            p.x,
            p.y,
            p.z
        );
        return Err(in_object(&objects[object].path, Error::Malformed { format: frame.format, reason }));
    }
    // An object shrunk to nothing (a scale of 0, metersPerUnit 1e-30) is named.
    for o in &objects {
        let (lo, hi) = o
            .points
            .iter()
            .map(|&p| to_y_up(p) * k)
            .filter(|q| q.is_finite())
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), q| (lo.min(q), hi.max(q)));
        let extent = (hi - lo).max_element();
        if o.points.len() > 1 && extent.is_finite() && extent < MIN_OBJECT_EXTENT_M {
            let reason = format!(
                "its curves span {extent:e} m after its transforms and the stage's units (metersPerUnit {k}): \
                 a scale of 0 or units that shrink a groom below {MIN_OBJECT_EXTENT_M:e} m leave no hair"
            );
            return Err(in_object(&o.path, Error::Malformed { format: frame.format, reason }));
        }
    }
    let all = |what: &str, has: &dyn Fn(&RawCurves) -> bool, skipped: &mut Vec<String>| {
        let n = objects.iter().filter(|o| has(o)).count();
        if n > 0 && n < objects.len() {
            skipped.push(format!("{what}: only {n} of {} curve objects have it", objects.len()));
        }
        n == objects.len()
    };
    let mut thickness: Option<Vec<f32>> = all("widths", &|o| o.widths.is_some(), &mut skipped)
        .then(|| objects.iter().flat_map(|o| o.widths.iter().flatten().map(|&w| (f64::from(w) * k) as f32)).collect());
    // A width is a diameter: a negative one, or one thicker than any hair
    // (MAX_WIDTH_M in metres), is a defect, refused (strict) or the widths
    // passed over, with the first named (repairing). A NaN or infinite one
    // is not a width at all: its strand is judged as any non-finite value
    // (dropped and named, or refused), not called "too thick".
    let absurd = |w: f32| w.is_finite() && (w < 0.0 || f64::from(w) * k > MAX_WIDTH_M);
    let negative = objects.iter().find_map(|o| {
        let widths = o.widths.as_ref()?;
        let at = widths.iter().position(|&w| absurd(w))?;
        let (strand, _) = strand_of_point(&o.counts, at)?;
        Some((o.path.as_str(), strand, widths[at]))
    });
    if let Some((path, strand, width)) = negative {
        let what = match width < 0.0 {
            true => format!("strand {strand} has a negative width ({width})"),
            false => format!(
                "strand {strand} has a width of {width:e} ({:.3e} m), thicker than any hair (at most {MAX_WIDTH_M} m)",
                f64::from(width) * k
            ),
        };
        match load {
            Load::Strict => return Err(in_object(path, Error::Malformed { format: frame.format, reason: what })),
            Load::Repair => {
                skipped.push(format!("widths: {path}: {what}; the widths are not read"));
                thickness = None;
            }
        }
    }
    let colors = all("colours", &|o| o.colors.is_some(), &mut skipped)
        .then(|| objects.iter().flat_map(|o| o.colors.iter().flatten().copied()).collect());
    let root_uvs: Option<Vec<Vec2>> = all("root UVs", &|o| o.root_uvs.is_some(), &mut skipped)
        .then(|| objects.iter().flat_map(|o| o.root_uvs.iter().flatten().copied()).collect());
    let guides: Option<Vec<bool>> = objects.iter().any(|o| o.guides.is_some()).then(|| {
        objects.iter().flat_map(|o| o.guides.clone().unwrap_or_else(|| vec![false; o.counts.len()])).collect()
    });
    if let Some(uvs) = &root_uvs {
        if let Some(s) = uvs.iter().position(|uv| !uv.is_finite()) {
            let e = Error::NonFinite { strand: s, point: 0, what: "root UV" };
            return Err(locate(e, &objects, &object_starts));
        }
    }
    let attributes = Attributes { thickness, transparency: None, colors };
    let (groom, repairs) =
        load.build(positions, &counts, attributes).map_err(|e| locate(e, &objects, &object_starts))?;
    let guides = guides.map(|v| kept(v, repairs.as_ref()));
    let root_uvs = root_uvs.map(|v| kept(v, repairs.as_ref()));
    let listed = objects.iter().map(|o| CurveObject { path: o.path.clone(), curves: o.counts.len(), basis: o.basis });
    let authored = AuthoredGroom {
        groom,
        guides: guides.filter(|g: &Vec<bool>| g.iter().any(|&g| g)),
        root_uvs,
        objects: listed.collect(),
        meters_per_unit: frame.meters_per_unit,
        units_stated: frame.units_stated,
        up_axis: frame.up_axis,
        skipped,
    };
    Ok((authored, repairs))
}

/// The values of the strands `repairs` kept (all of them without repairs).
fn kept<T: Copy>(v: Vec<T>, repairs: Option<&Repairs>) -> Vec<T> {
    match repairs {
        Some(r) => r.kept_strands().iter().map(|&s| v[s]).collect(),
        None => v,
    }
}

/// Thickest width (a diameter, in metres after the file's units) a strand of
/// an authored groom may have: a hair a metre thick is a broken file.
pub const MAX_WIDTH_M: f64 = 1.0;

/// Farthest a point of an authored groom may lie from the origin, along any
/// axis, meters (after the object's transforms and the file's units): 10 km,
/// far beyond any character, near enough that single-precision positions and
/// the renderer's framing stay meaningful.
pub const MAX_COORDINATE_M: f32 = 1e4;

/// Least extent a curve object may span after its transforms and the stage's units, meters.
pub const MIN_OBJECT_EXTENT_M: f64 = 1e-7;

#[cfg(test)]
mod tests;
