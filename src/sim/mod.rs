//! GPU strand simulation: position-based dynamics with a shared-memory
//! constraint solver, body collisions and head motion.
//!
//! [`HairSim`] records one simulation step into the caller's command buffer.
//! A step is `substeps` sub-steps, each running these stages in order (the
//! [`SimStage`] enum names their debug labels and timestamp scopes):
//!
//! 1. **Step** (`step.rs`, `glsl/sim/step.comp`): ONE dispatch, one
//!    workgroup per group of key hairs, each point's state loaded once into
//!    registers and shared memory; per sub-step
//!    1. external forces — gravity, wind with deterministic gust noise, a
//!       spring toward the rest shape in the head frame, each switchable —
//!       then v* = v + dt·a, x* = x + dt·v*; pinned particles (roots) follow
//!       the head transform;
//!    2. the constraint solve: for N iterations the constraints of the list
//!       in `gpu_types/constraints.rs`, in its order, separated by barriers
//!       between their sets — the even then odd distance constraints, two
//!       sets of bending constraints, in the last iteration the local shape
//!       constraints (one sweep root to tip,
//!       [`SimParams::local_shape_stiffness`]), the global shape constraint
//!       (each particle pulled toward its rest position in the head frame,
//!       [`SimParams::global_shape_stiffness`]) and the body collisions
//!       (spheres, capsules and the [`MeshCollider`]'s field, rigid with the
//!       head or following bones), and in the
//!       last iteration the stretch limit ([`SimParams::stretch_limit`],
//!       when set); then friction
//!       against the mesh collider. Each constraint is one GLSL include
//!       (`glsl/include/constraints/`) and one CPU twin
//!       (`reference/constraints/`); build.rs generates the calls. DFTL mode
//!       replaces the iterations with one follow-the-leader sweep and keeps
//!       the correction vectors in shared memory;
//!    3. velocity from the position change (plus the DFTL correction) and
//!       damping;
//!
//!    and one store of the final state into the other half of the double
//!    buffer. With the volume stage off, the one dispatch runs every sub-step
//!    of the step; with it on, one dispatch per sub-step, since the volume
//!    stage exchanges velocities between all hairs after each. With a level of
//!    detail ([`HairSim::set_simulated_hairs`]) the dispatch covers only the
//!    simulated key hairs;
//!
//!    1b. **Followers** (`lod.rs`, `glsl/sim/follow.comp`), with a level of
//!    detail only: one dispatch after each step dispatch moves the key hairs
//!    left out with their guides ([`SimStage::Follow`]).
//! 2. **Volume** ([`volume`], `glsl/sim/volume/`), when
//!    [`SimParams::volume`] switches it on: particles scattered onto a MAC
//!    grid (fixed-point sums: the same bits in any order), then either FLIP (pressure projection with a GPU conjugate-gradient solve)
//!    or density friction/repulsion corrects the new velocities. Four
//!    timestamp scopes: [`SimStage::VolumeScatter`], [`SimStage::VolumeTransfer`],
//!    [`SimStage::VolumePressure`], [`SimStage::VolumeUpdate`].
//!
//! Parameters ([`SimParams`]), colliders ([`Collider`], [`MeshCollider`]) and the head transform
//! ([`RigidTransform`]) are validated before any GPU work. [`CpuHairSim`] runs
//! the same algorithm on the CPU with the same operation order (the test
//! oracle and benchmark baseline); [`FixedStepDriver`] turns frame times into
//! a number of fixed steps.

mod body;
mod cpu;
mod driver;
pub mod lod;
pub(crate) mod math;
mod mesh_bones;
mod mesh_collider;
pub(crate) mod mesh_skin;
pub mod motion;
mod packing;
mod params;
mod planner;
mod record;
pub(crate) mod reference;
pub mod scalp;
mod scalp_gpu;
mod state;
mod step;
mod teleport;
#[cfg(test)]
mod tests;
mod view;
pub mod volume;

use std::sync::Arc;

use ash::vk;

