//! A procedural rig (hips, a neck and a head bone; a body, a neck and a head
//! of rings of vertices) checked against rotations computed here, and the real
//! character in `tests/data/`.

use std::f32::consts::FRAC_PI_2;

use glam::{Mat4, Quat, Vec3};

use super::skeleton::{Animation, Channel, Keys, Node, Sampling, Skeleton};
use super::*;

const NECK: Vec3 = Vec3::new(0.0, 1.5, 0.0);
const HEAD: Vec3 = Vec3::new(0.0, 1.6, 0.0);

fn node(name: &str, parent: Option<usize>, t: Vec3) -> Node {
    Node { name: name.into(), parent, translation: t, rotation: Quat::IDENTITY, scale: Vec3::ONE }
}

/// Rings of `per_ring` vertices of radius `r` at heights `ys`, weighted to
/// `joint`, with the triangles between neighbouring rings.
fn tube(out: &mut Character, joint: u16, r: f32, ys: &[f32]) {
    let per_ring = 16u32;
    let base = out.positions.len() as u32;
    for &y in ys {
        for k in 0..per_ring {
            let a = k as f32 / per_ring as f32 * std::f32::consts::TAU;
            out.positions.push(Vec3::new(r * a.cos(), y, r * a.sin()));
            out.weights.push(([joint, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]));
        }
    }
    for ring in 0..ys.len() as u32 - 1 {
        for k in 0..per_ring {
            let (a, b) = (base + ring * per_ring + k, base + ring * per_ring + (k + 1) % per_ring);
            out.triangles.push([a, b + per_ring, b]);
            out.triangles.push([a, a + per_ring, b + per_ring]);
        }
    }
}

/// The rig: joints 0 hips (origin), 1 neck (1.5 m), 2 head (1.6 m); the
/// animation "turn" turns the head a quarter about +Y over one second.
fn rig() -> Character {
    let nodes = vec![node("hips", None, Vec3::ZERO), node("neck", Some(0), NECK), node("head", Some(1), HEAD - NECK)];
    let inverse_bind = vec![Mat4::IDENTITY, Mat4::from_translation(-NECK), Mat4::from_translation(-HEAD)];
    let turn = Channel {
        node: 2,
        times: vec![0.0, 1.0],
        keys: Keys::Rotation(vec![Quat::IDENTITY, Quat::from_rotation_y(FRAC_PI_2)]),
        sampling: Sampling::Linear,
    };
    let animations = vec![Animation { name: "turn".into(), channels: vec![turn] }];
    let skeleton = Skeleton::new(nodes, vec![0, 1, 2], inverse_bind, animations).expect("skeleton");
    let mut c = Character { skeleton, positions: vec![], weights: vec![], triangles: vec![] };
    tube(&mut c, 0, 0.15, &[0.0, 0.5, 1.0, 1.45]);
    tube(&mut c, 1, 0.06, &[1.45, 1.52, 1.6]);
    tube(&mut c, 2, 0.1, &[1.6, 1.65, 1.7, 1.75, 1.8]);
    Character::new(c.skeleton, c.positions, c.weights, c.triangles).expect("character")
}

#[test]
fn the_pose_interpolates_and_the_head_turns_its_vertices_about_its_joint() {
    let c = rig();
    let pose = c.pose(Some(0), 0.5);
    let (_, rotation, translation) = c.joint_transform(&pose, 2).to_scale_rotation_translation();
    assert!(rotation.angle_between(Quat::from_rotation_y(FRAC_PI_2 / 2.0)) < 1e-5, "{rotation:?}");
    assert!(translation.distance(HEAD) < 1e-6);
    let skinned = c.skin(&pose);
    let turn = Quat::from_rotation_y(FRAC_PI_2 / 2.0);
    for v in c.region(2) {
        let expected = HEAD + turn * (c.positions[v] - HEAD);
        assert!(skinned[v].distance(expected) < 1e-5, "vertex {v}: {} vs {expected}", skinned[v]);
    }
    for v in c.region(0) {
        assert!(skinned[v].distance(c.positions[v]) < 1e-6, "the body does not move");
    }
    // Looping: one second later is the same pose.
    assert!(c.pose(Some(0), 1.5).nodes[2].abs_diff_eq(pose.nodes[2], 1e-5));
    assert_eq!(c.skeleton.animation_index("turn").expect("by name"), 0);
    assert_eq!(c.skeleton.animation_index("0").expect("by index"), 0);
    assert!(c.skeleton.animation_index("walk").is_err());
}

#[test]
fn the_head_is_found_by_the_weights_of_the_top() {
    let c = rig();
    assert_eq!(c.up_axis(), Vec3::Y);
    assert_eq!(c.head_joint(), 2);
    assert_eq!(c.joint_named("neck").expect("neck"), 1);
    assert!(c.joint_named("tail").is_err());
}

