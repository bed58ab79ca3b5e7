//! What a simulation compiles, and when.

use glam::Vec3;

use super::{HairSim, RigidTransform, SimParams};
use crate::groom::{grow, scenes};
use crate::vk::tests::TestGpu;

/// The step kernel is compiled only as the variants its switches ask for, the
/// followers' kernel when key hairs are first left out, the move's on the first
/// teleport: a simulation that never uses them never pays for them (compiling
/// is most of creating a simulation on a software device).
#[test]
fn kernels_are_compiled_when_a_step_first_needs_them() {
    let gpu = TestGpu::new();
    let params = grow::GrowParams { strands: 40, points_per_strand: 6, length: 0.3, ..Default::default() };
    let groom = grow::grow(&scenes::thesis_scalp(), &params).expect("groom");
    let head = RigidTransform::default();
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
