//! Roots bound to a skinned scalp ([`HairSim::bind_scalp_source`](super::HairSim::bind_scalp_source),
//! [`HairSim::bind_scalp_bones`](super::HairSim::bind_scalp_bones)):
//! each key hair's root is bound to a triangle of a scalp mesh (the triangle
//! and the root's barycentric weights, found in the bind pose), and every step
//! places the hair's rest pose by that triangle's frame where the host's
//! skinning put it, instead of by the head.
//!
//! A root's frame is the triangle's: origin the bound point, z the unit normal,
//! x the first edge made perpendicular to it, y = z × x. The rest pose (given
//! in the head frame, the frame of the scalp's bind pose) is placed by that
//! frame times the bind pose's frame inverted, so a hair keeps its cut relative
//! to its own patch of scalp when the scalp turns, stretches or slides over
//! the skull. Between two steps each corner moves linearly across the
//! sub-steps; a step that starts with a teleport, a reset or a newly bound
//! scalp starts from this step's scalp.
//!
//! The skinned vertices come from a buffer of the host's
//! ([`ScalpSource`], read by the step's own dispatch) or, for a host without
//! GPU skinning, from bone matrices that vkhair applies to the scalp's
//! vertices itself ([`Scalp::skin`], [`HairSim::set_scalp_bones`](super::HairSim::set_scalp_bones)).
//! `glsl/include/scalp.glsl` runs the frames on the GPU; the CPU reference
//! (`scalp_frame`) runs the same operations.

use ash::vk;
use glam::{Mat4, Vec3, Vec4};

use super::math::{cross, dot, rotate, transform_point};
use crate::error::{Error, Result};
use crate::gpu_types::{GpuScalpRoot, ScalpRootView, SimStep};
use crate::groom::binding::{bind_roots, RootBinding};
use crate::groom::mesh::TriMesh;

/// Bones per scalp vertex at most ([`VertexSkin`]).
pub const MAX_BONES_PER_VERTEX: usize = 4;

/// How far a root may lie from the scalp it is bound to by default, in the
/// groom's units (meters): 1 mm.
pub const DEFAULT_ROOT_TOLERANCE: f32 = 1e-3;

/// A scalp mesh in its bind pose: the triangles the roots are bound to.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalp {
    /// The triangles and their vertices in the bind pose, in the head frame
    /// (the groom's frame and units). Vertex indices are the skinned buffer's.
    pub mesh: TriMesh,
    /// For [`HairSim::set_scalp_bones`](super::HairSim::set_scalp_bones):
    /// each vertex's bones and weights (one entry per vertex); empty when the
    /// host skins on the GPU ([`ScalpSource`]).
    pub skin: Vec<VertexSkin>,
    /// Farthest a key hair's root may be from the mesh, in the groom's units
    /// (default [`DEFAULT_ROOT_TOLERANCE`]); a farther root is refused, naming
    /// the strand.
    pub tolerance: f32,
}

/// Up to four bones moving one scalp vertex (linear blend skinning).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VertexSkin {
    /// Indices into the bone matrices handed to `set_scalp_bones`.
    pub joints: [u32; MAX_BONES_PER_VERTEX],
    /// Their weights (non-negative, summing to 1 within 1e-3; unused ones 0).
    pub weights: [f32; MAX_BONES_PER_VERTEX],
}

impl Scalp {
    /// A scalp without bones (its skinned vertices come from a [`ScalpSource`]).
    pub fn new(mesh: TriMesh) -> Self {
        Scalp { mesh, skin: Vec::new(), tolerance: DEFAULT_ROOT_TOLERANCE }
    }

