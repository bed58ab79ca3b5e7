//! Which curve object, and which of its strands, an error of the whole
//! groom is about: a groom check counts strands over every object, a user
//! reads them per object.

use super::RawCurves;
use crate::error::Error;

/// `source` as an error of the object at `path`.
pub(crate) fn in_object(path: &str, source: Error) -> Error {
    Error::CurveObject { object: path.to_owned(), source: Box::new(source) }
}

/// The strand of `counts` (points per strand) holding point `point`, and the
/// strand's first point; `None` past the last.
pub(super) fn strand_of_point(counts: &[u32], point: usize) -> Option<(usize, usize)> {
    let mut first = 0usize;
    for (strand, &c) in counts.iter().enumerate() {
        if point < first + c as usize {
            return Some((strand, first));
        }
        first += c as usize;
    }
    None
}

/// The object holding strand `strand` of the whole groom (objects starting at
/// `starts`), and the strand's index within it.
pub(super) fn object_of(starts: &[usize], strand: usize) -> (usize, usize) {
    let object = starts.partition_point(|&s| s <= strand).saturating_sub(1);
    (object, strand - starts[object])
}

/// A groom check's error with its strand counted within its object.
pub(super) fn locate(e: Error, objects: &[RawCurves], starts: &[usize]) -> Error {
    let strand = match &e {
        Error::NonFinite { strand, .. }
        | Error::ZeroLengthSegment { strand, .. }
        | Error::OutlierPoint { strand, .. }
        | Error::DegenerateStrand { strand, .. }
        | Error::BadThickness { strand, .. }
        | Error::StrandPointCount { strand, .. } => *strand,
        _ => return e,
    };
    let (object, local) = object_of(starts, strand);
    let e = match e {
        Error::NonFinite { point, what, .. } => Error::NonFinite { strand: local, point, what },
        Error::ZeroLengthSegment { segment, .. } => Error::ZeroLengthSegment { strand: local, segment },
        Error::OutlierPoint { point, position, .. } => Error::OutlierPoint { strand: local, point, position },
        Error::DegenerateStrand { size, median, .. } => Error::DegenerateStrand { strand: local, size, median },
        Error::BadThickness { point, value, size, .. } => Error::BadThickness { strand: local, point, value, size },
        Error::StrandPointCount { points, max, .. } => Error::StrandPointCount { strand: local, points, max },
        e => e,
    };
    in_object(&objects[object].path, e)
}
