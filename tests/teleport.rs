//! Cuts and teleports: `HairSim::teleport`, `HairSim::reset` and
//! `SimParams::teleport_distance`, against a head that stays where it is and
//! against the CPU reference (bit for bit on lavapipe). Every test runs under
//! validation with synchronization validation.

use glam::{Quat, Vec3};
use vkhair::sim::{motion, CpuHairSim, HairSim, RigidTransform, SimParams, SimState, REFERENCE_STEP_TOLERANCE_M};
use vkhair::{GpuContext, Groom};

use crate::common;
use common::{grown_groom, Gpu};

/// Steps of head shaking before the cut: the hair is in motion when it comes.
const SWING: usize = 20;
/// Steps after the cut.
const AFTER: usize = 10;

fn groom() -> Groom {
    grown_groom(48, 16, 7)
}

fn shaking(step: usize, params: &SimParams) -> RigidTransform {
    motion::shaking_head((step + 1) as f32 * params.dt, 0.6, 1.5)
}

/// A GPU simulation and its CPU reference after `SWING` steps of shaking; the
/// head where the shaking stopped.
fn swung(ctx: &GpuContext, params: &SimParams) -> (HairSim, CpuHairSim, RigidTransform) {
    let head0 = RigidTransform::default();
    let mut gpu = HairSim::new(ctx, &groom(), params, &head0).expect("gpu sim");
    let mut cpu = CpuHairSim::new(&groom(), params, &head0).expect("cpu sim");
    let colliders = motion::thesis_colliders();
    gpu.set_colliders(&colliders).expect("colliders");
    cpu.set_colliders(&colliders).expect("colliders");
    common::run_both(ctx, (&mut gpu, &mut cpu), 0..SWING, |i| shaking(i, params), "swing");
    (gpu, cpu, shaking(SWING - 1, params))
}

/// Kinetic energy after each of `AFTER` steps at `head`, and the last state;
/// the CPU reference steps along and must agree.
fn hold(ctx: &GpuContext, gpu: &mut HairSim, cpu: &mut CpuHairSim, head: &RigidTransform) -> (Vec<f64>, SimState) {
    let mut energy = Vec::new();
    for _ in 0..AFTER {
        gpu.run(1, |_| *head, None).expect("step");
        cpu.step(head).expect("cpu step");
        let state = gpu.read_state().expect("readback");
        common::agree(ctx, &state, cpu, gpu.params().dt, "after the cut");
        energy.push(state.kinetic_energy());
    }
    (energy, gpu.read_state().expect("readback"))
}

fn moved(head: &RigidTransform, by: Vec3) -> RigidTransform {
    RigidTransform { rotation: head.rotation, translation: head.translation + by }
}

/// The largest distance between `a` moved by `m` and `b`, meters.
fn apart_after(a: &SimState, m: glam::Mat4, b: &SimState) -> f32 {
    a.positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| m.transform_point3(p.truncate()).distance(q.truncate()))
        .fold(0.0, f32::max)
}

/// A 10 m cut while the hair swings: with `teleport` (or detected by the
/// teleport distance) the following steps have the energy of a head that
/// stayed (within 1 %) and the hair is where that head's hair is, 10 m away;
/// without either, the hair is dragged across the jump and explodes.
#[test]
fn a_ten_metre_teleport_leaves_the_hair_as_calm_as_a_still_head() {
    let gpu = Gpu::new();
    // Two sub-steps: the head is interpolated between them, and must not be
    // across the jump.
    let params = SimParams { substeps: 2, ..SimParams::default() };
    let jump = Vec3::new(10.0, 0.0, 0.0);

    let (mut g, mut c, head) = swung(gpu.ctx(), &params);
    let (still, still_state) = hold(gpu.ctx(), &mut g, &mut c, &head);

    let far = moved(&head, jump);
    let (mut g, mut c, _) = swung(gpu.ctx(), &params);
    g.teleport(&far).expect("teleport");
    c.teleport(&far).expect("teleport");
    let (called, called_state) = hold(gpu.ctx(), &mut g, &mut c, &far);

    let (mut g, mut c, _) = swung(gpu.ctx(), &params);
    let (detected, _) = hold(gpu.ctx(), &mut g, &mut c, &far);

    let off = SimParams { teleport_distance: 1e6, ..params.clone() };
    let (mut g, mut c, _) = swung(gpu.ctx(), &off);
    let (dragged, _) = hold(gpu.ctx(), &mut g, &mut c, &far);

    eprintln!("energy after the cut, J/kg: still {still:?}\n teleport {called:?}\n detected {detected:?}\n dragged {dragged:?}");
    for (k, e) in still.iter().enumerate() {
        for (what, got) in [("teleport", called[k]), ("detected", detected[k])] {
            assert!((got - e).abs() <= 0.01 * e + 1e-9, "{what}, step {k}: energy {got} against {e} for a still head");
        }
    }
    assert!(dragged[0] > 1000.0 * still[0], "a 10 m drag without a teleport: {} against {}", dragged[0], still[0]);
    let apart = apart_after(&still_state, glam::Mat4::from_translation(jump), &called_state);
    eprintln!("teleported hair against the still head's, moved 10 m: {apart:e} m");
    assert!(apart < 1e-3, "teleported hair {apart} m from the still head's hair");
}