#[test]
fn capsules_fit_inside_each_bone_and_follow_it() {
    let c = rig();
    let capsules = c.fit_capsules(&[2]);
    assert_eq!(capsules.iter().map(|k| k.joint).collect::<Vec<_>>(), vec![0, 1], "body and neck, not the head");
    let neck = capsules[1];
    assert!((neck.radius - 0.06).abs() < 1e-4, "neck radius {}", neck.radius);
    let rest = c.pose(None, 0.0);
    let Collider::Capsule { a, b, .. } = neck.in_world(&c, &rest) else { panic!("a capsule") };
    // Along the neck's axis (towards the head joint), inside its span.
    for p in [a, b] {
        assert!(p.x.abs() < 1e-5 && p.z.abs() < 1e-5 && (1.45..=1.6).contains(&p.y), "{p}");
    }
    // The body's capsule ends one radius inside its vertices' span.
    let Collider::Capsule { a, b, radius } = capsules[0].in_world(&c, &rest) else { panic!("a capsule") };
    assert!((radius - 0.15).abs() < 1e-4);
    assert!((a.y.min(b.y) - 0.15).abs() < 1e-4 && (a.y.max(b.y) - 1.3).abs() < 1e-4, "{a} {b}");
    // In the head's frame a neck capsule turns with it when the head does not:
    // here only the head turns, so the neck stays.
    let turned = c.pose(Some(0), 1.0);
    let head = RigidTransform { rotation: Quat::from_rotation_y(FRAC_PI_2), translation: HEAD };
    let Collider::Capsule { a, .. } = neck.in_frame(&c, &turned, &head) else { panic!("a capsule") };
    let world = head.matrix().transform_point3(a);
    assert!(world.x.abs() < 1e-5 && world.z.abs() < 1e-5, "{world}");
}

use crate::sim::{Collider, RigidTransform};

#[test]
fn channels_sample_by_their_interpolation() {
    let keys = Keys::Translation(vec![Vec3::ZERO, Vec3::X]);
    let step = Channel { node: 0, times: vec![0.0, 1.0], keys: keys.clone(), sampling: Sampling::Step };
    let nodes = vec![node("a", None, Vec3::ZERO)];
    let sk = |c: Channel| {
        Skeleton::new(
            nodes.clone(),
            vec![0],
            vec![Mat4::IDENTITY],
            vec![Animation { name: "a".into(), channels: vec![c] }],
        )
        .expect("skeleton")
    };
    let at = |s: &Skeleton, t: f32| s.node_transforms(Some(0), t, false)[0].transform_point3(Vec3::ZERO);
    assert_eq!(at(&sk(step), 0.9), Vec3::ZERO, "step keeps the previous key");
    // A cubic spline with zero tangents: 0.5 at the middle, 0.104 at a fifth (3u² − 2u³).
    let cubic = Channel {
        node: 0,
        times: vec![0.0, 1.0],
        keys: Keys::Translation(vec![Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec3::ZERO]),
        sampling: Sampling::CubicSpline,
    };
    let s = sk(cubic);
    assert!((at(&s, 0.5).x - 0.5).abs() < 1e-6 && (at(&s, 0.2).x - 0.104).abs() < 1e-6);
    assert_eq!(at(&s, 5.0), Vec3::X, "clamped past the last key without looping");
}

#[test]
fn bad_channels_and_hierarchies_are_refused() {
    let keys = Keys::Translation(vec![Vec3::ZERO, Vec3::X]);
    let bad = [
        Channel { node: 0, times: vec![0.0, f32::NAN], keys: keys.clone(), sampling: Sampling::Linear },
        Channel { node: 0, times: vec![1.0, 0.0], keys: keys.clone(), sampling: Sampling::Linear },
        Channel { node: 0, times: vec![0.0], keys: keys.clone(), sampling: Sampling::Linear },
        Channel { node: 0, times: vec![0.0, 1.0], keys: keys.clone(), sampling: Sampling::CubicSpline },
        Channel {
            node: 0,
            times: vec![0.0, 1.0],
            keys: Keys::Translation(vec![Vec3::ZERO, Vec3::NAN]),
            sampling: Sampling::Linear,
        },
    ];
    for c in bad {
        assert!(c.validate().is_err(), "{c:?}");
    }
    let cycle = vec![node("a", Some(1), Vec3::ZERO), node("b", Some(0), Vec3::ZERO)];
    let err = Skeleton::new(cycle, vec![0], vec![Mat4::IDENTITY], vec![]).expect_err("a cycle");
    assert!(err.to_string().contains("cycle"), "{err}");
    let err =
        Skeleton::new(vec![node("a", None, Vec3::ZERO)], vec![3], vec![Mat4::IDENTITY], vec![]).expect_err("joint");
    assert!(err.to_string().contains("joint node 3"), "{err}");
    let c = rig();
    let err = Character::new(c.skeleton.clone(), c.positions.clone(), c.weights[1..].to_vec(), c.triangles.clone());
    assert!(err.is_err());
    let mut weights = c.weights.clone();
    weights[0].0[0] = 9;
    assert!(Character::new(c.skeleton, c.positions, weights, c.triangles).is_err(), "a joint past the skin");
}

