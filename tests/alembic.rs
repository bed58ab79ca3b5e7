//! Alembic grooms (`vkhair::groom::alembic`): real files written by Alembic
//! 1.6.1 (cortex's test data; the expected values are those cortex's own
//! `AlembicSceneTest.py` states), files written by `alembic::write` with
//! values stated here, and damaged files (every truncation, every byte
//! flipped, a cycle of objects): read or refused, never a panic.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec2, Vec3};
use vkhair::groom::alembic::{self, write};
use vkhair::groom::authored::Basis;
use vkhair::groom::Attributes;
use vkhair::{Error, Groom};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/curves").join(name)
}

#[test]
fn cortex_curves_read_as_cortex_states_them() {
    let (g, repairs) = alembic::open_repairing(data("cortex_curves.abc")).expect("curves.abc");
    assert!(repairs.is_empty());
    let objects: Vec<(&str, usize, Basis)> = g.objects.iter().map(|o| (o.path.as_str(), o.curves, o.basis)).collect();
    // testCurves: a 4-point b-spline; testLinearCurves: a linear curve through
    // (2, 0, 1) and (2, 0, -1).
    assert_eq!(objects, [("/curve/object", 1, Basis::Bspline), ("/linearLine/object", 1, Basis::Linear)]);
    assert_eq!(g.groom.strand_len(0), 4);
    assert_eq!(g.groom.strand(1), [Vec3::new(2.0, 0.0, 1.0), Vec3::new(2.0, 0.0, -1.0)]);
    assert!(!g.units_stated);
    // testNURBSCircle: periodic, so passed over and said...
    assert!(
        g.skipped.iter().any(|s| s.starts_with("/nurbsCircle/object") && s.contains("periodic")),
        "{:?}",
        g.skipped
    );
    // ...or refused with the object named.
    let e = alembic::open(data("cortex_curves.abc")).expect_err("a periodic curve");
    let text = e.to_string();
    assert!(
        text.contains("cortex_curves.abc") && text.contains("/nurbsCircle/object") && text.contains("periodic"),
        "{text}"
    );
}

#[test]
fn cortex_widths_read_per_vertex() {
    let g = alembic::open(data("cortex_widthTest.abc")).expect("widthTest.abc");
    // testReadWidths: /linear's widths are [0.2, 0.15, 0.1, 0.05], per vertex.
    let linear = g.objects.iter().position(|o| o.path == "/linear/curve").expect("/linear/curve");
    let t = g.groom.thickness().expect("widths");
    assert_eq!(&t[g.groom.strand_range(linear)], [0.2, 0.15, 0.1, 0.05]);
    // The points object is no curve: passed over and said.
    assert!(g.skipped.iter().any(|s| s.contains("/points") && s.contains("AbcGeom_Points_v1")), "{:?}", g.skipped);
}

/// Three strands with widths and colours, two marked guides, root UVs.
fn small_groom() -> (Groom, Vec<bool>, Vec<Vec2>) {
    let positions = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(0.1, 0.1, 0.0),
        Vec3::new(0.1, 0.2, 0.0),
        Vec3::new(0.2, 0.0, 0.0),
        Vec3::new(0.2, 0.1, 0.0),
    ];
    let attributes = Attributes {
        thickness: Some(vec![1e-4, 5e-5, 1e-4, 7e-5, 4e-5, 1e-4, 5e-5]),
        transparency: None,
        colors: Some(vec![Vec3::X, Vec3::X, Vec3::Y, Vec3::Y, Vec3::Y, Vec3::Z, Vec3::Z]),
    };
    let groom = Groom::with_attributes(positions, &[2, 3, 2], attributes).expect("groom");
    (groom, vec![true, false, true], vec![Vec2::new(0.25, 0.5), Vec2::new(0.5, 0.5), Vec2::new(0.75, 0.5)])
}

