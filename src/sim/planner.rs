//! How a step becomes sub-steps: [`SubstepPlanner`], the host-side
//! bookkeeping shared by [`crate::sim::HairSim`] and [`crate::sim::CpuHairSim`]
//! (parameters, colliders, the head transform of the previous step, simulated
//! time and the sub-step counter). Both turn a step into the same
//! [`SubstepInputs`], so GPU and CPU run on identical numbers.

use glam::Mat4;

use super::body::{validate_collider_total, validate_colliders, Collider, RigidTransform};
use super::mesh_collider::MeshGrid;
use super::mesh_skin::BoneTrack;
use super::packing::{self, ScalpLanes, SimShape, SubstepPose};
use super::params::SimParams;
use super::teleport::{root_displacement, Move, PendingMove};
use super::volume::VolumeParams;
use crate::codes::sim_flags;
use crate::error::{Error, Result};
use crate::gpu_types::{ColliderShape, SimStep, VolumeStep};

/// Everything one sub-step needs, identical for the GPU stages and the CPU reference.
pub(crate) struct SubstepInputs {
    pub params: SimStep,
    /// The same sub-step for each further parameter set ([`SubstepPlanner::sets`]).
    pub sets: Vec<SimStep>,
    /// The colliders in the world at the end of the sub-step.
    pub colliders: Vec<ColliderShape>,
    /// A skinned mesh collider's bones: per bone slot its rows at the end of
    /// the sub-step, then at its start (empty without one).
    pub bones: Vec<[glam::Vec4; 6]>,
}

impl SubstepInputs {
    /// The volume stage's parameters for this sub-step.
    pub(crate) fn volume_params(
        &self,
        grid: &super::volume::grid::GridLayout,
        params: &VolumeParams,
        colliders: u32,
    ) -> VolumeStep {
        let p = &self.params;
        let colliders = if p.flags & sim_flags::COLLISIONS != 0 { colliders } else { 0 };
        // A skinned field is not where the head places it: the volume marks no solid cells by it.
        let rigid_mesh = p.flags & sim_flags::MESH != 0 && p.flags & sim_flags::MESH_SKIN == 0;
        let mesh = rigid_mesh.then_some(MeshGrid { origin: p.mesh_origin, cell: p.mesh_cell, dims: p.mesh_dims });
        grid.step_params(params, &p.previous_head, &p.head, p.dt, colliders, mesh.as_ref())
    }
}

/// A step as the planner lays it out: the move applied to the state first (a
/// teleport or reset), then the sub-steps.
pub(crate) struct PlannedStep {
    pub start: Option<Move>,
    pub substeps: Vec<SubstepInputs>,
}

/// See the module docs.
#[derive(Debug, Clone)]
pub(crate) struct SubstepPlanner {
    pub params: SimParams,
    pub colliders: Vec<Collider>,
    /// The body's colliders (world) at the end of the next step, and where
    /// they were at the end of the previous one.
    pub body: Vec<Collider>,
    pub body_before: Vec<Collider>,
    /// The mesh collider's grid, when set.
    pub mesh: Option<MeshGrid>,
    /// A skinned mesh collider's bones, when one is set.
    pub mesh_bones: Option<BoneTrack>,
    pub head: RigidTransform,
    pub time: f64,
    pub substep: u32,
    pub strands: u32,
    pub points: u32,
    /// Subgroup size of the device the GPU stages run on.
    pub subgroup_size: u32,
    /// The roots at rest (head frame), for the teleport distance.
    pub roots: Vec<glam::Vec3>,
    /// A teleport or reset asked for, applied at the start of the next step.
    pub pending: Option<PendingMove>,
    /// With a bound scalp: where the next step's skinned vertices are.
    pub scalp: Option<ScalpLanes>,
    /// Further parameter sets, 1 onward (set 0 is `params`): key hairs whose
    /// scalp root names set `s` read `sets[s − 1]`'s sub-steps.
    pub sets: Vec<SimParams>,
}