pub(crate) use body::{validate_collider_total, validate_colliders};
pub use body::{Collider, RigidTransform, MAX_COLLIDERS};
pub use cpu::{CpuHairSim, REFERENCE_STEP_TOLERANCE_M};
pub use driver::{FixedStepDriver, StepPlan};
pub use lod::FOLLOW_FADE;
pub use mesh_collider::{MeshCollider, MeshColliderParams, MESH_COLLIDER_BUILD_LABEL};
pub use mesh_skin::{MeshSkin, MESH_MAX_BONES};
pub(crate) use packing::{check_set, SET_FIELDS};
pub use params::{SimParams, SolverMode, MAX_SIM_POINTS, MAX_SUBSTEPS};
pub use state::SimState;
pub use teleport::MOVE_LABEL;
pub use view::KeyHairs;
pub use volume::{Preconditioner, PressureSolver, VolumeGrid, VolumeMode, VolumeParams, VolumeStats};

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;
use crate::groom::Groom;
use crate::profiler::GpuProfiler;
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::SIM_FOLLOW_COMP;
use planner::SubstepPlanner;
use state::GpuState;

/// The stages of a simulation step, in order (the timestamp scopes of
/// [`HairSim::record_step`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimStage {
    /// Stage 1: prediction, constraint solve and velocity update of the sub-steps
    /// (all of a step's with the volume stage off, else one), one dispatch.
    Step,
    /// Stage 1b (with a level of detail, [`HairSim::set_simulated_hairs`]): the
    /// key hairs left out follow their guides, one dispatch after each step dispatch.
    Follow,
    /// Stage 2a: every particle's weight and weighted velocity added to the
    /// cell centres and MAC faces around it.
    VolumeScatter,
    /// Stage 2b: cell densities, mean velocities and labels, face velocities
    /// from those sums.
    VolumeTransfer,
    /// Stage 2c: pressure solve and projection (FLIP mode only).
    VolumePressure,
    /// Stage 2d: grid velocities back to the particles.
    VolumeUpdate,
}

impl SimStage {
    /// Every stage in execution order.
    pub const ALL: [SimStage; 6] = [
        SimStage::Step,
        SimStage::Follow,
        SimStage::VolumeScatter,
        SimStage::VolumeTransfer,
        SimStage::VolumePressure,
        SimStage::VolumeUpdate,
    ];

    /// The scopes of the volume stage.
    const VOLUME: [SimStage; 4] =
        [SimStage::VolumeScatter, SimStage::VolumeTransfer, SimStage::VolumePressure, SimStage::VolumeUpdate];

    /// The debug label and timestamp scope name of the stage.
    pub fn label(self) -> &'static str {
        match self {
            SimStage::Step => "vkhair sim: step",
            SimStage::Follow => "vkhair sim: followers",
            SimStage::VolumeScatter => "vkhair sim: volume scatter",
            SimStage::VolumeTransfer => "vkhair sim: volume transfer",
            SimStage::VolumePressure => "vkhair sim: volume pressure",
            SimStage::VolumeUpdate => "vkhair sim: volume update",
        }
    }

    /// Position of the stage in a step (its timestamp slot).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Whether the stage belongs to the volume step.
    pub fn is_volume(self) -> bool {
        Self::VOLUME.contains(&self)
    }
}

/// The GPU hair simulation (see the module docs for the stage list).
///
/// Steps are recorded into the caller's command buffer with
/// [`HairSim::record_step`]; here one step is recorded into a headless
/// submission and read back:
///
/// ```
/// use glam::Vec3;
/// use vkhair::headless::Submit;
/// use vkhair::sim::{HairSim, RigidTransform, SimParams};
/// use vkhair::{ContextOptions, GpuContext, Groom, ValidationLog};
///
/// let log = ValidationLog::new();
/// {
///     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
///     let strand: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.02 * i as f32, 0.0, 0.0)).collect();
///     let groom = Groom::from_strands(&[strand])?;
///     let head = RigidTransform::default();
///     let mut sim = HairSim::new(&ctx, &groom, &SimParams::default(), &head)?;
///     let mut result = Ok(());
///     // SAFETY: a recording command buffer of the context's device.
///     ctx.run_commands("step", |cmd| result = unsafe { sim.record_step(cmd, &head, None) })?;
///     result?;
///     let state = sim.read_state()?;
///     assert_eq!(state.positions[0].truncate(), Vec3::ZERO, "the root is pinned");
///     assert!(state.positions[5].y < 0.0, "the tip falls");
/// }
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
pub struct HairSim {
    device: Arc<Device>,
    gpu: GpuState,
    /// The step kernel, with a variant for each set of switches met so far
    /// ([`HairSim::prepare_step`]).
    pipeline: ComputePipeline,
    /// Its descriptor sets reading half 0 and half 1 of the double buffer.
    sets: [vk::DescriptorSet; 2],
    planner: SubstepPlanner,
    /// Rest shape and lengths as last uploaded (positions unused).
    shape: SimState,
    /// Particle ranges of `shape` to upload with the next step.
    pending_rest: Vec<std::ops::Range<usize>>,
    /// Key hairs moved on their own before the next step (a crowd member's teleport).
    partial_moves: Vec<teleport::PartialMove>,
    /// The half of the double buffer holding the latest state.
    current: usize,
    /// The volume stage, when switched on.
    volume: Option<volume::VolumeStage>,
    /// The mesh collider, when set.
    mesh: Option<MeshCollider>,
    /// Which key hairs are simulated, and whom the others follow.
    lod: lod::SimLod,
    /// Whether the guides changed since they were last uploaded.
    pending_guides: bool,
    /// The follower kernel, with its sets reading half 0 and half 1.
    follow: ComputePipeline,
    follow_sets: [vk::DescriptorSet; 2],
    /// The teleport and reset kernel.
    mover: teleport::MoveKernel,
    /// The bound scalp, when set.
    scalp: Option<scalp_gpu::GpuScalp>,
}

