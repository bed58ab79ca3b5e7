//! Groom validation and the `.hair` / `.tfx` / OBJ readers, including hostile input.

use glam::Vec3;
use proptest::prelude::*;
use vkhair::groom::cyhair::{HairDefaults, HairFile, INFO_LEN};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::{Attributes, Groom, MAX_POINTS, MAX_STRANDS};
use vkhair::{Error, FileFormat};

fn two_strands() -> Groom {
    Groom::from_strands(&[
        vec![Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.1, -2.0, 0.0)],
        vec![Vec3::X, Vec3::new(1.0, -0.5, 0.2), Vec3::new(1.0, -1.0, 0.3), Vec3::new(1.2, -1.5, 0.3)],
    ])
    .expect("valid groom")
}

// ---- Groom validation -------------------------------------------------------

#[test]
fn groom_rejects_each_invariant_with_its_own_error() {
    assert!(matches!(Groom::new(vec![], &[]), Err(Error::EmptyGroom)));
    assert!(matches!(Groom::new(vec![Vec3::ZERO], &[1]), Err(Error::StrandPointCount { strand: 0, points: 1, .. })));
    assert!(matches!(
        Groom::new(vec![Vec3::ZERO, Vec3::X], &[3]),
        Err(Error::AttributeLength { what: "positions", expected: 3, actual: 2 })
    ));
    assert!(matches!(
        Groom::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::new(f32::NAN, 0.0, 0.0)], &[2, 2]),
        Err(Error::NonFinite { strand: 1, point: 1, what: "position" })
    ));
    assert!(matches!(
        Groom::new(vec![Vec3::ZERO, Vec3::X, Vec3::X, Vec3::Y], &[4]),
        Err(Error::ZeroLengthSegment { strand: 0, segment: 1 })
    ));
    assert!(matches!(Groom::new(vec![Vec3::ZERO, Vec3::X], &[u32::MAX]), Err(Error::StrandPointCount { .. })));
    let too_many = vec![2u32; MAX_STRANDS + 1];
    assert!(matches!(Groom::new(vec![], &too_many), Err(Error::TooManyStrands { .. })));
    let huge = vec![65_536u32; MAX_POINTS / 65_536 + 1];
    assert!(matches!(Groom::new(vec![], &huge), Err(Error::TooManyPoints { .. })));
    let attrs = Attributes { thickness: Some(vec![1.0; 3]), ..Attributes::default() };
    assert!(matches!(
        Groom::with_attributes(vec![Vec3::ZERO, Vec3::X], &[2], attrs),
        Err(Error::AttributeLength { what: "thickness", .. })
    ));
    let attrs = Attributes { colors: Some(vec![Vec3::ONE, Vec3::splat(f32::INFINITY)]), ..Attributes::default() };
    assert!(matches!(
        Groom::with_attributes(vec![Vec3::ZERO, Vec3::X], &[2], attrs),
        Err(Error::NonFinite { what: "color", point: 1, .. })
    ));
}

#[test]
fn selecting_key_hairs() {
    let g = two_strands();
    let picked = g.select(&[1]).expect("select");
    assert_eq!(picked.strand_count(), 1);
    assert_eq!(picked.strand(0), g.strand(1));
    assert!(matches!(g.select(&[2]), Err(Error::StrandIndex { index: 2, count: 2 })));
    assert_eq!(g.every_nth(2).expect("every 2nd").strand_count(), 1);
    assert!(matches!(g.every_nth(0), Err(Error::InvalidParameter { .. })));
    assert_eq!(g.select_evenly(2).expect("evenly"), g);
    assert!(matches!(g.select_evenly(3), Err(Error::InvalidParameter { .. })));
}

// ---- .hair ------------------------------------------------------------------

