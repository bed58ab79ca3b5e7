//! Colliders on a body that moves on its own (`HairSim::set_body_colliders`):
//! world-space colliders moved across the sub-steps of a step, against the
//! CPU reference (bit for bit on lavapipe). Under validation with
//! synchronization validation.

use glam::Vec3;
use vkhair::sim::{Collider, CpuHairSim, HairSim, RigidTransform, SimParams, SimState, MAX_COLLIDERS};
use vkhair::Groom;

use crate::common;
use common::Gpu;

/// A curtain: 12 strands of 8 points hanging 20 cm straight down from roots
/// along x at the origin's height.
fn curtain() -> Groom {
    let strands: Vec<Vec<Vec3>> = (0..12)
        .map(|s| (0..8).map(|i| Vec3::new(0.01 * s as f32 - 0.055, -0.2 * i as f32 / 7.0, 0.0)).collect())
        .collect();
    Groom::from_strands(&strands).expect("groom")
}

fn ball(z: f32) -> Collider {
    Collider::Sphere { center: Vec3::new(0.0, -0.1, z), radius: 0.03 }
}

/// How far the farthest point moved from its place in the curtain.
fn moved(state: &SimState) -> f32 {
    let rest = curtain();
    state.positions.iter().zip(rest.positions()).map(|(p, r)| p.truncate().distance(*r)).fold(0.0, f32::max)
}

/// Two steps: the ball where `first` says (if anywhere), then at z = +0.1.
fn run(gpu: &Gpu, first: Option<f32>) -> SimState {
    let params = SimParams { substeps: 4, gravity_enabled: false, ..SimParams::default() };
    let head = RigidTransform::default();
    let mut g = HairSim::new(gpu.ctx(), &curtain(), &params, &head).expect("sim");
    let mut c = CpuHairSim::new(&curtain(), &params, &head).expect("cpu sim");
    for body in [first.map(ball), Some(ball(0.1))] {
        let body: Vec<Collider> = body.into_iter().collect();
        g.set_body_colliders(&body).expect("body");
        c.set_body_colliders(&body).expect("body");
        g.run(1, |_| head, None).expect("step");
        c.step(&head).expect("cpu step");
    }
    let state = g.read_state().expect("readback");
    let apart = state.step_difference(c.state(), params.dt);
    assert!(apart <= vkhair::sim::REFERENCE_STEP_TOLERANCE_M, "GPU and CPU apart by {apart} m");
    if common::on_lavapipe(gpu.ctx()) {
        assert!(common::bits(&state) == common::bits(c.state()), "not bit for bit on lavapipe");
    }
    state
}

/// A ball swept 20 cm through the curtain in one step of four sub-steps
/// meets the strands on its way (each sub-step sees it 5 cm further, less than
/// its 6 cm diameter, one of them in the curtain's plane) and pushes them out;
/// a ball that appears at the end of the same path (first set there) never
/// touches them.
#[test]
fn a_body_collider_sweeping_through_hair_pushes_it_at_every_sub_step() {
    let gpu = Gpu::new();
    let swept = moved(&run(&gpu, Some(-0.1)));
    let appeared = moved(&run(&gpu, None));
    eprintln!("farthest point moved after the sweep: {swept} m; after the ball appeared: {appeared} m");
    assert!(swept > 0.01, "the swept ball moved the curtain by {swept} m only");
    assert!(appeared < 1e-4, "a ball appearing past the curtain moved it by {appeared} m");
}

/// On a teleport the body's colliders start where they are set (the body
/// was cut to its new place with the head), not swept from where they were.
#[test]
fn a_teleport_places_the_body_without_sweeping_it() {
    let gpu = Gpu::new();
    let params = SimParams { substeps: 4, gravity_enabled: false, ..SimParams::default() };
    let head = RigidTransform::default();
    let mut sim = HairSim::new(gpu.ctx(), &curtain(), &params, &head).expect("sim");
    sim.set_body_colliders(&[ball(-0.1)]).expect("body");
    sim.run(1, |_| head, None).expect("step");
    sim.teleport(&head).expect("teleport in place");
    sim.set_body_colliders(&[ball(0.1)]).expect("body");
    sim.run(1, |_| head, None).expect("step");
    let moved = moved(&sim.read_state().expect("readback"));
    assert!(moved < 1e-4, "the body swept through the curtain on a teleport: {moved} m");
}