impl HairSim {
    /// Uploads `groom` (key hairs in the head frame, all with the same point count,
    /// at most [`MAX_SIM_POINTS`]) placed by `head`, at rest. This submits and waits.
    pub fn new(ctx: &GpuContext, groom: &Groom, params: &SimParams, head: &RigidTransform) -> Result<Self> {
        let state = SimState::from_groom(groom, params, head)?;
        Self::from_state(ctx, &state, params, head)
    }

    /// Starts from an arbitrary state (e.g. one read back or produced by [`CpuHairSim`]).
    pub fn from_state(ctx: &GpuContext, state: &SimState, params: &SimParams, head: &RigidTransform) -> Result<Self> {
        let device = ctx.device.clone();
        // Subgroup-synchronised solving needs full subgroups; without them the solver
        // synchronises whole workgroups.
        let subgroup = if device.full_subgroups { device.info.subgroup_size } else { 0 };
        let planner = SubstepPlanner::new(params, head, state.rest_roots(), state.points, subgroup)?;
        let lod = lod::SimLod::new(state);
        let gpu = GpuState::new(&device, state, &lod.order.order, &lod.guides)?;
        // Compiled when key hairs are first left out (`record_step`); the step
        // kernel only as the variants the switches ask for (`prepare_step`).
        let follow = ComputePipeline::deferred(&device, &SIM_FOLLOW_COMP, 2, false)?;
        let follow_sets = [
            follow.declared_buffer_set(0, &gpu.follow_bindings(0, None))?,
            follow.declared_buffer_set(0, &gpu.follow_bindings(1, None))?,
        ];
        let mover = teleport::MoveKernel::new(&device, &gpu)?;
        let pipeline = ComputePipeline::deferred(&device, step::SHADER, 2, device.full_subgroups)?;
        let sets = [
            pipeline.declared_buffer_set(0, &gpu.bindings(0, None))?,
            pipeline.declared_buffer_set(0, &gpu.bindings(1, None))?,
        ];
        let mut sim = HairSim {
            device,
            gpu,
            pipeline,
            sets,
            planner,
            shape: state.clone(),
            pending_rest: Vec::new(),
            partial_moves: Vec::new(),
            current: 0,
            volume: None,
            mesh: None,
            lod,
            pending_guides: false,
            follow,
            follow_sets,
            mover,
            scalp: None,
        };
        sim.configure_volume(&params.volume)?;
        sim.prepare_step()?;
        Ok(sim)
    }

    /// Compiles, unless it exists, the step kernel's variant for the current
    /// parameters and mesh collider (the kernel specialised to the switches they
    /// turn on), so that recording a step does not compile it.
    fn prepare_step(&mut self) -> Result<()> {
        use crate::codes::sim_flags::{MESH, MESH_SKIN, SCALP};
        let mut flags = packing::flags(&self.planner.params, self.mesh.is_some());
        if self.planner.scalp.is_some() {
            flags |= SCALP;
        }
        if self.planner.mesh_bones.is_some() && flags & MESH != 0 {
            flags |= MESH_SKIN;
        }
        self.pipeline.prepare_variant(flags)
    }