#[test]
fn hair_round_trip_is_exact_with_all_arrays() {
    let g = two_strands();
    let n = g.point_count();
    let attrs = Attributes {
        thickness: Some((0..n).map(|i| 0.1 + i as f32).collect()),
        transparency: Some((0..n).map(|i| i as f32 / 10.0).collect()),
        colors: Some((0..n).map(|i| Vec3::new(i as f32, 0.5, -0.0)).collect()),
    };
    let g = Groom::with_attributes(g.positions().to_vec(), &[3, 4], attrs).expect("groom");
    let mut file = HairFile::new(g, "test groom");
    file.defaults = HairDefaults { segments: 0, thickness: 0.25, transparency: 0.5, color: [0.1, 0.2, 0.3] };
    let bytes = file.to_bytes();
    assert_eq!(&bytes[..4], b"HAIR");
    // Header 128 + segments 2×2 + points 7×12 + thickness 7×4 + transparency 7×4 + colors 7×12.
    assert_eq!(bytes.len(), 128 + 4 + 84 + 28 + 28 + 84);
    let back = HairFile::parse(&bytes).expect("parse");
    assert_eq!(back, file);
    assert_eq!(back.info_str(), "test groom");
    assert_eq!(back.to_bytes(), bytes);
}

#[test]
fn hair_without_segments_array_uses_the_default_count() {
    let g = Groom::from_strands(&[vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], vec![Vec3::Y, Vec3::ONE, Vec3::ONE * 2.0]])
        .expect("groom");
    let file = HairFile::new(g, "");
    assert!(!file.has_segments_array);
    let bytes = file.to_bytes();
    assert_eq!(u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")), 2, "points only");
    assert_eq!(u32::from_le_bytes(bytes[16..20].try_into().expect("4 bytes")), 2, "default segments");
    assert_eq!(HairFile::parse(&bytes).expect("parse"), file);
}

/// A valid header with the given fields, followed by `body`.
fn hair_bytes(hairs: u32, points: u32, flags: u32, default_segments: u32, body: &[u8]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(b"HAIR");
    for v in [hairs, points, flags, default_segments] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [1.0f32, 0.0, 1.0, 1.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; INFO_LEN]);
    b.extend_from_slice(body);
    b
}

#[test]
fn hostile_hair_files_give_typed_errors() {
    let valid = HairFile::new(two_strands(), "x").to_bytes();
    // Truncated anywhere.
    for cut in [0, 3, 64, 127, 128, 131, valid.len() - 1] {
        let err = HairFile::parse(&valid[..cut]).expect_err("truncated");
        assert!(matches!(err, Error::Truncated { format: FileFormat::CyHair, .. }), "cut {cut}: {err}");
    }
    // Wrong signature.
    let mut bad = valid.clone();
    bad[0] = b'X';
    assert!(matches!(HairFile::parse(&bad), Err(Error::BadMagic { .. })));
    // Huge counts: rejected without allocating.
    assert!(matches!(HairFile::parse(&hair_bytes(u32::MAX, 10, 3, 0, &[])), Err(Error::TooManyStrands { .. })));
    assert!(matches!(HairFile::parse(&hair_bytes(10, u32::MAX, 3, 0, &[])), Err(Error::TooManyPoints { .. })));
    // Counts that fit the limits but not the file.
    assert!(matches!(
        HairFile::parse(&hair_bytes(1_000_000, 10_000_000, 3, 0, &[0; 64])),
        Err(Error::Truncated { what: "arrays announced by the header", .. })
    ));
    // Lying point count: segments say 3 + 4 points, header says 8.
    let mut lying = valid.clone();
    lying[8..12].copy_from_slice(&8u32.to_le_bytes());
    lying.extend_from_slice(&[0; 12]);
    assert!(matches!(HairFile::parse(&lying), Err(Error::Malformed { .. })));
    // No points array; unknown flags; zero hairs; missing default segment count.
    assert!(matches!(HairFile::parse(&hair_bytes(1, 2, 1, 0, &[1, 0])), Err(Error::Unsupported { .. })));
    assert!(matches!(HairFile::parse(&hair_bytes(1, 2, 2 | 64, 1, &[0; 24])), Err(Error::Unsupported { .. })));
    assert!(matches!(HairFile::parse(&hair_bytes(0, 0, 2, 1, &[])), Err(Error::EmptyGroom)));
    assert!(matches!(HairFile::parse(&hair_bytes(1, 2, 2, 0, &[0; 24])), Err(Error::Malformed { .. })));
    // NaN point.
    let mut nan = valid.clone();
    let first_point = 128 + 4;
    nan[first_point..first_point + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(HairFile::parse(&nan), Err(Error::NonFinite { strand: 0, point: 0, .. })));
    // A hair with zero segments (one point).
    let mut body = Vec::new();
    body.extend_from_slice(&0u16.to_le_bytes());
    body.extend_from_slice(&[0; 12]);
    assert!(matches!(HairFile::parse(&hair_bytes(1, 1, 3, 0, &body)), Err(Error::StrandPointCount { .. })));
    // Zero-length segment.
    let mut body = Vec::new();
    body.extend_from_slice(&1u16.to_le_bytes());
    body.extend_from_slice(&[0; 24]);
    assert!(matches!(HairFile::parse(&hair_bytes(1, 2, 3, 0, &body)), Err(Error::ZeroLengthSegment { .. })));
}

