//! What a host changes on a running scheduler's simulation, as one value
//! every backend takes the same way: applied to the simulation in place
//! (one queue, async compute) or sent to the second device's worker, which
//! applies it before its next job. A new kind of change is a variant here
//! and its line in [`SimUpdate::apply`]; the scheduler's setters check their
//! arguments and forward one of these (`control.rs`).

use glam::Mat4;

use crate::error::Result;
use crate::groom::mesh::TriMesh;
use crate::sim::scalp::{Scalp, VertexSkin};
use crate::sim::{Collider, HairSim, MeshColliderParams, RigidTransform, SimParams};

/// A change to the simulation, applied before its next step.
pub(crate) enum SimUpdate {
    Params(Box<SimParams>),
    ScalpBind(Box<(Scalp, Vec<Mat4>)>),
    ScalpBones(Vec<Mat4>),
    Colliders(Vec<Collider>),
    Body(Vec<Collider>),
    Teleport(RigidTransform),
    Reset,
    Mesh(Option<Box<(TriMesh, MeshColliderParams)>>),
    SkinnedMesh(Box<(TriMesh, Vec<VertexSkin>, Vec<Mat4>, MeshColliderParams)>),
    MeshBones(Vec<Mat4>),
    /// Key hairs simulated (checked by the sender).
    Simulated(usize),
}

impl SimUpdate {
    /// Applies the change to `sim`.
    pub(crate) fn apply(self, sim: &mut HairSim) -> Result<()> {
        match self {
            SimUpdate::Params(p) => sim.set_params(&p),
            SimUpdate::Colliders(c) => sim.set_colliders(&c),
            SimUpdate::Body(c) => sim.set_body_colliders(&c),
            SimUpdate::Teleport(to) => sim.teleport(&to),
            SimUpdate::Reset => {
                sim.reset();
                Ok(())
            }
            SimUpdate::Simulated(count) => sim.set_simulated_hairs(count),
            SimUpdate::ScalpBind(bound) => sim.bind_scalp_bones(&bound.0, &bound.1),
            SimUpdate::ScalpBones(bones) => sim.set_scalp_bones(&bones),
            SimUpdate::Mesh(m) => match m.as_deref() {
                Some((mesh, params)) => sim.set_mesh(Some(mesh), params),
                None => sim.set_mesh(None, &MeshColliderParams::default()),
            },
            SimUpdate::SkinnedMesh(m) => sim.set_skinned_mesh(&m.0, &m.1, &m.2, &m.3),
            SimUpdate::MeshBones(bones) => sim.set_mesh_bones(&bones),
        }
    }
}
