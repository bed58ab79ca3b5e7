//! Key-hair data: strands as structure-of-arrays, validated on construction.
//!
//! A [`Groom`] stores every point of every strand in one array (root to tip,
//! strand after strand) with a per-strand offset table, plus optional per-point
//! thickness, transparency and color. Construction checks every invariant the
//! GPU stages rely on and reports each violation as its own [`Error`] variant:
//!
//! | check | error |
//! | --- | --- |
//! | at least one strand | [`Error::EmptyGroom`] |
//! | at most [`MAX_STRANDS`] strands, [`MAX_POINTS`] points | [`Error::TooManyStrands`], [`Error::TooManyPoints`] |
//! | 2..=[`MAX_POINTS_PER_STRAND`] points per strand | [`Error::StrandPointCount`] |
//! | finite positions and attributes | [`Error::NonFinite`] |
//! | a bounding-box diagonal that f32 can hold | [`Error::GroomExtent`] |
//! | no outlier point: no segment over [`OUTLIER_SEGMENT_RATIO`] × its strand's median | [`Error::OutlierPoint`] |
//! | no segment shorter than [`MIN_SEGMENT_FRACTION`] × its strand's bounding-box diagonal | [`Error::ZeroLengthSegment`] |
//! | no strand under [`MIN_STRAND_FRACTION`] × the groom's median strand (bounding-box diagonals) | [`Error::DegenerateStrand`] |
//! | a thickness of at least 0 and at most [`MAX_THICKNESS_IN_SIZES`] × its strand's bounding-box diagonal | [`Error::BadThickness`] |
//! | no point over [`MAX_DISTANCE_IN_STRANDS`] × the median strand from the origin | [`Error::GroomFarAway`] |
//! | attribute arrays of the right length | [`Error::AttributeLength`] |
//!
//! Sources: [`cyhair`] (`.hair` read/write), [`tfx`] (TressFX `.tfx` read),
//! [`usd`] (USD `BasisCurves`) and [`alembic`] (Alembic curves, read/write),
//! both through [`authored`], [`grow`] (procedural growth on a sphere,
//! ellipsoid or OBJ mesh) and [`scenes`] (the reference scenes of the
//! design); [`guides`] chooses the strands of a dense groom to simulate. [`Groom::repaired`] builds a
//! groom from real assets, dropping what the checks refuse and counting it in
//! [`Repairs`]. [`Groom::resampled`] gives
//! every strand the same point count (the GPU simulation wants it) and
//! [`Groom::select`] picks key hairs.

pub mod alembic;
pub mod authored;
pub mod binding;
mod bytes;
pub mod cyhair;
pub mod enclosed;
pub mod grow;
pub mod guides;
pub mod mesh;
pub mod scenes;
pub mod sdf;
pub mod tfx;
pub mod usd;
mod usd_layers;
mod usd_stacks;
mod usda_arcs;
pub mod usda_check;
mod usda_tokens;
mod usdc_blocks;
pub mod usdc_check;
mod usdc_children;
mod usdc_nested;
mod usdc_specs;
mod usdc_values;

mod repair;
mod resample;
mod transform;

pub use repair::Repairs;

use glam::Vec3;

use crate::error::{Error, Result};