#[test]
fn missing_file_is_an_io_error() {
    assert!(matches!(HairFile::open("/nonexistent/dir/x.hair"), Err(Error::Io { .. })));
}

fn strand_strategy() -> impl Strategy<Value = Vec<Vec3>> {
    (2usize..12, -100.0f32..100.0, -100.0f32..100.0, -100.0f32..100.0, 0.01f32..5.0).prop_flat_map(
        |(n, x, y, z, step)| {
            prop::collection::vec((-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), n - 1).prop_map(move |dirs| {
                let mut p = Vec3::new(x, y, z);
                let mut out = vec![p];
                for (dx, dy, dz) in dirs {
                    let d = Vec3::new(dx, dy, dz).try_normalize().unwrap_or(Vec3::Y);
                    p += d * step;
                    out.push(p);
                }
                out
            })
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, .. ProptestConfig::default() })]

    #[test]
    fn hair_write_read_round_trips(strands in prop::collection::vec(strand_strategy(), 1..20), with_thickness: bool, info in "[a-z ]{0,100}") {
        let g = Groom::from_strands(&strands).expect("generated strands are valid");
        let n = g.point_count();
        let attrs = Attributes {
            // Within ten times the smallest strand (a first segment of 0.01).
            thickness: with_thickness.then(|| (0..n).map(|i| (i % 10) as f32 * 0.01).collect()),
            ..Attributes::default()
        };
        let counts: Vec<u32> = (0..g.strand_count()).map(|i| g.strand_len(i) as u32).collect();
        let g = Groom::with_attributes(g.positions().to_vec(), &counts, attrs).expect("valid");
        let file = HairFile::new(g, &info);
        let bytes = file.to_bytes();
        let back = HairFile::parse(&bytes).expect("round trip parses");
        prop_assert_eq!(&back, &file);
        prop_assert_eq!(back.to_bytes(), bytes);
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let _ = HairFile::parse(&bytes);
        let _ = TfxFile::parse(&bytes);
        let _ = TriMesh::parse_obj(&bytes);
    }

    #[test]
    fn random_bytes_after_a_valid_signature_give_errors_not_panics(body in prop::collection::vec(any::<u8>(), 0..600)) {
        let mut bytes = b"HAIR".to_vec();
        bytes.extend_from_slice(&body);
        let _ = HairFile::parse(&bytes);
    }

    #[test]
    fn mutated_valid_files_give_errors_not_panics(strands in prop::collection::vec(strand_strategy(), 1..6), edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8), cut in any::<prop::sample::Index>(), truncate: bool) {
        let file = HairFile::new(Groom::from_strands(&strands).expect("valid"), "m");
        let mut bytes = file.to_bytes();
        for (at, value) in edits {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        if truncate {
            let keep = cut.index(bytes.len());
            bytes.truncate(keep);
        }
        match HairFile::parse(&bytes) {
            Ok(parsed) => {
                // Whatever parses is a valid groom that writes back consistently.
                let again = HairFile::parse(&parsed.to_bytes()).expect("re-parse");
                prop_assert_eq!(again.groom, parsed.groom);
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}

// ---- .tfx -------------------------------------------------------------------

fn tfx_bytes(strands: u32, per_strand: u32, positions: &[[f32; 4]], thickness: Option<&[f32]>) -> Vec<u8> {
    let mut b = Vec::new();
    let positions_at = 160u32;
    let thickness_at = if thickness.is_some() { positions_at + 16 * positions.len() as u32 } else { 0 };
    b.extend_from_slice(&4.0f32.to_le_bytes());
    for v in [strands, per_strand, positions_at, 0, 0, thickness_at, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; 128]);
    for p in positions {
        for v in p {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    for t in thickness.unwrap_or(&[]) {
        b.extend_from_slice(&t.to_le_bytes());
    }
    b
}

#[test]
fn tfx_reads_positions_inverse_mass_and_thickness() {
    let positions = [[0.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0], [1.0, -1.0, 0.0, 1.0]];
    let f = TfxFile::parse(&tfx_bytes(2, 2, &positions, Some(&[0.5, 0.25]))).expect("parse");
    assert_eq!(f.version, 4.0);
    assert_eq!(f.groom.strand_count(), 2);
    assert_eq!(f.groom.strand(1), &[Vec3::X, Vec3::new(1.0, -1.0, 0.0)]);
    assert_eq!(f.inverse_mass, vec![0.0, 1.0, 0.0, 1.0]);
    assert_eq!(f.groom.thickness(), Some(&[0.5, 0.5, 0.25, 0.25][..]));
}

#[test]
fn hostile_tfx_files_give_typed_errors() {
    let positions = [[0.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 1.0]];
    let valid = tfx_bytes(1, 2, &positions, None);
    assert!(matches!(TfxFile::parse(&valid[..100]), Err(Error::Truncated { format: FileFormat::TressFx, .. })));
    assert!(matches!(TfxFile::parse(&valid[..valid.len() - 1]), Err(Error::Truncated { .. })));
    let mut bad_version = valid.clone();
    bad_version[..4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(TfxFile::parse(&bad_version), Err(Error::BadMagic { .. })));
    assert!(matches!(TfxFile::parse(&tfx_bytes(u32::MAX, 2, &positions, None)), Err(Error::TooManyStrands { .. })));
    assert!(matches!(TfxFile::parse(&tfx_bytes(1, 1, &positions, None)), Err(Error::StrandPointCount { .. })));
    assert!(matches!(TfxFile::parse(&tfx_bytes(4_000_000, 64, &positions, None)), Err(Error::TooManyPoints { .. })));
    assert!(matches!(TfxFile::parse(&tfx_bytes(0, 2, &positions, None)), Err(Error::EmptyGroom)));
    let negative_mass = [[0.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, -1.0]];
    assert!(matches!(
        TfxFile::parse(&tfx_bytes(1, 2, &negative_mass, None)),
        Err(Error::NonFinite { what: "inverse mass", .. })
    ));
}

/// A TressFX file like TressFX's own `mohawk.tfx`: one strand (of 4) with a
/// zero-length first segment, one whose inverse mass is NaN; the strict reader
/// refuses it, the repairing one drops exactly what is broken and keeps the
/// per-vertex inverse mass and per-strand thickness of what stays in step.
#[test]
fn tfx_with_a_degenerate_strand_is_refused_strictly_and_repaired_otherwise() {
    let strand = |x: f32, w: f32| [[x, 0.0, 0.0, 0.0], [x, -1.0, 0.0, w], [x, -2.0, 0.0, w]];
    let mut positions: Vec<[f32; 4]> =
        [strand(0.0, 1.0), strand(1.0, 0.5), strand(2.0, 1.0), strand(3.0, 0.25)].concat();
    positions[4] = positions[3]; // strand 1: segment 0 has zero length
    positions[8][3] = f32::NAN; // strand 2: inverse mass NaN
    let bytes = tfx_bytes(4, 3, &positions, Some(&[0.1, 0.2, 0.3, 0.4]));
    assert!(matches!(TfxFile::parse(&bytes), Err(Error::NonFinite { strand: 2, what: "inverse mass", .. })));
    let mut zero_only = positions.clone();
    zero_only[8][3] = 1.0;
    let zero_only = tfx_bytes(4, 3, &zero_only, None);
    assert!(matches!(TfxFile::parse(&zero_only), Err(Error::ZeroLengthSegment { strand: 1, segment: 0 })));
    let (f, repairs) = TfxFile::parse_repairing(&bytes).expect("repaired");
    assert_eq!((repairs.zero_length_segments, repairs.non_finite_strands, repairs.short_strands), (1, 1, 0));
    assert_eq!(f.groom.strand_count(), 3);
    assert_eq!(f.groom.strand_len(1), 2, "strand 1 lost its duplicate point");
    assert_eq!(f.groom.strand(2)[0], Vec3::new(3.0, 0.0, 0.0), "strand 3 became the third");
    assert_eq!(f.inverse_mass, vec![0.0, 1.0, 1.0, 0.0, 0.5, 0.0, 0.25, 0.25]);
    let thickness = f.groom.thickness().expect("thickness");
    assert_eq!(thickness[thickness.len() - 1], 0.4, "per-strand thickness followed its strand");
    // A clean file: nothing to repair, the same groom as the strict reader's.
    let clean = tfx_bytes(2, 3, &[strand(0.0, 1.0), strand(1.0, 1.0)].concat(), None);
    let (f, repairs) = TfxFile::parse_repairing(&clean).expect("clean");
    assert!(repairs.is_empty());
    assert_eq!(f, TfxFile::parse(&clean).expect("strict"));
}

#[test]
fn hair_with_a_collapsed_strand_is_repaired() {
    let strands = [
        vec![Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, -2.0, 0.0)],
        vec![Vec3::X; 3],
        vec![Vec3::Z, Vec3::new(0.0, -1.0, 1.0), Vec3::new(0.0, -2.0, 1.0)],
    ];
    let counts: Vec<u16> = vec![2, 2, 2];
    let mut body: Vec<u8> = counts.iter().flat_map(|c| c.to_le_bytes()).collect();
    body.extend(strands.concat().iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes));
    let bytes = hair_bytes(3, 9, 0b11, 0, &body);
    assert!(matches!(HairFile::parse(&bytes), Err(Error::ZeroLengthSegment { strand: 1, .. })));
    let (f, repairs) = HairFile::parse_repairing(&bytes).expect("repaired");
    assert_eq!((repairs.zero_length_segments, repairs.short_strands), (2, 1), "{repairs}");
    assert_eq!(f.groom.strand_count(), 2);
    assert_eq!(f.groom.strand(1), &strands[2][..]);
}

// ---- OBJ --------------------------------------------------------------------

#[test]
fn a_binary_obj_says_it_is_not_text() {
    let mut bytes = b"v 0 0 0\nv 1 0 0\n".to_vec();
    bytes.extend_from_slice(&[0xff, 0xfe, 0x00, 0x81]);
    let err = TriMesh::parse_obj(&bytes).expect_err("binary");
    assert!(err.to_string().contains("line 3 is not UTF-8"), "{err}");
}

/// A glTF document given where an OBJ mesh belongs (binary or JSON) is named
/// as a glTF document, not as a malformed OBJ; the shared character is one.
#[test]
fn a_gltf_document_given_as_a_mesh_is_named_as_one() {
    let glb = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb")).expect("read");
    let json = br#"  {"asset": {"version": "2.0"}, "nodes": []}"#;
    for bytes in [&glb[..], &json[..]] {
        let err = TriMesh::parse_obj(bytes).expect_err("a glTF document").to_string();
        assert!(err.contains("this is a glTF document, not an OBJ mesh"), "{err}");
    }
}

#[test]
fn obj_parsing_and_errors() {
    let quad = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let m = TriMesh::parse_obj(quad).expect("quad");
    assert_eq!(m.triangles.len(), 2);
    assert_eq!(m.positions.len(), 4);
    assert!(matches!(TriMesh::parse_obj(b"v 0 0 0\n"), Err(Error::Malformed { format: FileFormat::Obj, .. })));
    assert!(matches!(TriMesh::parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), Err(Error::Malformed { .. })));
    assert!(matches!(TriMesh::parse_obj(b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), Err(Error::Malformed { .. })));
}

// ---- Real third-party data (skipped when ../shared/data is absent) ----------

fn shared(path: &str) -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data").join(path);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipped: {} not present", p.display());
        None
    }
}

