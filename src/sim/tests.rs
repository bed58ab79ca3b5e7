//! What a simulation compiles, and when.

use glam::Vec3;

use super::{HairSim, RigidTransform, SimParams, VolumeMode, VolumeParams};
use crate::groom::{grow, scenes, Groom};
use crate::vk::tests::TestGpu;

/// A small grown groom (40 key hairs of 6 points) and a head at the origin.
fn small_groom() -> (Groom, RigidTransform) {
    let params = grow::GrowParams { strands: 40, points_per_strand: 6, length: 0.3, ..Default::default() };
    (grow::grow(&scenes::thesis_scalp(), &params).expect("groom"), RigidTransform::default())
}

/// The step kernel is compiled only as the variants its switches ask for, the
/// followers' kernel when key hairs are first left out, the move's on the first
/// teleport: a simulation that never uses them never pays for them (compiling
/// is most of creating a simulation on a software device).
#[test]
fn kernels_are_compiled_when_a_step_first_needs_them() {
    let gpu = TestGpu::new();
    let (groom, head) = small_groom();
    let mut sim = HairSim::new(gpu.ctx(), &groom, &SimParams::default(), &head).expect("sim");
    let compiled =
        |sim: &HairSim| (sim.pipeline.is_prepared(), sim.follow.is_prepared(), sim.mover.pipeline.is_prepared());
    assert_eq!(compiled(&sim), (false, false, false), "(step without switches, followers, move) at creation");
    sim.run(2, |_| head, None).expect("steps");
    assert_eq!(compiled(&sim), (false, false, false), "after steps of every hair");
    sim.set_simulated_hairs(10).expect("level of detail");
    sim.run(1, |_| head, None).expect("step with followers");
    assert_eq!(compiled(&sim), (false, true, false), "after a step with followers");
    let before = sim.read_state().expect("state before the teleport");
    let moved = RigidTransform { translation: Vec3::new(0.0, 0.0, 2.0), ..head };
    sim.teleport(&moved).expect("teleport");
    sim.run(1, |_| moved, None).expect("step after a teleport");
    assert_eq!(compiled(&sim), (false, true, true), "after a teleport");
    let state = sim.read_state().expect("state");
    // The move took every point along with the head (one step of falling aside).
    let left = before.positions.iter().zip(&state.positions);
    let behind = left.filter(|(a, b)| (b.truncate() - a.truncate() - moved.translation).length() > 0.05).count();
    assert_eq!(behind, 0, "points not moved with the head");
}

/// New volume parameters on the same grid give the stage a simulation created
/// with them would have: the same solver for the device (not `Auto` taken
/// literally) and the kernels the new mode records, so both step to the same
/// bits.
#[test]
fn volume_parameters_set_later_step_as_if_given_at_creation() {
    let gpu = TestGpu::new();
    let (groom, head) = small_groom();
    let flip = VolumeParams { mode: VolumeMode::Flip, resolution: [8; 3], ..VolumeParams::default() };
    let friction = VolumeParams { mode: VolumeMode::Friction, ..flip.clone() };
    let given = SimParams { volume: flip, ..SimParams::default() };
    let mut created = HairSim::new(gpu.ctx(), &groom, &given, &head).expect("sim with FLIP");
    let mut changed =
        HairSim::new(gpu.ctx(), &groom, &SimParams { volume: friction, ..given.clone() }, &head).expect("sim");
    changed.set_params(&given).expect("FLIP set later");
    // The solver `Auto` stands for on this device, named.
    let solver = given.volume.solver.on_device(gpu.device().info.device_type);
    let named = SimParams { volume: VolumeParams { solver, ..given.volume.clone() }, ..given.clone() };
    let mut explicit = HairSim::new(gpu.ctx(), &groom, &named, &head).expect("sim with the solver named");
    let mut bits = Vec::new();
    for sim in [&mut created, &mut changed, &mut explicit] {
        sim.run(3, |_| head, None).expect("steps");
        let state = sim.read_state().expect("state");
        bits.push(state.positions.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>());
    }
    assert!(bits[0] == bits[2], "`Auto` stepped to other bits than the solver it stands for on this device");
    assert!(bits[0] == bits[1], "FLIP set after creation stepped to other bits than FLIP given at creation");
}