/// Most strands a groom may have (4,194,304).
pub const MAX_STRANDS: usize = 1 << 22;
/// Most points a groom may have in total (16,777,216).
pub const MAX_POINTS: usize = 1 << 24;
/// Most points one strand may have (65,536: a `.hair` file stores segment counts as u16).
pub const MAX_POINTS_PER_STRAND: usize = 1 << 16;
/// A segment shorter than this fraction of its strand's bounding-box diagonal
/// counts as zero-length (scale-free, so it works for meters and for Blender
/// units alike; judged per strand, so a far point elsewhere in the groom
/// changes nothing).
pub const MIN_SEGMENT_FRACTION: f32 = 1e-6;
/// A strand whose bounding-box diagonal is under this fraction of the
/// groom's median strand's is degenerate: a point, not a hair (judged by the
/// median, so one far strand changes nothing; a strand judged by its own
/// size alone would keep every segment of a strand a few picometres long).
pub const MIN_STRAND_FRACTION: f32 = 1e-6;
/// The thickest a strand's point may be, in its strand's bounding-box
/// diagonals: a strand ten times as wide as it is long is no hair (a
/// thickness of 10⁶ on strands of 14 cm had been read as it came).
pub const MAX_THICKNESS_IN_SIZES: f32 = 10.0;
/// The farthest a groom's point may lie from the origin, in median strands
/// (bounding-box diagonals): f32's spacing there is 1.2 % of a strand, its
/// segments' shape already coarse (at 10⁶, 12 %). A head near the origin lies
/// about ten strands from it, a character a hundred metres away a thousand.
pub const MAX_DISTANCE_IN_STRANDS: f32 = 1e5;
/// A segment longer than this many times its strand's median segment (a
/// strand of three segments or more), or the groom's median segment, marks an
/// outlier point: a point far from where its strand runs, which no
/// zero-length judgement should be scaled by. (The groom's median judges a
/// strand too short to judge itself, and one whose far middle point makes
/// half its segments long.)
pub const OUTLIER_SEGMENT_RATIO: f32 = 1e4;

/// Most segments [`groom_median_segment`] samples.
const MEDIAN_SAMPLES: usize = 1 << 20;

/// The median length of the segments of `strands` (ranges of `positions`)
/// between distinct points ([`segment_lengths`]), from at most
/// [`MEDIAN_SAMPLES`] of them spread over the groom; `None` without one.
pub(crate) fn groom_median_segment(
    positions: &[Vec3],
    strands: impl Iterator<Item = std::ops::Range<usize>> + Clone,
) -> Option<f32> {
    let total: usize = strands.clone().map(|r| r.len().saturating_sub(1)).sum();
    let every = total.div_ceil(MEDIAN_SAMPLES).max(1);
    let mut lengths = Vec::with_capacity(total.div_ceil(every));
    let mut scratch = Vec::new();
    let mut k = 0usize;
    for r in strands {
        segment_lengths(&positions[r], &mut scratch);
        for &length in &scratch {
            if k.is_multiple_of(every) {
                lengths.push(length);
            }
            k += 1;
        }
    }
    median(&mut lengths)
}

/// The lengths of the segments of the strand `points` between distinct
/// points into `out` (cleared first): the medians an outlier is judged by
/// leave out repeated points, which a run of them would otherwise make zero.
/// (Exactly zero: a threshold relative to the strand's size would grow with
/// the outlier it is to find, and make its strand's real segments vanish.)
fn segment_lengths(points: &[Vec3], out: &mut Vec<f32>) {
    out.clear();
    out.extend(points.windows(2).map(|p| (p[1] - p[0]).length()).filter(|&l| l > 0.0));
}

/// The first outlier point of the strand `points` ([`OUTLIER_SEGMENT_RATIO`]
/// times the shorter of its median segment and `groom_median`, the groom's,
/// both leaving out repeated points):
/// its index and position. Of a too-long segment, the point it leads to is
/// the outlier, or the root where only the first of two or more segments is
/// too long. `scratch` is reused memory for the segments' lengths.
pub(crate) fn outlier_point(
    points: &[Vec3],
    groom_median: Option<f32>,
    scratch: &mut Vec<f32>,
) -> Option<(usize, Vec3)> {
    if points.len() < 2 {
        return None;
    }
    let length = |i: usize| (points[i + 1] - points[i]).length();
    segment_lengths(points, scratch);
    // A strand of fewer than three segments has no median of its own to trust.
    let own = if scratch.len() >= 3 { median(scratch) } else { None };
    let reference = match (own, groom_median) {
        (Some(a), Some(b)) => a.min(b),
        (a, b) => a.or(b)?,
    };
    let most = reference * OUTLIER_SEGMENT_RATIO;
    let long = |i: usize| i + 1 < points.len() && length(i) > most;
    let first = (0..points.len() - 1).find(|&i| long(i))?;
    // (A single segment gives no second to tell which end strayed: the tip,
    // where a root is the end a groom places on its scalp.)
    let point = if first == 0 && points.len() > 2 && !long(1) { 0 } else { first + 1 };
    Some((point, points[point]))
}