    /// Creates, rebuilds or drops the volume stage for `params`. The grid is fitted
    /// to the rest state (roots plus the longest rest strand, in the head frame),
    /// as `CpuHairSim` fits it; a new fit (new resolution, strands lengthened or
    /// shortened) rebuilds the stage.
    fn configure_volume(&mut self, params: &VolumeParams) -> Result<()> {
        if params.mode == VolumeMode::Off {
            self.volume = None;
            return Ok(());
        }
        let grid = volume::grid::GridLayout::new(params, &self.shape)?;
        if let Some(stage) = &mut self.volume {
            if stage.grid == grid {
                return stage.set_params(params);
            }
        }
        // The old stage's buffers may still be in use by submitted work.
        self.device.wait_idle()?;
        let g = &self.gpu;
        let particles = [(&g.positions[0], &g.velocities[0]), (&g.positions[1], &g.velocities[1])];
        let mesh_field = self.mesh.as_ref().map_or(&g.no_mesh, |m| &m.field);
        self.volume =
            Some(volume::VolumeStage::new(&self.device, grid, params, &g.volume_colliders, mesh_field, &particles)?);
        Ok(())
    }

    /// A cut or a respawn: the next recorded step starts with the whole state
    /// (positions, and velocities turned with the head) moved rigidly from the
    /// current head to `to`, adding no velocity, and interpolates the head from
    /// `to` (not across the jump) to the head it ends with. Call it, then record
    /// the step ending at `to` (or wherever the head goes next). A head that
    /// moves a root farther than [`SimParams::teleport_distance`] in one step is
    /// taken as a teleport without this call. Keeps a pending [`HairSim::reset`].
    pub fn teleport(&mut self, to: &RigidTransform) -> Result<()> {
        self.planner.teleport(to)
    }

    /// The next recorded step starts from the rest pose, velocities zero, placed
    /// by the head it starts from (a pending [`HairSim::teleport`]'s target, else
    /// the current head).
    pub fn reset(&mut self) {
        self.planner.reset();
    }

    /// Current parameters.
    pub fn params(&self) -> &SimParams {
        &self.planner.params
    }

    /// Changes parameters from the next step on (validated first).
    ///
    /// Switching the volume stage on or changing its resolution creates its buffers
    /// and waits for the device to be idle first.
    pub fn set_params(&mut self, params: &SimParams) -> Result<()> {
        params.validate()?;
        self.planner.sets.iter().try_for_each(|set| packing::check_set(params, set))?;
        self.configure_volume(&params.volume)?;
        self.planner.set_params(params)?;
        self.prepare_step()
    }

    /// Simulates only `count` key hairs from the next step on (1 up to every key
    /// hair; all by default): the first `count` of a spatially progressive
    /// order of the roots, so that they spread over the scalp at any count. The
    /// others follow them, each keeping its rest offset from a simulated
    /// neighbour (its guide) turned with the head, roots pinned; a hair that
    /// stops being simulated fades into that shape over a few steps
    /// ([`FOLLOW_FADE`] of its deviation kept per step), one that rejoins
    /// starts from where it was drawn (see [`lod`]). A step
    /// then costs about as much as one of `count` key hairs, plus one follower
    /// dispatch. [`CpuHairSim::set_simulated_hairs`] does the same.
    pub fn set_simulated_hairs(&mut self, count: usize) -> Result<()> {
        self.lod.set(count)?;
        self.pending_guides = true;
        Ok(())
    }

    /// How many key hairs are simulated (see [`HairSim::set_simulated_hairs`]).
    pub fn simulated_hairs(&self) -> usize {
        self.lod.simulated
    }