/// The real character (`tests/data/mannequiny-0.3.0.glb`, credit in
/// `tests/data/mannequiny.LICENSE.txt`): 45 joints, the head found by
/// weights, ten animations, 1.79 m tall, Y-up.
#[test]
fn the_mannequin_loads_and_its_head_is_found() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let c = Character::load(path).expect("mannequin");
    assert_eq!(c.skeleton.joints.len(), 45);
    assert_eq!(c.positions.len(), 7232 + 64 + 3070);
    assert_eq!(c.skeleton.animations.len(), 10);
    assert_eq!(c.up_axis(), Vec3::Y);
    assert!(c.forward().distance(Vec3::Z) < 1e-3, "the mannequin faces +Z: {}", c.forward());
    let head = c.head_joint();
    assert_eq!(c.skeleton.nodes[c.skeleton.joints[head]].name, "head");
    let rest = c.skin(&c.pose(None, 0.0));
    let top = rest.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    assert!((top - 1.793).abs() < 0.01, "height {top}");
    let run = c.skeleton.animation_index("run").expect("run");
    let duration = c.skeleton.animations[run].duration();
    assert!((duration - 0.63).abs() < 0.02, "run lasts {duration}");
    let capsules = c.fit_capsules(&[head]);
    assert!(capsules.len() >= 10, "{} capsules", capsules.len());
    // Truncated or foreign bytes are refused with an error, never a panic.
    let bytes = std::fs::read(path).expect("read");
    for cut in [0, 12, 20, 1000, bytes.len() / 2, bytes.len() - 1] {
        assert!(Character::parse(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    let err = Character::parse(br#"{"asset":{"version":"2.0"},"nodes":[{"name":"a"}]}"#).expect_err("no skin");
    assert!(err.to_string().contains("no skinned mesh"), "{err}");
}

/// Buffers as data URIs, outside the document's folder, or shorter than they
/// say are refused by name; nothing is read from outside the folder.
#[test]
fn buffers_that_cannot_be_read_safely_are_refused() {
    let doc = |uri: &str, length: usize| {
        format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":{length}}}]}}"#)
    };
    let err = Character::parse(doc("data:application/octet-stream;base64,AAAA", 3).as_bytes()).expect_err("data URI");
    assert!(err.to_string().contains("data URI"), "{err}");
    let dir = tempfile::tempdir().expect("temp dir");
    let err = gltf_read::parse(doc("../secret.bin", 4).as_bytes(), Some(dir.path())).expect_err("outside");
    assert!(err.to_string().contains("outside the document's folder"), "{err}");
    std::fs::write(dir.path().join("short.bin"), [0u8; 2]).expect("write");
    let err = gltf_read::parse(doc("short.bin", 4).as_bytes(), Some(dir.path())).expect_err("short");
    assert!(err.to_string().contains("truncated glTF file"), "{err}");
}

/// Amplification is bounded over the whole document: buffers naming one file
/// fifty times declare more than the cap together and are refused before any
/// is read; channels sharing one sampler of a million keys decode it once
/// each, and past [`super::gltf_read::MAX_DOCUMENT_KEYS`] keys the document
/// is refused (where it decoded them all).
#[test]
fn a_small_document_cannot_ask_for_copies_without_bound() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("data.bin"), [0u8; 16]).expect("write");
    let length = 25 << 20; // 50 × 25 MiB: 1.22 GiB
    let buffers: Vec<String> = (0..50).map(|_| format!(r#"{{"uri":"data.bin","byteLength":{length}}}"#)).collect();
    let doc = format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{}]}}"#, buffers.join(","));
    let err = gltf_read::parse(doc.as_bytes(), Some(dir.path())).expect_err("too much").to_string();
    assert!(err.contains("50 buffers declare 1310720000 bytes together"), "{err}");

    let keys = 1 << 20;
    let times: Vec<f32> = (0..keys).map(|i| i as f32 / keys as f32).collect();
    let values = vec![0.0f32; 3 * keys];
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    let shared = |channels: usize| with_translation_keys(&bytes, dir.path(), "keys.bin", &times, &values, channels);
    let character = gltf_read::parse(&shared(2), Some(dir.path())).expect("two channels of a million keys");
    assert!(!character.skeleton.animations.is_empty());
    let err = gltf_read::parse(&shared(5), Some(dir.path())).expect_err("five").to_string();
    assert!(err.contains("decode to more than 4194304 keys"), "{err}");
}