    /// Linear blend skinning of every vertex: Σ wₖ · bones\[jₖ\] · p (the bone
    /// matrices map the bind pose, head frame, to the world). Errors name a
    /// bone that is not finite or a joint index past `bones`.
    pub fn skin(&self, bones: &[Mat4]) -> Result<Vec<Vec3>> {
        if self.skin.len() != self.mesh.positions.len() {
            return Err(Error::incompatible(
                "scalp bones",
                format!("{} vertices have bones, the scalp has {}", self.skin.len(), self.mesh.positions.len()),
            ));
        }
        if let Some(j) = bones.iter().position(|m| !m.is_finite()) {
            return Err(Error::param("scalp bone matrix", format!("bone {j}"), "finite"));
        }
        self.mesh
            .positions
            .iter()
            .zip(&self.skin)
            .map(|(&p, s)| {
                let mut out = Vec3::ZERO;
                for (&j, &w) in s.joints.iter().zip(&s.weights).filter(|&(_, &w)| w != 0.0) {
                    let bone = bones.get(j as usize).ok_or_else(|| {
                        Error::param("scalp joint", j, format!("below the {} bone matrices given", bones.len()))
                    })?;
                    out += bone.transform_point3(p) * w;
                }
                Ok(out)
            })
            .collect()
    }

    /// Checks the bones: one entry per vertex, weights finite, non-negative,
    /// summing to 1.
    fn validate_skin(&self) -> Result<()> {
        if self.skin.is_empty() {
            return Ok(());
        }
        if self.skin.len() != self.mesh.positions.len() {
            return Err(Error::incompatible(
                "scalp bones",
                format!("{} vertices have bones, the scalp has {}", self.skin.len(), self.mesh.positions.len()),
            ));
        }
        check_weights("scalp bone weights", &self.skin)
    }
}

/// Refuses, as `what`, a vertex whose weights are not finite, non-negative and
/// summing to 1 (within 1e-3).
pub(crate) fn check_weights(what: &'static str, skin: &[VertexSkin]) -> Result<()> {
    for (v, s) in skin.iter().enumerate() {
        let sum: f32 = s.weights.iter().sum();
        if s.weights.iter().any(|w| !w.is_finite() || *w < 0.0) || (sum - 1.0).abs() > 1e-3 {
            return Err(Error::param(
                what,
                format!("vertex {v}: {:?}", s.weights),
                "finite, non-negative, summing to 1",
            ));
        }
    }
    Ok(())
}

/// The host's skinned scalp vertices in a GPU buffer of its own (its skinning
/// pass's output), read by the step's dispatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScalpSource {
    /// A buffer of the simulation's device with `STORAGE_BUFFER` usage.
    pub buffer: vk::Buffer,
    /// Its size in bytes (the descriptor covers `0..size`).
    pub size: u64,
    /// Bytes from one vertex to the next (a multiple of 4, at least the format's size).
    pub stride: u64,
    /// `R32G32B32_SFLOAT` or `R32G32B32A32_SFLOAT` (xyz read, in the world).
    pub format: vk::Format,
    /// Vertices the buffer holds from each step's offset on.
    pub vertex_count: u32,
}

impl ScalpSource {
    /// Bytes of one vertex in the format.
    fn element_size(&self) -> Result<u64> {
        match self.format {
            vk::Format::R32G32B32_SFLOAT => Ok(12),
            vk::Format::R32G32B32A32_SFLOAT => Ok(16),
            other => Err(Error::param(
                "scalp source format",
                format!("{other:?}"),
                "R32G32B32_SFLOAT or R32G32B32A32_SFLOAT",
            )),
        }
    }

    /// Checks the description against the bound scalp (`vertices` needed) and
    /// the device's storage range; returns the stride in floats.
    pub(crate) fn validate(&self, vertices: usize, max_range: u64) -> Result<u32> {
        let element = self.element_size()?;
        if self.buffer == vk::Buffer::null() {
            return Err(Error::param("scalp source buffer", "VK_NULL_HANDLE", "a buffer of the device"));
        }
        if !self.stride.is_multiple_of(4) || self.stride < element || self.stride > 1 << 20 {
            return Err(Error::param(
                "scalp source stride",
                self.stride,
                format!("a multiple of 4 from {element} (the format's size) to 1 MiB"),
            ));
        }
        if (self.vertex_count as usize) < vertices {
            return Err(Error::param(
                "scalp source vertex count",
                self.vertex_count,
                format!("at least {vertices} (the bound scalp's vertices)"),
            ));
        }
        let needed = self.stride * u64::from(self.vertex_count.max(1) - 1) + element;
        if self.size < needed || self.size > max_range || !self.size.is_multiple_of(4) {
            return Err(Error::param(
                "scalp source size",
                self.size,
                format!("a multiple of 4 from {needed} (its vertices) to {max_range} (the device's storage range)"),
            ));
        }
        Ok((self.stride / 4) as u32)
    }

