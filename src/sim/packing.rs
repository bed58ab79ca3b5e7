//! The GPU packing of one sub-step: the knobs, the head's pose and the bodies
//! as the step kernel, the volume stage and the CPU reference read them
//! ([`SimStep`], [`ColliderShape`](crate::gpu_types::ColliderShape)). Which
//! lane of the parameter block holds which field is written once, in
//! `gpu_types/views.rs`; this file decides what the fields hold.

use glam::Mat4;

use super::mesh_collider::MeshGrid;
use super::params::{SimParams, SolverMode};
use super::step::Packing;
use crate::codes::sim_flags;
use crate::gpu_types::{SimKnobs, SimStep};

/// The `SIM_*` switches for `p`, with a mesh collider set when `mesh`.
pub(crate) fn flags(p: &SimParams, mesh: bool) -> u32 {
    let switches = [
        (p.gravity_enabled, sim_flags::GRAVITY),
        (p.wind_enabled, sim_flags::WIND),
        (p.spring_enabled, sim_flags::SPRING),
        (p.bending_enabled, sim_flags::BENDING),
        (p.collisions_enabled, sim_flags::COLLISIONS),
        (p.solver == SolverMode::Dftl, sim_flags::DFTL),
        (p.global_shape_stiffness > 0.0, sim_flags::GLOBAL_SHAPE),
        (p.sag_free, sim_flags::SAG_FREE),
        (p.local_shape_stiffness > 0.0 && p.solver == SolverMode::Pbd, sim_flags::LOCAL_SHAPE),
        (mesh && p.collisions_enabled, sim_flags::MESH),
    ];
    switches.iter().filter(|(on, _)| *on).fold(0, |flags, (_, flag)| flags | flag)
}

/// Stiffness per iteration equivalent to `k` per sub-step (Müller et al.'s
/// k' = 1 − (1 − k)^(1/n)), so that a constraint's strength does not depend on
/// the iteration count.
pub(crate) fn per_iteration(p: &SimParams, k: f32) -> f32 {
    let n = match p.solver {
        SolverMode::Pbd => p.iterations,
        SolverMode::Dftl => 1,
    };
    1.0 - (1.0 - k).powf(1.0 / n as f32)
}

/// Each knob's value from `SimParams`, as the constraint list
/// (`gpu_types/constraints.rs`) says.
macro_rules! sim_constraints {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident : $kind:ident [ $($set:literal),* ] {
            $( $(#[doc = $kdoc:literal])* $knob:ident = $from:expr ),* $(,)?
        }
    )*) => {
        /// The constraints' knobs for `p`.
        pub(crate) fn knobs(p: &SimParams) -> SimKnobs {
            SimKnobs {
                $($( $knob: {
                    let from: fn(&SimParams) -> f32 = $from;
                    from(p)
                }, )*)*
            }
        }
    };
}

include!("../gpu_types/constraints.rs");

/// The parameters a set of key hairs may have of its own in one simulation
/// ([`HairSim::set_parameter_sets`](super::HairSim)): those no control flow of
/// the step kernel and no sweep over another hair depends on.
pub(crate) const SET_FIELDS: [&str; 10] = [
    "gravity",
    "wind",
    "wind_turbulence",
    "wind_frequency",
    "spring_stiffness",
    "damping",
    "bending_root",
    "bending_tip",
    "global_shape_stiffness",
    "global_shape_range",
];

/// `step` (a sub-step of the simulation's own parameters) for a parameter
/// set `p`: its [`SET_FIELDS`] in place of the simulation's.
pub(crate) fn for_set(step: &SimStep, p: &SimParams) -> SimStep {
    SimStep {
        gravity: p.gravity,
        wind: p.wind,
        wind_turbulence: p.wind_turbulence,
        wind_frequency: p.wind_frequency,
        spring_stiffness: p.spring_stiffness,
        damping: p.damping,
        knobs: knobs(p),
        ..*step
    }
}

