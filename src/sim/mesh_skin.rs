//! A mesh collider that follows bones: a character's body near the head
//! (head, neck, shoulders, chest) as one field in the bind pose, each point of
//! it carried by the bones that skin the mesh there.
//!
//! The rigid mesh collider moves its whole field with the head; a body's
//! shoulders do not move with the head, and even the skinned scalp strays
//! from the head's rigid motion where neck bones share its vertices. A skinned
//! field keeps, per grid point, the two heaviest bones (and the first one's
//! weight) of the vertex nearest the point on its closest triangle; each
//! sub-step, a particle is taken to the bind pose by the blend of its grid
//! point's bones (looked up where the head places it, then again where that
//! blend takes it), measured and pushed out there, and moved back by the same
//! blend: linear blend skinning inverted per point, exact at the skin's own
//! vertices. The host hands the bones' matrices before each step
//! ([`super::HairSim::set_mesh_bones`]); the sub-steps blend them linearly from the
//! previous step's.

use glam::{Mat4, Vec4};

use super::scalp::{check_weights, VertexSkin};
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;
use crate::groom::sdf::MeshSdf;
use crate::limits::SIM_MESH_MAX_BONES;

/// Most bones a skinned mesh collider follows.
pub const MESH_MAX_BONES: usize = SIM_MESH_MAX_BONES as usize;

/// The bones of a skinned field's grid points (see the module docs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshSkin {
    /// The host's bone index (into the matrices of [`super::HairSim::set_mesh_bones`])
    /// of each bone slot: the two heaviest of every vertex, ascending.
    pub joints: Vec<u32>,
    /// Per grid point (x fastest): bone slot 0 in bits 0–7, slot 1 in 8–15,
    /// the first one's weight in 16–31 as a fraction of 65,535.
    pub words: Vec<u32>,
}

impl MeshSkin {
    /// The bones of `sdf`'s grid points for `mesh` (the mesh the field was
    /// built from) skinned by `skin` (one entry per vertex), each grid point's
    /// closest triangle found as the field's build finds it (on the CPU here).
    pub fn fit(sdf: &MeshSdf, mesh: &TriMesh, skin: &[VertexSkin]) -> Result<MeshSkin> {
        let joints = skin_joints(mesh, skin)?;
        Ok(Self::from_closest(sdf, mesh, skin, joints, &sdf.closest_triangles(mesh)))
    }

    /// As [`MeshSkin::fit`], with the skin checked (`joints`, from
    /// [`skin_joints`]) and each grid point's closest triangle given.
    pub(crate) fn from_closest(
        sdf: &MeshSdf,
        mesh: &TriMesh,
        skin: &[VertexSkin],
        joints: Vec<u32>,
        closest: &[u32],
    ) -> Self {
        let slot = |j: u32| joints.partition_point(|&x| x < j) as u32;
        let words = closest
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let x = sdf.point(sdf.grid_point(k));
                let tri = mesh.triangles.get(t as usize).copied().unwrap_or(mesh.triangles[0]);
                let d = |v: u32| mesh.positions[v as usize].distance_squared(x);
                let nearest = tri.into_iter().fold(tri[0], |best, v| if d(v) < d(best) { v } else { best });
                let (a, b, w) = heaviest_two(&skin[nearest as usize]);
                slot(a) | (slot(b) << 8) | (((w * 65535.0).round() as u32) << 16)
            })
            .collect();
        MeshSkin { joints, words }
    }

    /// Refuses words of another count than `points` grid points, more than
    /// [`MESH_MAX_BONES`] bones, or a word naming a slot past them.
    pub(crate) fn check(&self, points: usize) -> Result<()> {
        if self.words.len() != points {
            return Err(Error::incompatible(
                "mesh collider bones",
                format!("{} grid points have bones, the field has {points}", self.words.len()),
            ));
        }
        if self.joints.len() > MESH_MAX_BONES {
            return Err(Error::param("mesh collider bones", self.joints.len(), format!("at most {MESH_MAX_BONES}")));
        }
        let slots = self.joints.len() as u32;
        if let Some(k) = self.words.iter().position(|w| (w & 0xFF) >= slots || ((w >> 8) & 0xFF) >= slots) {
            return Err(Error::param(
                "mesh collider bones",
                format!("grid point {k}'s word {:#010x}", self.words[k]),
                format!("slots below the {slots} bones"),
            ));
        }
        Ok(())
    }

    /// The rows of each slot's bone of `bones` (see [`bone_rows`]).
    pub(crate) fn rows(&self, bones: &[Mat4]) -> Result<Vec<[Vec4; 3]>> {
        bone_rows(&self.joints, bones)
    }
}

