//! The authored-groom assembly's unit tests.

use super::*;

#[test]
fn bezier_strands_pass_through_their_ends_and_thirds() {
    let p = [DVec3::ZERO, DVec3::X, DVec3::new(2.0, 1.0, 0.0), DVec3::new(3.0, 1.0, 0.0)];
    let s = bezier_samples(&p).expect("4 points");
    assert_eq!(s.len(), 4);
    assert_eq!((s[0], s[3]), (p[0], p[3]));
    // B(1/3) = (8 p0 + 12 p1 + 6 p2 + p3) / 27.
    let third = (p[0] * 8.0 + p[1] * 12.0 + p[2] * 6.0 + p[3]) / 27.0;
    assert!((s[1] - third).length() < 1e-12);
    assert!(bezier_samples(&p[..3]).is_none());
}

#[test]
fn pinned_b_spline_ends_are_kept_once() {
    let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    let mut o = RawCurves {
        path: "/c".into(),
        basis: Basis::Bspline,
        counts: vec![7, 3, 1, 4],
        points: vec![a, a, a, b, c, c, c, a, b, c, d, a, a, b, c],
        widths: Some((0..15).map(|i| i as f32).collect()),
        colors: None,
        guides: None,
        root_uvs: None,
    };
    collapse_pinned_ends(&mut o);
    // Two equal points are a zero-length segment, left for the checks.
    assert_eq!(o.counts, vec![3, 3, 1, 4]);
    assert_eq!(o.points, vec![a, b, c, a, b, c, d, a, a, b, c]);
    assert_eq!(o.widths, Some(vec![2.0, 3.0, 4.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0]));
}

#[test]
fn spaced_values_interpolate_along_each_curve() {
    // Two curves of 3 and 5 points, values at 2 places along each.
    let v = per_point_from_spaced(&[0.0f32, 1.0, 10.0, 20.0], &[3, 5], |_| 2).expect("lengths add up");
    assert_eq!(v, vec![0.0, 0.5, 1.0, 10.0, 12.5, 15.0, 17.5, 20.0]);
    assert!(per_point_from_spaced(&[0.0f32; 3], &[3, 5], |_| 2).is_none());
}
