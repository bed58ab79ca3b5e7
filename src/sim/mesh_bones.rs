//! The skinned mesh collider's entry points (see `mesh_skin.rs` for how a
//! field follows bones): building one, and handing a simulation its bones.

use glam::Mat4;

use super::mesh_collider::{MeshCollider, MeshColliderParams};
use super::mesh_skin::{check_skinned, skin_joints};
use super::scalp::VertexSkin;
use super::HairSim;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;

impl MeshCollider {
    /// A mesh collider of `mesh` (bind pose, head frame, the groom's units)
    /// that follows the bones skinning it (`skin`, one entry per vertex; see
    /// the module docs): the field built on the GPU as [`MeshCollider::new`]
    /// builds it, each grid point's bones from its closest triangle. Set it
    /// with [`HairSim::set_mesh_collider`], then hand its bones with
    /// [`HairSim::set_mesh_bones`] before each step. Refuses a skin of
    /// another length, invalid weights, and more than [`super::MESH_MAX_BONES`]
    /// bones among the vertices' two heaviest. This submits and waits.
    pub fn skinned(ctx: &GpuContext, mesh: &TriMesh, skin: &[VertexSkin], params: &MeshColliderParams) -> Result<Self> {
        let joints = skin_joints(mesh, skin)?;
        Self::build_skinned(&ctx.device, mesh, skin, joints, params)
    }
}

impl HairSim {
    /// Builds a [`MeshCollider::skinned`] of `mesh` and `skin` on this
    /// simulation's device, sets it ([`HairSim::set_mesh_collider`]) and hands
    /// it `bones` ([`HairSim::set_mesh_bones`]).
    pub fn set_skinned_mesh(
        &mut self,
        mesh: &TriMesh,
        skin: &[VertexSkin],
        bones: &[Mat4],
        params: &MeshColliderParams,
    ) -> Result<()> {
        let joints = check_skinned(mesh, skin, bones)?;
        let collider = MeshCollider::build_skinned(self.device(), mesh, skin, joints, params)?;
        self.set_mesh_collider(Some(collider))?;
        self.set_mesh_bones(bones)
    }

    /// A skinned mesh collider's bones at the end of the next step, indexed as
    /// the collider's skin names them (each maps the bind pose, head frame,
    /// to the world): the sub-steps blend each bone's matrix linearly from
    /// where it was at the end of the previous step (from these, for the first
    /// step after the collider is set and after a teleport). Call it before
    /// every step while a skinned collider is set; the bones keep their place
    /// when not called again. Refuses a missing or non-finite bone, and a
    /// simulation without a skinned collider.
    pub fn set_mesh_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let Some(skin) = self.mesh.as_ref().and_then(MeshCollider::skin) else {
            return Err(Error::incompatible("mesh collider bones", "no skinned mesh collider is set"));
        };
        let rows = skin.rows(bones)?;
        self.planner.set_mesh_bones(rows)
    }
}