/// The rows of each of `joints`' bones among `bones` (indexed by the host's
/// bone index: bind pose, head frame → world). Refuses a missing or
/// non-finite bone, naming it.
pub(crate) fn bone_rows(joints: &[u32], bones: &[Mat4]) -> Result<Vec<[Vec4; 3]>> {
    joints
        .iter()
        .map(|&j| {
            let m = bones.get(j as usize).ok_or_else(|| {
                Error::param("mesh collider bone", j, format!("below the {} bone matrices given", bones.len()))
            })?;
            if !m.is_finite() {
                return Err(Error::param("mesh collider bone matrix", format!("bone {j}"), "finite"));
            }
            Ok([m.row(0), m.row(1), m.row(2)])
        })
        .collect()
}

/// Checks a skinned collider's mesh skin and bones as building and setting it
/// do (see [`skin_joints`] and [`bone_rows`]); returns the bones it follows.
pub(crate) fn check_skinned(mesh: &TriMesh, skin: &[VertexSkin], bones: &[Mat4]) -> Result<Vec<u32>> {
    let joints = skin_joints(mesh, skin)?;
    bone_rows(&joints, bones)?;
    Ok(joints)
}

/// The bones a skinned field of `mesh` follows: every vertex's two heaviest
/// (host indices, ascending). Refuses a skin of another length, invalid
/// weights and more than [`MESH_MAX_BONES`] bones.
pub(crate) fn skin_joints(mesh: &TriMesh, skin: &[VertexSkin]) -> Result<Vec<u32>> {
    if skin.len() != mesh.positions.len() {
        return Err(Error::incompatible(
            "mesh collider bones",
            format!("{} vertices have bones, the mesh has {}", skin.len(), mesh.positions.len()),
        ));
    }
    check_weights("mesh collider bone weights", skin)?;
    let mut joints: Vec<u32> = skin
        .iter()
        .flat_map(|s| {
            let (a, b, _) = heaviest_two(s);
            [a, b]
        })
        .collect();
    joints.sort_unstable();
    joints.dedup();
    if joints.len() > MESH_MAX_BONES {
        return Err(Error::param(
            "mesh collider bones",
            format!("{} bones (each vertex's two heaviest)", joints.len()),
            format!("at most {MESH_MAX_BONES}: a body region nearer the head"),
        ));
    }
    Ok(joints)
}

/// A vertex's two heaviest bones (the lower slot first on ties) and the
/// first's share of their weight; one bone twice when only one weighs.
fn heaviest_two(s: &VertexSkin) -> (u32, u32, f32) {
    let mut order: Vec<usize> = (0..s.weights.len()).collect();
    order.sort_by(|&a, &b| s.weights[b].total_cmp(&s.weights[a]).then(a.cmp(&b)));
    let (a, b) = (order[0], order[1]);
    let (wa, wb) = (s.weights[a], s.weights[b]);
    if wb <= 0.0 {
        return (s.joints[a], s.joints[a], 1.0);
    }
    (s.joints[a], s.joints[b], wa / (wa + wb))
}

/// A skinned field's bones over a step: where they were at the end of the
/// previous step and where they are at the end of the next.
#[derive(Debug, Clone, Default)]
pub(crate) struct BoneTrack {
    pub before: Vec<[Vec4; 3]>,
    pub now: Vec<[Vec4; 3]>,
}