/// Refuses a parameter set `p` that differs from the simulation's `base`
/// anywhere but in [`SET_FIELDS`], naming the fields.
pub(crate) fn check_set(base: &SimParams, p: &SimParams) -> crate::error::Result<()> {
    p.validate()?;
    let table = |p: &SimParams| {
        toml::Table::try_from(p).map_err(|e| crate::error::Error::param("simulation parameters", e, "serialisable"))
    };
    let (a, b) = (table(base)?, table(p)?);
    let differ: Vec<&str> = a
        .keys()
        .chain(b.keys())
        .filter(|k| !SET_FIELDS.contains(&k.as_str()) && a.get(*k) != b.get(*k))
        .map(String::as_str)
        .collect();
    let (on, own) = (flags(base, false), flags(p, false));
    if differ.is_empty() && on == own {
        return Ok(());
    }
    if differ.is_empty() {
        return Err(crate::error::Error::param(
            "simulation parameters of a set",
            format!("switches {own:#x} (a global shape stiffness of 0 turns the constraint off)"),
            format!("the simulation's switches, {on:#x}"),
        ));
    }
    let mut differ = differ;
    differ.sort_unstable();
    differ.dedup();
    Err(crate::error::Error::param(
        "simulation parameters of a set",
        format!("they differ in {}", differ.join(", ")),
        format!("the simulation's but for {}", SET_FIELDS.join(", ")),
    ))
}

/// Where and when one sub-step happens.
pub(crate) struct SubstepPose {
    /// World-from-head transform at the start of the sub-step.
    pub previous_head: Mat4,
    /// World-from-head transform at its end.
    pub head: Mat4,
    /// Simulated time at its end, s.
    pub time: f32,
    /// Its index since the simulation started (wraps).
    pub index: u32,
}

/// What a simulation's groom and device fix for every sub-step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SimShape {
    pub strands: u32,
    pub points: u32,
    pub packing: Packing,
}

/// The step kernel's parameters of one sub-step of `p` at `pose`, with
/// `colliders` colliders and the mesh collider's grid when one is set.
pub(crate) fn sim_step(
    p: &SimParams,
    pose: &SubstepPose,
    shape: SimShape,
    colliders: u32,
    mesh: Option<&MeshGrid>,
) -> SimStep {
    let unset = MeshGrid { origin: glam::Vec3::ZERO, cell: 1.0, dims: [0; 3] };
    let grid = mesh.unwrap_or(&unset);
    SimStep {
        head: pose.head,
        gravity: p.gravity,
        dt: p.substep_dt(),
        wind: p.wind,
        wind_turbulence: p.wind_turbulence,
        wind_frequency: p.wind_frequency,
        time: pose.time,
        spring_stiffness: p.spring_stiffness,
        damping: p.damping,
        dftl_damping: p.dftl_damping,
        follow_fade: super::lod::FOLLOW_FADE,
        strands: shape.strands,
        points: shape.points,
        iterations: p.iterations,
        flags: flags(p, mesh.is_some()),
        colliders,
        hairs_per_group: shape.packing.hairs_per_group,
        step_index: pose.index,
        sync_group: shape.packing.sync_group,
        knobs: knobs(p),
        previous_head: pose.previous_head,
        mesh_origin: grid.origin,
        mesh_cell: grid.cell,
        mesh_dims: grid.dims,
        mesh_set: u32::from(mesh.is_some()),
        // Set by the planner when a scalp is bound (`ScalpLanes`).
        scalp_from: 0.0,
        scalp_to: 0.0,
        scalp_first: 0,
        scalp_stride: 0,
        scalp_restart: 0,
        scalp_last: 0,
    }
}

/// With a bound scalp (`sim::scalp`): where a step's skinned vertices are, and
/// whether it starts from them (no motion from the previous step's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScalpLanes {
    /// The source's float holding vertex 0's x.
    pub first: u32,
    /// Floats from one vertex to the next.
    pub stride: u32,
    /// The scalp was bound or its source changed since the last step.
    pub restart: bool,
}

