//! Structure-aware fuzzing of the asset readers: valid `.hair`, `.tfx` and OBJ
//! files are generated, then one field, count or float is changed (or the file
//! cut); every reader, strict and repairing, returns a groom or mesh that holds
//! its invariants or one of the typed file errors — never a panic.

use glam::Vec3;
use proptest::prelude::*;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::Groom;
use vkhair::Error;

/// The errors a reader may give for a bad file.
fn is_file_error(e: &Error) -> bool {
    matches!(
        e,
        Error::BadMagic { .. }
            | Error::Truncated { .. }
            | Error::Malformed { .. }
            | Error::Unsupported { .. }
            | Error::EmptyGroom
            | Error::NothingLeft { .. }
            | Error::TooManyStrands { .. }
            | Error::TooManyPoints { .. }
            | Error::StrandPointCount { .. }
            | Error::NonFinite { .. }
            | Error::ZeroLengthSegment { .. }
            | Error::OutlierPoint { .. }
            | Error::DegenerateStrand { .. }
            | Error::AttributeLength { .. }
            | Error::GroomExtent { .. }
            | Error::GroomFarAway { .. }
            | Error::BadThickness { .. }
            | Error::BadScalp(_)
    )
}

/// A parsed groom holds the invariants: finite points, 2+ points a strand.
fn check_groom(g: &Groom) -> Result<(), TestCaseError> {
    prop_assert!(g.strand_count() > 0);
    prop_assert!(g.positions().iter().all(|p| p.is_finite()));
    prop_assert!((0..g.strand_count()).all(|s| g.strand_len(s) >= 2));
    Ok(())
}

fn check<T>(result: Result<T, Error>, groom: impl Fn(&T) -> &Groom) -> Result<(), TestCaseError> {
    match result {
        Ok(value) => check_groom(groom(&value)),
        Err(e) => {
            prop_assert!(is_file_error(&e), "untyped error: {e:?}");
            prop_assert!(!e.to_string().is_empty());
            Ok(())
        }
    }
}

/// Floats a mutation writes: the awkward ones and ordinary ones.
fn weird_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        Just(f32::MAX),
        Just(-f32::MAX),
        Just(0.0),
        Just(-0.0),
        Just(f32::MIN_POSITIVE / 2.0),
        -1e6f32..1e6,
    ]
}

/// Counts and offsets a mutation writes.
fn weird_u32() -> impl Strategy<Value = u32> {
    prop_oneof![Just(0u32), Just(1), Just(2), Just(u32::MAX), Just(1 << 22), Just(1 << 24), 0u32..2000]
}

/// One change to a file: a u32 or f32 written at a 4-byte-aligned place, a
/// byte, or a cut.
#[derive(Debug, Clone)]
enum Change {
    Word(prop::sample::Index, u32),
    Float(prop::sample::Index, f32),
    Byte(prop::sample::Index, u8),
    Cut(prop::sample::Index),
}

fn change() -> impl Strategy<Value = Change> {
    prop_oneof![
        (any::<prop::sample::Index>(), weird_u32()).prop_map(|(i, v)| Change::Word(i, v)),
        (any::<prop::sample::Index>(), weird_f32()).prop_map(|(i, v)| Change::Float(i, v)),
        (any::<prop::sample::Index>(), any::<u8>()).prop_map(|(i, v)| Change::Byte(i, v)),
        any::<prop::sample::Index>().prop_map(Change::Cut),
    ]
}

