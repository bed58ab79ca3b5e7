//! Reading a skinned, animated character from glTF 2.0 (`.glb`, or `.gltf`
//! with its buffers in files beside it): the skinned primitives of the first
//! skinned mesh node, its skin, the node hierarchy and every animation's
//! translation, rotation and scale channels. Textures, materials, morph targets
//! and cameras are not read; buffers given as data URIs are refused.

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};

use super::skeleton::{Animation, Channel, Keys, Node, Sampling, Skeleton};
use super::Character;
use crate::error::{Error, FileFormat, Result};
use crate::files;

/// The most bytes read of a glTF document or one of its buffers.
pub const MAX_GLTF_BYTES: u64 = 1 << 30;
/// The most vertices of a character's skinned primitives together.
pub const MAX_CHARACTER_VERTICES: usize = 4 << 20;

/// The most indices of the skinned primitives together (three a triangle).
const MAX_INDICES: usize = 3 << 22;
/// The most keys of one animation channel.
const MAX_KEYS: usize = 1 << 20;
/// Most animation keys a document may decode over all its channels (4 Mi:
/// under 100 MiB of times and values).
pub const MAX_DOCUMENT_KEYS: usize = 1 << 22;

use gltf::accessor::{DataType, Dimensions};

/// Checks an accessor before the crate's readers touch it: a type and shape
/// they expect, 1..=`max` elements, no sparse storage, and every element
/// inside its buffer view and the view inside its buffer (the readers index
/// the bytes without checking).
fn check_accessor(a: &gltf::Accessor<'_>, types: &[DataType], dims: Dimensions, max: usize, what: &str) -> Result<()> {
    let bad = |why: String| malformed(format!("{what}: accessor {}: {why}", a.index()));
    if a.sparse().is_some() {
        return Err(unsupported(format!("{what}: accessor {} is sparse", a.index())));
    }
    if !types.contains(&a.data_type()) || a.dimensions() != dims {
        return Err(bad(format!("{:?} {:?}, not one of {types:?} {dims:?}", a.data_type(), a.dimensions())));
    }
    let count = a.count();
    if count == 0 || count > max {
        return Err(bad(format!("{count} elements (allowed 1..={max})")));
    }
    let view = a.view().ok_or_else(|| bad("no buffer view".into()))?;
    let size = a.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(bad(format!("stride {stride} below the element's {size} bytes")));
    }
    let end = stride.checked_mul(count - 1).and_then(|n| n.checked_add(a.offset())).and_then(|n| n.checked_add(size));
    let view_end = view.offset().checked_add(view.length());
    match (end, view_end) {
        (Some(end), Some(view_end)) if end <= view.length() && view_end <= view.buffer().length() => Ok(()),
        _ => Err(bad("elements past the end of the buffer view, or the view past its buffer".into())),
    }
}

fn malformed(reason: impl Into<String>) -> Error {
    Error::Malformed { format: FileFormat::Gltf, reason: reason.into() }
}

fn unsupported(reason: impl Into<String>) -> Error {
    Error::Unsupported { format: FileFormat::Gltf, reason: reason.into() }
}

/// Reads `path` (see the module docs); errors name the file.
pub(super) fn load(path: &Path) -> Result<Character> {
    let bytes = files::read_capped(path, MAX_GLTF_BYTES, "a glTF document")?;
    let dir = path.parent().unwrap_or(Path::new("."));
    // The gltf crate indexes some of the file's indices unchecked: those
    // known are checked before (check_indices); a panic on one not yet known
    // is the file's defect, reported, not printed.
    crate::files::read_guarded(|| parse(&bytes, Some(dir)))
        .unwrap_or_else(|what| Err(malformed(format!("the glTF reader stopped: {what}"))))
        .map_err(|e| e.in_asset(path))
}