/// A translation or scale no character has (10³⁰ m, a node scaled 10⁶×),
/// on a node, in an animation key or in a joint's inverse bind matrix, is
/// refused naming where it is.
#[test]
fn absurd_transforms_are_refused_naming_the_node_or_channel() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    let err = Character::parse(&mutated(&bytes, |j| j["nodes"][0]["translation"] = serde_json::json!([1e30, 0, 0])))
        .expect_err("far")
        .to_string();
    assert!(err.contains("node 0") && err.contains("is beyond ±10000 m"), "{err}");
    let err = Character::parse(&mutated(&bytes, |j| j["nodes"][0]["scale"] = serde_json::json!([1e6, 1, 1])))
        .expect_err("huge")
        .to_string();
    assert!(err.contains("node 0") && err.contains("scale"), "{err}");
    // Node matrices: one with an entry of 10³⁰ is decomposed in f64 and its
    // scale named (f32's decomposition had made it NaN, "not finite"); a
    // singular and a projective one say so; a plain one reads.
    let matrix = |m: [f64; 16]| {
        Character::parse(&mutated(&bytes, |j| {
            let n = &mut j["nodes"][0];
            for key in ["translation", "rotation", "scale"] {
                n.as_object_mut().map(|o| o.remove(key));
            }
            n["matrix"] = serde_json::json!(m);
        }))
        .map(drop)
        .map_err(|e| e.to_string())
    };
    let mut m = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    assert!(matrix(m).is_ok(), "{:?}", matrix(m));
    m[0] = 1e30;
    let err = matrix(m).expect_err("a huge scale");
    assert!(err.contains("node 0") && err.contains("scale [1000000000000000000000000000000, 1, 1]"), "{err}");
    let err = matrix([0.0; 16]).expect_err("singular");
    assert!(err.contains("node 0") && err.contains("a singular matrix (determinant 0e0)"), "{err}");
    m[0] = 1.0;
    m[3] = 0.5;
    let err = matrix(m).expect_err("projective");
    assert!(err.contains("node 0") && err.contains("a projective matrix"), "{err}");
    // An animation key 10³⁰ m away, from a buffer of its own.
    let dir = tempfile::tempdir().expect("temp dir");
    let far = [0.0, 0.0, 0.0, 1e30, 0.0, 0.0];
    let doc = with_translation_keys(&bytes, dir.path(), "keys.bin", &[0.0, 1.0], &far, 1);
    let err = gltf_read::parse(&doc, Some(dir.path())).expect_err("a far key").to_string();
    assert!(err.contains("channel") && err.contains("a key's translation") && err.contains("beyond"), "{err}");
    // The first joint's inverse bind matrix translated 10³⁰ m (its column 3's
    // x, in the binary chunk after the JSON chunk and the chunk header).
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("length")) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("json");
    let accessor = &json["accessors"][json["skins"][0]["inverseBindMatrices"].as_u64().expect("ibm") as usize];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
    let offset = 20
        + json_len
        + 8
        + view["byteOffset"].as_u64().unwrap_or(0) as usize
        + accessor["byteOffset"].as_u64().unwrap_or(0) as usize
        + 12 * 4;
    let mut far = bytes.clone();
    far[offset..offset + 4].copy_from_slice(&1e30f32.to_le_bytes());
    let err = Character::parse(&far).expect_err("a far bind pose").to_string();
    assert!(err.contains("skin 0 joint 0") && err.contains("inverse bind") && err.contains("beyond"), "{err}");
}

/// A vertex far beyond any character is refused naming the mesh's
/// position, and a head joint that an animation scales to nothing (or past
/// 10⁴, multiplied along its ancestors) has no frame: refused naming the
/// joint, the time and the animation, not a NaN or infinite head.
#[test]
fn a_far_vertex_and_a_head_scaled_to_nothing_are_refused_naming_them() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    // The first vertex's x, in the binary chunk: after the JSON chunk and the
    // eight bytes of the binary chunk's header.
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("length")) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("json");
    let accessor = &json["accessors"]
        [json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().expect("POSITION") as usize];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
    let offset = 20
        + json_len
        + 8
        + view["byteOffset"].as_u64().unwrap_or(0) as usize
        + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
    let mut far = bytes.clone();
    far[offset..offset + 4].copy_from_slice(&3e38f32.to_le_bytes());
    let err = Character::parse(&far).expect_err("a far vertex").to_string();
    assert!(err.contains("position") && err.contains("beyond ±10000 m"), "{err}");

    let flat = mutated(&bytes, |j| {
        for node in j["nodes"].as_array_mut().expect("nodes") {
            node["scale"] = serde_json::json!([0.0, 0.0, 0.0]);
        }
    });
    let character = Character::parse(&flat).expect("a zero scale is a pose, not a broken file");
    let err = HairRig::new(character, None, None).map(|_| ()).expect_err("a head without a frame").to_string();
    assert!(err.contains("head joint") && err.contains("no frame at 0 s") && err.contains("scale"), "{err}");

    // Scales each within the bound that multiply past it on the way to the
    // head (9,000 at every node; the renderer was handed an infinite head).
    let mut character = Character::parse(&bytes).expect("the character");
    for node in &mut character.skeleton.nodes {
        node.scale = Vec3::splat(9000.0);
    }
    for channel in &mut character.skeleton.animations[0].channels {
        if let Keys::Scale(keys) = &mut channel.keys {
            keys.iter_mut().for_each(|k| *k = Vec3::splat(9000.0));
        }
    }
    let err = HairRig::new(character, None, None).map(|_| ()).expect_err("a head grown past the bound").to_string();
    assert!(err.contains("head joint") && err.contains("scales past 10000 multiplied"), "{err}");

    // A scale through zero between two keys, at 1/3 s, between the samples.
    let mut character = Character::parse(&bytes).expect("the character");
    let node = character.skeleton.joints[character.head_joint()];
    let keys = Keys::Scale(vec![Vec3::ONE, Vec3::new(-2.0, 1.0, 1.0)]);
    let through = Channel { node, times: vec![0.0, 1.0], keys, sampling: Sampling::Linear };
    character.skeleton.animations[0].channels.push(through);
    let err = HairRig::new(character, None, None).map(|_| ()).expect_err("a head scaled through zero").to_string();
    assert!(err.contains("head joint") && err.contains("no frame at 0.333") && err.contains("scaled to zero"), "{err}");
}

