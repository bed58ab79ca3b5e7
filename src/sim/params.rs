//! Simulation parameters, colliders and the head's rigid transform.
//!
//! All lengths are meters (or the groom's unit), times seconds. Everything is
//! validated before any GPU work; each rejected field is named in the error.

use glam::{Mat4, Quat, Vec3};

use super::volume::VolumeParams;
use crate::error::{Error, Result};
use crate::gpu_types::{GpuCollider, SimStepParams};

/// Most colliders a simulation may have.
pub const MAX_COLLIDERS: usize = crate::limits::SIM_MAX_COLLIDERS as usize;
/// Most points per key hair the GPU solver handles (one 64-invocation workgroup).
pub const MAX_SIM_POINTS: usize = crate::limits::SIM_WORKGROUP as usize;
/// Most sub-steps per step ([`SimParams::substeps`]).
pub const MAX_SUBSTEPS: u32 = 64;

/// How the constraints are solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverMode {
    /// Position-based dynamics: alternating even/odd distance constraints, bending
    /// and collisions, `iterations` times (the thesis' solver).
    #[default]
    Pbd,
    /// Dynamic follow-the-leader (Müller et al. 2012): one sweep root to tip that
    /// places each point at its rest distance, with velocity correction.
    Dftl,
}

/// Tunable simulation parameters (a technical artist's knobs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// Time step of one simulation step, seconds (0 < dt ≤ 0.1). Default: 1/60.
    pub dt: f32,
    /// Sub-steps per step (1..=64); the head transform is interpolated between them.
    /// Default: 1.
    pub substeps: u32,
    /// Constraint iterations per sub-step in PBD mode (1..=1000). Default: 20.
    pub iterations: u32,
    /// Solver mode. Default: [`SolverMode::Pbd`].
    pub solver: SolverMode,
    /// Gravity, m/s². Default: (0, −9.81, 0).
    pub gravity: Vec3,
    /// Whether gravity acts. Default: true.
    pub gravity_enabled: bool,
    /// Wind acceleration (direction × strength), m/s². Default: (0, 0, 0).
    pub wind: Vec3,
    /// Wind turbulence: relative strength of the gust noise (0..=1). Default: 0.3.
    pub wind_turbulence: f32,
    /// Gust noise frequency, 1/s (≥ 0). Default: 1.5.
    pub wind_frequency: f32,
    /// Whether wind acts. Default: false.
    pub wind_enabled: bool,
    /// Stiffness of the spring pulling each particle toward its rest position in the
    /// head's frame, 1/s² (≥ 0). Default: 2.
    pub spring_stiffness: f32,
    /// Whether the rest-shape spring acts. Default: true.
    pub spring_enabled: bool,
    /// Bending stiffness at the root (0..=1; fraction of the bending error removed per
    /// sub-step, independent of iterations). Default: 0.6.
    pub bending_root: f32,
    /// Bending stiffness at the tip (0..=1). Default: 0.1.
    pub bending_tip: f32,
    /// Whether bending constraints act. Default: true.
    pub bending_enabled: bool,
    /// Global shape constraint (PBD solver): fraction of each particle's offset from
    /// its rest position in the head's frame removed per sub-step, independent of
    /// the iteration count (0..=1; 0 switches it off). What holds a styled groom's
    /// shape near the scalp against gravity; see `global_shape_range`. Default: 0.
    pub global_shape_stiffness: f32,
    /// Fraction of each strand, from the root, where the global shape constraint
    /// acts at full strength (0..=1); beyond it the constraint fades linearly to
    /// nothing over the next quarter of the strand, so that the rest swings freely.
    /// 1 holds the whole strand. Default: 0.5.
    pub global_shape_range: f32,
    /// Sag-free rest state: the global shape constraint's targets are raised
    /// against gravity by each particle's static sag, so that with a still head
    /// the groom keeps its authored shape while motion and wind still move it
    /// (see `glsl/include/sim.glsl`, `sim_shape_target`). Particles the
    /// constraint barely holds (under 1 % of their offset removed per sub-step)
    /// are left uncompensated. Default: true.
    pub sag_free: bool,
    /// Local shape constraint: the fraction of each segment's deviation from its
    /// rest offset, carried along with the parent segment's rotation (the rest
    /// frames parallel-transported along the current strand; the first
    /// segment's frame is the head's), removed per sub-step by one sweep root to
    /// tip after the last iteration, so independent of the iteration count
    /// (0..=1; 0 switches it off). Both ends of a segment move, so it conserves
    /// momentum: it keeps curls curled and strands' bends where the groom put
    /// them, while their weight is carried by the root and the global shape
    /// constraint (pair them, as `presets/curly.toml` does). 1 makes strands
    /// rigid. Default: 0.
    pub local_shape_stiffness: f32,
    /// Friction against the mesh collider: the fraction of a touching particle's
    /// motion along the surface, relative to the mesh, removed per sub-step
    /// (0..=1). Default: 0.3.
    pub mesh_friction: f32,
    /// Whether body collisions act (spheres, capsules and the mesh collider).
    /// Default: true.
    pub collisions_enabled: bool,
    /// Fraction of velocity removed per sub-step (0..1). Default: 0.02.
    pub damping: f32,
    /// DFTL velocity correction factor s_damping (0..=1). Default: 0.9.
    pub dftl_damping: f32,
    /// Collision radius of each particle ("pearl"), at the root, in groom units (≥ 0).
    /// Default: 0.002.
    pub pearl_radius_root: f32,
    /// Collision radius at the tip (≥ 0). Default: 0.004.
    pub pearl_radius_tip: f32,
    /// Key hairs packed into one solver workgroup; 0 packs as many as fit into its 64
    /// invocations. Default: 0.
    pub hairs_per_workgroup: u32,
    /// Let the solver synchronise with subgroup barriers when every hair fits into one
    /// subgroup (hairs are then packed so that none straddles two) and that keeps at
    /// least as many lanes busy as packing the whole workgroup; otherwise every
    /// constraint set ends with a workgroup barrier. Same results either way.
    /// Default: true.
    pub subgroup_sync: bool,
    /// The volume stage (hair-hair interaction on a grid) after each sub-step.
    /// Default: off ([`VolumeParams::default`]).
    pub volume: VolumeParams,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            dt: 1.0 / 60.0,
            substeps: 1,
            iterations: 20,
            solver: SolverMode::Pbd,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            gravity_enabled: true,
            wind: Vec3::ZERO,
            wind_turbulence: 0.3,
            wind_frequency: 1.5,
            wind_enabled: false,
            spring_stiffness: 2.0,
            spring_enabled: true,
            bending_root: 0.6,
            bending_tip: 0.1,
            bending_enabled: true,
            global_shape_stiffness: 0.0,
            global_shape_range: 0.5,
            sag_free: true,
            local_shape_stiffness: 0.0,
            mesh_friction: 0.3,
            collisions_enabled: true,
            damping: 0.02,
            dftl_damping: 0.9,
            pearl_radius_root: 0.002,
            pearl_radius_tip: 0.004,
            hairs_per_workgroup: 0,
            subgroup_sync: true,
            volume: VolumeParams::default(),
        }
    }
}