    /// The first float of vertex 0 for a step whose vertices start `offset`
    /// bytes into the buffer.
    pub(crate) fn first_float(&self, offset: u64) -> Result<u32> {
        let element = self.element_size()?;
        let end = self.stride * u64::from(self.vertex_count.max(1) - 1) + element;
        if !offset.is_multiple_of(4) || offset.checked_add(end).is_none_or(|e| e > self.size) {
            return Err(Error::param(
                "scalp source offset",
                offset,
                format!("a multiple of 4 with {end} bytes of vertices after it within the {}-byte buffer", self.size),
            ));
        }
        Ok((offset / 4) as u32)
    }
}

/// Every key hair's root on the scalp, as the GPU reads it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ScalpBinding {
    pub roots: Vec<GpuScalpRoot>,
    /// The same, unpacked for the CPU reference.
    pub views: Vec<ScalpRootView>,
    /// Vertices of the scalp.
    pub vertices: usize,
}

impl ScalpBinding {
    /// Binds `roots` (the key hairs' rest roots, head frame) to `scalp`.
    pub(crate) fn new(scalp: &Scalp, roots: &[Vec3]) -> Result<Self> {
        if !(scalp.tolerance.is_finite() && scalp.tolerance > 0.0) {
            return Err(Error::param("scalp root tolerance", scalp.tolerance, "finite and above 0"));
        }
        scalp.validate_skin()?;
        let mesh = TriMesh::new(scalp.mesh.positions.clone(), scalp.mesh.triangles.clone())?;
        let bound = bind_roots(roots, &mesh, scalp.tolerance)?;
        let views = bound.iter().enumerate().map(|(s, b)| root_view(&mesh, s, b)).collect::<Result<Vec<_>>>()?;
        Ok(ScalpBinding {
            roots: views.iter().map(GpuScalpRoot::from).collect(),
            views,
            vertices: mesh.positions.len(),
        })
    }

    /// The bindings of consecutive runs of key hairs, each to its own scalp,
    /// as one: the scalps' vertices laid one after another in the order given,
    /// each part's corners shifted past the vertices of the parts before it.
    pub(crate) fn concat(parts: Vec<ScalpBinding>) -> ScalpBinding {
        let mut joined = ScalpBinding { roots: Vec::new(), views: Vec::new(), vertices: 0 };
        for part in parts {
            let base = joined.vertices as u32;
            for mut view in part.views {
                view.corners = view.corners.map(|c| c + base);
                joined.roots.push(GpuScalpRoot::from(&view));
                joined.views.push(view);
            }
            joined.vertices += part.vertices;
        }
        joined
    }

    /// Key hair `h`'s triangle corners in `vertices`.
    pub(crate) fn corners(&self, h: usize, vertices: &[Vec3]) -> [Vec3; 3] {
        self.views[h].corners.map(|v| vertices[v as usize])
    }
}

/// Strand `s`'s root bound as `b`: its corners, weights and the bind pose's
/// frame inverted.
fn root_view(mesh: &TriMesh, s: usize, b: &RootBinding) -> Result<ScalpRootView> {
    let t = mesh.triangles[b.triangle as usize];
    let [a, bb, c] = t.map(|v| mesh.positions[v as usize]);
    let w = Vec3::from_array(b.weights);
    let frame = triangle_frame([a, bb, c], w).ok_or_else(|| {
        Error::param("scalp", format!("strand {s}'s root on triangle {}", b.triangle), "a triangle with an area")
    })?;
    // The frame is rigid: its inverse is the transposed rotation and −Rᵀo.
    let r = glam::Mat3::from_mat4(frame).transpose();
    let o = frame.col(3).truncate();
    let unbind =
        Mat4::from_cols(r.col(0).extend(0.0), r.col(1).extend(0.0), r.col(2).extend(0.0), (-(r * o)).extend(1.0));
    Ok(ScalpRootView { corners: t, weights: w, unbind, set: 0 })
}

