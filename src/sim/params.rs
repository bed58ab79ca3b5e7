//! The simulation's knobs: [`SimParams`] and what it validates.
//!
//! All lengths are meters (or the groom's unit), times seconds. Everything is
//! validated before any GPU work; each rejected field is named in the error.
//! How the knobs reach the GPU is `packing.rs`; how a step becomes sub-steps
//! is `planner.rs`.

use glam::Vec3;

use super::volume::VolumeParams;
use crate::error::{Error, Result};

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
    /// Gravity, m/s² (each component within ±10,000). Default: (0, −9.81, 0).
    pub gravity: Vec3,
    /// Whether gravity acts. Default: true.
    pub gravity_enabled: bool,
    /// Wind acceleration (direction × strength), m/s² (each component within
    /// ±10,000). Default: (0, 0, 0).
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
    /// Stretch limit (PBD solver): after the last iteration's other
    /// constraints and the collisions, one sweep root to tip shortens every
    /// segment longer than (1 + this) × its rest length to that length, moving
    /// the point toward the tip only, so hair never stretches visibly under
    /// violent motion even at few iterations (a fraction, 0..=1; 0 switches
    /// it off). Default: 0.
    pub stretch_limit: f32,
    /// Friction against the mesh collider: the fraction of a touching particle's
    /// motion along the surface, relative to the mesh, removed per sub-step
    /// (0..=1). Default: 0.3.
    pub mesh_friction: f32,
    /// Friction against spheres and capsules, head's and body's: the fraction
    /// of a touching particle's velocity along the surface, relative to the
    /// surface's own velocity over the sub-step (a moving shoulder carries the
    /// hair resting on it), removed per sub-step, fading to none a pearl
    /// radius off the surface (0..=1). Default: 0.3.
    pub collider_friction: f32,
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
    /// A step whose head moves some root farther than this, meters, is a
    /// teleport ([`super::HairSim::teleport`]): the whole state moves rigidly with
    /// the head instead of being dragged across the jump ((0, 1e6]; 1e6 turns it
    /// off for any scene). Default: 1 (a head moving a meter in one step is a cut,
    /// not motion).
    pub teleport_distance: f32,
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
            stretch_limit: 0.0,
            mesh_friction: 0.3,
            collider_friction: 0.3,
            collisions_enabled: true,
            damping: 0.02,
            dftl_damping: 0.9,
            pearl_radius_root: 0.002,
            pearl_radius_tip: 0.004,
            hairs_per_workgroup: 0,
            subgroup_sync: true,
            volume: VolumeParams::default(),
            teleport_distance: 1.0,
        }
    }
}

pub(super) fn finite_vec(name: &'static str, v: Vec3) -> Result<()> {
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
        for (name, v) in [("gravity", self.gravity), ("wind", self.wind)] {
            finite_vec(name, v)?;
            if v.abs().max_element() > 1e4 {
                return Err(Error::param(name, v, "each component within ±10,000 m/s²"));
            }
        }
        in_range("wind_turbulence", self.wind_turbulence, 0.0, 1.0)?;
        in_range("wind_frequency", self.wind_frequency, 0.0, 1000.0)?;
        in_range("spring_stiffness", self.spring_stiffness, 0.0, 1e6)?;
        in_range("bending_root", self.bending_root, 0.0, 1.0)?;
        in_range("bending_tip", self.bending_tip, 0.0, 1.0)?;
        in_range("global_shape_stiffness", self.global_shape_stiffness, 0.0, 1.0)?;
        in_range("global_shape_range", self.global_shape_range, 0.0, 1.0)?;
        in_range("local_shape_stiffness", self.local_shape_stiffness, 0.0, 1.0)?;
        in_range("stretch_limit", self.stretch_limit, 0.0, 1.0)?;
        in_range("mesh_friction", self.mesh_friction, 0.0, 1.0)?;
        in_range("collider_friction", self.collider_friction, 0.0, 1.0)?;
        in_range("damping", self.damping, 0.0, 0.999)?;
        in_range("dftl_damping", self.dftl_damping, 0.0, 1.0)?;
        in_range("pearl_radius_root", self.pearl_radius_root, 0.0, 1e6)?;
        in_range("pearl_radius_tip", self.pearl_radius_tip, 0.0, 1e6)?;
        if !(self.teleport_distance.is_finite() && self.teleport_distance > 0.0 && self.teleport_distance <= 1e6) {
            return Err(Error::param("teleport_distance", self.teleport_distance, "(0, 1e6] m"));
        }
        if self.hairs_per_workgroup as usize > MAX_SIM_POINTS / 2 {
            return Err(Error::param("hairs_per_workgroup", self.hairs_per_workgroup, "at most 32"));
        }
        self.volume.validate()
    }

    /// Sub-step length, seconds.
    pub fn substep_dt(&self) -> f32 {
        self.dt / self.substeps as f32
    }
}