/// A groom's optional per-point thickness, transparency and colours.
pub(crate) type PointAttributes<'a> = (Option<&'a [f32]>, Option<&'a [f32]>, Option<&'a [Vec3]>);

/// What of point `i` is not finite — its "position", "thickness",
/// "transparency" or "color" (of `attributes`, in that order) — if anything.
pub(crate) fn not_finite(
    positions: &[Vec3],
    (thickness, transparency, colors): PointAttributes<'_>,
    i: usize,
) -> Option<&'static str> {
    if !positions[i].is_finite() {
        Some("position")
    } else if thickness.is_some_and(|t| !t[i].is_finite()) {
        Some("thickness")
    } else if transparency.is_some_and(|t| !t[i].is_finite()) {
        Some("transparency")
    } else if colors.is_some_and(|c| !c[i].is_finite()) {
        Some("color")
    } else {
        None
    }
}

/// The bounding-box diagonal of the strand `points`.
pub(crate) fn strand_size(points: &[Vec3]) -> f32 {
    let (lo, hi) = bounding_box(points.iter().copied());
    (hi - lo).length()
}

/// The median of `values` (the upper one of an even count; reordered in
/// place), `None` for none.
pub(crate) fn median(values: &mut [f32]) -> Option<f32> {
    if values.is_empty() {
        return None;
    }
    let middle = values.len() / 2;
    Some(*values.select_nth_unstable_by(middle, f32::total_cmp).1)
}

/// Whether a strand of bounding-box diagonal `size` is degenerate in a groom
/// whose median strand's is `median` ([`MIN_STRAND_FRACTION`]).
pub(crate) fn degenerate(size: f32, median: f32) -> bool {
    size < median * MIN_STRAND_FRACTION
}

/// Whether `thickness` is a diameter a strand `size` across could have: at
/// least 0 and at most [`MAX_THICKNESS_IN_SIZES`] times its size.
pub(crate) fn thickness_fits(thickness: f32, size: f32) -> bool {
    (0.0..=size * MAX_THICKNESS_IN_SIZES).contains(&thickness)
}

/// The shortest segment of the strand `points` that is not zero-length
/// ([`MIN_SEGMENT_FRACTION`] of its bounding-box diagonal).
pub(crate) fn min_segment(points: &[Vec3]) -> f32 {
    strand_size(points) * MIN_SEGMENT_FRACTION
}

/// The axis-aligned bounding box (min, max) of `points`; (+∞, −∞) for none.
pub fn bounding_box(points: impl IntoIterator<Item = Vec3>) -> (Vec3, Vec3) {
    points
        .into_iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// The sphere around the bounding box (min, max) `bounds` ([`bounding_box`]),
/// which the tools and the viewer frame a camera by: its centre and half its
/// diagonal.
pub fn bounding_sphere((lo, hi): (Vec3, Vec3)) -> (Vec3, f32) {
    (0.5 * (lo + hi), 0.5 * (hi - lo).length())
}

/// The bounding box `lo..hi` of finite points: its diagonal must be finite for
/// lengths relative to it (zero-length segments) to mean anything.
fn check_extent(lo: Vec3, hi: Vec3) -> Result<()> {
    if lo.cmple(hi).all() && !(hi - lo).length().is_finite() {
        let extent = (0..3).map(|k| f64::from(hi[k]) - f64::from(lo[k])).fold(0.0, f64::max);
        return Err(Error::GroomExtent { extent });
    }
    Ok(())
}

/// A set of hair strands (see the module docs for the invariants).
///
/// ```
/// use glam::Vec3;
/// use vkhair::groom::grow::{grow, GrowParams};
/// use vkhair::groom::scenes::thesis_scalp;
/// use vkhair::{Error, Groom};
///
/// let groom = Groom::from_strands(&[vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X]])?;
/// assert_eq!((groom.strand_count(), groom.point_count()), (1, 3));
/// let grown = grow(&thesis_scalp(), &GrowParams { strands: 100, points_per_strand: 8, ..Default::default() })?;
/// assert_eq!(grown.strand_count(), 100);
/// // Broken input is a typed error, never a panic.
/// assert!(matches!(Groom::from_strands(&[vec![Vec3::ZERO, Vec3::NAN]]), Err(Error::NonFinite { .. })));
/// # Ok::<(), vkhair::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Groom {
    positions: Vec<Vec3>,
    offsets: Vec<u32>,
    thickness: Option<Vec<f32>>,
    transparency: Option<Vec<f32>>,
    colors: Option<Vec<Vec3>>,
}

