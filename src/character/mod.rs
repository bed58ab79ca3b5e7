//! Skinned, animated characters on the host side: what the `vkhair` tool and
//! the viewer read from glTF 2.0 to put hair on a moving body.
//!
//! A [`Character`] is one skinned mesh (its triangle primitives merged, four
//! joint weights per vertex), the skin's joints in a node hierarchy, and the
//! file's animations ([`skeleton`]). [`Character::pose`] samples an animation
//! at a time; [`Character::skin`] deforms the mesh on the CPU (linear blend
//! skinning, as the glTF specification defines it: joint world transform ·
//! inverse bind matrix, weighted); [`Character::head_joint`] finds the head by
//! the weights of the mesh's top; [`Character::fit_capsules`] fits a capsule
//! per bone to the vertices it dominates, so that colliders follow the body
//! without hand placement. A [`HairRig`] puts hair on one: the animation
//! played, the head joint, the capsules within the hair's reach, the scalp the
//! roots are bound to and the bones that skin it, key hairs grown on the head.
//!
//! A host with its own characters does not need this module: it hands vkhair
//! the head's transform and the colliders it keeps itself.

mod fit;
mod gltf_read;
mod hair;
pub mod skeleton;
#[cfg(test)]
mod tests;

use std::path::Path;

use glam::{Mat4, Vec3};

pub use fit::{BoneCapsule, MIN_CAPSULE_VERTICES};
pub use gltf_read::{MAX_CHARACTER_VERTICES, MAX_GLTF_BYTES, MAX_GLTF_JSON_OBJECTS};
pub use hair::{
    HairRig, BODY_REACH, FACE_FACING, FACE_HALF_WIDTH, NO_ROOT_FACING, RIG_CAPSULES, RIG_HAIR_LENGTH, RIG_KEY_HAIRS,
};
use skeleton::Skeleton;

use crate::error::{Error, FileFormat, Result};
use crate::groom::mesh::TriMesh;

/// Vertices of the top of a character (by height along its up axis) whose
/// dominant joints decide which joint is the head: the top 8 %.
pub const HEAD_TOP_FRACTION: f32 = 0.08;

/// Vertices of the bottom of a character (the feet) that say which way it
/// faces: the lowest 5 %.
pub const FEET_FRACTION: f32 = 0.05;

/// A skinned, animated character (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Character {
    /// The node hierarchy, skin and animations.
    pub skeleton: Skeleton,
    /// Vertex positions as the file gives them (the skin's bind space).
    pub positions: Vec<Vec3>,
    /// Per vertex: four skin joint indices and their weights (normalised).
    pub weights: Vec<([u16; 4], [f32; 4])>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// A character's pose at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Every node's world transform.
    pub nodes: Vec<Mat4>,
    /// Every skin joint's skinning matrix (world transform · inverse bind).
    pub skin: Vec<Mat4>,
}

impl Character {
    /// A character from its parts, checked: weights name joints that exist,
    /// triangles vertices that exist, every position finite.
    pub fn new(
        skeleton: Skeleton,
        positions: Vec<Vec3>,
        weights: Vec<([u16; 4], [f32; 4])>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self> {
        let bad = |reason: String| Error::Malformed { format: FileFormat::Gltf, reason };
        if weights.len() != positions.len() {
            return Err(bad(format!("{} vertices, {} weight sets", positions.len(), weights.len())));
        }
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(bad("a vertex position is not finite".into()));
        }
        let joints = skeleton.joints.len();
        if joints == 0 {
            return Err(bad("the skin has no joints".into()));
        }
        if weights.iter().any(|(j, w)| j.iter().zip(w).any(|(&j, &w)| usize::from(j) >= joints && w > 0.0)) {
            return Err(bad(format!("a vertex is weighted to a joint past the skin's {joints}")));
        }
        if let Some(v) = weights.iter().position(|(_, w)| {
            let sum: f32 = w.iter().sum();
            !(sum.is_finite() && sum > 0.0 && w.iter().all(|&x| x >= 0.0))
        }) {
            return Err(bad(format!("vertex {v}'s weights are not positive with a positive sum")));
        }
        if triangles.is_empty() || triangles.iter().flatten().any(|&i| i as usize >= positions.len()) {
            return Err(bad("no triangles, or a triangle naming a vertex that does not exist".into()));
        }
        Ok(Character { skeleton, positions, weights, triangles })
    }