/// `scalp_corner` of `glsl/include/scalp.glsl`: a corner at `f` of the step.
pub(crate) fn corner(before: Vec3, now: Vec3, f: f32) -> Vec3 {
    before * (1.0 - f) + now * f
}

/// The triangle's frame (columns x, y, z, origin) as `scalp_frame` builds it,
/// or `None` for a collapsed triangle.
fn triangle_frame([a, b, c]: [Vec3; 3], w: Vec3) -> Option<Mat4> {
    let origin = (a * w.x + b * w.y) + c * w.z;
    let e1 = b - a;
    let e2 = c - a;
    let n = cross(e1, e2);
    let n_len = dot(n, n).sqrt();
    if n_len.is_nan() || n_len <= 0.0 {
        return None;
    }
    let z = n / n_len;
    let t = e1 - z * dot(z, e1);
    let t_len = dot(t, t).sqrt();
    if t_len.is_nan() || t_len <= 0.0 {
        return None;
    }
    let x = t / t_len;
    let y = cross(z, x);
    Some(Mat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), origin.extend(1.0)))
}

/// `scalp_frame` of `glsl/include/scalp.glsl`: world from head frame for a
/// root bound as `root` whose corners are `corners`, or `fallback` for a
/// collapsed triangle.
pub(crate) fn scalp_frame(root: &ScalpRootView, corners: [Vec3; 3], fallback: &Mat4) -> Mat4 {
    let Some(frame) = triangle_frame(corners, root.weights) else {
        return *fallback;
    };
    let u = &root.unbind;
    let column = |i: usize| rotate(&frame, u.col(i).truncate()).extend(0.0);
    Mat4::from_cols(column(0), column(1), column(2), transform_point(&frame, u.col(3).truncate()).extend(1.0))
}

/// The corners of every key hair at `f` of a step, for the CPU reference:
/// from `previous` (per key hair, the previous step's) toward `now`'s scalp
/// vertices, or `now`'s alone on a restart.
pub(crate) fn frames_at(
    binding: &ScalpBinding,
    previous: &[[Vec3; 3]],
    now: &[Vec3],
    f: f32,
    restart: bool,
    fallback: &Mat4,
) -> Vec<Mat4> {
    (0..binding.views.len())
        .map(|h| {
            let current = binding.corners(h, now);
            let at = std::array::from_fn(|k| {
                let before = if restart { current[k] } else { previous[h][k] };
                corner(before, current[k], f)
            });
            scalp_frame(&binding.views[h], at, fallback)
        })
        .collect()
}

/// A bound scalp in the CPU reference: the binding, each key hair's corners
/// after the previous step and the scalp's vertices this step.
#[derive(Debug, Clone)]
pub(crate) struct CpuScalp {
    pub binding: ScalpBinding,
    pub scalp: Scalp,
    pub previous: Vec<[Vec3; 3]>,
    pub now: Vec<Vec3>,
}

impl CpuScalp {
    /// Every key hair's frame at `f` of the step whose sub-step `p` is
    /// (`fallback` for a collapsed triangle).
    pub(crate) fn frames(&self, p: &SimStep, f: f32, fallback: &Mat4) -> Vec<Mat4> {
        frames_at(&self.binding, &self.previous, &self.now, f, p.scalp_restart != 0, fallback)
    }

    /// At the end of a step: this step's corners become the previous ones.
    pub(crate) fn keep_corners(&mut self) {
        self.previous = (0..self.binding.views.len()).map(|h| self.binding.corners(h, &self.now)).collect();
    }

    /// Checks and takes this step's vertices.
    pub(crate) fn set_vertices(&mut self, vertices: &[Vec3]) -> Result<()> {
        check_vertices(vertices, self.binding.vertices)?;
        self.now = vertices.to_vec();
        Ok(())
    }
}