fn finite_vec(name: &'static str, v: Vec3) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::param(name, v, "finite"))
    }
}

fn in_range(name: &'static str, v: f32, lo: f32, hi: f32) -> Result<()> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(Error::param(name, v, format!("{lo}..={hi}")))
    }
}

impl SimParams {
    /// Parameters for an authored groom: [`SimParams::default`] with the whole
    /// strand held softly in its authored shape (global shape stiffness 0.15 over
    /// the whole strand, sag-free) instead of the rest-shape spring, so a still
    /// head keeps the style and motion still swings it (as `presets/bob.toml`).
    /// What the `vkhair` tool simulates an `--input` groom with.
    pub fn styled() -> SimParams {
        SimParams {
            global_shape_stiffness: 0.15,
            global_shape_range: 1.0,
            sag_free: true,
            spring_enabled: false,
            ..SimParams::default()
        }
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= 0.1) {
            return Err(Error::param("dt", self.dt, "(0, 0.1] seconds"));
        }
        if !(1..=MAX_SUBSTEPS).contains(&self.substeps) {
            return Err(Error::param("substeps", self.substeps, "1..=64"));
        }
        if !(1..=1000).contains(&self.iterations) {
            return Err(Error::param("iterations", self.iterations, "1..=1000"));
        }
        finite_vec("gravity", self.gravity)?;
        finite_vec("wind", self.wind)?;
        in_range("wind_turbulence", self.wind_turbulence, 0.0, 1.0)?;
        in_range("wind_frequency", self.wind_frequency, 0.0, 1000.0)?;
        in_range("spring_stiffness", self.spring_stiffness, 0.0, 1e6)?;
        in_range("bending_root", self.bending_root, 0.0, 1.0)?;
        in_range("bending_tip", self.bending_tip, 0.0, 1.0)?;
        in_range("global_shape_stiffness", self.global_shape_stiffness, 0.0, 1.0)?;
        in_range("global_shape_range", self.global_shape_range, 0.0, 1.0)?;
        in_range("local_shape_stiffness", self.local_shape_stiffness, 0.0, 1.0)?;
        in_range("mesh_friction", self.mesh_friction, 0.0, 1.0)?;
        in_range("damping", self.damping, 0.0, 0.999)?;
        in_range("dftl_damping", self.dftl_damping, 0.0, 1.0)?;
        in_range("pearl_radius_root", self.pearl_radius_root, 0.0, 1e6)?;
        in_range("pearl_radius_tip", self.pearl_radius_tip, 0.0, 1e6)?;
        if self.hairs_per_workgroup as usize > MAX_SIM_POINTS / 2 {
            return Err(Error::param("hairs_per_workgroup", self.hairs_per_workgroup, "at most 32"));
        }
        self.volume.validate()
    }

    /// Sub-step length, seconds.
    pub fn substep_dt(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    /// Stiffness per iteration equivalent to `k` per sub-step (Müller et al.'s
    /// k' = 1 − (1 − k)^(1/n)), so that bending does not depend on the iteration count.
    fn per_iteration(&self, k: f32) -> f32 {
        let n = match self.solver {
            SolverMode::Pbd => self.iterations,
            SolverMode::Dftl => 1,
        };
        1.0 - (1.0 - k).powf(1.0 / n as f32)
    }
}