fn written() -> Vec<u8> {
    let (groom, guides, uvs) = small_groom();
    // A quarter turn about +Y, then a move by (1, 2, 3).
    let m = DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0)) * DMat4::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let objects = [
        write::CurvesObject {
            name: "plain",
            groom: &groom,
            guides: Some(&guides),
            root_uvs: Some(&uvs),
            transform: None,
        },
        write::CurvesObject { name: "moved", groom: &groom, guides: None, root_uvs: Some(&uvs), transform: Some(m) },
    ];
    write::to_bytes(&objects).expect("written")
}

#[test]
fn written_files_read_back_with_transforms_and_groom_attributes() {
    let (groom, _, uvs) = small_groom();
    let g = alembic::parse(&written()).expect("written file");
    let paths: Vec<&str> = g.objects.iter().map(|o| o.path.as_str()).collect();
    assert_eq!(paths, ["/plain", "/moved_xform/moved"]);
    assert_eq!((g.groom.strand_count(), g.groom.point_count()), (6, 14));
    assert_eq!(&g.groom.positions()[..7], groom.positions());
    // Turned a quarter about +Y, (x, y, z) → (z, y, -x), then moved by (1, 2, 3).
    for (p, q) in g.groom.positions()[7..].iter().zip(groom.positions()) {
        let want = Vec3::new(q.z + 1.0, q.y + 2.0, -q.x + 3.0);
        assert!((*p - want).length() < 1e-6, "{p} against {want}");
    }
    let t = g.groom.thickness().expect("widths");
    assert_eq!(&t[..7], groom.thickness().expect("widths"));
    assert_eq!(&g.groom.colors().expect("colours")[7..], groom.colors().expect("colours"));
    // Guides marked on the first object only; root UVs on both.
    assert_eq!(g.guides.as_deref(), Some(&[true, false, true, false, false, false][..]));
    assert_eq!(g.root_uvs.as_deref(), Some(&[uvs.clone(), uvs].concat()[..]));
}