/// A `.gltf` document whose buffer file is missing, a folder or a FIFO no one
/// writes is refused naming the document, the buffer and its file — not a
/// bare "no such file" about the buffer, nor a truncated file.
#[test]
fn an_unreadable_buffer_file_is_named_with_its_document() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("length")) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("json");
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("folder.bin")).expect("mkdir");
    let fifo = std::ffi::CString::new(dir.path().join("pipe.bin").to_str().expect("utf-8")).expect("path");
    // SAFETY: mkfifo with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0, "mkfifo");
    for (file, what) in [("gone.bin", "gone.bin"), ("folder.bin", "folder.bin"), ("pipe.bin", "not a regular file")] {
        json["buffers"][0]["uri"] = serde_json::json!(file);
        let doc = dir.path().join(format!("{file}.gltf"));
        std::fs::write(&doc, serde_json::to_vec(&json).expect("json")).expect("write");
        let err = Character::load(&doc).map(|_| ()).expect_err(file).to_string();
        assert!(err.contains(&format!("{file}.gltf")) && err.contains("buffer 0") && err.contains(what), "{err}");
    }
}

/// The mannequin's GLB (`bytes`) with an animation sampler of its own added
/// to its first animation: `times` and translation `values` (three a key)
/// written to `dir`/`name`, a buffer naming that file, and `channels`
/// channels sharing the sampler, translating node 0. Parse it with
/// `gltf_read::parse(…, Some(dir))`.
fn with_translation_keys(
    bytes: &[u8],
    dir: &Path,
    name: &str,
    times: &[f32],
    values: &[f32],
    channels: usize,
) -> Vec<u8> {
    let keys = times.len();
    let bin: Vec<u8> = times.iter().chain(values).flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join(name), &bin).expect("write the keys");
    mutated(bytes, |j| {
        let buffer = j["buffers"].as_array().map_or(0, Vec::len);
        j["buffers"].as_array_mut().expect("buffers").push(serde_json::json!({"uri": name, "byteLength": bin.len()}));
        let views = j["bufferViews"].as_array_mut().expect("views");
        let view = views.len();
        views.push(serde_json::json!({"buffer": buffer, "byteOffset": 0, "byteLength": 4 * keys}));
        views.push(serde_json::json!({"buffer": buffer, "byteOffset": 4 * keys, "byteLength": 4 * values.len()}));
        let accessors = j["accessors"].as_array_mut().expect("accessors");
        let accessor = accessors.len();
        let (first, last) = (times.first().copied().unwrap_or(0.0), times.last().copied().unwrap_or(0.0));
        accessors.push(serde_json::json!({"bufferView": view, "componentType": 5126, "count": keys,
            "type": "SCALAR", "min": [first], "max": [last]}));
        accessors
            .push(serde_json::json!({"bufferView": view + 1, "componentType": 5126, "count": keys, "type": "VEC3"}));
        let samplers = j["animations"][0]["samplers"].as_array_mut().expect("samplers");
        let sampler = samplers.len();
        samplers.push(serde_json::json!({"input": accessor, "output": accessor + 1}));
        let channels_of = j["animations"][0]["channels"].as_array_mut().expect("channels");
        for _ in 0..channels {
            channels_of.push(serde_json::json!({"sampler": sampler, "target": {"node": 0, "path": "translation"}}));
        }
    })
}