/// Head and body colliders together are limited to what a sub-step holds.
#[test]
fn head_and_body_colliders_share_the_limit() {
    let gpu = Gpu::new();
    let head = RigidTransform::default();
    let mut sim = HairSim::new(gpu.ctx(), &curtain(), &SimParams::default(), &head).expect("sim");
    let half = vec![ball(1.0); MAX_COLLIDERS / 2];
    sim.set_colliders(&half).expect("half on the head");
    sim.set_body_colliders(&half).expect("half on the body");
    let err = sim.set_body_colliders(&[half.clone(), vec![ball(1.0)]].concat()).expect_err("one too many");
    assert!(err.to_string().contains("head and body colliders together"), "{err}");
    let err = sim.set_colliders(&[half, vec![ball(1.0)]].concat()).expect_err("one too many");
    assert!(err.to_string().contains("head and body colliders together"), "{err}");
    let bad = Collider::Sphere { center: Vec3::new(f32::NAN, 0.0, 0.0), radius: 0.1 };
    assert!(sim.set_body_colliders(&[bad]).is_err(), "NaN refused");
}

/// A long capsule (a shoulder) closing in on the lower curtain until the
/// strands' rest-shape spring holds them against it, then slid 5 mm a step
/// along its own axis: with `collider_friction` it carries
/// the hair touching it along (the particles' motion relative to its surface
/// is what friction takes away); without, sliding along its axis pushes
/// nothing sideways. GPU against the CPU reference at every run.
#[test]
fn a_sliding_capsule_carries_the_hair_touching_it_by_its_friction() {
    let gpu = Gpu::new();
    let slide = |friction: f32| {
        let params =
            SimParams { substeps: 4, gravity_enabled: false, collider_friction: friction, ..SimParams::default() };
        let head = RigidTransform::default();
        let mut g = HairSim::new(gpu.ctx(), &curtain(), &params, &head).expect("sim");
        let mut c = CpuHairSim::new(&curtain(), &params, &head).expect("cpu sim");
        // 6 steps closing in from z = 5 cm to 2 cm, then 16 sliding along x.
        for step in 0..22 {
            let (x, z) = (0.005 * step.max(6) as f32 - 0.03, 0.05 - 0.005 * step.min(6) as f32);
            let shoulder =
                [Collider::Capsule { a: Vec3::new(x - 0.5, -0.15, z), b: Vec3::new(x + 0.5, -0.15, z), radius: 0.03 }];
            g.set_body_colliders(&shoulder).expect("body");
            c.set_body_colliders(&shoulder).expect("body");
            g.run(1, |_| head, None).expect("step");
            c.step(&head).expect("cpu step");
        }
        let state = g.read_state().expect("readback");
        let apart = state.step_difference(c.state(), params.dt);
        assert!(
            apart <= vkhair::sim::REFERENCE_STEP_TOLERANCE_M,
            "friction {friction}: GPU and CPU apart by {apart} m"
        );
        if common::on_lavapipe(gpu.ctx()) {
            assert!(
                common::bits(&state) == common::bits(c.state()),
                "friction {friction}: not bit for bit on lavapipe"
            );
        }
        // Mean drift along x of the points below the roots' first 10 cm.
        let drift: Vec<f32> = state
            .positions
            .iter()
            .zip(curtain().positions())
            .filter(|(_, r)| r.y < -0.1)
            .map(|(p, r)| p.x - r.x)
            .collect();
        drift.iter().sum::<f32>() / drift.len() as f32
    };
    let held = slide(0.3);
    let free = slide(0.0);
    eprintln!("mean drift along the capsule's slide (8 cm): friction 0.3 {held} m, friction 0 {free} m");
    assert!(held > 0.003, "friction carried the hair by {held} m only");
    assert!(free.abs() < 1e-4, "a capsule sliding along its own axis without friction moved the hair by {free} m");
}