/// The indices the `gltf` crate's validation indexes with before checking
/// them, or its readers index with unchecked (a mesh attribute's or morph target's accessor, an
/// animation channel's target node): each must name an object of the
/// document, else the file is malformed, named by where the index is.
fn check_indices(root: &gltf::json::Root) -> Result<()> {
    let (accessors, nodes) = (root.accessors.len(), root.nodes.len());
    let past = |what: String, index: usize, count: usize, of: &str| {
        malformed(format!("{what} names {of} {index}, past the {count} the file has"))
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= accessors {
                    let name = match semantic {
                        gltf::json::validation::Checked::Valid(s) => s.to_string(),
                        gltf::json::validation::Checked::Invalid => "an attribute".into(),
                    };
                    return Err(past(
                        format!("meshes[{m}].primitives[{p}] {name}"),
                        index.value(),
                        accessors,
                        "accessor",
                    ));
                }
            }
            for (t, target) in primitive.targets.iter().flatten().enumerate() {
                for index in [&target.positions, &target.normals, &target.tangents].into_iter().flatten() {
                    if index.value() >= accessors {
                        let what = format!("meshes[{m}].primitives[{p}].targets[{t}]");
                        return Err(past(what, index.value(), accessors, "accessor"));
                    }
                }
            }
        }
    }
    use gltf::json::validation::Checked;
    for (a, animation) in root.animations.iter().enumerate() {
        for (c, channel) in animation.channels.iter().enumerate() {
            let node = channel.target.node.value();
            if node >= nodes {
                return Err(past(format!("animations[{a}].channels[{c}].target"), node, nodes, "node"));
            }
            // The crate's readers unwrap the target's property.
            if matches!(channel.target.path, Checked::Invalid) {
                return Err(malformed(format!(
                    "animations[{a}].channels[{c}].target.path is none of translation, rotation, scale, weights"
                )));
            }
            let samplers = animation.samplers.len();
            if channel.sampler.value() >= samplers {
                let what = format!("animations[{a}].channels[{c}].sampler");
                return Err(past(what, channel.sampler.value(), samplers, "sampler"));
            }
        }
        for (k, sampler) in animation.samplers.iter().enumerate() {
            if matches!(sampler.interpolation, Checked::Invalid) {
                return Err(malformed(format!(
                    "animations[{a}].samplers[{k}].interpolation is none of LINEAR, STEP, CUBICSPLINE"
                )));
            }
        }
    }
    Ok(())
}

/// Most JSON objects a glTF document may hold (nodes, accessors, keys of
/// every kind together): the `gltf` crate builds a structure of each before
/// any can be judged (3,000,000 empty nodes took it past 10 s, 15,000,000
/// asked for gigabytes; a million took 6.5 s more than the mannequin's 6,895
/// objects, released).
pub const MAX_GLTF_JSON_OBJECTS: usize = 1 << 18;