#[test]
fn non_finite_points_are_named_with_the_object() {
    let mut bytes = written();
    // The first object's point 1 of strand 1 is (0.1, 0.1, 0): its y is the
    // first 0.1 after the strand's x. Patch the first P's fourth coordinate
    // (strand 0, point 1, y = 0.1) to NaN.
    let p = 0.1f32.to_le_bytes();
    let at = bytes.windows(4).position(|w| w == p).expect("a 0.1 in P");
    bytes[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = alembic::parse(&bytes).expect_err("NaN");
    let text = e.to_string();
    assert!(text.contains("/plain") && text.contains("strand 0") && text.contains("point 1"), "{text}");
    let (g, repairs) = alembic::parse_repairing(&bytes).expect("repaired");
    assert_eq!(repairs.non_finite_strands, 1);
    assert_eq!(g.groom.strand_count(), 5);
    // The guide marks follow the strands kept.
    assert_eq!(g.guides.as_deref(), Some(&[false, true, false, false, false][..]));
}

fn must_not_panic(bytes: &[u8]) {
    // Either outcome is fine; a panic fails the test.
    let _ = alembic::parse(bytes);
    let _ = alembic::parse_repairing(bytes);
}

#[test]
fn every_truncation_and_every_flipped_byte_is_read_or_refused() {
    let real = std::fs::read(data("cortex_curves.abc")).expect("fixture");
    for bytes in [real, written()] {
        for cut in 0..bytes.len() {
            if let Ok(g) = alembic::parse(&bytes[..cut]) {
                panic!("a file cut at {cut} of {} read as {} strands", bytes.len(), g.groom.strand_count());
            }
        }
        for at in 0..bytes.len() {
            let mut b = bytes.clone();
            b[at] ^= 0xff;
            must_not_panic(&b);
        }
    }
}

#[test]
fn the_writer_refuses_what_it_cannot_write() {
    let (groom, guides, uvs) = small_groom();
    let object =
        |name, guides, root_uvs| write::CurvesObject { name, groom: &groom, guides, root_uvs, transform: None };
    assert!(write::to_bytes(&[object("a/b", None, None)]).is_err());
    assert!(write::to_bytes(&[object("", None, None)]).is_err());
    assert!(write::to_bytes(&[object("a", None, None), object("a", None, None)]).is_err());
    assert!(write::to_bytes(&[object("a", Some(&guides[1..]), None)]).is_err());
    assert!(write::to_bytes(&[object("a", None, Some(&uvs[1..]))]).is_err());
    assert!(write::to_bytes(&[object("a", Some(&guides), Some(&uvs))]).is_ok());
}

/// Appends to `f` a data block of object headers, one per name (inline
/// empty metadata), then the 32 bytes of the objects' hashes.
fn append_object_headers(f: &mut Vec<u8>, names: &[&str]) {
    let mut headers = Vec::new();
    for name in names {
        headers.extend_from_slice(&(name.len() as u32).to_le_bytes());
        headers.extend_from_slice(name.as_bytes());
        headers.push(0xff);
        headers.extend_from_slice(&0u32.to_le_bytes());
    }
    headers.extend_from_slice(&[0u8; 32]);
    f.extend_from_slice(&(headers.len() as u64).to_le_bytes());
    f.extend_from_slice(&headers);
}

#[test]
fn a_cycle_of_objects_is_refused() {
    // Header, then the top object's child headers (two children named "a"),
    // then the top object's group listing itself as both children.
    let mut f = b"Ogawa\xff\x00\x01".to_vec();
    f.extend_from_slice(&[0u8; 8]);
    let headers_at = f.len() as u64;
    append_object_headers(&mut f, &["a", "a"]);
    let top = f.len() as u64;
    for v in [4u64, 0, top, top, headers_at | 1 << 63] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    let root = f.len() as u64;
    for v in [6u64, 1 << 63, 1 << 63, top, 1 << 63, 1 << 63, 1 << 63] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f[8..16].copy_from_slice(&root.to_le_bytes());
    let e = alembic::parse(&f).expect_err("a cycle");
    let text = e.to_string();
    assert!(text.contains("belongs to another object too"), "{text}");
}

/// An archive whose top object's children are `children` (after its empty
/// properties group), with the headers of `names` last — or, with
/// `headers_as_group`, a group offset in the headers' place.
fn archive_with_children(names: &[&str], children: usize, headers_as_group: Option<u64>) -> Vec<u8> {
    let mut f = b"Ogawa\xff\x00\x01".to_vec();
    f.extend_from_slice(&[0u8; 8]);
    let headers_at = f.len() as u64;
    append_object_headers(&mut f, names);
    let top = f.len() as u64;
    f.extend_from_slice(&(children as u64 + 2).to_le_bytes());
    // The properties, then empty groups for the children, then the headers.
    f.extend(std::iter::repeat_n(0u8, 8 * (children + 1)));
    f.extend_from_slice(&headers_as_group.unwrap_or(headers_at | 1 << 63).to_le_bytes());
    let root = f.len() as u64;
    for v in [6u64, 1 << 63, 1 << 63, top, 1 << 63, 1 << 63, 1 << 63] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f[8..16].copy_from_slice(&root.to_le_bytes());
    f
}

/// Child objects the reader cannot name are an error, never dropped: a group
/// where the children's headers belong (an offset past the file, or the empty
/// group 0; the reader had read "no children" and gone on without them), and
/// more child groups than headers. Two groups with their two headers read.
#[test]
fn child_objects_without_their_headers_are_refused_not_dropped() {
    for offset in [1_000_000u64, 0] {
        let e = alembic::parse(&archive_with_children(&["a", "b"], 2, Some(offset))).expect_err("refused");
        let text = e.to_string();
        assert!(text.contains(&format!("headers are a group (byte {offset}) where a data block belongs")), "{text}");
    }
    let e = alembic::parse(&archive_with_children(&["a", "b"], 3, None)).expect_err("refused").to_string();
    assert!(e.contains("it has 3 child object groups but headers for 2"), "{e}");
    // Named as they should be, they read: no curves, said as such.
    let e = alembic::parse(&archive_with_children(&["a", "b"], 2, None)).expect_err("no curves").to_string();
    assert!(e.contains("no curves object"), "{e}");
}

/// A thousand child objects naming one group of 150,000 children (1.2 MB)
/// would have the reader copy that list a thousand times (2.4 GB, past the
/// decoding budget) before the cycle check saw them: refused at the second,
/// naming it, before the list is read again.
#[test]
fn a_fan_out_of_objects_to_one_group_is_refused_before_it_is_read_again() {
    const CHILDREN: usize = 1000;
    let mut f = b"Ogawa\xff\x00\x01".to_vec();
    f.extend_from_slice(&[0u8; 8]);
    let shared = f.len() as u64;
    f.extend_from_slice(&150_000u64.to_le_bytes());
    f.extend(std::iter::repeat_n(0u8, 8 * 150_000));
    let headers_at = f.len() as u64;
    let names: Vec<String> = (0..CHILDREN).map(|i| format!("c{i}")).collect();
    append_object_headers(&mut f, &names.iter().map(String::as_str).collect::<Vec<_>>());
    let top = f.len() as u64;
    f.extend_from_slice(&(CHILDREN as u64 + 2).to_le_bytes());
    f.extend_from_slice(&0u64.to_le_bytes());
    for _ in 0..CHILDREN {
        f.extend_from_slice(&shared.to_le_bytes());
    }
    f.extend_from_slice(&(headers_at | 1 << 63).to_le_bytes());
    let root = f.len() as u64;
    for v in [6u64, 1 << 63, 1 << 63, top, 1 << 63, 1 << 63, 1 << 63] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f[8..16].copy_from_slice(&root.to_le_bytes());
    let text = alembic::parse(&f).expect_err("a fan-out").to_string();
    assert!(text.contains("object c1's group belongs to another object too"), "{text}");
}

/// A negative width (a diameter) in an Alembic file is a defect: refused
/// strictly naming the object and strand, passed over when repairing (the
/// widths dropped and said, the strands kept). The file is written, then one
/// width's bytes turned negative.
#[test]
fn a_negative_width_is_refused_strictly_and_passed_over_when_repairing() {
    let (groom, _, _) = small_groom();
    let o = write::CurvesObject { name: "w", groom: &groom, guides: None, root_uvs: None, transform: None };
    let mut bytes = write::to_bytes(&[o]).expect("written");
    // The fourth point's width, 7e-5, is the only one of its value.
    let width = 7e-5f32.to_le_bytes();
    let at = bytes.windows(4).position(|w| w == width).expect("the width in the file");
    bytes[at..at + 4].copy_from_slice(&(-7e-5f32).to_le_bytes());
    let text = alembic::parse(&bytes).expect_err("strict").to_string();
    assert!(text.contains("/w") && text.contains("strand 1 has a negative width"), "{text}");
    let (g, _) = alembic::parse_repairing(&bytes).expect("repairing");
    assert_eq!(g.groom.strand_count(), 3);
    assert!(g.groom.thickness().is_none(), "the widths were read");
    assert!(g.skipped.iter().any(|s| s.contains("negative width")), "{:?}", g.skipped);
}

/// A transform that moves a groom farther than 10 km from the origin (or
/// scales it there) is refused naming the object, the strand, the point and
/// where it lies, not read into a groom no scene can frame.
#[test]
fn a_transform_that_throws_the_groom_far_away_is_refused() {
    let (groom, _, _) = small_groom();
    for (m, what) in [
        (DMat4::from_translation(DVec3::new(1e30, 0.0, 0.0)), "a 1e30 translation"),
        (DMat4::from_scale(DVec3::splat(1e6)), "a scale of a million"),
    ] {
        let o = write::CurvesObject { name: "far", groom: &groom, guides: None, root_uvs: None, transform: Some(m) };
        let text = alembic::parse(&write::to_bytes(&[o]).expect("written")).expect_err(what).to_string();
        assert!(text.contains("/far_xform/far") && text.contains("strand 0 point"), "{what}: {text}");
        assert!(text.contains("within 1e4 m of the origin"), "{what}: {text}");
    }
    // 1 km away reads.
    let near = DMat4::from_translation(DVec3::new(1e3, 0.0, 0.0));
    let o = write::CurvesObject { name: "near", groom: &groom, guides: None, root_uvs: None, transform: Some(near) };
    assert!(alembic::parse(&write::to_bytes(&[o]).expect("written")).is_ok());
}

#[test]
fn not_alembic_files_are_named() {
    let e = alembic::parse(b"\x89HDF\r\n\x1a\n and more bytes").expect_err("HDF5");
    assert!(e.to_string().contains("HDF5"), "{e}");
    let e = alembic::parse(b"Ogawa\x00\x00\x01\0\0\0\0\0\0\0\0").expect_err("unfinished");
    assert!(e.to_string().contains("did not finish"), "{e}");
    let e = alembic::parse(b"not an alembic file at all").expect_err("junk");
    assert!(matches!(e, Error::BadMagic { .. }), "{e:?}");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("cut.abc");
    std::fs::write(&path, &written()[..100]).expect("write");
    let e = alembic::open(&path).expect_err("truncated");
    assert!(e.to_string().contains("cut.abc"), "{e}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 512, ..Default::default() })]
    /// Several bytes overwritten at once (offsets, counts and names broken
    /// together): read or refused, never a panic.
    #[test]
    fn random_damage_is_read_or_refused(edits in proptest::collection::vec((0usize..4096, proptest::prelude::any::<u8>()), 1..12)) {
        let mut b = written();
        for (at, v) in edits {
            let n = b.len();
            b[at % n] = v;
        }
        must_not_panic(&b);
    }
}

/// A groom of 20,000 strands (the size of an artist's) written and read
/// back whole.
#[test]
fn twenty_thousand_strands_read_back() {
    let strands: Vec<Vec<Vec3>> = (0..20_000)
        .map(|s| {
            let a = s as f32 * 2.399;
            let root = Vec3::new(a.cos(), 1.0, a.sin()) * (0.05 + 0.04 * (s as f32 / 20_000.0));
            (0..24).map(|i| root + Vec3::new(0.003 * (i as f32).sin(), -0.01 * i as f32, 0.0)).collect()
        })
        .collect();
    let groom = Groom::from_strands(&strands).expect("groom");
    let object = write::CurvesObject { name: "dense", groom: &groom, guides: None, root_uvs: None, transform: None };
    let g = alembic::parse(&write::to_bytes(&[object]).expect("written")).expect("20,000 strands");
    assert_eq!((g.groom.strand_count(), g.groom.point_count()), (20_000, 480_000));
    assert_eq!(g.groom.positions(), groom.positions());
}

/// An empty Alembic file is named as empty, and a FIFO nothing writes to as
/// what it is, not as an archive cut short.
#[test]
fn an_empty_file_and_a_silent_fifo_are_named_as_such() {
    let dir = tempfile::tempdir().expect("tempdir");
    let empty = dir.path().join("empty.abc");
    std::fs::write(&empty, b"").expect("write");
    let e = alembic::open(&empty).expect_err("empty").to_string();
    assert!(e.contains("empty.abc") && e.contains("the file is empty"), "{e}");
    let fifo = dir.path().join("pipe.abc");
    crate::common::mkfifo(&fifo);
    let e = alembic::open(&fifo).expect_err("a silent FIFO").to_string();
    assert!(e.contains("pipe.abc") && e.contains("a FIFO nothing wrote to"), "{e}");
}