/// Says, through `log`, when the sag-free rest state is asked for but cannot be
/// met: a shape stiffness under 1 % per sub-step leaves every particle
/// uncompensated (see `sim_shape_target`), so the groom sags as without it.
fn warn_unmet_sag_free(params: &SimParams) {
    let k = params.global_shape_stiffness;
    if params.sag_free && params.gravity_enabled && k > 0.0 && k < 0.01 {
        log::warn!(
            "vkhair: sag-free rest state not met: global_shape_stiffness {k} holds less than 1 % per sub-step, \
             so no particle is compensated and the groom sags under gravity"
        );
    }
}

impl SubstepPlanner {
    pub(crate) fn new(
        params: &SimParams,
        head: &RigidTransform,
        roots: Vec<glam::Vec3>,
        points: usize,
        subgroup_size: u32,
    ) -> Result<Self> {
        params.validate()?;
        head.validate()?;
        warn_unmet_sag_free(params);
        Ok(SubstepPlanner {
            params: params.clone(),
            colliders: Vec::new(),
            body: Vec::new(),
            body_before: Vec::new(),
            mesh: None,
            mesh_bones: None,
            head: *head,
            time: 0.0,
            substep: 0,
            strands: roots.len() as u32,
            points: points as u32,
            subgroup_size,
            roots,
            pending: None,
            scalp: None,
            sets: Vec::new(),
        })
    }

    pub(crate) fn set_params(&mut self, params: &SimParams) -> Result<()> {
        params.validate()?;
        warn_unmet_sag_free(params);
        self.params = params.clone();
        Ok(())
    }