/// The JSON of a glTF document in `bytes` (a `.glb`'s first chunk, or the
/// whole of a `.gltf`) holds at most [`MAX_GLTF_JSON_OBJECTS`] objects:
/// counted as the `{` outside strings, before the crate parses it.
fn check_json_size(bytes: &[u8]) -> Result<()> {
    let json = match bytes {
        [b'g', b'l', b'T', b'F', ..] if bytes.len() >= 20 => {
            let length = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as usize;
            &bytes[20..bytes.len().min(20usize.saturating_add(length))]
        }
        _ => bytes,
    };
    let (mut objects, mut in_string, mut escaped) = (0usize, false, false);
    for &b in json {
        match (in_string, escaped, b) {
            (true, true, _) => escaped = false,
            (true, false, b'\\') => escaped = true,
            (true, false, b'"') => in_string = false,
            (false, _, b'"') => in_string = true,
            (false, _, b'{') => {
                objects += 1;
                if objects > MAX_GLTF_JSON_OBJECTS {
                    return Err(malformed(format!(
                        "its JSON holds more than {MAX_GLTF_JSON_OBJECTS} objects (nodes, accessors and the rest \
                         together)"
                    )));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Longest message of the `gltf` crate's passed on: it lists every invalid
/// item of a document (3,000,000 accessors without a buffer view made 134 MB
/// of it).
const MAX_MESSAGE_CHARS: usize = 2000;

/// `message` cut to [`MAX_MESSAGE_CHARS`], saying how much was left out.
pub(super) fn shortened(message: String) -> String {
    match message.char_indices().nth(MAX_MESSAGE_CHARS) {
        Some((at, _)) => format!("{} … ({} more bytes of the same)", &message[..at], message.len() - at),
        None => message,
    }
}

/// Parses a glTF document held in memory; external buffers are read from `dir`
/// (refused without one).
pub(super) fn parse(bytes: &[u8], dir: Option<&Path>) -> Result<Character> {
    // The crate's own validation indexes with some indices before checking
    // them: those are checked first.
    check_json_size(bytes)?;
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| malformed(shortened(e.to_string())))?;
    check_indices(raw.document.as_json())?;
    let document =
        gltf::Document::from_json(raw.document.into_json()).map_err(|e| malformed(shortened(e.to_string())))?;
    let gltf = gltf::Gltf { document, blob: raw.blob };
    let buffers = buffers(&gltf, dir)?;
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(Vec::as_slice);
    let doc = &gltf.document;

    let (mesh, skin) = doc
        .nodes()
        .find_map(|n| Some((n.mesh()?, n.skin()?)))
        .ok_or_else(|| unsupported("no skinned mesh: a node with both a mesh and a skin is needed"))?;
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    if joints.is_empty() {
        return Err(malformed(format!("skin {} has no joints", skin.index())));
    }
    if let Some(a) = skin.inverse_bind_matrices() {
        check_accessor(&a, &[DataType::F32], Dimensions::Mat4, joints.len(), "inverse bind matrices")?;
    }
    let inverse_bind: Vec<Mat4> = match skin.reader(get).read_inverse_bind_matrices() {
        Some(m) => m.map(|c| Mat4::from_cols_array_2d(&c)).collect(),
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if inverse_bind.len() != joints.len()
        || inverse_bind.iter().any(|m| !m.is_finite() || m.determinant().abs() < 1e-12)
    {
        return Err(malformed(format!(
            "skin {}: {} inverse bind matrices for {} joints, or one not finite or singular",
            skin.index(),
            inverse_bind.len(),
            joints.len()
        )));
    }
    // A bind pose is where a character stands: its matrices' translations
    // and scales are a character's too (1e30 put every vertex out of reach).
    for (j, m) in inverse_bind.iter().enumerate() {
        let (scale, _, translation) = m.to_scale_rotation_translation();
        if let Some(why) = absurd(translation, scale) {
            return Err(malformed(format!("skin {} joint {j}'s inverse bind matrix: its {why}", skin.index())));
        }
    }

    let mut positions = Vec::new();
    let mut weights = Vec::new();
    let mut triangles = Vec::new();
    for (k, primitive) in mesh.primitives().enumerate() {
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            continue;
        }
        let what = |part: &str| format!("mesh {} primitive {k}: {part}", mesh.index());
        let attribute = |semantic: gltf::Semantic, name: &str| {
            primitive.get(&semantic).ok_or_else(|| malformed(what(&format!("no {name}"))))
        };
        let max = MAX_CHARACTER_VERTICES;
        check_accessor(
            &attribute(gltf::Semantic::Positions, "POSITION")?,
            &[DataType::F32],
            Dimensions::Vec3,
            max,
            &what("POSITION"),
        )?;
        let joint_types = [DataType::U8, DataType::U16];
        check_accessor(
            &attribute(gltf::Semantic::Joints(0), "JOINTS_0")?,
            &joint_types,
            Dimensions::Vec4,
            max,
            &what("JOINTS_0"),
        )?;
        let weight_types = [DataType::F32, DataType::U8, DataType::U16];
        check_accessor(
            &attribute(gltf::Semantic::Weights(0), "WEIGHTS_0")?,
            &weight_types,
            Dimensions::Vec4,
            max,
            &what("WEIGHTS_0"),
        )?;
        if let Some(i) = primitive.indices() {
            let index_types = [DataType::U8, DataType::U16, DataType::U32];
            check_accessor(&i, &index_types, Dimensions::Scalar, MAX_INDICES, &what("indices"))?;
        }
        let reader = primitive.reader(get);
        let p: Vec<Vec3> =
            reader.read_positions().ok_or_else(|| malformed(what("no POSITION")))?.map(Vec3::from).collect();
        let j: Vec<[u16; 4]> =
            reader.read_joints(0).ok_or_else(|| malformed(what("no JOINTS_0")))?.into_u16().collect();
        let w: Vec<[f32; 4]> =
            reader.read_weights(0).ok_or_else(|| malformed(what("no WEIGHTS_0")))?.into_f32().collect();
        if j.len() != p.len() || w.len() != p.len() {
            return Err(malformed(what(&format!("{} positions, {} joints, {} weights", p.len(), j.len(), w.len()))));
        }
        if positions.len() + p.len() > MAX_CHARACTER_VERTICES {
            return Err(unsupported(format!("more than {MAX_CHARACTER_VERTICES} skinned vertices")));
        }
        let base = positions.len() as u32;
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..p.len() as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) || triangles.len() * 3 + indices.len() > MAX_INDICES {
            return Err(malformed(what(&format!("{} indices: not whole triangles, or too many", indices.len()))));
        }
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= p.len()) {
            return Err(malformed(what(&format!("index {bad} past its {} vertices", p.len()))));
        }
        triangles.extend(indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
        for ((pos, joint), weight) in p.into_iter().zip(j).zip(w) {
            if !pos.is_finite() {
                return Err(malformed(what("a position is not finite")));
            }
            if pos.abs().max_element() > MAX_TRANSFORM_COMPONENT {
                return Err(malformed(what(&format!("a position {pos} is beyond ±{MAX_TRANSFORM_COMPONENT} m"))));
            }
            if let Some(bad) = joint.iter().find(|&&i| usize::from(i) >= joints.len()) {
                return Err(malformed(what(&format!("joint {bad} past the skin's {} joints", joints.len()))));
            }
            let sum: f32 = weight.iter().sum();
            if !(sum.is_finite() && sum > 0.0 && weight.iter().all(|&x| x >= 0.0)) {
                return Err(malformed(what(&format!("weights {weight:?} do not add up to a positive sum"))));
            }
            positions.push(pos);
            weights.push((joint, weight.map(|x| x / sum)));
        }
    }
    if triangles.is_empty() {
        return Err(unsupported(format!("mesh {} has no triangles", mesh.index())));
    }

    let nodes = nodes(doc)?;
    let animations = animations(doc, &get)?;
    let skeleton = Skeleton::new(nodes, joints, inverse_bind, animations)?;
    Character::new(skeleton, positions, weights, triangles)
}

/// Every buffer's bytes, checked against its declared length.
fn buffers(gltf: &gltf::Gltf, dir: Option<&Path>) -> Result<Vec<Vec<u8>>> {
    let mut out: Vec<Vec<u8>> = Vec::new();
    // What the buffers hold together, each counted as often as it is named
    // (fifty buffers naming one file read it fifty times).
    let declared = gltf.document.buffers().map(|b| b.length() as u64).fold(0u64, u64::saturating_add);
    if declared > MAX_GLTF_BYTES {
        return Err(unsupported(format!(
            "the document's {} buffers declare {declared} bytes together, more than {MAX_GLTF_BYTES} (each counted \
             as often as it is named)",
            gltf.document.buffers().len()
        )));
    }
    let mut total = 0u64;
    for buffer in gltf.document.buffers() {
        let budget = MAX_GLTF_BYTES.saturating_sub(total);
        let too_much = || {
            unsupported(format!(
                "buffer {}: the document's buffers add up to more than {MAX_GLTF_BYTES} bytes (each counted as \
                 often as it is named)",
                buffer.index()
            ))
        };
        if buffer.length() as u64 > budget
            || (matches!(buffer.source(), gltf::buffer::Source::Bin)
                && gltf.blob.as_ref().is_some_and(|b| b.len() as u64 > budget))
        {
            return Err(too_much());
        }
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| malformed(format!("buffer {} names a missing BIN chunk", buffer.index())))?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                return Err(unsupported(format!("buffer {} is a data URI; use .glb or a .bin file", buffer.index())))
            }
            gltf::buffer::Source::Uri(uri) => {
                let dir = dir.ok_or_else(|| unsupported(format!("buffer {} is an external file", buffer.index())))?;
                if uri.contains("..") || Path::new(uri).is_absolute() {
                    return Err(unsupported(format!(
                        "buffer {} at {uri:?} is outside the document's folder",
                        buffer.index()
                    )));
                }
                // A buffer that is not a regular file (missing, a folder, a
                // FIFO no one writes) is the document's defect, named with
                // the buffer and reported under the document's name.
                let file = dir.join(uri);
                let unreadable =
                    |e: Error| malformed(format!("buffer {} at {uri:?} cannot be read: {e}", buffer.index()));
                files::check_regular(&file, budget, "a glTF buffer").map_err(|e| match e {
                    Error::InputTooLarge { .. } if budget < MAX_GLTF_BYTES => too_much(),
                    Error::InputTooLarge { .. } => e,
                    e => unreadable(e),
                })?;
                files::read_capped(&file, budget, "a glTF buffer").map_err(|e| match e {
                    Error::InputTooLarge { .. } if budget < MAX_GLTF_BYTES => too_much(),
                    Error::InputTooLarge { .. } => e,
                    e => unreadable(e),
                })?
            }
        };
        total += data.len() as u64;
        if data.len() < buffer.length() {
            return Err(Error::Truncated {
                format: FileFormat::Gltf,
                what: "a buffer",
                needed: buffer.length() as u64,
                available: data.len() as u64,
            });
        }
        out.push(data);
    }
    Ok(out)
}

