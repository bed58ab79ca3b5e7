//! Loading real assets: what can be repaired is, and said.
//!
//! Exported grooms carry defects that the strict constructor refuses (TressFX's
//! own `mohawk.tfx` has one zero-length segment among 2,228 strands).
//! [`Groom::repaired`] drops, in this order: strands with a NaN or infinite value
//! (position or attribute), then strands with an outlier point (far from where
//! the strand runs, as [`Groom::new`] judges it; the first is named), then
//! every point that coincides with the strand's previous kept point (a
//! zero-length segment, judged against its own strand), then strands left with
//! fewer than two points. [`Repairs`] counts what went.

use glam::Vec3;

use super::{Attributes, Groom};
use crate::error::{Error, Result};

/// What [`Groom::repaired`] dropped (all zero: nothing needed repair).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Repairs {
    /// Strands dropped for a NaN or infinite position or attribute.
    pub non_finite_strands: usize,
    /// The first of them: strand (in the input), point and what was not finite.
    pub first_non_finite: Option<(usize, usize, &'static str)>,
    /// Strands dropped for an outlier point.
    pub outlier_strands: usize,
    /// The first outlier dropped: strand (in the input), point and position.
    pub first_outlier: Option<(usize, usize, [f32; 3])>,
    /// Strands dropped for being a point, not a hair (see
    /// [`crate::groom::MIN_STRAND_FRACTION`]).
    pub degenerate_strands: usize,
    /// The first of them: strand (in the input) and its bounding-box diagonal.
    pub first_degenerate: Option<(usize, f32)>,
    /// The thickness array, dropped for a value no diameter of its strand:
    /// the first such strand (in the input), point, value and strand size.
    pub bad_thickness: Option<(usize, usize, f32, f32)>,
    /// Points dropped because they coincided with the previous kept point.
    pub zero_length_segments: usize,
    /// Strands dropped for having fewer than two points (left or given).
    pub short_strands: usize,
    /// The first of them (in the input).
    pub first_short: Option<usize>,
    /// Original index of every kept point, in order.
    kept_points: Vec<usize>,
    /// Original index of every kept strand, in order.
    kept_strands: Vec<usize>,
}

impl Repairs {
    /// Whether nothing was dropped.
    pub fn is_empty(&self) -> bool {
        self.non_finite_strands == 0
            && self.outlier_strands == 0
            && self.degenerate_strands == 0
            && self.bad_thickness.is_none()
            && self.zero_length_segments == 0
            && self.short_strands == 0
    }

    /// Original index of every kept point, in order.
    pub(crate) fn kept_points(&self) -> &[usize] {
        &self.kept_points
    }

    /// Original index of every kept strand, in order.
    pub(crate) fn kept_strands(&self) -> &[usize] {
        &self.kept_strands
    }

    /// Counts `strand` (its index in the input) as dropped for too few points.
    fn short(&mut self, strand: usize) {
        self.short_strands += 1;
        self.first_short = Some(self.first_short.map_or(strand, |s| s.min(strand)));
    }
}

impl std::fmt::Display for Repairs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plural = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let parts: Vec<String> = [
            (
                self.non_finite_strands,
                plural(self.non_finite_strands, "strand", "strands")
                    + " with NaN or infinite values"
                    + &self.first_non_finite.map_or(String::new(), |(s, p, what)| {
                        format!(" (the first: strand {s} point {p}, its {what})")
                    }),
            ),
            (
                self.outlier_strands,
                plural(self.outlier_strands, "strand", "strands")
                    + " with an outlier point"
                    + &self.first_outlier.map_or(String::new(), |(s, p, [x, y, z])| {
                        format!(" (the first: strand {s} point {p} at ({x}, {y}, {z}))")
                    }),
            ),
            (
                self.degenerate_strands,
                plural(self.degenerate_strands, "strand", "strands")
                    + " collapsed to a point"
                    + &self.first_degenerate.map_or(String::new(), |(s, size)| {
                        format!(" (the first: strand {s}, {size:e} across, under a millionth of the median strand)")
                    }),
            ),
            (
                self.zero_length_segments,
                plural(self.zero_length_segments, "zero-length segment", "zero-length segments"),
            ),
            (
                self.short_strands,
                plural(self.short_strands, "strand", "strands")
                    + " with fewer than two points"
                    + &self.first_short.map_or(String::new(), |s| format!(" (the first: strand {s})")),
            ),
        ]
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(_, s)| s)
        .chain(self.bad_thickness.map(|(s, p, value, size)| {
            format!(
                "the thickness (strand {s} point {p} has {value:e}, not a diameter of a strand {size:e} across; \
                 the default widths are drawn)"
            )
        }))
        .collect();
        if parts.is_empty() {
            write!(f, "nothing to repair")
        } else {
            write!(f, "dropped {}", parts.join(", "))
        }
    }
}

