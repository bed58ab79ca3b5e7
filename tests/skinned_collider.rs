//! The skinned mesh collider (`MeshCollider::skinned`): a field that follows
//! bones, on a two-bone arm whose upper half bends 90° at the elbow. The
//! hair is checked against the bent arm's own shape (an ellipsoid turned by
//! the upper bone), the GPU against the CPU reference, and bad input refused.

use crate::common;

use common::Gpu;
use glam::{Mat4, Quat, Vec3};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::Groom;
use vkhair::sim::scalp::VertexSkin;
use vkhair::sim::{CpuHairSim, HairSim, MeshCollider, MeshColliderParams, RigidTransform, SimParams, SimState};

/// Half extents of the arm: an ellipsoid along y centred at the elbow (the origin).
const ARM: Vec3 = Vec3::new(0.05, 0.25, 0.05);
/// Below −BLEND the lower bone (0) skins the arm alone, above BLEND the upper
/// one (1), linearly between.
const BLEND: f32 = 0.03;
/// Steps over which the upper bone turns from 0 to 90°, then steps held there.
const TURN_STEPS: usize = 20;
const HOLD_STEPS: usize = 10;

fn arm() -> (TriMesh, Vec<VertexSkin>) {
    let unit = TriMesh::uv_sphere(Vec3::ZERO, 1.0, 24, 24).expect("sphere");
    let mesh = TriMesh::new(unit.positions.iter().map(|p| *p * ARM).collect(), unit.triangles).expect("arm");
    let skin = mesh
        .positions
        .iter()
        .map(|p| {
            let upper = ((p.y + BLEND) / (2.0 * BLEND)).clamp(0.0, 1.0);
            VertexSkin { joints: [0, 1, 0, 0], weights: [1.0 - upper, upper, 0.0, 0.0] }
        })
        .collect();
    (mesh, skin)
}

/// The bones at step `step` (its end): the lower one still, the upper one
/// turned about z at the elbow, reaching 90° (the upper arm along −x) after
/// [`TURN_STEPS`].
fn bones(step: usize) -> [Mat4; 2] {
    let angle = std::f32::consts::FRAC_PI_2 * ((step + 1) as f32 / TURN_STEPS as f32).min(1.0);
    [Mat4::IDENTITY, Mat4::from_quat(Quat::from_rotation_z(angle))]
}

/// Whether `p` lies inside the bent arm's upper part, deeper than `depth`
/// (measured along the ellipsoid's axes): the ellipsoid's part skinned by the
/// upper bone alone, turned by 90°.
fn inside_bent_upper_arm(p: Vec3, depth: f32) -> bool {
    let q = Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2) * p;
    let shrunk = ARM - Vec3::splat(depth);
    q.y > BLEND && (q / shrunk).length_squared() < 1.0
}

/// Nine hairs hanging across where the upper arm ends up: roots pinned at
/// y = 0.2, 16 points down to y = −0.2, at x from −0.18 to −0.12 (all outside
/// the unbent arm).
fn curtain() -> Groom {
    let strands: Vec<Vec<Vec3>> = (0..9)
        .map(|s| {
            let (x, z) = (-0.12 - 0.03 * (s / 3) as f32, -0.02 + 0.02 * (s % 3) as f32);
            (0..16).map(|i| Vec3::new(x, 0.2 - 0.4 * i as f32 / 15.0, z)).collect()
        })
        .collect();
    Groom::from_strands(&strands).expect("curtain")
}

fn params() -> MeshColliderParams {
    MeshColliderParams { resolution: 48, margin: 0.03 }
}

/// Free points of `state` inside the bent upper arm by more than 1 mm.
fn inside(state: &SimState) -> usize {
    state.positions.iter().filter(|p| p.w > 0.0 && inside_bent_upper_arm(p.truncate(), 1e-3)).count()
}

/// Runs the turn and the hold on the GPU with `collider`, handing it the bones
/// when it is skinned; returns the last state.
fn bend(gpu: &Gpu, collider: MeshCollider) -> SimState {
    let skinned = collider.skin().is_some();
    let mut sim = HairSim::new(gpu.ctx(), &curtain(), &SimParams::default(), &RigidTransform::default()).expect("sim");
    sim.set_mesh_collider(Some(collider)).expect("set");
    for step in 0..TURN_STEPS + HOLD_STEPS {
        if skinned {
            sim.set_mesh_bones(&bones(step)).expect("bones");
        }
        sim.run(1, |_| RigidTransform::default(), None).expect("step");
    }
    sim.read_state().expect("readback")
}