/// The node hierarchy with each node's rest transform.
/// A node's translation, rotation and scale: as given, or decomposed from
/// its matrix in f64 (a matrix entry of 1e30 overflowed f32's decomposition
/// into NaN, named "not finite"); a matrix that has none is refused saying
/// why.
fn decomposed(n: &gltf::Node) -> Result<([f32; 3], [f32; 4], [f32; 3])> {
    let gltf::scene::Transform::Matrix { matrix } = n.transform() else { return Ok(n.transform().decomposed()) };
    let m = glam::DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)));
    let why = if !m.is_finite() {
        Some("a matrix that is not finite".to_owned())
    } else if m.determinant().abs() < 1e-18 {
        Some(format!("a singular matrix (determinant {:e}): no rotation and scale", m.determinant()))
    } else if m.row(3) != glam::DVec4::W {
        Some(format!("a projective matrix (its last row is {:?}, not 0, 0, 0, 1)", m.row(3).to_array()))
    } else {
        None
    };
    if let Some(why) = why {
        return Err(malformed(format!("node {} ({:?}) has {why}", n.index(), n.name().unwrap_or_default())));
    }
    let (s, r, t) = m.to_scale_rotation_translation();
    Ok((t.as_vec3().to_array(), r.as_quat().to_array(), s.as_vec3().to_array()))
}