/// How a file reader turns strands into a groom.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Load {
    /// Refuse any defect ([`Groom::with_attributes`]).
    Strict,
    /// Repair what can be ([`Groom::repaired`]).
    Repair,
}

impl Load {
    /// The groom, with what was repaired (`None` when strict).
    pub(crate) fn build(
        self,
        positions: Vec<Vec3>,
        points_per_strand: &[u32],
        attributes: Attributes,
    ) -> Result<(Groom, Option<Repairs>)> {
        match self {
            Load::Strict => Ok((Groom::with_attributes(positions, points_per_strand, attributes)?, None)),
            Load::Repair => {
                let (groom, repairs) = Groom::repaired(positions, points_per_strand, attributes)?;
                Ok((groom, Some(repairs)))
            }
        }
    }
}

/// Most rounds of judging strands by the median of those left
/// ([`Groom::repaired`]).
const MAX_DEGENERATE_ROUNDS: usize = 64;

impl Groom {
    /// A groom from concatenated positions, per-strand point counts and optional
    /// attributes, repairing what can be repaired (see the module docs of
    /// `groom::repair`); [`Groom::with_attributes`] refuses instead. Errors: point
    /// counts that do not add up, attribute arrays of the wrong length, too many
    /// strands or points, a bounding box too large for f32, nothing left.
    pub fn repaired(
        positions: Vec<Vec3>,
        points_per_strand: &[u32],
        attributes: Attributes,
    ) -> Result<(Groom, Repairs)> {
        let total: u64 = points_per_strand.iter().map(|&n| u64::from(n)).sum();
        if total != positions.len() as u64 {
            return Err(Error::AttributeLength {
                what: "positions",
                expected: total as usize,
                actual: positions.len(),
            });
        }
        let check = |what, len: Option<usize>| match len {
            Some(actual) if actual != positions.len() => {
                Err(Error::AttributeLength { what, expected: positions.len(), actual })
            }
            _ => Ok(()),
        };
        check("thickness", attributes.thickness.as_ref().map(Vec::len))?;
        check("transparency", attributes.transparency.as_ref().map(Vec::len))?;
        check("colors", attributes.colors.as_ref().map(Vec::len))?;
        let given = (attributes.thickness.as_deref(), attributes.transparency.as_deref(), attributes.colors.as_deref());
        let not_finite = |i: usize| super::not_finite(&positions, given, i);
        let mut repairs = Repairs::default();
        let mut strands = Vec::new(); // (strand, first point) of finite strands with 2+ points
        let mut start = 0usize;
        for (strand, &n) in points_per_strand.iter().enumerate() {
            let range = start..start + n as usize;
            start = range.end;
            if n < 2 {
                repairs.short(strand);
            } else if let Some((i, what)) = range.clone().find_map(|i| not_finite(i).map(|w| (i, w))) {
                repairs.non_finite_strands += 1;
                repairs.first_non_finite.get_or_insert((strand, i - range.start, what));
            } else {
                strands.push((strand, range));
            }
        }
        if strands.is_empty() {
            return Err(Error::NothingLeft { repairs: repairs.to_string() });
        }
        // Outliers first, judged by their strand and the groom's median segment:
        // one far point must not make the groom's extent overflow for all.
        let median = super::groom_median_segment(&positions, strands.iter().map(|(_, r)| r.clone()));
        let mut scratch = Vec::new();
        strands.retain(|(strand, range)| match super::outlier_point(&positions[range.clone()], median, &mut scratch) {
            Some((point, at)) => {
                repairs.outlier_strands += 1;
                repairs.first_outlier.get_or_insert((*strand, point, at.to_array()));
                false
            }
            None => true,
        });
        if strands.is_empty() {
            return Err(Error::NothingLeft { repairs: repairs.to_string() });
        }
        let (lo, hi) = super::bounding_box(strands.iter().flat_map(|(_, r)| positions[r.clone()].iter().copied()));
        super::check_extent(lo, hi)?;
        let mut survivors = Vec::with_capacity(strands.len()); // (strand, kept points, size)
        for (strand, range) in strands {
            let min_segment = super::min_segment(&positions[range.clone()]);
            let first = range.start;
            let mut kept = vec![first];
            for i in range.skip(1) {
                let last = positions[*kept.last().unwrap_or(&first)];
                let length = (positions[i] - last).length();
                if length <= min_segment || length == 0.0 {
                    repairs.zero_length_segments += 1;
                } else {
                    kept.push(i);
                }
            }
            if kept.len() < 2 {
                repairs.short(strand);
                continue;
            }
            let (lo, hi) = super::bounding_box(kept.iter().map(|&i| positions[i]));
            survivors.push((strand, kept, (hi - lo).length()));
        }
        // Degenerate strands, judged by the median of what is left until none
        // is (dropping the smallest can only raise the median), so that the
        // groom built below has none by its own median either. (Rounds are
        // bounded: a file built to creep the median up round after round is
        // refused by the groom's own check instead.)
        for _ in 0..MAX_DEGENERATE_ROUNDS {
            let Some(median) = super::median(&mut survivors.iter().map(|s| s.2).collect::<Vec<_>>()) else { break };
            let before = survivors.len();
            survivors.retain(|(strand, _, size)| {
                let keep = !super::degenerate(*size, median);
                if !keep {
                    repairs.degenerate_strands += 1;
                    repairs.first_degenerate.get_or_insert((*strand, *size));
                }
                keep
            });
            if survivors.len() == before {
                break;
            }
        }
        // A thickness that is no diameter of its strand makes the whole array
        // suspect: it is dropped (the default widths drawn), the first named.
        let mut thickness = attributes.thickness;
        if let Some(t) = &thickness {
            let bad = survivors.iter().find_map(|(strand, kept, size)| {
                kept.iter()
                    .find(|&&i| !super::thickness_fits(t[i], *size))
                    .map(|&i| (*strand, i - kept[0], t[i], *size))
            });
            if bad.is_some() {
                repairs.bad_thickness = bad;
                thickness = None;
            }
        }
        let mut counts = Vec::with_capacity(survivors.len());
        for (strand, kept, _) in survivors {
            counts.push(kept.len() as u32);
            repairs.kept_strands.push(strand);
            repairs.kept_points.extend(kept);
        }
        if counts.is_empty() {
            return Err(Error::NothingLeft { repairs: repairs.to_string() });
        }
        let pick = |v: &Vec<f32>| repairs.kept_points.iter().map(|&i| v[i]).collect();
        let attributes = Attributes {
            thickness: thickness.as_ref().map(pick),
            transparency: attributes.transparency.as_ref().map(pick),
            colors: attributes.colors.as_ref().map(|c| repairs.kept_points.iter().map(|&i| c[i]).collect()),
        };
        let positions = repairs.kept_points.iter().map(|&i| positions[i]).collect();
        let groom = Groom::with_attributes(positions, &counts, attributes)?;
        Ok((groom, repairs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize, x: f32) -> Vec<Vec3> {
        (0..n).map(|i| Vec3::new(x, -0.01 * i as f32, 0.0)).collect()
    }

    #[test]
    fn drops_what_the_strict_constructor_refuses_and_counts_it() {
        let mut doubled = line(4, 0.0);
        doubled.insert(2, doubled[1]); // one zero-length segment
        let mut nan = line(3, 0.1);
        nan[1].y = f32::NAN;
        let collapsed = vec![Vec3::new(0.2, 0.0, 0.0); 3]; // nothing left but the root
        let strands = [line(3, 0.3), doubled, nan, collapsed, vec![Vec3::new(0.4, 0.0, 0.0)]];
        let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
        let positions = strands.concat();
        let strict = Groom::new(positions.clone(), &counts);
        assert!(strict.is_err(), "the strict constructor refuses these strands");
        let (groom, repairs) = Groom::repaired(positions, &counts, Attributes::default()).expect("repaired");
        assert_eq!(
            (repairs.non_finite_strands, repairs.zero_length_segments, repairs.short_strands),
            (1, 3, 2),
            "{repairs}"
        );
        assert_eq!(groom.strand_count(), 2);
        assert_eq!(groom.strand(1), &line(4, 0.0)[..], "the duplicate point is gone, the rest kept in order");
        assert_eq!(repairs.kept_strands(), &[0, 1]);
        assert_eq!(
            repairs.to_string(),
            "dropped 1 strand with NaN or infinite values (the first: strand 2 point 1, its position), 3 zero-length \
             segments, 2 strands with fewer than two points (the first: strand 3)"
        );
        // A NaN width is named as such.
        let thickness = Some(vec![0.001, f32::NAN, 0.001, 0.001, 0.001]);
        let (_, repairs) = Groom::repaired(
            [line(2, 0.0), line(3, 0.1)].concat(),
            &[2, 3],
            Attributes { thickness, ..Default::default() },
        )
        .expect("one strand left");
        assert!(repairs.to_string().contains("(the first: strand 0 point 1, its thickness)"), "{repairs}");
    }

    /// Strands too short to judge themselves, a far middle point that makes
    /// half a short strand's segments long, and a point at 3e38 are outliers
    /// by the groom's median segment: those strands are dropped and named,
    /// the others kept (the 3e38 point had made the whole groom's extent
    /// overflow).
    #[test]
    fn short_strands_and_far_points_are_judged_by_the_groom_too() {
        let mut two = line(2, 0.0);
        two[1] = Vec3::new(0.0, 1e5, 0.0);
        let mut three = line(3, 0.1);
        three[2] = Vec3::new(0.1, 1e3, 0.0);
        let mut four = line(4, 0.2);
        four[1] = Vec3::new(3e3, 0.0, 0.0);
        let mut huge = line(5, 0.3);
        huge[2] = Vec3::new(3e38, 0.0, 0.0);
        let good: Vec<Vec<Vec3>> = (0..6).map(|k| line(5, 0.5 + 0.1 * k as f32)).collect();
        let strands: Vec<Vec<Vec3>> = [vec![two, three, four, huge], good].concat();
        let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
        let (groom, repairs) = Groom::repaired(strands.concat(), &counts, Attributes::default()).expect("repaired");
        assert_eq!((repairs.outlier_strands, repairs.zero_length_segments), (4, 0), "{repairs}");
        assert_eq!(groom.strand_count(), 6, "the good strands kept");
        assert_eq!(repairs.first_outlier.map(|(s, p, _)| (s, p)), Some((0, 1)), "{repairs}");
        assert!(Groom::new(strands.concat(), &counts).is_err(), "the strict constructor refuses them");
    }

    /// One far point in one strand is an outlier of that strand: the strict
    /// constructor names it (strand, point, position), repairing drops that
    /// strand alone and says so, and every other strand keeps every segment
    /// (judged against the whole groom's extent, 1e5 wide, their 1 cm
    /// segments had been "zero-length").
    #[test]
    fn a_far_point_is_an_outlier_of_its_strand_not_a_new_scale_for_zero() {
        let mut broken = line(6, 0.2);
        broken[3] = Vec3::new(1e5, 0.0, 0.0);
        let strands = [line(6, 0.0), line(6, 0.1), broken, line(6, 0.3)];
        let counts = [6u32; 4];
        match Groom::new(strands.concat(), &counts) {
            Err(e @ Error::OutlierPoint { strand: 2, point: 3, .. }) => {
                assert!(e.to_string().contains("(100000, 0, 0)"), "{e}")
            }
            other => panic!("expected the outlier named, got {other:?}"),
        }
        let (groom, repairs) = Groom::repaired(strands.concat(), &counts, Attributes::default()).expect("repaired");
        assert_eq!((repairs.outlier_strands, repairs.zero_length_segments, repairs.short_strands), (1, 0, 0));
        assert_eq!(repairs.kept_strands(), &[0, 1, 3]);
        for (kept, original) in [(0, 0), (1, 1), (2, 3)] {
            assert_eq!(groom.strand(kept), &strands[original][..], "strand {original} lost points");
        }
        assert_eq!(
            repairs.to_string(),
            "dropped 1 strand with an outlier point (the first: strand 2 point 3 at (100000, 0, 0))"
        );
        // The tip and the root are named as the outlier where they are the far point.
        let mut tip = line(5, 0.0);
        tip[4] = Vec3::splat(1e4);
        let mut root = line(5, 0.0);
        root[0] = Vec3::splat(-1e4);
        let outlier = |points: &[Vec3]| crate::groom::outlier_point(points, None, &mut Vec::new());
        assert_eq!(outlier(&tip).map(|o| o.0), Some(4));
        assert_eq!(outlier(&root).map(|o| o.0), Some(0));
        assert_eq!(outlier(&line(5, 0.0)), None);
    }

    #[test]
    fn a_clean_groom_passes_unchanged() {
        let strands = [line(5, 0.0), line(3, 0.1)];
        let counts = [5, 3];
        let (groom, repairs) = Groom::repaired(strands.concat(), &counts, Attributes::default()).expect("clean");
        assert!(repairs.is_empty());
        assert_eq!(groom, Groom::new(strands.concat(), &counts).expect("strict"));
    }

    #[test]
    fn an_overflowing_bounding_box_is_named_as_such() {
        let strands = [vec![Vec3::new(-3e38, 0.0, 0.0), Vec3::new(3e38, 0.0, 0.0)]];
        for result in [
            Groom::new(strands.concat(), &[2]).map(drop),
            Groom::repaired(strands.concat(), &[2], Attributes::default()).map(drop),
        ] {
            match result {
                Err(e @ Error::GroomExtent { .. }) => assert!(e.to_string().contains("overflows"), "{e}"),
                other => panic!("expected GroomExtent, got {other:?}"),
            }
        }
    }

    /// When repairing drops every strand, the error says how many and why.
    #[test]
    fn nothing_left_says_what_was_dropped() {
        let positions = vec![Vec3::NAN, Vec3::ZERO, Vec3::ONE, Vec3::INFINITY, Vec3::X];
        let err = Groom::repaired(positions, &[2, 2, 1], Attributes::default()).expect_err("nothing left");
        assert!(matches!(err, Error::NothingLeft { .. }), "{err:?}");
        let text = err.to_string();
        assert!(text.contains("2 strands with NaN or infinite values"), "{text}");
        assert!(text.contains("1 strand with fewer than two points"), "{text}");
    }

    /// A run of repeated points inside a strand is zero-length segments to
    /// drop, not an outlier: with four repeats of seven segments, the strand's
    /// median segment had been zero and the strand dropped, its root named
    /// the outlier.
    #[test]
    fn a_run_of_repeated_points_loses_its_repeats_and_keeps_its_strand() {
        let mut repeated = line(4, 0.2);
        for _ in 0..4 {
            repeated.insert(2, repeated[1]);
        }
        let strands = [line(8, 0.0), line(8, 0.1), repeated, line(8, 0.3)];
        let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
        match Groom::new(strands.concat(), &counts) {
            Err(Error::ZeroLengthSegment { strand: 2, segment: 1 }) => {}
            other => panic!("expected the zero-length segment named, got {other:?}"),
        }
        let (groom, repairs) = Groom::repaired(strands.concat(), &counts, Attributes::default()).expect("repaired");
        assert_eq!((repairs.outlier_strands, repairs.zero_length_segments), (0, 4), "{repairs}");
        assert_eq!(groom.strand(2), &line(4, 0.2)[..], "the strand keeps its distinct points");
    }

    /// A strand a few picometres across beside 7 cm ones is a point, not a
    /// hair: named by the strict constructor, dropped and named by repairing,
    /// judged by the groom's median (so strands of 1 mm beside 50 cm ones,
    /// real eyebrows beside real hair, are kept), and judged again until none
    /// is left, so that the groom built has none by its own median either.
    #[test]
    fn a_strand_that_is_a_point_is_dropped_by_the_grooms_median() {
        let tiny: Vec<Vec3> = (0..8).map(|i| Vec3::new(0.5, -1e-12 * i as f32, 0.0)).collect();
        let strands = [line(8, 0.0), line(8, 0.1), tiny.clone(), line(8, 0.3)];
        match Groom::new(strands.concat(), &[8; 4]) {
            Err(e @ Error::DegenerateStrand { strand: 2, .. }) => {
                assert!(e.to_string().contains("a point, not a hair"), "{e}")
            }
            other => panic!("expected the degenerate strand named, got {other:?}"),
        }
        let (groom, repairs) = Groom::repaired(strands.concat(), &[8; 4], Attributes::default()).expect("repaired");
        assert_eq!((repairs.degenerate_strands, groom.strand_count()), (1, 3), "{repairs}");
        assert!(repairs.to_string().contains("1 strand collapsed to a point (the first: strand 2, 7e-12"), "{repairs}");
        // Real sizes apart: kept.
        let short: Vec<Vec3> = (0..8).map(|i| Vec3::new(0.6, -1.4e-4 * i as f32, 0.0)).collect();
        let long: Vec<Vec3> = (0..8).map(|i| Vec3::new(0.7, -0.07 * i as f32, 0.0)).collect();
        let groom = Groom::new([short, long.clone(), long].concat(), &[8; 3]).expect("1 mm beside 50 cm");
        assert_eq!(groom.strand_count(), 3);
        // Three strands of 5e-14 and two of 1e-7 beside two of 0.5 (999
        // segments each, so that no segment is an outlier by the groom's
        // median): the first median (1e-7) drops the first three, the next
        // (0.5) the two.
        let strand = |x: f32, points: usize, length: f32| {
            (0..points).map(|i| Vec3::new(x, -length * i as f32 / (points - 1) as f32, 0.0)).collect::<Vec<_>>()
        };
        let strands: Vec<Vec<Vec3>> = (0..3)
            .map(|k| strand(k as f32, 2, 5e-14))
            .chain((0..2).map(|k| strand(10.0 + k as f32, 2, 1e-7)))
            .chain((0..2).map(|k| strand(20.0 + k as f32, 1000, 0.5)))
            .collect();
        let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
        let (groom, repairs) = Groom::repaired(strands.concat(), &counts, Attributes::default()).expect("repaired");
        assert_eq!((repairs.degenerate_strands, groom.strand_count()), (5, 2), "{repairs}");
    }

    /// A groom whose points lie past 10⁵ median strands from the origin is
    /// refused whole, repaired or not (f32 would round its points by over a
    /// hundredth of a strand; a `.hair` file at 3·10³⁸ had been read as it
    /// came); at 10⁴ strands it is taken.
    #[test]
    fn a_groom_far_from_the_origin_for_its_size_is_refused() {
        let at = |offset: f32| -> Vec<Vec3> {
            (0..4).flat_map(|k| line(8, 0.1 * k as f32)).map(|p| p + Vec3::new(offset, 0.0, 0.0)).collect()
        };
        // Strands 0.07 across: 10⁴ of them is 700, 10⁵ is 7,000.
        assert!(Groom::new(at(700.0), &[8; 4]).is_ok());
        for offset in [7_100.0, 3e38] {
            for result in [
                Groom::new(at(offset), &[8; 4]).map(drop),
                Groom::repaired(at(offset), &[8; 4], Attributes::default()).map(drop),
            ] {
                match result {
                    Err(e @ Error::GroomFarAway { .. }) => {
                        // The message states the bound the check applies (error.rs, below
                        // groom, spells it out).
                        let bound = format!(
                            "over {} times its median strand (7e-2 across)",
                            crate::groom::MAX_DISTANCE_IN_STRANDS
                        );
                        assert!(e.to_string().contains(&bound), "{e}")
                    }
                    other => panic!("{offset}: expected GroomFarAway, got {other:?}"),
                }
            }
        }
    }

    /// A thickness below zero or over ten times its strand's size is no
    /// diameter: the
    /// strict constructor names it, repairing drops the thickness array and
    /// says so (a `.hair` file's negative thickness had been read even with
    /// `--strict`); a real one (0.1 mm on 7 cm strands) is kept, and so is
    /// 0.7 (ten times the strand).
    #[test]
    fn a_thickness_that_is_no_diameter_drops_the_array() {
        let strands = [line(8, 0.0), line(8, 0.1)].concat();
        for (value, named) in [(-1e-4, "has a thickness of -1e-4"), (0.8, "has a thickness of 8e-1")] {
            let mut t = vec![1e-4; 16];
            t[11] = value;
            let attributes = || Attributes { thickness: Some(t.clone()), ..Default::default() };
            match Groom::with_attributes(strands.clone(), &[8, 8], attributes()) {
                Err(e @ Error::BadThickness { strand: 1, point: 3, .. }) => {
                    assert!(e.to_string().contains(named), "{e}");
                    let bound = format!("(at least 0, at most {} times that)", crate::groom::MAX_THICKNESS_IN_SIZES);
                    assert!(e.to_string().contains(&bound), "{e}");
                }
                other => panic!("{value}: expected BadThickness, got {other:?}"),
            }
            let (groom, repairs) = Groom::repaired(strands.clone(), &[8, 8], attributes()).expect("repaired");
            assert!(groom.thickness().is_none() && groom.strand_count() == 2, "{value}: the strands kept, not it");
            assert!(repairs.to_string().contains("the thickness (strand 1 point 3 has"), "{repairs}");
        }
        for value in [1e-4, 0.7] {
            let attributes = Attributes { thickness: Some(vec![value; 16]), ..Default::default() };
            let groom = Groom::with_attributes(strands.clone(), &[8, 8], attributes).expect("a thickness");
            assert_eq!(groom.thickness().map(<[f32]>::len), Some(16));
        }
    }
}