/// A collision shape in the head's frame; it moves with the head transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Collider {
    /// A sphere.
    Sphere {
        /// Centre in the head frame.
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
    },
    /// A capsule: the points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end in the head frame.
        a: Vec3,
        /// Second end in the head frame.
        b: Vec3,
        /// Radius (> 0).
        radius: f32,
    },
}

/// Checks a collider list: at most [`MAX_COLLIDERS`], each valid.
pub(crate) fn validate_colliders(colliders: &[Collider]) -> Result<()> {
    if colliders.len() > MAX_COLLIDERS {
        return Err(Error::param("colliders", colliders.len(), format!("at most {MAX_COLLIDERS}")));
    }
    colliders.iter().try_for_each(Collider::validate)
}

impl Collider {
    pub(crate) fn validate(&self) -> Result<()> {
        let (points, radius) = match *self {
            Collider::Sphere { center, radius } => ([center, center], radius),
            Collider::Capsule { a, b, radius } => ([a, b], radius),
        };
        finite_vec("collider position", points[0])?;
        finite_vec("collider position", points[1])?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::param("collider radius", radius, "finite and > 0"));
        }
        Ok(())
    }

    /// The collider in world space for the GPU (and the CPU reference).
    pub(crate) fn to_gpu(self, head: &Mat4) -> GpuCollider {
        match self {
            Collider::Sphere { center, radius } => {
                let c = head.transform_point3(center);
                GpuCollider { a_radius: [c.x, c.y, c.z, radius], b_kind: [c.x, c.y, c.z, 0.0] }
            }
            Collider::Capsule { a, b, radius } => {
                let (a, b) = (head.transform_point3(a), head.transform_point3(b));
                GpuCollider { a_radius: [a.x, a.y, a.z, radius], b_kind: [b.x, b.y, b.z, 1.0] }
            }
        }
    }
}