    pub(crate) fn set_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        validate_colliders(colliders)?;
        validate_collider_total(colliders.len(), self.body.len())?;
        self.colliders = colliders.to_vec();
        Ok(())
    }

    /// The body's colliders in the world at the end of the next step; the
    /// sub-steps move each from where it was at the end of the previous step.
    pub(crate) fn set_body_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        validate_colliders(colliders)?;
        validate_collider_total(self.colliders.len(), colliders.len())?;
        self.body = colliders.to_vec();
        Ok(())
    }

    /// A skinned mesh collider's bones (rows per slot) at the end of the next step.
    pub(crate) fn set_mesh_bones(&mut self, rows: Vec<[glam::Vec4; 3]>) -> Result<()> {
        let Some(track) = &mut self.mesh_bones else {
            return Err(Error::incompatible("mesh collider bones", "no skinned mesh collider is set"));
        };
        track.now = rows;
        Ok(())
    }

    /// Colliders each sub-step sees: the head's, then the body's.
    pub(crate) fn collider_count(&self) -> u32 {
        (self.colliders.len() + self.body.len()) as u32
    }

    /// How the solver packs hairs for the current parameters.
    pub(crate) fn packing(&self) -> super::step::Packing {
        super::step::packing(
            self.points,
            self.subgroup_size,
            self.params.hairs_per_workgroup,
            self.params.subgroup_sync,
        )
    }

    /// Asks for the next step to start with the state moved rigidly from the
    /// current head to `to` (keeping a pending reset).
    pub(crate) fn teleport(&mut self, to: &RigidTransform) -> Result<()> {
        to.validate()?;
        let reset = self.pending.is_some_and(|p| p.reset);
        self.pending = Some(PendingMove { to: *to, reset });
        Ok(())
    }

    /// Asks for the next step to start from the rest pose, placed by the head
    /// it starts from (a pending teleport's, else the current one).
    pub(crate) fn reset(&mut self) {
        let to = self.pending.map_or(self.head, |p| p.to);
        self.pending = Some(PendingMove { to, reset: true });
    }

    /// The move the next step, ending with the head at `head`, starts with: the
    /// pending one, or a teleport to `head` when it would move a root farther
    /// than the teleport distance. The head the step starts from becomes the
    /// move's.
    fn start(&mut self, head: &RigidTransform) -> Option<Move> {
        let pending = self.pending.take();
        let from = pending.map_or(self.head, |p| p.to);
        let jump = root_displacement(&self.roots, &from, head) > self.params.teleport_distance;
        let pending =
            if jump { Some(PendingMove { to: *head, reset: pending.is_some_and(|p| p.reset) }) } else { pending }?;
        let start = Move::between(&self.head, &pending);
        self.head = pending.to;
        Some(start)
    }

    /// The next step, which ends with the head at `head`.
    pub(crate) fn next(&mut self, head: &RigidTransform) -> Result<PlannedStep> {
        head.validate()?;
        if self.mesh_bones.as_ref().is_some_and(|b| b.now.is_empty()) && self.params.collisions_enabled {
            return Err(Error::incompatible(
                "mesh collider",
                "a skinned mesh collider needs its bones before a step (HairSim::set_mesh_bones)",
            ));
        }
        let start = self.start(head);
        // A new body (another count) or a cut starts where the body is now.
        if start.is_some() || self.body_before.len() != self.body.len() {
            self.body_before.clone_from(&self.body);
        }
        // A cut starts where the bones are now (a first step, with none before,
        // does too: `BoneTrack::substep`).
        if let Some(track) = self.mesh_bones.as_mut().filter(|_| start.is_some()) {
            track.before.clone_from(&track.now);
        }
        let p = &self.params;
        let dt = p.substep_dt();
        let shape = SimShape { strands: self.strands, points: self.points, packing: self.packing() };
        let restart = start.is_some() || self.scalp.is_some_and(|s| s.restart);
        let inputs = (0..p.substeps)
            .map(|k| {
                let at = |k: u32| self.head.lerp(head, k as f32 / p.substeps as f32).matrix();
                let pose = SubstepPose {
                    previous_head: at(k),
                    head: at(k + 1),
                    time: (self.time + f64::from(dt) * f64::from(k + 1)) as f32,
                    index: self.substep.wrapping_add(k),
                };
                let colliders = self.collider_count();
                let t = |k: u32| k as f32 / p.substeps as f32;
                let friction = p.collider_friction;
                let head_colliders = self
                    .colliders
                    .iter()
                    .map(|c| moving(c.in_world(&pose.previous_head), c.in_world(&pose.head), friction));
                let body = self.body_before.iter().zip(&self.body).map(|(b0, b1)| {
                    let at = |k: u32| b0.lerp(b1, t(k)).in_world(&Mat4::IDENTITY);
                    moving(at(k), at(k + 1), friction)
                });
                let mut params = packing::sim_step(p, &pose, shape, colliders, self.mesh.as_ref());
                if let Some(scalp) = &self.scalp {
                    scalp.apply(&mut params, k, p.substeps, restart);
                }
                let bones = match &self.mesh_bones {
                    Some(track) if params.flags & sim_flags::MESH != 0 => {
                        params.flags |= sim_flags::MESH_SKIN;
                        track.substep(k, p.substeps)
                    }
                    _ => Vec::new(),
                };
                let sets = self.sets.iter().map(|s| packing::for_set(&params, s)).collect();
                SubstepInputs { params, sets, colliders: head_colliders.chain(body).collect(), bones }
            })
            .collect();
        if let Some(scalp) = &mut self.scalp {
            scalp.restart = false;
        }
        self.head = *head;
        self.body_before.clone_from(&self.body);
        if let Some(track) = &mut self.mesh_bones {
            track.before.clone_from(&track.now);
        }
        self.time += f64::from(p.dt);
        self.substep = self.substep.wrapping_add(p.substeps);
        Ok(PlannedStep { start, substeps: inputs })
    }
}

/// A collider where it ends a sub-step (`end`), with how far it moved from
/// `start` and the friction against it.
fn moving(start: ColliderShape, end: ColliderShape, friction: f32) -> ColliderShape {
    ColliderShape { moved_a: end.a - start.a, moved_b: end.b - start.b, friction, ..end }
}