fn nodes(doc: &gltf::Document) -> Result<Vec<Node>> {
    let mut nodes: Vec<Node> = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = decomposed(&n)?;
            Ok(Node {
                name: n.name().unwrap_or_default().to_owned(),
                parent: None,
                translation: Vec3::from(t),
                rotation: Quat::from_array(r),
                scale: Vec3::from(s),
            })
        })
        .collect::<Result<_>>()?;
    for n in doc.nodes() {
        for c in n.children() {
            if nodes[c.index()].parent.replace(n.index()).is_some() {
                return Err(malformed(format!("node {} has two parents", c.index())));
            }
        }
    }
    for (i, n) in nodes.iter().enumerate() {
        if !(n.translation.is_finite() && n.rotation.is_finite() && n.scale.is_finite()) {
            return Err(malformed(format!("node {i} ({:?}) has a transform that is not finite", n.name)));
        }
        if let Some(why) = super::skeleton::not_a_rotation(n.rotation) {
            return Err(malformed(format!("node {i} ({:?}): its rotation {why}", n.name)));
        }
        if let Some(why) = absurd(n.translation, n.scale) {
            return Err(malformed(format!("node {i} ({:?}): {why}", n.name)));
        }
    }
    Ok(nodes)
}

/// Largest translation or scale component a node or an animation key may
/// have (meters for translations): a character is metres across, and a
/// value past this is a broken file, not a pose.
pub const MAX_TRANSFORM_COMPONENT: f32 = 1e4;