#[test]
fn sintel_tfx_reads_as_documented() {
    let Some(path) = shared("sintel/sintel_hair.tfx") else { return };
    let f = TfxFile::open(path).expect("sintel tfx");
    assert_eq!(f.groom.strand_count(), 228);
    assert_eq!(f.groom.uniform_points_per_strand(), Some(32));
    // Only the root vertex of each strand is pinned.
    for s in 0..228 {
        assert_eq!(f.inverse_mass[s * 32], 0.0);
        assert!(f.inverse_mass[s * 32 + 1..(s + 1) * 32].iter().all(|&w| w > 0.0));
    }
    // Blender units: the bust is about 50 tall; hair lies within it.
    let (lo, hi) = f.groom.bounds();
    assert!(lo.y > 0.0 && hi.y < 60.0, "{lo} {hi}");
    // Round trip through .hair keeps positions bit for bit.
    let bytes = HairFile::new(f.groom.clone(), "sintel").to_bytes();
    assert_eq!(HairFile::parse(&bytes).expect("parse").groom, f.groom);
}

#[test]
fn sintel_bust_loads() {
    let Some(path) = shared("sintel/sintel_bust.obj") else { return };
    let m = TriMesh::load_obj(path).expect("bust");
    assert!(m.triangles.len() >= 5952);
    let (lo, hi) = m.bounds();
    assert!((hi.y - lo.y) > 20.0 && (hi.y - lo.y) < 80.0, "about 50 units tall: {lo} {hi}");
}