/// The head's rigid motion: rotation then translation (world from head).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTransform {
    /// Rotation (normalised on use).
    pub rotation: Quat,
    /// Translation, meters.
    pub translation: Vec3,
}

impl Default for RigidTransform {
    fn default() -> Self {
        RigidTransform { rotation: Quat::IDENTITY, translation: Vec3::ZERO }
    }
}

impl RigidTransform {
    /// Checks for NaN/Inf and a degenerate rotation.
    pub fn validate(&self) -> Result<()> {
        if !self.translation.is_finite() || !self.rotation.is_finite() || self.rotation.length_squared() < 1e-12 {
            return Err(Error::param("head transform", format!("{self:?}"), "a finite rigid transform"));
        }
        Ok(())
    }

    /// The matrix (world from head).
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_rotation_translation(self.rotation.normalize(), self.translation)
    }

    /// Interpolates rotation (slerp) and translation (lerp).
    pub fn lerp(&self, to: &RigidTransform, t: f32) -> RigidTransform {
        RigidTransform {
            rotation: self.rotation.normalize().slerp(to.rotation.normalize(), t),
            translation: self.translation.lerp(to.translation, t),
        }
    }
}

/// Flags of `SimStepParams::counts.w`, as in `glsl/include/sim.glsl`.
pub(crate) mod flags {
    pub const GRAVITY: u32 = 1;
    pub const WIND: u32 = 2;
    pub const SPRING: u32 = 4;
    pub const BENDING: u32 = 8;
    pub const COLLISIONS: u32 = 16;
    pub const DFTL: u32 = 32;
    pub const GLOBAL_SHAPE: u32 = 64;
    pub const SAG_FREE: u32 = 128;
    pub const LOCAL_SHAPE: u32 = 256;
    pub const MESH: u32 = 512;
}

/// Everything one sub-step needs, identical for the GPU stages and the CPU reference.
pub(crate) struct SubstepInputs {
    pub params: SimStepParams,
    /// World-from-head transform at the start of the sub-step.
    pub previous_head: Mat4,
    pub colliders: Vec<GpuCollider>,
}

impl SubstepInputs {
    /// The volume stage's uniform block for this sub-step.
    pub(crate) fn volume_params(
        &self,
        grid: &super::volume::grid::GridLayout,
        params: &VolumeParams,
        colliders: u32,
    ) -> crate::gpu_types::GpuVolumeParams {
        let head = Mat4::from_cols_array_2d(&self.params.head);
        let colliders = if self.params.flags() & flags::COLLISIONS != 0 { colliders } else { 0 };
        let mesh = (self.params.flags() & flags::MESH != 0).then_some((self.params.mesh_grid, self.params.mesh_dims));
        grid.gpu_params(params, &self.previous_head, &head, self.params.dt(), colliders, mesh)
    }
}