/// Why a translation `t` or scale `s` is beyond any character's, if it is.
fn absurd(t: Vec3, s: Vec3) -> Option<String> {
    let most = MAX_TRANSFORM_COMPONENT;
    if t.abs().max_element() > most {
        return Some(format!("translation {t} is beyond ±{most} m"));
    }
    (s.abs().max_element() > most).then(|| format!("scale {s} is beyond ±{most}"))
}

/// Every animation's transform channels.
fn animations<'s>(
    doc: &gltf::Document,
    get: &(impl Clone + Fn(gltf::Buffer<'_>) -> Option<&'s [u8]>),
) -> Result<Vec<Animation>> {
    let mut out = Vec::new();
    // Keys decoded over the whole document: channels sharing a sampler each
    // decode its keys, so a small file could ask for many copies.
    let mut decoded = 0usize;
    for a in doc.animations() {
        let name = a.name().map_or_else(|| format!("animation {}", a.index()), str::to_owned);
        let mut channels = Vec::new();
        for c in a.channels() {
            let what = |part: &str| format!("{name:?} channel {}: {part}", c.index());
            let (input, output) = (c.sampler().input(), c.sampler().output());
            check_accessor(&input, &[DataType::F32], Dimensions::Scalar, MAX_KEYS, &what("input"))?;
            decoded = decoded.saturating_add(input.count());
            if decoded > MAX_DOCUMENT_KEYS {
                return Err(malformed(format!(
                    "{}: the animations decode to more than {MAX_DOCUMENT_KEYS} keys over all channels (a sampler \
                     shared by several channels counts once for each)",
                    what("keys")
                )));
            }
            let (types, dims): (&[DataType], _) = match c.target().property() {
                Property::Translation | Property::Scale => (&[DataType::F32], Dimensions::Vec3),
                Property::Rotation => {
                    (&[DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16], Dimensions::Vec4)
                }
                Property::MorphTargetWeights => continue,
            };
            check_accessor(&output, types, dims, 3 * MAX_KEYS, &what("output"))?;
            let reader = c.reader(get.clone());
            let times: Vec<f32> = reader.read_inputs().ok_or_else(|| malformed(what("no input")))?.collect();
            let keys = match reader.read_outputs().ok_or_else(|| malformed(what("no output")))? {
                ReadOutputs::Translations(t) => Keys::Translation(t.map(Vec3::from).collect()),
                ReadOutputs::Scales(s) => Keys::Scale(s.map(Vec3::from).collect()),
                ReadOutputs::Rotations(r) => Keys::Rotation(r.into_f32().map(Quat::from_array).collect()),
                ReadOutputs::MorphTargetWeights(_) => continue,
            };
            if c.target().property() == Property::MorphTargetWeights {
                continue;
            }
            let sampling = match c.sampler().interpolation() {
                Interpolation::Linear => Sampling::Linear,
                Interpolation::Step => Sampling::Step,
                Interpolation::CubicSpline => Sampling::CubicSpline,
            };
            let beyond = match &keys {
                Keys::Translation(v) => v.iter().find_map(|&t| absurd(t, Vec3::ONE)),
                Keys::Scale(v) => v.iter().find_map(|&sc| absurd(Vec3::ZERO, sc)),
                Keys::Rotation(_) => None,
            };
            if let Some(why) = beyond {
                return Err(malformed(what(&format!("a key's {why}"))));
            }
            let channel = Channel { node: c.target().node().index(), times, keys, sampling };
            channel.validate().map_err(|reason| malformed(what(&reason)))?;
            channels.push(channel);
        }
        out.push(Animation { name, channels });
    }
    Ok(out)
}