/// Applies `c`; `header` is the header's length, where words land more often.
fn apply(bytes: &mut Vec<u8>, c: &Change, header: usize) {
    let word_at = |i: &prop::sample::Index, bytes: &Vec<u8>| {
        // Half the words land in the header (counts, flags, offsets).
        let words = bytes.len() / 4;
        let raw = i.index(2 * words.max(1));
        4 * if raw < words { raw } else { (raw - words) % (header / 4).max(1) }
    };
    match c {
        Change::Word(i, v) => {
            let at = word_at(i, bytes);
            if at + 4 <= bytes.len() {
                bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        Change::Float(i, v) => {
            let at = word_at(i, bytes);
            if at + 4 <= bytes.len() {
                bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
        }
        Change::Byte(i, v) => {
            let at = i.index(bytes.len().max(1));
            if at < bytes.len() {
                bytes[at] = *v;
            }
        }
        Change::Cut(i) => {
            let keep = i.index(bytes.len().max(1));
            bytes.truncate(keep);
        }
    }
}

fn strands() -> impl Strategy<Value = Vec<Vec<Vec3>>> {
    (1usize..6, 2usize..7).prop_flat_map(|(count, points)| {
        prop::collection::vec(
            prop::collection::vec((-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), points).prop_map(|offsets| {
                let mut p = Vec3::ZERO;
                offsets
                    .into_iter()
                    .enumerate()
                    .map(|(k, (x, y, z))| {
                        p += Vec3::new(x, y - 2.0, z) * if k == 0 { 0.0 } else { 0.01 };
                        p + Vec3::new(x, 0.0, z)
                    })
                    .collect()
            }),
            count,
        )
    })
}

/// A TressFX file of `strands` (all of the same length), with thickness, UVs
/// and colours.
fn tfx(strands: &[Vec<Vec3>]) -> Vec<u8> {
    let per = strands.iter().map(Vec::len).min().unwrap_or(2);
    let n = strands.len() as u32;
    let points = n as usize * per;
    let positions_at = 160u32;
    let uvs_at = positions_at + 16 * points as u32;
    let thickness_at = uvs_at + 8 * n;
    let colors_at = thickness_at + 4 * n;
    let mut b = 4.0f32.to_le_bytes().to_vec();
    for v in [n, per as u32, positions_at, uvs_at, 0, thickness_at, colors_at] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.resize(160, 0);
    for s in strands {
        for (k, p) in s.iter().take(per).enumerate() {
            for v in [p.x, p.y, p.z, if k == 0 { 0.0 } else { 1.0 }] {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    for i in 0..n {
        b.extend_from_slice(&(i as f32 * 0.1).to_le_bytes());
        b.extend_from_slice(&0.5f32.to_le_bytes());
    }
    for _ in 0..n {
        b.extend_from_slice(&0.001f32.to_le_bytes());
    }
    for _ in 0..points {
        for v in [0.3f32, 0.2, 0.1, 1.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

/// An OBJ file of a triangle fan and a quad per strand's points.
fn obj(strands: &[Vec<Vec3>]) -> String {
    let mut text = String::from("# generated\n");
    let mut count = 0;
    for s in strands {
        for p in s {
            text += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        let base = count + 1;
        for k in 1..s.len().saturating_sub(1) {
            text += &format!("f {} {} {}\n", base, base + k, base + k + 1);
        }
        count += s.len();
    }
    text
}

/// One change to OBJ text: a number token replaced by an awkward one, a line
/// dropped or doubled, or a non-UTF-8 byte.
fn obj_change() -> impl Strategy<Value = (prop::sample::Index, prop::sample::Index, &'static str)> {
    let tokens = prop::sample::select(vec![
        "nan",
        "inf",
        "-inf",
        "1e39",
        "-1e39",
        "0",
        "-1",
        "-99999",
        "4294967296",
        "x",
        "",
        "f",
        "v",
        "\u{ff}",
        "DROP",
        "DUP",
        "BYTE",
    ]);
    (any::<prop::sample::Index>(), any::<prop::sample::Index>(), tokens)
}

fn mutate_obj(text: &str, line: &prop::sample::Index, word: &prop::sample::Index, token: &str) -> Vec<u8> {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let at = line.index(lines.len());
    match token {
        "DROP" => {
            lines.remove(at);
        }
        "DUP" => {
            let l = lines[at].clone();
            lines.insert(at, l);
        }
        "BYTE" => {
            let mut bytes = text.as_bytes().to_vec();
            let i = word.index(bytes.len());
            bytes[i] = 0xff;
            return bytes;
        }
        _ => {
            let mut words: Vec<&str> = lines[at].split(' ').collect();
            let w = word.index(words.len());
            words[w] = token;
            lines[at] = words.join(" ");
        }
    }
    (lines.join("\n") + "\n").into_bytes()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    #[test]
    fn mutated_tfx_files_give_grooms_or_typed_errors(s in strands(), changes in prop::collection::vec(change(), 1..3)) {
        let mut bytes = tfx(&s);
        for c in &changes {
            apply(&mut bytes, c, 160);
        }
        check(TfxFile::parse(&bytes), |f| &f.groom)?;
        let repaired = TfxFile::parse_repairing(&bytes);
        if let Ok((f, _)) = &repaired {
            prop_assert_eq!(f.inverse_mass.len(), f.groom.point_count(), "inverse mass out of step");
            if let Some(uvs) = &f.strand_uvs {
                prop_assert_eq!(uvs.len(), f.groom.strand_count(), "strand UVs out of step");
            }
        }
        check(repaired, |(f, _)| &f.groom)?;
    }

    #[test]
    fn mutated_hair_files_give_grooms_or_typed_errors(s in strands(), changes in prop::collection::vec(change(), 1..3)) {
        let mut bytes = HairFile::new(Groom::from_strands(&s).expect("valid"), "fuzz").to_bytes();
        for c in &changes {
            apply(&mut bytes, c, 128);
        }
        check(HairFile::parse(&bytes), |f| &f.groom)?;
        check(HairFile::parse_repairing(&bytes), |(f, _)| &f.groom)?;
    }

    #[test]
    fn mutated_obj_files_give_meshes_or_typed_errors(s in strands(), edit in obj_change()) {
        let bytes = mutate_obj(&obj(&s), &edit.0, &edit.1, edit.2);
        match TriMesh::parse_obj(&bytes) {
            Ok(mesh) => {
                prop_assert!(mesh.positions.iter().all(|p| p.is_finite()));
                let n = mesh.positions.len() as u32;
                prop_assert!(mesh.triangles.iter().flatten().all(|&i| i < n), "an index past the vertices");
            }
            Err(e) => prop_assert!(is_file_error(&e), "untyped error: {e:?}"),
        }
    }
}

/// The generators make valid files: without a change every reader accepts them.
#[test]
fn unchanged_generated_files_are_valid() {
    let s: Vec<Vec<Vec3>> =
        (0..3).map(|i| (0..4).map(|k| Vec3::new(i as f32 * 0.1, -0.02 * k as f32, 0.0)).collect()).collect();
    let f = TfxFile::parse(&tfx(&s)).expect("tfx");
    assert_eq!((f.groom.strand_count(), f.inverse_mass.len()), (3, 12));
    assert!(f.strand_uvs.is_some() && f.groom.thickness().is_some());
    HairFile::parse(&HairFile::new(Groom::from_strands(&s).expect("groom"), "x").to_bytes()).expect("hair");
    let mesh = TriMesh::parse_obj(obj(&s).as_bytes()).expect("obj");
    assert_eq!(mesh.triangles.len(), 6);
}