/// A teleport with a quarter turn: without gravity every force turns with the
/// head, so the hair after the cut is the still head's hair turned and moved
/// (velocities turned too, else it would swing the wrong way).
#[test]
fn a_teleport_turns_positions_and_velocities_with_the_head() {
    let gpu = Gpu::new();
    let params = SimParams { gravity_enabled: false, ..SimParams::default() };
    let (mut g, mut c, head) = swung(gpu.ctx(), &params);
    let (_, still_state) = hold(gpu.ctx(), &mut g, &mut c, &head);

    let turn = RigidTransform {
        rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        translation: Vec3::new(3.0, 1.0, -2.0),
    };
    let to = RigidTransform {
        rotation: turn.rotation * head.rotation,
        translation: turn.rotation * head.translation + turn.translation,
    };
    let (mut g, mut c, _) = swung(gpu.ctx(), &params);
    g.teleport(&to).expect("teleport");
    c.teleport(&to).expect("teleport");
    let (energy, turned) = hold(gpu.ctx(), &mut g, &mut c, &to);
    assert!(energy[0] > 1e-6, "the hair still moves after the cut: {energy:?}");
    let apart = apart_after(&still_state, turn.matrix(), &turned);
    eprintln!("turned hair against the still head's, turned: {apart:e} m");
    assert!(apart < 1e-3, "teleported hair {apart} m from the turned still hair");
}

/// `reset` puts the hair back at rest where the head is: one step after it is
/// the first step of a new simulation started at rest at that head; with a
/// teleport asked before or after it, at the teleport's head.
#[test]
fn reset_starts_again_from_rest_at_the_current_head() {
    let gpu = Gpu::new();
    let params = SimParams::default();
    let (mut g, mut c, head) = swung(gpu.ctx(), &params);
    let far = moved(&head, Vec3::new(0.0, 0.0, -4.0));
    for (teleport, at) in [(false, head), (true, far)] {
        let mut fresh = HairSim::new(gpu.ctx(), &groom(), &params, &at).expect("fresh sim");
        fresh.set_colliders(&motion::thesis_colliders()).expect("colliders");
        fresh.run(1, |_| at, None).expect("fresh step");
        let expected = fresh.read_state().expect("readback");
        // The reset asked before the teleport on the GPU, after it on the CPU:
        // either order keeps both.
        g.reset();
        if teleport {
            g.teleport(&far).expect("teleport");
            c.teleport(&far).expect("teleport");
        }
        c.reset();
        g.run(1, |_| at, None).expect("step");
        c.step(&at).expect("cpu step");
        let state = g.read_state().expect("readback");
        let apart = state.step_difference(&expected, params.dt);
        let reference = state.step_difference(c.state(), params.dt);
        eprintln!("teleport {teleport}: reset against a fresh start {apart:e} m, against the CPU {reference:e} m");
        assert!(apart <= 1e-6, "teleport {teleport}: one step after the reset {apart} m from a fresh start");
        assert!(reference <= REFERENCE_STEP_TOLERANCE_M, "teleport {teleport}: GPU and CPU apart by {reference} m");
    }
}

/// A teleport to a head with NaN is refused when asked for, before any GPU work.
#[test]
fn a_teleport_to_a_broken_transform_is_refused() {
    let gpu = Gpu::new();
    let head = RigidTransform::default();
    let mut sim = HairSim::new(gpu.ctx(), &groom(), &SimParams::default(), &head).expect("sim");
    let broken = RigidTransform { translation: Vec3::new(f32::NAN, 0.0, 0.0), ..head };
    let err = sim.teleport(&broken).expect_err("NaN refused");
    assert!(err.to_string().contains("head transform"), "{err}");
    let err = SimParams { teleport_distance: 0.0, ..SimParams::default() }.validate().expect_err("0 refused");
    assert!(err.to_string().contains("teleport_distance"), "{err}");
}