/// The mannequin's GLB with its JSON chunk changed by `edit`.
fn mutated(bytes: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("length")) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("json");
    edit(&mut json);
    let mut text = serde_json::to_vec(&json).expect("json");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let rest = &bytes[20 + json_len..];
    let mut out = Vec::new();
    out.extend_from_slice(&bytes[0..8]);
    out.extend_from_slice(&((12 + 8 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    out
}

/// Accessors the readers would index blindly (a joint stored as floats, no
/// elements, more elements than their view holds, a stride shorter than an
/// element, a sparse one), a degenerate rotation key and a singular inverse
/// bind matrix are refused with an error naming them: never a panic.
#[test]
fn malformed_accessors_and_keys_are_refused_not_read() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    assert!(Character::parse(&mutated(&bytes, |_| {})).is_ok(), "the unchanged JSON still loads");
    let attribute = |j: &serde_json::Value, name: &str| {
        j["meshes"][0]["primitives"][0]["attributes"][name].as_u64().expect("attribute") as usize
    };
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "JOINTS_0",
            Box::new(move |j| {
                let a = attribute(j, "JOINTS_0");
                j["accessors"][a]["componentType"] = 5126.into();
            }),
        ),
        (
            "POSITION",
            Box::new(move |j| {
                let a = attribute(j, "POSITION");
                j["accessors"][a]["count"] = 0.into();
            }),
        ),
        (
            "POSITION",
            Box::new(move |j| {
                let a = attribute(j, "POSITION");
                j["accessors"][a]["count"] = 4_000_000.into();
            }),
        ),
        (
            // The README's bound on a character's vertices, one past it.
            "POSITION: accessor 0: 4194305 elements (allowed 1..=4194304)",
            Box::new(move |j| {
                let a = attribute(j, "POSITION");
                j["accessors"][a]["count"] = (super::MAX_CHARACTER_VERTICES + 1).into();
            }),
        ),
        (
            "WEIGHTS_0",
            Box::new(move |j| {
                let a = attribute(j, "WEIGHTS_0");
                let v = j["accessors"][a]["bufferView"].as_u64().expect("view") as usize;
                j["bufferViews"][v]["byteStride"] = 4.into();
            }),
        ),
        (
            "POSITION",
            Box::new(move |j| {
                let a = attribute(j, "POSITION");
                j["accessors"][a]["sparse"] = serde_json::json!({
                    "count": 1,
                    "indices": {"bufferView": 0, "componentType": 5125},
                    "values": {"bufferView": 0}
                });
            }),
        ),
        (
            "inverse bind",
            Box::new(|j| {
                let a = j["skins"][0]["inverseBindMatrices"].as_u64().expect("ibm") as usize;
                j["accessors"][a]["type"] = "VEC4".into();
            }),
        ),
        (
            // The crate's reader unwrapped it: a caught panic, not an error.
            "animations[0].channels[0].target.path is none of",
            Box::new(|j| j["animations"][0]["channels"][0]["target"]["path"] = "colour".into()),
        ),
        (
            "animations[0].samplers[0].interpolation is none of",
            Box::new(|j| j["animations"][0]["samplers"][0]["interpolation"] = "SMOOTH".into()),
        ),
        (
            "animations[0].channels[0].sampler names sampler 9999",
            Box::new(|j| j["animations"][0]["channels"][0]["sampler"] = 9999.into()),
        ),
        (
            // Empty nodes, past the bound with the document's own objects.
            "its JSON holds more than 262144 objects",
            Box::new(|j| {
                let nodes = j["nodes"].as_array_mut().expect("nodes");
                nodes.extend(std::iter::repeat_n(serde_json::json!({}), super::MAX_GLTF_JSON_OBJECTS));
            }),
        ),
        (
            // Finite, but its length overflows when squared: normalising it
            // would give a zero quaternion (a node scaled to nothing).
            "node 8 (\"head\"): its rotation [1e30, 0.0, 0.0, 1e30] is not a rotation",
            Box::new(|j| j["nodes"][8]["rotation"] = serde_json::json!([1e30, 0.0, 0.0, 1e30])),
        ),
    ];
    for (k, (what, edit)) in cases.into_iter().enumerate() {
        let err = Character::parse(&mutated(&bytes, edit)).expect_err("refused");
        eprintln!("case {k}: {err}");
        assert!(err.to_string().contains(what), "case {k}: {err}");
    }
}

/// Indices past the end that the `gltf` crate's own checks index with (a
/// mesh attribute's or a morph target's accessor) or its readers do (an
/// animation channel's target node) are refused naming where they are: no
/// panic; the indices it checks itself stay refused.
#[test]
fn indices_past_the_end_are_refused_not_followed() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let bytes = std::fs::read(path).expect("read");
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "meshes[0].primitives[0] POSITION names accessor 9999",
            Box::new(|j| j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9999.into()),
        ),
        (
            "meshes[0].primitives[0].targets[0] names accessor 70000",
            Box::new(|j| j["meshes"][0]["primitives"][0]["targets"] = serde_json::json!([{"POSITION": 70000}])),
        ),
        (
            "animations[0].channels[0].target names node 9999",
            Box::new(|j| j["animations"][0]["channels"][0]["target"]["node"] = 9999.into()),
        ),
        ("skins[0].joints[0]", Box::new(|j| j["skins"][0]["joints"][0] = 9999.into())),
        ("meshes[0].primitives[0].indices", Box::new(|j| j["meshes"][0]["primitives"][0]["indices"] = 9999.into())),
    ];
    for (what, edit) in cases {
        let document = mutated(&bytes, edit);
        let result = std::panic::catch_unwind(|| Character::parse(&document));
        let err = result.unwrap_or_else(|_| panic!("{what}: the reader panicked")).expect_err("refused");
        assert!(err.to_string().contains(what), "{what}: {err}");
    }
}