/// Optional per-point attributes of a groom.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes {
    /// Per-point thickness (diameter, in the groom's length unit).
    pub thickness: Option<Vec<f32>>,
    /// Per-point transparency in 0..=1.
    pub transparency: Option<Vec<f32>>,
    /// Per-point linear RGB color.
    pub colors: Option<Vec<Vec3>>,
}

/// Summary numbers of a groom, as `vkhair inspect` prints them.
#[derive(Debug, Clone, PartialEq)]
pub struct GroomStats {
    /// Number of strands.
    pub strands: usize,
    /// Number of points.
    pub points: usize,
    /// Smallest, mean and largest points per strand.
    pub points_per_strand: (usize, f64, usize),
    /// Smallest, mean and largest strand length.
    pub strand_length: (f32, f64, f32),
    /// Smallest and largest segment length.
    pub segment_length: (f32, f32),
    /// Bounding box minimum and maximum.
    pub bounds: (Vec3, Vec3),
    /// Whether thickness, transparency and colors are present.
    pub has_thickness: bool,
    /// See `has_thickness`.
    pub has_transparency: bool,
    /// See `has_thickness`.
    pub has_colors: bool,
}

impl Groom {
    /// A groom from concatenated positions and per-strand point counts.
    pub fn new(positions: Vec<Vec3>, points_per_strand: &[u32]) -> Result<Self> {
        Self::with_attributes(positions, points_per_strand, Attributes::default())
    }

    /// A groom with optional per-point attributes.
    pub fn with_attributes(positions: Vec<Vec3>, points_per_strand: &[u32], attributes: Attributes) -> Result<Self> {
        if points_per_strand.is_empty() {
            return Err(Error::EmptyGroom);
        }
        if points_per_strand.len() > MAX_STRANDS {
            return Err(Error::TooManyStrands { count: points_per_strand.len() as u64, max: MAX_STRANDS as u64 });
        }
        let mut offsets = Vec::with_capacity(points_per_strand.len() + 1);
        offsets.push(0u32);
        let mut total: u64 = 0;
        for (strand, &n) in points_per_strand.iter().enumerate() {
            if !(2..=MAX_POINTS_PER_STRAND as u64).contains(&u64::from(n)) {
                return Err(Error::StrandPointCount { strand, points: n.into(), max: MAX_POINTS_PER_STRAND as u64 });
            }
            total += u64::from(n);
            if total > MAX_POINTS as u64 {
                return Err(Error::TooManyPoints { count: total, max: MAX_POINTS as u64 });
            }
            offsets.push(total as u32);
        }
        let groom = Groom {
            positions,
            offsets,
            thickness: attributes.thickness,
            transparency: attributes.transparency,
            colors: attributes.colors,
        };
        groom.validate()?;
        Ok(groom)
    }

    /// A groom from one vector of points per strand.
    pub fn from_strands(strands: &[Vec<Vec3>]) -> Result<Self> {
        let counts: Vec<u32> = strands.iter().map(|s| s.len().min(u32::MAX as usize) as u32).collect();
        let total: usize = strands.iter().map(Vec::len).sum();
        if total > MAX_POINTS {
            return Err(Error::TooManyPoints { count: total as u64, max: MAX_POINTS as u64 });
        }
        Self::new(strands.concat(), &counts)
    }