impl BoneTrack {
    /// Each bone's rows `t` of the way through the step.
    fn at(&self, t: f32) -> impl Iterator<Item = [Vec4; 3]> + '_ {
        let from = if self.before.len() == self.now.len() { &self.before } else { &self.now };
        from.iter().zip(&self.now).map(move |(a, b)| [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t))
    }

    /// Sub-step `k` of `n`'s bones: per bone its rows at the end of the
    /// sub-step, then at its start (`mesh_bones` of `glsl/include/mesh_sdf.glsl`).
    pub(crate) fn substep(&self, k: u32, n: u32) -> Vec<[Vec4; 6]> {
        let end = self.at((k + 1) as f32 / n as f32);
        let start = self.at(k as f32 / n as f32);
        end.zip(start).map(|(e, s)| [e[0], e[1], e[2], s[0], s[1], s[2]]).collect()
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec3, Vec4};

    use super::*;
    use crate::codes::sim_flags;
    use crate::groom::Groom;
    use crate::sim::mesh_collider::MeshGrid;
    use crate::sim::planner::SubstepPlanner;
    use crate::sim::volume::grid::GridLayout;
    use crate::sim::{RigidTransform, SimParams, SimState, VolumeParams};

    /// A vertex's two heaviest bones, the lower slot first on ties; one bone
    /// alone counts twice.
    #[test]
    fn the_two_heaviest_bones_are_kept() {
        let skin = |joints, weights| VertexSkin { joints, weights };
        assert_eq!(heaviest_two(&skin([4, 7, 9, 1], [0.1, 0.6, 0.3, 0.0])), (7, 9, 0.6 / 0.9));
        assert_eq!(heaviest_two(&skin([4, 7, 9, 1], [0.4, 0.2, 0.4, 0.0])), (4, 9, 0.5));
        assert_eq!(heaviest_two(&skin([3, 5, 0, 0], [1.0, 0.0, 0.0, 0.0])), (3, 3, 1.0));
    }

    /// The sub-steps blend each bone's rows linearly over the step, end then
    /// start; the first step (no rows before) holds the bones where they are.
    #[test]
    fn the_sub_steps_blend_the_bones_over_the_step() {
        let rows = |x: f32| [Vec4::splat(x), Vec4::splat(2.0 * x), Vec4::splat(3.0 * x)];
        let first = BoneTrack { before: Vec::new(), now: vec![rows(4.0)] };
        let [a, b, c] = rows(4.0);
        assert_eq!(first.substep(0, 2), vec![[a, b, c, a, b, c]]);
        let track = BoneTrack { before: vec![rows(0.0)], now: vec![rows(4.0)] };
        let [e0, e1, e2, s0, s1, s2] = track.substep(1, 4)[0];
        assert_eq!([e0, e1, e2], rows(2.0));
        assert_eq!([s0, s1, s2], rows(1.0));
    }

    /// A skinned field's sub-steps carry `SIM_MESH_SKIN` and its bones, need
    /// the bones before a step, and the volume stage marks no solid cells by
    /// it (a rigid field's it does).
    #[test]
    fn a_skinned_field_switches_its_flag_and_leaves_the_volume_solid_free() {
        let params = SimParams { volume: VolumeParams::flip([8, 8, 8]), ..SimParams::default() };
        let head = RigidTransform::default();
        let groom = Groom::from_strands(&[vec![Vec3::ZERO, Vec3::Y * 0.1, Vec3::Y * 0.2]]).expect("groom");
        let state = SimState::from_groom(&groom, &params, &head).expect("state");
        let grid = GridLayout::new(&params.volume, &state).expect("grid");
        let mut planner = SubstepPlanner::new(&params, &head, state.rest_roots(), state.points, 32).expect("planner");
        planner.mesh = Some(MeshGrid { origin: Vec3::splat(-1.0), cell: 0.1, dims: [21, 21, 21] });
        let rigid = planner.next(&head).expect("rigid step");
        let sub = &rigid.substeps[0];
        assert_eq!(sub.params.flags & (sim_flags::MESH | sim_flags::MESH_SKIN), sim_flags::MESH);
        assert!(sub.bones.is_empty());
        assert_eq!(sub.volume_params(&grid, &params.volume, 0).mesh_solid, 1);
        planner.mesh_bones = Some(BoneTrack::default());
        let err = planner.next(&head).map(|_| ()).expect_err("no bones yet").to_string();
        assert!(err.contains("needs its bones"), "{err}");
        planner.set_mesh_bones(vec![[Vec4::X, Vec4::Y, Vec4::Z]]).expect("bones");
        let skinned = planner.next(&head).expect("skinned step");
        let sub = &skinned.substeps[0];
        assert_ne!(sub.params.flags & sim_flags::MESH_SKIN, 0);
        assert_eq!(sub.bones.len(), 1);
        assert_eq!(sub.volume_params(&grid, &params.volume, 0).mesh_solid, 0);
    }
}