/// The host-side bookkeeping shared by [`crate::sim::HairSim`] and
/// [`crate::sim::CpuHairSim`]: parameters, colliders, the head transform of the
/// previous step, simulated time and the sub-step counter. Both turn a step into
/// the same [`SubstepInputs`], so GPU and CPU run on identical numbers.
#[derive(Debug, Clone)]
pub(crate) struct SubstepPlanner {
    pub params: SimParams,
    pub colliders: Vec<Collider>,
    /// The mesh collider's grid (origin and cell edge, points per axis), when set.
    pub mesh: Option<([f32; 4], [u32; 4])>,
    pub head: RigidTransform,
    pub time: f64,
    pub substep: u32,
    pub strands: u32,
    pub points: u32,
    /// Subgroup size of the device the GPU stages run on.
    pub subgroup_size: u32,
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
        strands: usize,
        points: usize,
        subgroup_size: u32,
    ) -> Result<Self> {
        params.validate()?;
        head.validate()?;
        warn_unmet_sag_free(params);
        Ok(SubstepPlanner {
            params: params.clone(),
            colliders: Vec::new(),
            mesh: None,
            head: *head,
            time: 0.0,
            substep: 0,
            strands: strands as u32,
            points: points as u32,
            subgroup_size,
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
        self.colliders = colliders.to_vec();
        Ok(())
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

    /// The sub-steps of the next step, which ends with the head at `head`.
    pub(crate) fn next(&mut self, head: &RigidTransform) -> Result<Vec<SubstepInputs>> {
        head.validate()?;
        let p = &self.params;
        let dt = p.substep_dt();
        let mut flags = 0;
        flags |= if p.gravity_enabled { flags::GRAVITY } else { 0 };
        flags |= if p.wind_enabled { flags::WIND } else { 0 };
        flags |= if p.spring_enabled { flags::SPRING } else { 0 };
        flags |= if p.bending_enabled { flags::BENDING } else { 0 };
        flags |= if p.collisions_enabled { flags::COLLISIONS } else { 0 };
        flags |= if p.solver == SolverMode::Dftl { flags::DFTL } else { 0 };
        flags |= if p.global_shape_stiffness > 0.0 { flags::GLOBAL_SHAPE } else { 0 };
        flags |= if p.sag_free { flags::SAG_FREE } else { 0 };
        flags |= if p.local_shape_stiffness > 0.0 && p.solver == SolverMode::Pbd { flags::LOCAL_SHAPE } else { 0 };
        flags |= if self.mesh.is_some() && p.collisions_enabled { flags::MESH } else { 0 };
        let (mesh_grid, mesh_dims) = self.mesh.unwrap_or(([0.0, 0.0, 0.0, 1.0], [0; 4]));
        let packing = self.packing();
        let inputs = (0..p.substeps)
            .map(|k| {
                let previous_head = self.head.lerp(head, k as f32 / p.substeps as f32).matrix();
                let head = self.head.lerp(head, (k + 1) as f32 / p.substeps as f32).matrix();
                let t = (self.time + f64::from(dt) * f64::from(k + 1)) as f32;
                SubstepInputs {
                    previous_head,
                    params: SimStepParams {
                        head: head.to_cols_array_2d(),
                        gravity_dt: [p.gravity.x, p.gravity.y, p.gravity.z, dt],
                        wind: [p.wind.x, p.wind.y, p.wind.z, p.wind_turbulence],
                        wind_noise: [p.wind_frequency, t, p.spring_stiffness, p.damping],
                        bending: [p.per_iteration(p.bending_root), p.per_iteration(p.bending_tip), p.dftl_damping, 0.0],
                        counts: [self.strands, self.points, p.iterations, flags],
                        shape: [
                            p.per_iteration(p.global_shape_stiffness),
                            p.global_shape_range,
                            p.local_shape_stiffness,
                            p.mesh_friction,
                        ],
                        previous_head: previous_head.to_cols_array_2d(),
                        mesh_grid,
                        mesh_dims,
                        layout_info: [
                            self.colliders.len() as u32,
                            packing.hairs_per_group,
                            self.substep.wrapping_add(k),
                            packing.sync_group,
                        ],
                    },
                    colliders: self.colliders.iter().map(|c| c.to_gpu(&head)).collect(),
                }
            })
            .collect();
        self.head = *head;
        self.time += f64::from(p.dt);
        self.substep = self.substep.wrapping_add(p.substeps);
        Ok(inputs)
    }
}