    fn validate(&self) -> Result<()> {
        let points = *self.offsets.last().unwrap_or(&0) as usize;
        if self.positions.len() != points {
            return Err(Error::AttributeLength { what: "positions", expected: points, actual: self.positions.len() });
        }
        let check_len = |what, len: Option<usize>| match len {
            Some(actual) if actual != points => Err(Error::AttributeLength { what, expected: points, actual }),
            _ => Ok(()),
        };
        check_len("thickness", self.thickness.as_ref().map(Vec::len))?;
        check_len("transparency", self.transparency.as_ref().map(Vec::len))?;
        check_len("colors", self.colors.as_ref().map(Vec::len))?;
        for strand in 0..self.strand_count() {
            let range = self.strand_range(strand);
            let start = range.start;
            for i in range {
                let attributes = (self.thickness.as_deref(), self.transparency.as_deref(), self.colors.as_deref());
                if let Some(what) = not_finite(&self.positions, attributes, i) {
                    return Err(Error::NonFinite { strand, point: i - start, what });
                }
            }
        }
        let mut scratch = Vec::new();
        let segment = groom_median_segment(&self.positions, (0..self.strand_count()).map(|s| self.strand_range(s)));
        for strand in 0..self.strand_count() {
            if let Some((point, position)) = outlier_point(self.strand(strand), segment, &mut scratch) {
                return Err(Error::OutlierPoint { strand, point, position: position.to_array() });
            }
        }
        let (lo, hi) = self.bounds();
        check_extent(lo, hi)?;
        let sizes: Vec<f32> = (0..self.strand_count()).map(|s| strand_size(self.strand(s))).collect();
        for (strand, &size) in sizes.iter().enumerate() {
            let min_segment = size * MIN_SEGMENT_FRACTION;
            for (segment, pair) in self.strand(strand).windows(2).enumerate() {
                let length = (pair[1] - pair[0]).length();
                if length <= min_segment || length == 0.0 {
                    return Err(Error::ZeroLengthSegment { strand, segment });
                }
            }
        }
        if let Some(median) = median(&mut sizes.clone()) {
            if let Some(strand) = sizes.iter().position(|&size| degenerate(size, median)) {
                return Err(Error::DegenerateStrand { strand, size: sizes[strand], median });
            }
            if let Some(t) = &self.thickness {
                for (strand, &size) in sizes.iter().enumerate() {
                    let range = self.strand_range(strand);
                    let start = range.start;
                    if let Some(i) = range.into_iter().find(|&i| !thickness_fits(t[i], size)) {
                        return Err(Error::BadThickness { strand, point: i - start, value: t[i], size });
                    }
                }
            }
            let distance = self.positions.iter().map(|p| p.as_dvec3().length()).fold(0.0, f64::max);
            if distance > f64::from(median * MAX_DISTANCE_IN_STRANDS) {
                return Err(Error::GroomFarAway { distance, median });
            }
        }
        Ok(())
    }

    /// Number of strands.
    pub fn strand_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of points of all strands.
    pub fn point_count(&self) -> usize {
        self.positions.len()
    }

    /// Index range of strand `i` in the per-point arrays. Panics if `i` is out of range.
    pub fn strand_range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Points of strand `i`, root first. Panics if `i` is out of range.
    pub fn strand(&self, i: usize) -> &[Vec3] {
        &self.positions[self.strand_range(i)]
    }

    /// Number of points of strand `i`. Panics if `i` is out of range.
    pub fn strand_len(&self, i: usize) -> usize {
        self.strand_range(i).len()
    }

    /// Points per strand when every strand has the same count.
    pub fn uniform_points_per_strand(&self) -> Option<usize> {
        let n = self.strand_len(0);
        (0..self.strand_count()).all(|i| self.strand_len(i) == n).then_some(n)
    }

    /// All positions, strand after strand.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Start offsets of every strand plus the total point count at the end.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// Per-point thickness, when present.
    pub fn thickness(&self) -> Option<&[f32]> {
        self.thickness.as_deref()
    }

    /// Per-point transparency, when present.
    pub fn transparency(&self) -> Option<&[f32]> {
        self.transparency.as_deref()
    }