    /// Reads a `.glb`, or a `.gltf` with its buffers in files beside it (at most
    /// [`MAX_GLTF_BYTES`] each, [`MAX_CHARACTER_VERTICES`] vertices; textures,
    /// materials and morph targets are not read, data URIs refused); errors name the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        gltf_read::load(path.as_ref())
    }

    /// Parses a glTF document in memory (a `.glb`, or a `.gltf` whose buffers
    /// are all in a GLB's binary chunk).
    pub fn parse(bytes: &[u8]) -> Result<Self> {
        gltf_read::parse(bytes, None)
    }

    /// The pose of `animation` (none: the rest pose) at `time` seconds, looping.
    pub fn pose(&self, animation: Option<usize>, time: f32) -> Pose {
        let nodes = self.skeleton.node_transforms(animation, time, true);
        let skin = self.skeleton.skinning(&nodes);
        Pose { nodes, skin }
    }

    /// The bind pose: the mesh as the file gives it, every joint where its
    /// inverse bind matrix says it was bound (other nodes at rest). Characters
    /// are usually bound standing (a T or A pose), whatever their nodes' rest
    /// transforms say, so the fitting and the searches below use this pose.
    pub fn bind_pose(&self) -> Pose {
        let mut nodes = self.skeleton.node_transforms(None, 0.0, false);
        for (&n, ib) in self.skeleton.joints.iter().zip(&self.skeleton.inverse_bind) {
            nodes[n] = ib.inverse();
        }
        let skin = vec![Mat4::IDENTITY; self.skeleton.joints.len()];
        Pose { nodes, skin }
    }

    /// The vertices deformed by `pose` (linear blend skinning).
    pub fn skin(&self, pose: &Pose) -> Vec<Vec3> {
        self.positions
            .iter()
            .zip(&self.weights)
            .map(|(p, (j, w))| {
                let mut sum = Vec3::ZERO;
                for k in 0..4 {
                    if w[k] > 0.0 {
                        sum += w[k] * pose.skin[usize::from(j[k])].transform_point3(*p);
                    }
                }
                sum
            })
            .collect()
    }

    /// The mesh deformed by `pose`.
    pub fn mesh(&self, pose: &Pose) -> Result<TriMesh> {
        TriMesh::new(self.skin(pose), self.triangles.clone())
    }

    /// The joint (index into the skin's joints) with the largest weight on a vertex.
    pub fn dominant_joint(&self, vertex: usize) -> usize {
        let (j, w) = self.weights[vertex];
        let k = (0..4).fold(0, |best, k| if w[k] > w[best] { k } else { best });
        usize::from(j[k])
    }

    /// The up axis of the bind pose: +Y (glTF's) unless the character is
    /// clearly longer along Z (a Z-up export), then +Z.
    pub fn up_axis(&self) -> Vec3 {
        let (lo, hi) = self
            .positions
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(l, h), p| (l.min(*p), h.max(*p)));
        let extent = hi - lo;
        if extent.z > 1.5 * extent.y && extent.z >= extent.x {
            Vec3::Z
        } else {
            Vec3::Y
        }
    }

    /// The direction the character faces in the bind pose, horizontal: where
    /// its feet point (the lowest [`FEET_FRACTION`] of the vertices lie, on
    /// average, ahead of the joints that move them); when the feet say
    /// nothing, glTF's +Z (−Y for a Z-up character).
    pub fn forward(&self) -> Vec3 {
        let (up, heights, lo, hi) = self.heights();
        let rest = self.bind_pose();
        let cut = lo + FEET_FRACTION * (hi - lo);
        let mut ahead = Vec3::ZERO;
        for (v, p) in self.positions.iter().enumerate().filter(|(v, _)| heights[*v] <= cut) {
            ahead += *p - self.joint_transform(&rest, self.dominant_joint(v)).transform_point3(Vec3::ZERO);
        }
        let flat = ahead - up * ahead.dot(up);
        let fallback = if up == Vec3::Z { Vec3::NEG_Y } else { Vec3::Z };
        flat.try_normalize().unwrap_or(fallback)
    }

    /// The up axis, every bind-pose vertex's height along it, and the lowest
    /// and highest.
    fn heights(&self) -> (Vec3, Vec<f32>, f32, f32) {
        let up = self.up_axis();
        let heights: Vec<f32> = self.positions.iter().map(|p| p.dot(up)).collect();
        let (lo, hi) = heights.iter().fold((f32::MAX, f32::MIN), |(l, h), &y| (l.min(y), h.max(y)));
        (up, heights, lo, hi)
    }

    /// The skin joint named `name`.
    pub fn joint_named(&self, name: &str) -> Result<usize> {
        self.skeleton.joints.iter().position(|&n| self.skeleton.nodes[n].name == name).ok_or_else(|| {
            let names: Vec<&str> = self.skeleton.joints.iter().map(|&n| self.skeleton.nodes[n].name.as_str()).collect();
            Error::param("head joint", name, format!("a joint of the skin: {names:?}"))
        })
    }

    /// The head: the joint that dominates the most vertices of the top
    /// [`HEAD_TOP_FRACTION`] of the bind pose along [`Character::up_axis`].
    pub fn head_joint(&self) -> usize {
        let (_, heights, lo, hi) = self.heights();
        let cut = hi - HEAD_TOP_FRACTION * (hi - lo);
        let mut votes = vec![0usize; self.skeleton.joints.len()];
        for (v, &y) in heights.iter().enumerate() {
            if y >= cut {
                votes[self.dominant_joint(v)] += 1;
            }
        }
        (0..votes.len()).fold(0, |best, j| if votes[j] > votes[best] { j } else { best })
    }

    /// The vertices `joint` dominates.
    pub fn region(&self, joint: usize) -> Vec<usize> {
        (0..self.positions.len()).filter(|&v| self.dominant_joint(v) == joint).collect()
    }

    /// The triangles all of whose vertices `joint` dominates (its region:
    /// the head's is the scalp and face), deformed by `pose`, as their own mesh.
    pub fn region_mesh(&self, joint: usize, pose: &Pose) -> Result<TriMesh> {
        let (mesh, _) = self.sub_mesh(|v| self.dominant_joint(v) == joint, &self.skin(pose))?.ok_or_else(|| {
            let name = &self.skeleton.nodes[self.skeleton.joints[joint]].name;
            Error::incompatible("character", format!("joint {joint} ({name:?}) dominates no whole triangle"))
        })?;
        Ok(mesh)
    }

    /// The triangles all of whose vertices `keep` takes, with their vertices at
    /// `positions` (one per vertex of the character), as their own mesh, and
    /// each of its vertices' index in the character; `None` when no triangle
    /// is kept.
    pub(crate) fn sub_mesh(
        &self,
        keep: impl Fn(usize) -> bool,
        positions: &[Vec3],
    ) -> Result<Option<(TriMesh, Vec<usize>)>> {
        let kept: Vec<bool> = (0..self.positions.len()).map(keep).collect();
        let whole = self.triangles.iter().copied().filter(|t| t.iter().all(|&v| kept[v as usize]));
        crate::groom::mesh::compact(positions, whole)
    }

    /// Skin joint `joint`'s frame in `pose` as a rigid transform (its scale
    /// dropped): what the simulation takes as the head.
    pub fn rigid_frame(&self, pose: &Pose, joint: usize) -> crate::sim::RigidTransform {
        let (_, rotation, translation) = self.joint_transform(pose, joint).to_scale_rotation_translation();
        crate::sim::RigidTransform { rotation: rotation.normalize(), translation }
    }

    /// The world transform of skin joint `joint` in `pose`.
    pub fn joint_transform(&self, pose: &Pose, joint: usize) -> Mat4 {
        pose.nodes[self.skeleton.joints[joint]]
    }
}