/// Hostile parts given through the public constructors: a NaN or infinite time
/// samples the first keys; a zero rotation key, zero weights and a skin without
/// joints are refused; a long chain of nodes listed child first is ordered in
/// one pass.
#[test]
fn hostile_parts_are_refused_or_harmless() {
    let c = rig();
    for t in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let pose = c.pose(Some(0), t);
        assert!(pose.nodes.iter().all(|m| m.is_finite()), "time {t}");
    }
    let zero = Channel {
        node: 0,
        times: vec![0.0, 1.0],
        keys: Keys::Rotation(vec![Quat::IDENTITY, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)]),
        sampling: Sampling::Linear,
    };
    let err = Skeleton::new(
        vec![node("a", None, Vec3::ZERO)],
        vec![0],
        vec![Mat4::IDENTITY],
        vec![Animation { name: "z".into(), channels: vec![zero] }],
    )
    .expect_err("zero rotation");
    assert!(err.to_string().contains("channel 0"), "{err}");
    // A rotation key too long to normalise, a key time past the bound: each
    // refused naming it; a cubic spline's zero tangents are no rotations and
    // are taken.
    let skeleton_with = |times: Vec<f32>, keys: Vec<Quat>, sampling: Sampling| {
        let channel = Channel { node: 0, times, keys: Keys::Rotation(keys), sampling };
        let animation = Animation { name: "a".into(), channels: vec![channel] };
        Skeleton::new(vec![node("a", None, Vec3::ZERO)], vec![0], vec![Mat4::IDENTITY], vec![animation])
    };
    let long = Quat::from_xyzw(1e30, 0.0, 0.0, 1e30);
    let err = skeleton_with(vec![0.0, 1.0], vec![Quat::IDENTITY, long], Sampling::Linear).expect_err("long");
    assert!(err.to_string().contains("rotation key 1: [1e30, 0.0, 0.0, 1e30] is not a rotation"), "{err}");
    let err = skeleton_with(vec![0.0, 3e38], vec![Quat::IDENTITY; 2], Sampling::Linear).expect_err("time");
    assert!(err.to_string().contains("key time of 3e38 s is beyond ±1000000.0 s"), "{err}");
    let zero = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    let spline = vec![zero, Quat::IDENTITY, zero, zero, Quat::from_rotation_y(1.0), zero];
    skeleton_with(vec![0.0, 1.0], spline, Sampling::CubicSpline).expect("zero tangents are taken");
    // Unnormalised but normalisable rotations are taken, to the bounds' ends.
    for length in [1e-6, 100.0, 1e6] {
        let q = Quat::from_xyzw(0.0, 0.0, 0.0, length);
        skeleton_with(vec![0.0, 1.0], vec![Quat::IDENTITY, q], Sampling::Linear).expect("a normalisable rotation");
    }
    let mut weights = c.weights.clone();
    weights[3].1 = [0.0; 4];
    let err =
        Character::new(c.skeleton.clone(), c.positions.clone(), weights, c.triangles.clone()).expect_err("weights");
    assert!(err.to_string().contains("vertex 3"), "{err}");
    let chain: Vec<Node> = (0..200_000).map(|i| node("n", (i + 1 < 200_000).then_some(i + 1), Vec3::ZERO)).collect();
    let started = std::time::Instant::now();
    let sk = Skeleton::new(chain, vec![0], vec![Mat4::IDENTITY], vec![]).expect("a long chain");
    eprintln!("200,000 nodes child first ordered in {:?}", started.elapsed());
    assert_eq!(sk.node_transforms(None, 0.0, false).len(), 200_000);
}

