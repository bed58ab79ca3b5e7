//! The CPU reference simulation.

use super::lod::SimLod;
use super::mesh_skin::MeshSkin;
use super::packing::ScalpLanes;
use super::planner::SubstepPlanner;
use super::scalp::{check_vertices, CpuScalp, Scalp, ScalpBinding};
use super::{reference, volume, Collider, RigidTransform, SimParams, SimState, VolumeGrid, VolumeMode, MAX_SIM_POINTS};
use crate::error::{Error, Result};
use crate::groom::sdf::MeshSdf;
use crate::groom::Groom;
use glam::{Mat4, Vec3};

/// How far one step of [`HairSim`](super::HairSim) and one of [`CpuHairSim`] from
/// the same state may end apart, measured by [`SimState::step_difference`],
/// meters: 10 µm. Without the volume stage and with density friction the two run
/// the same f32 operations in the same order (bit for bit on lavapipe); FLIP's
/// pressure solves differ (the GPU's Jacobi or multigrid PCG in f32, the
/// reference's MIC(0) PCG in f64), each to its relative residual. Over many steps
/// FLIP trajectories drift apart as any chaotic system's do.
pub const REFERENCE_STEP_TOLERANCE_M: f32 = 1e-5;

/// The CPU reference simulation: the same algorithm as [`HairSim`](super::HairSim), one particle
/// at a time. Used as the oracle of the GPU tests and as the benchmark baseline.
///
/// ```
/// use glam::Vec3;
/// use vkhair::sim::{CpuHairSim, RigidTransform, SimParams};
/// use vkhair::Groom;
///
/// let strand: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.02 * i as f32, 0.0, 0.0)).collect();
/// let head = RigidTransform::default();
/// let mut cpu = CpuHairSim::new(&Groom::from_strands(&[strand])?, &SimParams::default(), &head)?;
/// cpu.step(&head)?;
/// assert!(cpu.state().positions[5].y < 0.0);
/// # Ok::<(), vkhair::Error>(())
/// ```
pub struct CpuHairSim {
    planner: SubstepPlanner,
    state: SimState,
    volume: Option<volume::grid::GridLayout>,
    /// Intermediate results of the latest volume step.
    last_volume: Option<volume::reference::VolumeSnapshot>,
    /// The mesh collider's field, when set, and a skinned one's grid points' bones.
    mesh: Option<MeshSdf>,
    mesh_skin: Option<MeshSkin>,
    /// Wall time of the volume stage in the latest step.
    volume_time: std::time::Duration,
    /// Which key hairs are simulated, and whom the others follow.
    lod: SimLod,
    /// The bound scalp, when set.
    scalp: Option<CpuScalp>,
}

impl CpuHairSim {
    /// See [`HairSim::new`](super::HairSim::new).
    pub fn new(groom: &Groom, params: &SimParams, head: &RigidTransform) -> Result<Self> {
        let state = SimState::from_groom(groom, params, head)?;
        Self::from_state(state, params, head)
    }

    /// See [`HairSim::from_state`](super::HairSim::from_state).
    pub fn from_state(state: SimState, params: &SimParams, head: &RigidTransform) -> Result<Self> {
        // The CPU runs the same constraint sets in the same order whatever the packing.
        let planner = SubstepPlanner::new(params, head, state.rest_roots(), state.points, MAX_SIM_POINTS as u32)?;
        let volume = cpu_volume_grid(params, &state)?;
        let lod = SimLod::new(&state);
        Ok(CpuHairSim {
            planner,
            state,
            volume,
            last_volume: None,
            mesh: None,
            mesh_skin: None,
            volume_time: Default::default(),
            lod,
            scalp: None,
        })
    }

    /// See [`HairSim::set_params`](super::HairSim::set_params).
    pub fn set_params(&mut self, params: &SimParams) -> Result<()> {
        params.validate()?;
        self.volume = cpu_volume_grid(params, &self.state)?;
        self.planner.set_params(params)
    }

