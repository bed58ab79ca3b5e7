//! What a host changes on a running scheduler: parameters, colliders, the mesh
//! collider, a scalp skinned from bone matrices, and stopping the simulation side.

use super::update::SimUpdate;
use super::{Backend, FrameScheduler};
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;
use crate::sim::mesh_skin::{bone_rows, check_skinned};
use crate::sim::scalp::{Scalp, ScalpBinding, VertexSkin};
use crate::sim::{Collider, MeshCollider, MeshColliderParams, RigidTransform, SimParams};
use glam::Mat4;

impl FrameScheduler {
    /// Changes simulation parameters from the next step on (validated now). The
    /// volume stage's mode and resolution are fixed for the scheduler's lifetime.
    pub fn set_sim_params(&mut self, params: &SimParams) -> Result<()> {
        params.validate()?;
        let has_volume = self.mirror.layout().density > 0;
        let grid = self.mirror.meta().grid.map(|g| g.dims);
        let same = (params.volume.mode == crate::sim::VolumeMode::Off) != has_volume
            && grid.is_none_or(|dims| dims == params.volume.resolution);
        if !same {
            return Err(Error::incompatible(
                "volume",
                "the volume stage's mode and resolution are fixed for a scheduler",
            ));
        }
        self.forward(SimUpdate::Params(Box::new(params.clone())))
    }

    /// Replaces the colliders (validated now) from the next step on.
    pub fn set_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        crate::sim::validate_colliders(colliders)?;
        // Checked here, so that a second device's worker never fails on it.
        crate::sim::validate_collider_total(colliders.len(), self.colliders.1)?;
        self.colliders.0 = colliders.len();
        self.forward(SimUpdate::Colliders(colliders.to_vec()))
    }

    /// The body's colliders in the world at the end of the next step (validated
    /// now; see [`crate::sim::HairSim::set_body_colliders`]).
    pub fn set_body_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        crate::sim::validate_colliders(colliders)?;
        crate::sim::validate_collider_total(self.colliders.0, colliders.len())?;
        self.colliders.1 = colliders.len();
        self.forward(SimUpdate::Body(colliders.to_vec()))
    }

    /// A cut or a respawn: the next step starts with the state moved rigidly to
    /// the head `to` (checked now; see [`crate::sim::HairSim::teleport`]).
    pub fn teleport(&mut self, to: &RigidTransform) -> Result<()> {
        to.validate()?;
        self.forward(SimUpdate::Teleport(*to))
    }

    /// The next step starts from the rest pose (see [`crate::sim::HairSim::reset`]).
    pub fn reset(&mut self) -> Result<()> {
        self.forward(SimUpdate::Reset)
    }

    /// Simulates only `count` key hairs from the next step on, the others
    /// following them (checked now: 1 up to the key hairs; see
    /// [`crate::sim::HairSim::set_simulated_hairs`]).
    pub fn set_simulated_hairs(&mut self, count: usize) -> Result<()> {
        let (strands, _) = self.key_hairs().size();
        if !(1..=strands).contains(&count) {
            return Err(Error::param("simulated key hairs", count, format!("1..={strands} (the key hairs)")));
        }
        self.forward(SimUpdate::Simulated(count))
    }

    /// Sets the mesh collider of `mesh` (head frame, the groom's units; `None`
    /// removes it), built on the simulation's device (see
    /// [`crate::sim::HairSim::set_mesh_collider`]). The mesh and parameters are checked now; on
    /// the SECOND DEVICE the build happens on the worker before its next step.
    pub fn set_mesh_collider(&mut self, mesh: Option<&TriMesh>, params: &MeshColliderParams) -> Result<()> {
        if let Some(m) = mesh {
            MeshCollider::validate(m, params)?;
        }
        self.forward(SimUpdate::Mesh(mesh.map(|m| Box::new((m.clone(), params.clone())))))?;
        self.mesh_joints = None;
        Ok(())
    }

    /// A mesh collider that follows bones (see
    /// [`crate::sim::HairSim::set_skinned_mesh`]) with its bones at the end of
    /// the next frame's steps; the mesh, its skin and the bones checked now.
    pub fn set_skinned_mesh_collider(
        &mut self,
        mesh: &TriMesh,
        skin: &[VertexSkin],
        bones: &[Mat4],
        params: &MeshColliderParams,
    ) -> Result<()> {
        MeshCollider::validate(mesh, params)?;
        let joints = check_skinned(mesh, skin, bones)?;
        let update = (mesh.clone(), skin.to_vec(), bones.to_vec(), params.clone());
        self.forward(SimUpdate::SkinnedMesh(Box::new(update)))?;
        self.mesh_joints = Some(joints);
        Ok(())
    }

    /// A skinned mesh collider's bones at the end of the next frame's steps
    /// (see [`crate::sim::HairSim::set_mesh_bones`]; checked now), taken per
    /// frame as the body's colliders are.
    pub fn set_mesh_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let Some(joints) = &self.mesh_joints else {
            return Err(Error::incompatible("mesh collider bones", "no skinned mesh collider is set"));
        };
        bone_rows(joints, bones)?;
        self.forward(SimUpdate::MeshBones(bones.to_vec()))
    }

    /// Binds the key hairs' roots to `scalp`, skinned by vkhair from `bones`
    /// (see [`crate::sim::HairSim::bind_scalp_bones`]), in every mode; the
    /// roots, weights and bones are checked now, so that a second device's
    /// worker never fails on them.
    pub fn bind_scalp_bones(&mut self, scalp: &Scalp, bones: &[Mat4]) -> Result<()> {
        ScalpBinding::new(scalp, &self.key_hairs().rest.rest_roots())?;
        if scalp.skin.is_empty() {
            return Err(Error::incompatible("scalp bones", "the scalp has no vertex bones (Scalp::skin)"));
        }
        scalp.skin(bones)?;
        self.forward(SimUpdate::ScalpBind(Box::new((scalp.clone(), bones.to_vec()))))?;
        self.scalp = Some(scalp.clone());
        Ok(())
    }

    /// The bones at the end of the next frame's steps (see
    /// [`crate::sim::HairSim::set_scalp_bones`]; checked now). Like the body's
    /// colliders they are taken per frame: with several steps a frame the
    /// first step's sub-steps carry the scalp the whole frame's way.
    pub fn set_scalp_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let Some(scalp) = &self.scalp else {
            return Err(Error::incompatible("scalp bones", "no scalp skinned from bone matrices is bound"));
        };
        scalp.skin(bones)?;
        self.forward(SimUpdate::ScalpBones(bones.to_vec()))
    }

    /// Applies `update` to the simulation in place, or sends it to the
    /// second device's worker, which applies it before its next step.
    fn forward(&mut self, update: SimUpdate) -> Result<()> {
        match &mut self.backend {
            Backend::Local { sim, .. } => update.apply(sim),
            Backend::Async { sim, .. } => update.apply(&mut sim.sim),
            Backend::Remote { worker, .. } => worker.update(update),
            Backend::Stopped(why) => Err(Error::SimulationStopped(why.clone())),
        }
    }

    /// Stops and drops the simulation side now (its thread, its own submissions
    /// waited for, its buffers; the mirror stays for frames still in flight). Later
    /// frames get [`Error::SimulationStopped`].
    pub fn stop_simulation(&mut self) {
        let old =
            std::mem::replace(&mut self.backend, Backend::Stopped("the simulation was stopped by the host".into()));
        drop(old);
        self.sim_device = None;
    }
}