/// The bent arm pushes the hair out of its own bent shape: no free point ends
/// inside it by more than 1 mm. The same arm as a rigid collider (its field
/// where the head puts it, unbent) leaves points inside the bent arm.
#[test]
fn a_skinned_field_keeps_hair_out_of_the_bent_arm() {
    let gpu = Gpu::new();
    let (mesh, skin) = arm();
    let rigid = bend(&gpu, MeshCollider::new(gpu.ctx(), &mesh, &params()).expect("rigid collider"));
    let left_in = inside(&rigid);
    eprintln!("rigid collider: {left_in} points inside the bent arm");
    assert!(left_in > 0, "the rigid collider was expected to miss the bent arm");
    let state = bend(&gpu, MeshCollider::skinned(gpu.ctx(), &mesh, &skin, &params()).expect("skinned collider"));
    assert!(state.positions.iter().all(|p| p.is_finite()), "NaN or Inf");
    assert_eq!(inside(&state), 0, "points inside the bent arm with the skinned collider");
}

/// GPU and CPU agree with a skinned collider through the turn (bit for bit on
/// lavapipe, else within one step's tolerance: `common::agree`).
#[test]
fn gpu_matches_cpu_with_a_skinned_mesh_collider() {
    let gpu = Gpu::new();
    let (mesh, skin) = arm();
    let params = SimParams::default();
    let collider = MeshCollider::skinned(gpu.ctx(), &mesh, &skin, &self::params()).expect("collider");
    let field = collider.read_field().expect("field");
    let bones_of_grid = collider.skin().cloned().expect("a skinned collider has bones");
    assert_eq!(bones_of_grid.joints, vec![0, 1]);
    let mut sim = HairSim::new(gpu.ctx(), &curtain(), &params, &RigidTransform::default()).expect("sim");
    let mut cpu = CpuHairSim::new(&curtain(), &params, &RigidTransform::default()).expect("cpu");
    sim.set_mesh_collider(Some(collider)).expect("set");
    let mut foreign = bones_of_grid.clone();
    foreign.words[7] |= 5 << 8;
    let named = cpu.set_skinned_mesh_collider(field.clone(), foreign).expect_err("slot 5 of 2").to_string();
    assert!(named.contains("grid point 7"), "{named}");
    let short = vkhair::sim::MeshSkin { words: bones_of_grid.words[1..].to_vec(), ..bones_of_grid.clone() };
    assert!(cpu.set_skinned_mesh_collider(field.clone(), short).is_err(), "a skin of another grid was taken");
    cpu.set_skinned_mesh_collider(field, bones_of_grid).expect("cpu collider");
    for step in 0..TURN_STEPS + HOLD_STEPS {
        sim.set_mesh_bones(&bones(step)).expect("bones");
        cpu.set_mesh_bones(&bones(step)).expect("cpu bones");
        sim.run(1, |_| RigidTransform::default(), None).expect("step");
        cpu.step(&RigidTransform::default()).expect("cpu step");
        let state = sim.read_state().expect("readback");
        common::agree(gpu.ctx(), &state, &mut cpu, params.dt, &format!("step {step}"));
    }
}