impl ScalpLanes {
    /// Sub-step `k` of `count` of a step, which starts anew when `restart`.
    pub(crate) fn apply(&self, step: &mut SimStep, k: u32, count: u32, restart: bool) {
        step.flags |= sim_flags::SCALP;
        step.scalp_from = k as f32 / count as f32;
        step.scalp_to = (k + 1) as f32 / count as f32;
        step.scalp_first = self.first;
        step.scalp_stride = self.stride;
        step.scalp_restart = u32::from(restart);
        step.scalp_last = u32::from(k + 1 == count);
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::gpu_types::SimStepParams;

    /// Every knob lands in its own field, and through the packed block and
    /// back unchanged: a field packed into a wrong or shared lane fails.
    #[test]
    fn every_knob_reaches_its_field_and_survives_the_packing() {
        let p = SimParams {
            gravity: Vec3::new(0.5, -9.0, 0.25),
            wind: Vec3::new(1.5, 0.0, -2.5),
            wind_turbulence: 0.375,
            wind_frequency: 2.25,
            spring_stiffness: 3.5,
            damping: 0.0625,
            bending_root: 0.75,
            bending_tip: 0.125,
            dftl_damping: 0.8125,
            global_shape_stiffness: 0.5,
            global_shape_range: 0.625,
            local_shape_stiffness: 0.4375,
            stretch_limit: 0.09375,
            mesh_friction: 0.15625,
            iterations: 7,
            substeps: 2,
            ..SimParams::default()
        };
        let pose = SubstepPose {
            previous_head: Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            head: Mat4::from_rotation_y(0.5),
            time: 4.75,
            index: 11,
        };
        let shape = SimShape { strands: 13, points: 17, packing: Packing { sync_group: 8, hairs_per_group: 3 } };
        let grid = MeshGrid { origin: Vec3::new(-0.5, -0.25, -0.125), cell: 0.03125, dims: [21, 22, 23] };
        let s = sim_step(&p, &pose, shape, 5, Some(&grid));
        let expected = SimStep {
            head: pose.head,
            gravity: p.gravity,
            dt: p.dt / 2.0,
            wind: p.wind,
            wind_turbulence: 0.375,
            wind_frequency: 2.25,
            time: 4.75,
            spring_stiffness: 3.5,
            damping: 0.0625,
            dftl_damping: 0.8125,
            follow_fade: crate::sim::lod::FOLLOW_FADE,
            strands: 13,
            points: 17,
            iterations: 7,
            flags: sim_flags::GRAVITY
                | sim_flags::SPRING
                | sim_flags::BENDING
                | sim_flags::COLLISIONS
                | sim_flags::GLOBAL_SHAPE
                | sim_flags::SAG_FREE
                | sim_flags::LOCAL_SHAPE
                | sim_flags::MESH,
            colliders: 5,
            hairs_per_group: 3,
            step_index: 11,
            sync_group: 8,
            knobs: SimKnobs {
                bending_root: 1.0 - 0.25f32.powf(1.0 / 7.0),
                bending_tip: 1.0 - 0.875f32.powf(1.0 / 7.0),
                global_shape: 1.0 - 0.5f32.powf(1.0 / 7.0),
                global_shape_range: 0.625,
                local_shape: 0.4375,
                stretch_limit: 0.09375,
                mesh_friction: 0.15625,
            },
            previous_head: pose.previous_head,
            mesh_origin: grid.origin,
            mesh_cell: 0.03125,
            mesh_dims: [21, 22, 23],
            mesh_set: 1,
            scalp_from: 0.0,
            scalp_to: 0.0,
            scalp_first: 0,
            scalp_stride: 0,
            scalp_restart: 0,
            scalp_last: 0,
        };
        assert_eq!(s, expected);
        assert_eq!(SimStep::from(&SimStepParams::from(&s)), s, "the packing loses or mixes fields");
        // A bound scalp's lanes: sub-step 1 of 2 ends the step.
        let mut scalped = s;
        ScalpLanes { first: 9, stride: 4, restart: true }.apply(&mut scalped, 1, 2, true);
        let lanes = (scalped.scalp_from, scalped.scalp_to, scalped.scalp_first, scalped.scalp_stride);
        assert_eq!(lanes, (0.5, 1.0, 9, 4));
        assert_eq!(
            (scalped.scalp_restart, scalped.scalp_last, scalped.flags & sim_flags::SCALP),
            (1, 1, sim_flags::SCALP)
        );
        assert_eq!(SimStep::from(&SimStepParams::from(&scalped)), scalped, "the scalp lanes are lost or mixed");
        let unset = sim_step(&p, &pose, shape, 0, None);
        assert_eq!((unset.mesh_set, unset.flags & sim_flags::MESH, unset.mesh_cell), (0, 0, 1.0));
    }
}