/// A file that is read but cannot be parsed names the file and keeps the parser's
/// typed error as its source; a missing file is an I/O error naming it.
#[test]
fn unreadable_assets_name_their_file() {
    let dir = std::env::temp_dir().join(format!("vkhair-asset-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let cases: [(&str, &[u8]); 3] = [("bad.hair", b"HAIX"), ("bad.tfx", b"\x01"), ("bad.obj", b"f 1 2 3\n")];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write");
        let result = match name {
            "bad.hair" => HairFile::open(&path).map(|_| ()),
            "bad.tfx" => TfxFile::open(&path).map(|_| ()),
            _ => TriMesh::load_obj(&path).map(|_| ()),
        };
        match result {
            Err(Error::Asset { path: p, source }) => {
                assert_eq!(p, path);
                assert!(
                    matches!(*source, Error::BadMagic { .. } | Error::Truncated { .. } | Error::Malformed { .. }),
                    "{name}: {source:?}"
                );
                let message = Error::Asset { path: p, source }.to_string();
                assert!(message.starts_with(&path.display().to_string()), "{message}");
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let missing = dir.join("missing.hair");
    assert!(matches!(HairFile::open(&missing), Err(Error::Io { path, .. }) if path == missing));
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// The README's caps: an OBJ file over 256 MiB is refused before reading (a
/// sparse file: nothing is written or read), naming the file and the cap; a
/// `.hair` file is bounded by its format's limits, 520 MiB.
#[test]
fn input_caps_hold_before_reading() {
    use vkhair::groom::mesh::{TriMesh, MAX_OBJ_BYTES};
    assert_eq!(MAX_OBJ_BYTES, 256 << 20);
    assert_eq!(HairFile::MAX_FILE_BYTES, (520 << 20) + 128);
    let dir = tempfile::tempdir().expect("temp dir");
    let big = dir.path().join("big.obj");
    std::fs::File::create(&big).expect("create").set_len(MAX_OBJ_BYTES + 1).expect("sparse");
    match TriMesh::load_obj(&big) {
        Err(e @ Error::InputTooLarge { cap, .. }) => {
            assert_eq!(cap, MAX_OBJ_BYTES);
            assert!(e.to_string().contains("big.obj"), "{e}");
        }
        other => panic!("expected InputTooLarge, got {other:?}"),
    }
}