    /// See [`HairSim::set_colliders`](super::HairSim::set_colliders).
    pub fn set_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        self.planner.set_colliders(colliders)
    }

    /// See [`HairSim::set_mesh_collider`](super::HairSim::set_mesh_collider); the
    /// field is the CPU reference's ([`MeshSdf::build`]) with the same grid.
    pub fn set_mesh_collider(&mut self, mesh: Option<MeshSdf>) -> Option<MeshSdf> {
        self.planner.mesh =
            mesh.as_ref().map(|m| super::mesh_collider::MeshGrid { origin: m.origin, cell: m.cell, dims: m.dims });
        self.planner.mesh_bones = None;
        self.mesh_skin = None;
        std::mem::replace(&mut self.mesh, mesh)
    }

    /// See [`MeshCollider::skinned`](super::MeshCollider::skinned) and
    /// [`HairSim::set_mesh_collider`](super::HairSim::set_mesh_collider): the
    /// field `mesh` following bones by `skin` (e.g. a GPU collider's
    /// [`MeshCollider::skin`](super::MeshCollider::skin), or [`MeshSkin::fit`]).
    /// Refuses a skin of another grid, or words naming bones it does not list.
    pub fn set_skinned_mesh_collider(&mut self, mesh: MeshSdf, skin: MeshSkin) -> Result<()> {
        skin.check(mesh.values.len())?;
        self.set_mesh_collider(Some(mesh));
        self.planner.mesh_bones = Some(Default::default());
        self.mesh_skin = Some(skin);
        Ok(())
    }

    /// See [`HairSim::set_mesh_bones`](super::HairSim::set_mesh_bones).
    pub fn set_mesh_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let Some(skin) = &self.mesh_skin else {
            return Err(Error::incompatible("mesh collider bones", "no skinned mesh collider is set"));
        };
        let rows = skin.rows(bones)?;
        self.planner.set_mesh_bones(rows)
    }

    /// See [`HairSim::set_body_colliders`](super::HairSim::set_body_colliders).
    pub fn set_body_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        self.planner.set_body_colliders(colliders)
    }

    /// See [`HairSim::set_strand_length`](super::HairSim::set_strand_length).
    pub fn set_strand_length(&mut self, strand: usize, length: f32) -> Result<()> {
        self.state.set_strand_length(strand, length)?;
        self.volume = cpu_volume_grid(&self.planner.params, &self.state)?;
        Ok(())
    }

    /// Binds every key hair's root to `scalp` (see [`HairSim::bind_scalp_source`](super::HairSim::bind_scalp_source)),
    /// its vertices now at `vertices` (world); the next step starts from them.
    pub fn bind_scalp(&mut self, scalp: &Scalp, vertices: &[Vec3]) -> Result<()> {
        let binding = ScalpBinding::new(scalp, &self.state.rest_roots())?;
        check_vertices(vertices, binding.vertices)?;
        self.scalp = Some(CpuScalp { binding, scalp: scalp.clone(), previous: Vec::new(), now: vertices.to_vec() });
        self.planner.scalp = Some(ScalpLanes { first: 0, stride: 3, restart: true });
        Ok(())
    }

    /// The bound scalp's vertices (world) at the end of the next step: the
    /// CPU form of the host's skinned buffer.
    pub fn set_scalp_vertices(&mut self, vertices: &[Vec3]) -> Result<()> {
        self.bound_scalp()?.set_vertices(vertices)
    }

    /// See [`HairSim::set_scalp_bones`](super::HairSim::set_scalp_bones).
    pub fn set_scalp_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let scalp = self.bound_scalp()?;
        let vertices = scalp.scalp.skin(bones)?;
        scalp.set_vertices(&vertices)
    }

    /// Roots follow the head again.
    pub fn unbind_scalp(&mut self) {
        self.scalp = None;
        self.planner.scalp = None;
    }

    fn bound_scalp(&mut self) -> Result<&mut CpuScalp> {
        self.scalp.as_mut().ok_or_else(|| Error::incompatible("scalp vertices", "no scalp is bound"))
    }

    /// Advances one step ending with the head at `head`.
    pub fn step(&mut self, head: &RigidTransform) -> Result<()> {
        let planned = self.planner.next(head)?;
        let scalp = self.scalp.as_ref();
        if let Some(start) = &planned.start {
            reference::move_state(&mut self.state, start, scalp.zip(planned.substeps.first().map(|s| &s.params)));
        }
        let inputs = planned.substeps;
        self.volume_time = std::time::Duration::ZERO;
        let active = self.lod.active();
        // The positions the followers start from: of the step without the volume
        // stage (the GPU runs its sub-steps in one dispatch, then the followers),
        // of each sub-step with it.
        let mut before = active.map(|_| self.state.positions.clone());
        for (k, sub) in inputs.iter().enumerate() {
            let words = self.mesh_skin.as_ref().map(|s| s.words.as_slice());
            let mesh = self.mesh.as_ref().map(|m| reference::MeshField::new(m).with_skin(words));
            reference::step(&mut self.state, std::slice::from_ref(sub), mesh, active, scalp);
            if let Some(before) = &mut before {
                if self.volume.is_some() {
                    let one = std::slice::from_ref(sub);
                    reference::follow(&mut self.state, before, &self.lod.guides, one, mesh, scalp);
                    before.clone_from(&self.state.positions);
                } else if k + 1 == inputs.len() {
                    reference::follow(&mut self.state, before, &self.lod.guides, &inputs, mesh, scalp);
                }
            }
            if let Some(grid) = &self.volume {
                let started = std::time::Instant::now();
                let vp = &self.planner.params.volume;
                let gpu = sub.volume_params(grid, vp, self.planner.collider_count());
                let snapshot = volume::reference::step(
                    grid,
                    &gpu,
                    &sub.colliders,
                    mesh,
                    &self.state.positions,
                    &mut self.state.velocities,
                );
                self.last_volume = Some(snapshot);
                self.volume_time += started.elapsed();
            }
        }
        if let Some(scalp) = &mut self.scalp {
            scalp.keep_corners();
        }
        Ok(())
    }

    /// See [`HairSim::teleport`](super::HairSim::teleport).
    pub fn teleport(&mut self, to: &RigidTransform) -> Result<()> {
        self.planner.teleport(to)
    }

    /// See [`HairSim::reset`](super::HairSim::reset).
    pub fn reset(&mut self) {
        self.planner.reset();
    }

    /// The grid of the volume stage, when it is on.
    pub fn volume_grid(&self) -> Option<VolumeGrid> {
        self.volume.as_ref().map(|g| g.describe(&self.planner.head.matrix()))
    }

    /// MIC(0)-PCG iterations of the latest volume step (FLIP mode).
    pub fn volume_iterations(&self) -> Option<u32> {
        self.last_volume.as_ref().map(|s| s.iterations)
    }

    /// Wall time the volume stage took in the latest step (zero when it is off):
    /// the benchmark's CPU-reference figure for the volume step alone.
    pub fn last_volume_time(&self) -> std::time::Duration {
        self.volume_time
    }

    /// The current state.
    pub fn state(&self) -> &SimState {
        &self.state
    }

    /// Replaces the positions and velocities (as [`HairSim::write_state`](super::HairSim::write_state)):
    /// the reference then continues from another simulation's state, e.g. the
    /// GPU's, to compare one step at a time. Refuses a state of another size.
    pub fn write_state(&mut self, state: &SimState) -> Result<()> {
        if (state.strands, state.points) != (self.state.strands, self.state.points)
            || state.positions.len() != self.state.positions.len()
            || state.velocities.len() != self.state.velocities.len()
        {
            return Err(Error::incompatible("state", "its size differs from the simulation's"));
        }
        self.state.positions.clone_from(&state.positions);
        self.state.velocities.clone_from(&state.velocities);
        Ok(())
    }

    /// As [`HairSim::set_simulated_hairs`](super::HairSim::set_simulated_hairs).
    pub fn set_simulated_hairs(&mut self, count: usize) -> Result<()> {
        self.lod.set(count)
    }

    /// As [`HairSim::simulated_hairs`](super::HairSim::simulated_hairs).
    pub fn simulated_hairs(&self) -> usize {
        self.lod.simulated
    }
}

/// The grid of the CPU reference's volume stage for `params`, none when it is off.
fn cpu_volume_grid(params: &SimParams, state: &SimState) -> Result<Option<volume::grid::GridLayout>> {
    match params.volume.mode {
        VolumeMode::Off => Ok(None),
        _ => volume::grid::GridLayout::new(&params.volume, state).map(Some),
    }
}