/// Bad skins and bones are refused, naming the problem; a step without bones
/// is refused rather than run against an unplaced field.
#[test]
fn a_skinned_collider_refuses_bad_skins_and_bones() {
    let gpu = Gpu::new();
    let (mesh, skin) = arm();
    let message = |r: vkhair::Result<MeshCollider>| r.expect_err("refused").to_string();
    let short = message(MeshCollider::skinned(gpu.ctx(), &mesh, &skin[1..], &params()));
    assert!(short.contains("vertices have bones"), "{short}");
    let mut heavy = skin.clone();
    heavy[5].weights = [0.7, 0.7, 0.0, 0.0];
    let weights = message(MeshCollider::skinned(gpu.ctx(), &mesh, &heavy, &params()));
    assert!(weights.contains("vertex 5"), "{weights}");
    let many: Vec<VertexSkin> = (0..skin.len())
        .map(|v| VertexSkin { joints: [(v % 40) as u32, 0, 0, 0], weights: [1.0, 0.0, 0.0, 0.0] })
        .collect();
    let bones_over = message(MeshCollider::skinned(gpu.ctx(), &mesh, &many, &params()));
    assert!(bones_over.contains("40 bones") && bones_over.contains("at most 32"), "{bones_over}");

    let mut sim = HairSim::new(gpu.ctx(), &curtain(), &SimParams::default(), &RigidTransform::default()).expect("sim");
    let none = sim.set_mesh_bones(&bones(0)).expect_err("no skinned collider").to_string();
    assert!(none.contains("no skinned mesh collider"), "{none}");
    let collider = MeshCollider::skinned(gpu.ctx(), &mesh, &skin, &params()).expect("collider");
    sim.set_mesh_collider(Some(collider)).expect("set");
    let unplaced = sim.run(1, |_| RigidTransform::default(), None).expect_err("no bones yet").to_string();
    assert!(unplaced.contains("needs its bones"), "{unplaced}");
    let missing = sim.set_mesh_bones(&bones(0)[..1]).expect_err("one bone of two").to_string();
    assert!(missing.contains("mesh collider bone") && missing.contains('1'), "{missing}");
    let mut bad = bones(0);
    bad[1].w_axis.x = f32::NAN;
    let nan = sim.set_mesh_bones(&bad).expect_err("NaN bone").to_string();
    assert!(nan.contains("bone 1") && nan.contains("finite"), "{nan}");
    sim.set_mesh_bones(&bones(0)).expect("bones");
    sim.run(1, |_| RigidTransform::default(), None).expect("a step once the bones are given");
}

/// Through the frame scheduler, on one queue and on a second device (whose
/// worker builds the field): the bones are checked before they leave the
/// host's thread, and the state after the bend is the direct simulation's,
/// bit for bit.
#[test]
fn the_scheduler_hands_a_skinned_collider_and_its_bones_over() {
    use vkhair::headless::Submit;
    use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
    let render = Gpu::new();
    let second = Gpu::new();
    let (mesh, skin) = arm();
    let direct = bend(&render, MeshCollider::skinned(render.ctx(), &mesh, &skin, &params()).expect("collider"));
    let modes = [
        SchedulerOptions { mode: Some(ScheduleMode::SingleQueue), ..SchedulerOptions::default() },
        SchedulerOptions {
            mode: Some(ScheduleMode::SecondDevice),
            sim_device: Some(second.ctx().clone()),
            hand_off: Some(HandOff::HostStaging),
            pipelining: Pipelining::Latency,
            ..SchedulerOptions::default()
        },
    ];
    let head = RigidTransform::default();
    for options in modes {
        let mut s = FrameScheduler::new(render.ctx(), &curtain(), &SimParams::default(), &head, &[], &options)
            .expect("scheduler");
        let early = s.set_mesh_bones(&bones(0)).expect_err("no skinned collider yet").to_string();
        assert!(early.contains("no skinned mesh collider"), "{early}");
        let short = s.set_skinned_mesh_collider(&mesh, &skin, &bones(0)[..1], &params()).expect_err("one bone");
        assert!(short.to_string().contains("mesh collider bone"), "{short}");
        s.set_skinned_mesh_collider(&mesh, &skin, &bones(0), &params()).expect("collider");
        let mut nan = bones(0);
        nan[0].x_axis.y = f32::INFINITY;
        assert!(s.set_mesh_bones(&nan).is_err(), "a non-finite bone was taken");
        for step in 0..TURN_STEPS + HOLD_STEPS {
            s.set_mesh_bones(&bones(step)).expect("bones");
            // SAFETY: a recording command buffer of the rendering device, waited for.
            render.ctx().run_frame("frame", |cmd| unsafe { s.record_frame(cmd, &[head], None) }).expect("frame");
        }
        let state = s.read_state().expect("state");
        assert!(common::bits(&state) == common::bits(&direct), "{:?}: not the direct simulation's state", options.mode);
    }
}