/// Skinned vertices handed over on the CPU: one per scalp vertex, finite.
pub(crate) fn check_vertices(vertices: &[Vec3], expected: usize) -> Result<()> {
    if vertices.len() != expected {
        return Err(Error::incompatible(
            "scalp vertices",
            format!("{} given, the bound scalp has {expected}", vertices.len()),
        ));
    }
    if let Some(v) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(Error::param("scalp vertex", format!("vertex {v} at {}", vertices[v]), "finite"));
    }
    Ok(())
}

/// Vertices as the bone path uploads them (vec4, w = 1).
pub(crate) fn as_vec4(vertices: &[Vec3]) -> Vec<Vec4> {
    vertices.iter().map(|v| v.extend(1.0)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> TriMesh {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -1.0)];
        TriMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).expect("a valid square")
    }

    /// At the bind pose a root's frame is the identity (up to rounding), and a
    /// scalp moved rigidly moves the frame by the same motion.
    #[test]
    fn frames_follow_the_triangles() {
        let scalp = Scalp::new(square());
        let roots = [Vec3::new(0.6, 0.0, -0.2), Vec3::new(0.2, 0.0, -0.7)];
        let binding = ScalpBinding::new(&scalp, &roots).expect("roots on the square");
        let rest = binding.frames_identity_error(&scalp.mesh.positions);
        assert!(rest < 1e-6, "bind pose frames off the identity by {rest}");
        let motion = Mat4::from_rotation_translation(glam::Quat::from_rotation_z(0.7), Vec3::new(0.3, -2.0, 1.0));
        let moved: Vec<Vec3> = scalp.mesh.positions.iter().map(|p| motion.transform_point3(*p)).collect();
        let frames = frames_at(&binding, &[], &moved, 1.0, true, &Mat4::IDENTITY);
        for (frame, root) in frames.iter().zip(roots) {
            let probe = root + Vec3::new(0.1, 0.3, -0.05);
            let error = frame.transform_point3(probe).distance(motion.transform_point3(probe));
            assert!(error < 1e-5, "a rigidly moved scalp moves its hair rigidly: off by {error}");
        }
    }

    /// Collapsed triangles, far roots and broken skins are named.
    #[test]
    fn bad_scalps_are_refused() {
        let mut scalp = Scalp::new(square());
        let far = ScalpBinding::new(&scalp, &[Vec3::new(0.5, 0.5, -0.5)]).expect_err("a root 0.5 m off");
        assert!(far.to_string().contains("strand 0"), "{far}");
        scalp.skin = vec![VertexSkin { joints: [0; 4], weights: [0.5, 0.0, 0.0, 0.0] }; 4];
        let weights = ScalpBinding::new(&scalp, &[Vec3::new(0.5, 0.0, -0.2)]).expect_err("weights summing to 0.5");
        assert!(weights.to_string().contains("vertex 0"), "{weights}");
        scalp.skin = vec![VertexSkin { joints: [0; 4], weights: [1.0, 0.0, 0.0, 0.0] }; 4];
        let nan = scalp.skin(&[Mat4::from_translation(Vec3::NAN)]).expect_err("a NaN bone");
        assert!(nan.to_string().contains("bone 0"), "{nan}");
        let missing = scalp.skin(&[]).expect_err("no bones");
        assert!(missing.to_string().contains("scalp joint"), "{missing}");
    }

    impl ScalpBinding {
        /// The largest difference of any bind-pose frame from the identity.
        fn frames_identity_error(&self, positions: &[Vec3]) -> f32 {
            let frames = frames_at(self, &[], positions, 1.0, true, &Mat4::ZERO);
            let cols = |m: &Mat4| m.to_cols_array();
            frames
                .iter()
                .flat_map(|f| cols(f).into_iter().zip(cols(&Mat4::IDENTITY)).map(|(a, b)| (a - b).abs()))
                .fold(0.0, f32::max)
        }
    }
}