    /// Replaces the colliders (in the head frame; at most [`MAX_COLLIDERS`]
    /// together with the body's).
    pub fn set_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        self.planner.set_colliders(colliders)
    }

    /// The colliders of a body that moves on its own bones (shoulders, chest,
    /// arms), in the world where they are at the end of the next step: each
    /// sub-step sees every one moved linearly from where it was at the end of
    /// the previous step (where it is now for the first step, after a change
    /// of their count, and on a teleport). Set them before every step; they
    /// keep their place when not set again. At most [`MAX_COLLIDERS`] together
    /// with the head's; they push particles out as the head's do, and hold
    /// the hair touching them by [`SimParams::collider_friction`] against
    /// their own motion across the sub-step (a moving shoulder carries the
    /// hair resting on it).
    pub fn set_body_colliders(&mut self, colliders: &[Collider]) -> Result<()> {
        self.planner.set_body_colliders(colliders)
    }

    /// Sets (or with `None` removes) the mesh collider: from the next step on,
    /// particles are projected out of its field along the gradient and rub against
    /// it with [`SimParams::mesh_friction`], alongside the spheres and capsules,
    /// when [`SimParams::collisions_enabled`]. Its field is in the head frame and
    /// moves with the head transform, or, for a [`MeshCollider::skinned`] one,
    /// with the bones of [`HairSim::set_mesh_bones`] (needed before the next
    /// step; the volume stage then marks no solid cells by it). The collider must come from this
    /// simulation's context. This waits for the device to be idle (the solver's
    /// descriptors are rewritten) and returns the previous collider.
    pub fn set_mesh_collider(&mut self, mesh: Option<MeshCollider>) -> Result<Option<MeshCollider>> {
        if let Some(m) = &mesh {
            if !Arc::ptr_eq(&m.device, &self.device) {
                return Err(Error::incompatible("mesh collider", "it was built on another context's device"));
            }
        }
        self.planner.mesh = mesh.as_ref().map(MeshCollider::grid);
        self.planner.mesh_bones = mesh.as_ref().and_then(MeshCollider::skin).map(|_| Default::default());
        let previous = std::mem::replace(&mut self.mesh, mesh);
        self.rewrite_sets()?;
        self.prepare_step()?;
        // The volume stage binds the field too: rebuild it around the new one.
        if self.volume.take().is_some() {
            let params = self.planner.params.volume.clone();
            self.configure_volume(&params)?;
        }
        Ok(previous)
    }

    /// Builds a mesh collider of `mesh` (head frame, the groom's units) on this
    /// simulation's device and sets it (see [`HairSim::set_mesh_collider`]); `None`
    /// removes the current one.
    pub fn set_mesh(&mut self, mesh: Option<&TriMesh>, params: &MeshColliderParams) -> Result<()> {
        let collider = match mesh {
            Some(m) => Some(MeshCollider::on_device(&self.device, m, params)?),
            None => None,
        };
        self.set_mesh_collider(collider).map(drop)
    }

    /// Changes the rest length of key hair `strand`; only its tip segments change.
    /// Takes effect with the next recorded step. With the volume stage on, its grid
    /// is refitted when the new rest lengths change the fit (as in `CpuHairSim`),
    /// waiting for the device to be idle first.
    pub fn set_strand_length(&mut self, strand: usize, length: f32) -> Result<()> {
        let first = self.shape.set_strand_length(strand, length)?;
        let end = (strand + 1) * self.shape.points;
        self.pending_rest.push(first..end);
        // The volume grid follows the rest lengths (refitted when they change it).
        let volume = self.planner.params.volume.clone();
        self.configure_volume(&volume)
    }

    /// Key hairs and points per key hair.
    pub fn size(&self) -> (usize, usize) {
        (self.shape.strands, self.shape.points)
    }

    /// The positions buffer holding the latest state (vec4 per particle, w = inverse
    /// mass). It is written by the compute stage (`SHADER_STORAGE_WRITE`) of the last
    /// recorded step: a reader needs a barrier from `COMPUTE_SHADER` after it.
    pub fn positions_buffer(&self) -> vk::Buffer {
        self.gpu.positions[self.current].raw()
    }

    pub(crate) fn device(&self) -> &Arc<Device> {
        &self.device
    }

    /// The latest state as a renderer reads it.
    pub fn key_hairs(&self) -> KeyHairs<'_> {
        KeyHairs {
            device: &self.device,
            rest: &self.shape,
            halves: [&self.gpu.positions[0], &self.gpu.positions[1]],
            current: self.current,
            before: [&self.gpu.before, &self.gpu.before],
            alpha: 1.0,
            head: self.planner.head,
            volume: self.volume.as_ref().map(|v| (v.grid.describe(&self.planner.head.matrix()), &v.buffers.cells)),
            bounds: None,
        }
    }

    /// The latest positions and velocities and, with the volume stage, the density
    /// cells: the buffers a hand-off copies (see the schedule module).
    pub(crate) fn latest_buffers(&self) -> (&crate::vk::buffer::Buffer, Option<&crate::vk::buffer::Buffer>) {
        (&self.gpu.positions[self.current], self.volume.as_ref().map(|v| &v.buffers.cells))
    }

    /// The head transform at the end of the latest recorded step.
    pub fn head(&self) -> RigidTransform {
        self.planner.head
    }

    /// The positions before the latest step (for [`KeyHairs::blended`]); same
    /// layout and barrier rule as [`HairSim::positions_buffer`].
    pub fn previous_positions_buffer(&self) -> vk::Buffer {
        self.gpu.before.raw()
    }

    /// The volume grid as placed for the latest step, when the volume stage is on.
    pub fn volume_grid(&self) -> Option<VolumeGrid> {
        self.volume.as_ref().map(|v| v.grid.describe(&self.planner.head.matrix()))
    }

    /// The volume stage's cell buffer, when it is on: one vec4 per cell (index
    /// i + nx·(j + ny·k)) holding the particles' mean velocity along the grid axes
    /// (m/s) in xyz and the density (summed trilinear particle weights) in w, as of
    /// the latest sub-step. Written by the compute stage (`SHADER_STORAGE_WRITE`) of
    /// the last recorded step; a reader needs a barrier from `COMPUTE_SHADER`. Place
    /// it in the world with [`HairSim::volume_grid`].
    pub fn density_buffer(&self) -> Option<vk::Buffer> {
        self.volume.as_ref().map(|v| v.buffers.cells.raw())
    }

    /// How this simulation records the pressure solve: the parameters' solver,
    /// [`PressureSolver::Auto`] resolved for this device. `None` when the volume
    /// stage is off.
    pub fn pressure_solver(&self) -> Option<PressureSolver> {
        self.volume.as_ref().map(|v| v.params.solver)
    }

    /// What the pressure solve of the latest sub-step did (FLIP mode; this waits for
    /// the device to be idle and reads back). `None` when the volume stage is off.
    pub fn volume_stats(&self) -> Result<Option<VolumeStats>> {
        match &self.volume {
            Some(v) => {
                self.device.wait_idle()?;
                v.read_stats().map(Some)
            }
            None => Ok(None),
        }
    }

    /// Reads the latest state back (this submits and waits for the queue).
    pub fn read_state(&self) -> Result<SimState> {
        let n = self.shape.positions.len();
        let mut state = self.shape.clone();
        state.positions = self.device.readback_pod(&self.gpu.positions[self.current], n)?;
        state.velocities = self.device.readback_pod(&self.gpu.velocities[self.current], n)?;
        Ok(state)
    }

    /// Replaces positions and velocities (same size; this submits and waits).
    pub fn write_state(&mut self, state: &SimState) -> Result<()> {
        if (state.strands, state.points) != (self.shape.strands, self.shape.points)
            || state.positions.len() != self.shape.positions.len()
            || state.velocities.len() != self.shape.positions.len()
        {
            return Err(Error::incompatible("state", "its size differs from the simulation's"));
        }
        self.gpu.upload(&self.device, state, self.current)
    }

    /// Runs `steps` steps with the head at `head(i)` for step i, in one submission
    /// (headless use: tests, tools, benchmarks; this submits and waits). With a
    /// profiler, returns the per-stage GPU timings of the whole run (the profiler
    /// needs one scope per step, or 5 per sub-step with the volume stage, and
    /// one more per step or sub-step with a level of detail).
    pub fn run(
        &mut self,
        steps: usize,
        mut head: impl FnMut(usize) -> RigidTransform,
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<Option<crate::profiler::ProfileReport>> {
        let device = self.device.clone();
        let mut result = Ok(());
        device.submit_once("vkhair sim run", |cmd| {
            // SAFETY: submit_once hands over a recording command buffer of this device,
            // and waits for the previous one: every earlier frame has completed.
            unsafe {
                if let Some(p) = profiler.as_deref_mut() {
                    let frame = p.latest().map_or(0, |r| r.frame + 1);
                    let _ = p.begin_frame(cmd, frame);
                }
                for i in 0..steps {
                    if let Err(e) = self.record_step(cmd, &head(i), profiler.as_deref_mut()) {
                        result = Err(e);
                        return;
                    }
                }
            }
        })?;
        result?;
        Ok(profiler.and_then(|p| p.drain().pop()))
    }
}