    /// Per-point colors, when present.
    pub fn colors(&self) -> Option<&[Vec3]> {
        self.colors.as_deref()
    }

    /// The optional attributes (cloned).
    pub fn attributes(&self) -> Attributes {
        Attributes {
            thickness: self.thickness.clone(),
            transparency: self.transparency.clone(),
            colors: self.colors.clone(),
        }
    }

    /// Axis-aligned bounding box (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        bounding_box(self.positions.iter().copied())
    }

    /// Length of strand `i` along its segments.
    pub fn strand_length(&self, i: usize) -> f32 {
        self.strand(i).windows(2).map(|w| (w[1] - w[0]).length()).sum()
    }

    /// Counts, lengths and bounds.
    pub fn stats(&self) -> GroomStats {
        let n = self.strand_count();
        let counts = (0..n).map(|i| self.strand_len(i));
        let lengths: Vec<f32> = (0..n).map(|i| self.strand_length(i)).collect();
        let segments = (0..n).flat_map(|i| self.strand(i).windows(2).map(|w| (w[1] - w[0]).length()));
        let (seg_min, seg_max) = segments.fold((f32::INFINITY, 0.0f32), |(a, b), l| (a.min(l), b.max(l)));
        GroomStats {
            strands: n,
            points: self.point_count(),
            points_per_strand: (
                counts.clone().min().unwrap_or(0),
                self.point_count() as f64 / n as f64,
                counts.max().unwrap_or(0),
            ),
            strand_length: (
                lengths.iter().copied().fold(f32::INFINITY, f32::min),
                lengths.iter().map(|&l| f64::from(l)).sum::<f64>() / n as f64,
                lengths.iter().copied().fold(0.0, f32::max),
            ),
            segment_length: (seg_min, seg_max),
            bounds: self.bounds(),
            has_thickness: self.thickness.is_some(),
            has_transparency: self.transparency.is_some(),
            has_colors: self.colors.is_some(),
        }
    }

    /// A groom of the strands at `indices` (in that order), with their attributes.
    pub fn select(&self, indices: &[usize]) -> Result<Groom> {
        let mut positions = Vec::new();
        let mut counts = Vec::with_capacity(indices.len());
        let mut attributes = Attributes {
            thickness: self.thickness.as_ref().map(|_| Vec::new()),
            transparency: self.transparency.as_ref().map(|_| Vec::new()),
            colors: self.colors.as_ref().map(|_| Vec::new()),
        };
        for &index in indices {
            if index >= self.strand_count() {
                return Err(Error::StrandIndex { index, count: self.strand_count() });
            }
            let range = self.strand_range(index);
            counts.push(range.len() as u32);
            positions.extend_from_slice(&self.positions[range.clone()]);
            if let (Some(dst), Some(src)) = (&mut attributes.thickness, &self.thickness) {
                dst.extend_from_slice(&src[range.clone()]);
            }
            if let (Some(dst), Some(src)) = (&mut attributes.transparency, &self.transparency) {
                dst.extend_from_slice(&src[range.clone()]);
            }
            if let (Some(dst), Some(src)) = (&mut attributes.colors, &self.colors) {
                dst.extend_from_slice(&src[range]);
            }
        }
        Groom::with_attributes(positions, &counts, attributes)
    }

    /// Every `stride`-th strand starting at strand 0 (key hairs from a dense groom).
    pub fn every_nth(&self, stride: usize) -> Result<Groom> {
        if stride == 0 {
            return Err(Error::param("stride", stride, "at least 1"));
        }
        let indices: Vec<usize> = (0..self.strand_count()).step_by(stride).collect();
        self.select(&indices)
    }

    /// `count` strands spread evenly over the groom's strand order.
    pub fn select_evenly(&self, count: usize) -> Result<Groom> {
        let n = self.strand_count();
        if count == 0 || count > n {
            return Err(Error::param("key hair count", count, format!("1..={n}")));
        }
        let indices: Vec<usize> = (0..count).map(|i| i * n / count).collect();
        self.select(&indices)
    }
}