/// A bone whose rings widen from 5 mm to 10 cm: its capsule takes the 90th
/// percentile of its vertices' distances from the axis (ring 19 of 20: 9.5 cm),
/// not their median (5.5 cm).
#[test]
fn a_capsule_takes_the_ninetieth_percentile_of_its_bone() {
    let skeleton =
        Skeleton::new(vec![node("bone", None, Vec3::ZERO)], vec![0], vec![Mat4::IDENTITY], vec![]).expect("skeleton");
    let mut c = Character { skeleton, positions: vec![], weights: vec![], triangles: vec![] };
    for ring in 0..20 {
        let y = ring as f32 * 0.05;
        let before = c.positions.len();
        tube(&mut c, 0, 0.005 * (ring + 1) as f32, &[y, y + 0.01]);
        // One ring of each tube: drop the second ring's vertices and triangles.
        c.positions.truncate(before + 16);
        c.weights.truncate(before + 16);
        c.triangles.retain(|t| t.iter().all(|&v| (v as usize) < c.positions.len()));
    }
    c.triangles.push([0, 1, 2]);
    let c = Character::new(c.skeleton, c.positions, c.weights, c.triangles).expect("character");
    let capsules = c.fit_capsules(&[]);
    assert_eq!(capsules.len(), 1);
    assert!((capsules[0].radius - 0.095).abs() < 1e-4, "radius {}", capsules[0].radius);
}

/// The `gltf` crate's messages list every invalid item: passed on cut to
/// 2,000 characters, saying how much was left out (a document of 3,000,000
/// bad accessors made a message of 134 MB).
#[test]
fn the_gltf_crates_long_messages_are_cut() {
    let long = "accessor without a view; ".repeat(10_000);
    let cut = super::gltf_read::shortened(long.clone());
    assert_eq!(cut.chars().take_while(|c| *c != '…').count(), 2001, "{}", &cut[..100]);
    assert!(cut.ends_with(&format!("({} more bytes of the same)", long.len() - 2000)), "{}", &cut[cut.len() - 60..]);
    assert_eq!(super::gltf_read::shortened("short".into()), "short");
}

/// Hair grown on the mannequin is rooted on its skin, not on the inner body
/// some 8 mm under it (the head's region leaves enclosed triangles out): the
/// character winds about half a time around a root on the skin, 1.5 times
/// around one on the inner layer. Four roots at the sides of the head, inside
/// the band of the mannequin's eyes (a part of its own), are wound twice;
/// with the inner layer in the region, 80 of the 600 were under the skin.
#[test]
fn grown_roots_lie_on_the_mannequins_skin() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let rig = HairRig::new(Character::load(path).expect("mannequin"), Some("run"), None).expect("rig");
    let (groom, _) = rig.grow(4).expect("grown");
    let body = TriMesh::new(rig.character.positions.clone(), rig.character.triangles.clone()).expect("body");
    let bind = rig.bind_frame();
    let under: Vec<(usize, f32)> = (0..groom.strand_count())
        .map(|s| (s, crate::groom::enclosed::winding_number(&body, bind.transform_point3(groom.strand(s)[0]))))
        .filter(|&(_, w)| w >= 1.0)
        .collect();
    assert!(under.len() <= groom.strand_count() / 100, "{} roots under the skin: {under:?}", under.len());
}

/// The mannequin's body region (the skinned mesh collider): the head, neck,
/// shoulders and upper back, every vertex within `BODY_REACH` of the head
/// joint in the bind pose, its bones within the collider's limit, its mesh
/// the character's own vertices carried into the head's frame.
#[test]
fn the_body_region_reaches_the_shoulders_and_no_farther() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let rig = HairRig::new(Character::load(path).expect("mannequin"), Some("run"), None).expect("rig");
    let (body, skin) = rig.body_region().expect("body region");
    assert_eq!(body.positions.len(), skin.len());
    let bind = rig.bind_frame();
    let names: std::collections::BTreeSet<&str> = skin
        .iter()
        .flat_map(|s| {
            s.joints.iter().zip(&s.weights).filter(|(_, w)| **w >= 0.5).map(|(j, _)| rig.joint_name(*j as usize))
        })
        .collect();
    for bone in ["head", "neck_01", "clavicle.l", "clavicle.r", "spine_02"] {
        assert!(names.contains(bone), "{bone} is missing from {names:?}");
    }
    assert!(!names.iter().any(|n| n.contains("hand") || n.contains("thigh")), "{names:?}");
    for p in &body.positions {
        let world = bind.transform_point3(*p);
        assert!(world.distance(bind.transform_point3(Vec3::ZERO)) <= BODY_REACH + 1e-5, "{world} beyond reach");
        assert!(
            rig.character.positions.iter().any(|v| v.distance(world) < 1e-5),
            "{world} is no vertex of the character"
        );
    }
    crate::sim::MeshSkin::fit(&crate::groom::sdf::MeshSdf::build(&body, 24, 0.02).expect("field"), &body, &skin)
        .expect("the region's bones fit a collider");
    // The mannequin's inner body (a second layer some 8 mm under its skin) is
    // left out: of the 3,774 triangles within reach, 2,268 are its skin.
    let origin = bind.transform_point3(Vec3::ZERO);
    let within = rig
        .character
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| rig.character.positions[v as usize].distance(origin) <= BODY_REACH))
        .count();
    assert!(3 * body.triangles.len() < 2 * within, "{} of {within} triangles kept", body.triangles.len());
}
