//! Roots bound to a skinned scalp (`HairSim::bind_scalp_source`,
//! `HairSim::bind_scalp_bones`, `sim::scalp`): a procedural rig (a neck bone
//! and a head bone, the lower scalp weighted to both, so that it stretches
//! when the head turns on the neck), its scalp skinned by bone matrices or
//! read from a host's buffer, against the CPU reference bit for bit on
//! lavapipe, the roots on their skinned triangles and the cut in their
//! frames. Every test runs under validation with synchronization validation.

use ash::vk;
use glam::{Mat4, Quat, Vec3};
use vkhair::groom::mesh::TriMesh;
use vkhair::headless::HostBuffer;
use vkhair::sim::scalp::{Scalp, VertexSkin};
use vkhair::sim::{CpuHairSim, HairSim, RigidTransform, SimParams, SimState};
use vkhair::Groom;

use crate::common;
use common::{bits, Gpu};

/// The head's centre in the bind pose (the neck bone turns about the origin).
const CENTRE: Vec3 = Vec3::new(0.0, 0.25, 0.0);
const RADIUS: f32 = 0.1;
const RINGS: usize = 8;
const SEGMENTS: usize = 16;
const POINTS: usize = 8;

/// The scalp: a sphere cap from the crown to 100° below it, its lower rings
/// weighted between the neck (bone 0) and the head (bone 1).
fn scalp() -> Scalp {
    let mut positions = vec![CENTRE + Vec3::Y * RADIUS];
    for ring in 1..=RINGS {
        let polar = (100f32.to_radians()) * ring as f32 / RINGS as f32;
        for j in 0..SEGMENTS {
            let azimuth = std::f32::consts::TAU * j as f32 / SEGMENTS as f32;
            let d = Vec3::new(polar.sin() * azimuth.cos(), polar.cos(), polar.sin() * azimuth.sin());
            positions.push(CENTRE + d * RADIUS);
        }
    }
    let at = |ring: usize, j: usize| (1 + (ring - 1) * SEGMENTS + j % SEGMENTS) as u32;
    let mut triangles = Vec::new();
    for j in 0..SEGMENTS {
        triangles.push([0, at(1, j + 1), at(1, j)]);
    }
    for ring in 1..RINGS {
        for j in 0..SEGMENTS {
            triangles.push([at(ring, j), at(ring, j + 1), at(ring + 1, j)]);
            triangles.push([at(ring, j + 1), at(ring + 1, j + 1), at(ring + 1, j)]);
        }
    }
    let skin = positions
        .iter()
        .map(|p| {
            let head = ((p.y - (CENTRE.y - 0.06)) / 0.12).clamp(0.0, 1.0);
            VertexSkin { joints: [0, 1, 0, 0], weights: [1.0 - head, head, 0.0, 0.0] }
        })
        .collect();
    let mesh = TriMesh::new(positions, triangles).expect("a valid scalp");
    Scalp { skin, ..Scalp::new(mesh) }
}

/// A strand from the centre of every other triangle of rings 1 to 5 (exactly
/// on the scalp), out along the normal and bending down.
fn groom(scalp: &Scalp) -> Groom {
    let mesh = &scalp.mesh;
    let strands: Vec<Vec<Vec3>> = (0..SEGMENTS * 9)
        .step_by(2)
        .map(|t| {
            let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
            let root = (a + b + c) / 3.0;
            let normal = (b - a).cross(c - a).normalize();
            let mut points = vec![root];
            for k in 1..POINTS {
                let bend = k as f32 / POINTS as f32;
                let dir = (normal * (1.0 - bend) - Vec3::Y * bend).normalize();
                points.push(points[k - 1] + dir * 0.02);
            }
            points
        })
        .collect();
    Groom::from_strands(&strands).expect("a valid groom")
}

/// The rig at time `t`: the whole body walking along x, the neck turning
/// `neck` rad about y, the head `turn` rad more about its centre (and nodding).
fn bones(t: f32, neck: f32, turn: f32) -> [Mat4; 2] {
    let walk = Mat4::from_translation(Vec3::new(0.4 * t, 0.0, 0.0));
    let neck_bone = walk * Mat4::from_rotation_y(neck);
    let head_local = Mat4::from_translation(CENTRE)
        * Mat4::from_quat(Quat::from_rotation_y(turn) * Quat::from_rotation_x(0.3 * turn))
        * Mat4::from_translation(-CENTRE);
    [neck_bone, neck_bone * head_local]
}

/// The head bone as the simulation's head (it places colliders and decides teleports).
fn head_of(bones: &[Mat4; 2]) -> RigidTransform {
    let (_, rotation, translation) = bones[1].to_scale_rotation_translation();
    RigidTransform { rotation, translation }
}

/// The motion of the first tests: a head turning back and forth on a turning neck.
fn swinging(step: usize, dt: f32) -> [Mat4; 2] {
    let t = (step + 1) as f32 * dt;
    bones(t, 0.4 * (3.0 * t).sin(), 1.2 * (5.0 * t).sin())
}

fn params() -> SimParams {
    SimParams { substeps: 2, local_shape_stiffness: 0.3, ..SimParams::styled() }
}

/// Steps the GPU through the bone path and the CPU reference side by side,
/// with a level of detail, a teleport and a reset, and checks that they agree
/// after every step (bit for bit on lavapipe; elsewhere within one step's
/// reference tolerance, `common::agree`).
#[test]
fn gpu_and_cpu_agree_on_a_skinned_scalp() {
    let gpu_ctx = Gpu::new();
    let ctx = gpu_ctx.ctx();
    let (scalp, p) = (scalp(), params());
    let groom = groom(&scalp);
    let start = swinging(0, 0.0);
    let mut gpu = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
    let mut cpu = CpuHairSim::new(&groom, &p, &head_of(&start)).expect("cpu sim");
    gpu.bind_scalp_bones(&scalp, &start).expect("bind on the gpu");
    cpu.bind_scalp(&scalp, &scalp.skin(&start).expect("skinned")).expect("bind on the cpu");
    gpu.set_simulated_hairs(groom.strand_count() / 2).expect("lod");
    cpu.set_simulated_hairs(groom.strand_count() / 2).expect("lod");
    let far = Mat4::from_translation(Vec3::new(10.0, 0.0, 3.0));
    for step in 0..24 {
        let mut b = swinging(step, p.dt);
        if step >= 10 {
            b = b.map(|m| far * m);
        }
        if step == 10 {
            gpu.teleport(&head_of(&b)).expect("teleport");
            cpu.teleport(&head_of(&b)).expect("teleport");
        }
        if step == 17 {
            gpu.reset();
            cpu.reset();
        }
        gpu.set_scalp_bones(&b).expect("gpu bones");
        cpu.set_scalp_bones(&b).expect("cpu bones");
        gpu.run(1, |_| head_of(&b), None).expect("gpu step");
        cpu.step(&head_of(&b)).expect("cpu step");
        let state = gpu.read_state().expect("readback");
        assert!(state.positions.iter().all(|x| x.is_finite()), "step {step}: non-finite state");
        common::agree(ctx, &state, &mut cpu, p.dt, &format!("step {step}"));
    }
}

/// The host's buffer (xyz floats 20 bytes apart, at an offset alternating
/// between two halves, as a host with two frames in flight keeps them) gives
/// the state the bone path gives, bit for bit.
#[test]
fn a_host_buffer_gives_what_the_bones_give() {
    let gpu_ctx = Gpu::new();
    let ctx = gpu_ctx.ctx();
    let (scalp, p) = (scalp(), params());
    let groom = groom(&scalp);
    let vertices = scalp.mesh.positions.len();
    let stride = 20u64;
    let half = stride * vertices as u64;
    let buffer = HostBuffer::new(ctx, "test skinned scalp", 2 * half).expect("host buffer");
    let write = |offset: u64, b: &[Mat4; 2]| {
        let skinned = scalp.skin(b).expect("skinned");
        let mut bytes = vec![0u8; half as usize];
        for (v, p) in skinned.iter().enumerate() {
            let at = v * stride as usize;
            bytes[at..at + 12].copy_from_slice(bytemuck::cast_slice(&p.to_array()));
        }
        buffer.write(offset, &bytes).expect("write the host buffer");
    };
    let start = swinging(0, 0.0);
    write(0, &start);
    let source = buffer.scalp_source(stride, vk::Format::R32G32B32_SFLOAT, vertices as u32);
    let mut host = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
    let mut boned = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
    // SAFETY: the buffer is the context's, has storage usage and outlives `host`;
    // each write below completes before the step that reads it is submitted.
    unsafe { host.bind_scalp_source(&scalp, &source) }.expect("bind the host buffer");
    boned.bind_scalp_bones(&scalp, &start).expect("bind bones");
    for step in 0..12 {
        let b = swinging(step, p.dt);
        let offset = (step as u64 % 2) * half;
        write(offset, &b);
        host.set_scalp_offset(offset).expect("offset");
        boned.set_scalp_bones(&b).expect("bones");
        host.run(1, |_| head_of(&b), None).expect("host step");
        boned.run(1, |_| head_of(&b), None).expect("bones step");
    }
    let (a, b) = (host.read_state().expect("readback"), boned.read_state().expect("readback"));
    assert_eq!(bits(&a), bits(&b), "the host buffer and the bones disagree");
    drop((host, boned, buffer));
}

/// The roots' distance from their skinned triangle points, meters, at most.
fn root_error(state: &SimState, scalp: &Scalp, groom: &Groom, skinned: &[Vec3]) -> f32 {
    // Each root was grown at the centre of the triangle `2s` (see `groom`).
    (0..groom.strand_count())
        .map(|s| {
            let t = scalp.mesh.triangles[2 * s];
            let point = t.iter().map(|&v| skinned[v as usize]).sum::<Vec3>() / 3.0;
            state.positions[s * state.points].truncate().distance(point)
        })
        .fold(0.0, f32::max)
}

/// Tip drift in each root's own frame: the tip against the rest tip placed by
/// the frame of the root's triangle now (relative to the strand's length).
fn tip_drift_in_root_frames(state: &SimState, scalp: &Scalp, skinned: &[Vec3]) -> Vec<f32> {
    let frame = |corners: [Vec3; 3]| {
        let [a, b, c] = corners;
        let z = (b - a).cross(c - a).normalize();
        let x = ((b - a) - z * z.dot(b - a)).normalize();
        Mat4::from_cols(x.extend(0.0), z.cross(x).extend(0.0), z.extend(0.0), ((a + b + c) / 3.0).extend(1.0))
    };
    (0..state.strands)
        .map(|s| {
            let t = scalp.mesh.triangles[2 * s];
            let now = frame(t.map(|v| skinned[v as usize]));
            let bind = frame(t.map(|v| scalp.mesh.positions[v as usize]));
            let rest_tip = state.rest[(s + 1) * state.points - 1].truncate();
            let placed = (now * bind.inverse()).transform_point3(rest_tip);
            let tip = state.positions[(s + 1) * state.points - 1].truncate();
            tip.distance(placed) / state.rest_strand_length(s)
        })
        .collect()
}

/// A quarter turn of the head on the neck in 0.3 s, then held: the roots ride
/// their skinned triangles to float precision (a rigid head misses them by
/// centimetres on the stretched scalp) and the cut holds in the roots' frames.
#[test]
fn roots_ride_their_triangles_and_the_cut_holds() {
    let gpu_ctx = Gpu::new();
    let ctx = gpu_ctx.ctx();
    let (scalp, p) = (scalp(), params());
    let groom = groom(&scalp);
    let turn = |step: usize| {
        let t = (step + 1) as f32 * p.dt;
        bones(t.min(0.3), 0.0, std::f32::consts::FRAC_PI_2 * (t / 0.3).min(1.0))
    };
    let start = bones(0.0, 0.0, 0.0);
    let mut bound = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
    let mut rigid = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
    bound.bind_scalp_bones(&scalp, &start).expect("bind");
    let (mut bound_error, mut rigid_error) = (0.0f32, 0.0f32);
    let steps = 90;
    for step in 0..steps {
        let b = turn(step);
        bound.set_scalp_bones(&b).expect("bones");
        bound.run(1, |_| head_of(&b), None).expect("bound step");
        rigid.run(1, |_| head_of(&b), None).expect("rigid step");
        let skinned = scalp.skin(&b).expect("skinned");
        bound_error = bound_error.max(root_error(&bound.read_state().expect("readback"), &scalp, &groom, &skinned));
        rigid_error = rigid_error.max(root_error(&rigid.read_state().expect("readback"), &scalp, &groom, &skinned));
    }
    println!("roots from their skinned points: bound {bound_error:.2e} m, rigid head {rigid_error:.2e} m");
    assert!(bound_error < 2e-6, "bound roots {bound_error} m from their triangles");
    assert!(rigid_error > 3e-3, "the rig does not stretch the scalp: a rigid head misses by only {rigid_error} m");
    let skinned = scalp.skin(&turn(steps)).expect("skinned");
    let mut drift = tip_drift_in_root_frames(&bound.read_state().expect("readback"), &scalp, &skinned);
    drift.sort_by(f32::total_cmp);
    let p95 = drift[drift.len() * 95 / 100];
    println!(
        "tip drift in the roots' frames after the turn: p50 {:.2} % p95 {:.2} %",
        100.0 * drift[drift.len() / 2],
        100.0 * p95
    );
    assert!(p95 < 0.05, "the cut did not hold in the roots' frames: tip drift p95 {:.1} %", 100.0 * p95);
}

/// Bad sources, bones and roots are named before anything is recorded; a
/// scalp bound and unbound again leaves the rigid head's state bit for bit.
#[test]
fn bad_scalps_are_named_and_unbinding_restores_the_rigid_head() {
    let gpu_ctx = Gpu::new();
    let ctx = gpu_ctx.ctx();
    let (scalp, p) = (scalp(), params());
    let groom = groom(&scalp);
    let head = head_of(&bones(0.0, 0.0, 0.0));
    let mut sim = HairSim::new(ctx, &groom, &p, &head).expect("gpu sim");
    let mut plain = HairSim::new(ctx, &groom, &p, &head).expect("gpu sim");
    let vertices = scalp.mesh.positions.len() as u32;
    let buffer = HostBuffer::new(ctx, "test scalp", u64::from(vertices) * 16).expect("buffer");
    let cases = [
        (buffer.scalp_source(8, vk::Format::R32G32B32_SFLOAT, vertices), "stride"),
        (buffer.scalp_source(14, vk::Format::R32G32B32_SFLOAT, vertices), "stride"),
        (buffer.scalp_source(16, vk::Format::R16G16B16A16_SFLOAT, vertices), "format"),
        (buffer.scalp_source(16, vk::Format::R32G32B32A32_SFLOAT, vertices - 1), "vertex count"),
        (buffer.scalp_source(32, vk::Format::R32G32B32A32_SFLOAT, vertices), "size"),
    ];
    for (source, named) in cases {
        // SAFETY: the buffer is the context's, with storage usage; refused anyway.
        let e = unsafe { sim.bind_scalp_source(&scalp, &source) }.expect_err(named);
        assert!(e.to_string().contains(named), "{named}: {e}");
    }
    let source = buffer.scalp_source(16, vk::Format::R32G32B32A32_SFLOAT, vertices);
    let far = Scalp {
        mesh: TriMesh::new(scalp.mesh.positions.iter().map(|p| *p + Vec3::X).collect(), scalp.mesh.triangles.clone())
            .expect("mesh"),
        ..scalp.clone()
    };
    // SAFETY: as above.
    let e = unsafe { sim.bind_scalp_source(&far, &source) }.expect_err("roots 1 m off the scalp");
    assert!(e.to_string().contains("strand 0"), "{e}");
    let e = sim.set_scalp_bones(&bones(0.0, 0.0, 0.0)).expect_err("no scalp bound");
    assert!(e.to_string().contains("no scalp"), "{e}");
    sim.bind_scalp_bones(&scalp, &bones(0.0, 0.0, 0.0)).expect("bind");
    let nan = [Mat4::IDENTITY, Mat4::from_translation(Vec3::NAN)];
    let e = sim.set_scalp_bones(&nan).expect_err("a NaN bone");
    assert!(e.to_string().contains("bone 1"), "{e}");
    let e = sim.set_scalp_offset(4).expect_err("an offset on the bone path");
    assert!(e.to_string().contains("bone matrices"), "{e}");
    let e = sim.bind_scalp_bones(&Scalp::new(scalp.mesh.clone()), &[]).expect_err("no vertex bones");
    assert!(e.to_string().contains("no vertex bones"), "{e}");
    // SAFETY: as above; this one is kept until `sim` is dropped.
    unsafe { sim.bind_scalp_source(&scalp, &source) }.expect("a good source");
    let e = sim.set_scalp_offset(2).expect_err("a misaligned offset");
    assert!(e.to_string().contains("offset"), "{e}");
    sim.unbind_scalp().expect("unbind");
    for step in 0..6 {
        let b = swinging(step, p.dt);
        sim.run(1, |_| head_of(&b), None).expect("step");
        plain.run(1, |_| head_of(&b), None).expect("step");
    }
    let (a, b) = (sim.read_state().expect("readback"), plain.read_state().expect("readback"));
    assert_eq!(bits(&a), bits(&b), "an unbound scalp changed the rigid head's steps");
    drop((sim, plain, buffer));
}

/// A bound scalp adds no dispatch and no barrier: the frames are computed
/// inside the step's own dispatch (one per step with the volume stage off).
#[test]
fn a_bound_scalp_adds_no_dispatch() {
    let gpu_ctx = Gpu::new();
    let ctx = gpu_ctx.ctx();
    let scalp = scalp();
    let groom = groom(&scalp);
    let p = SimParams {
        volume: vkhair::sim::VolumeParams { mode: vkhair::sim::VolumeMode::Off, ..Default::default() },
        ..params()
    };
    let start = bones(0.0, 0.0, 0.0);
    let mut work = Vec::new();
    for bound in [false, true] {
        let mut sim = HairSim::new(ctx, &groom, &p, &head_of(&start)).expect("gpu sim");
        if bound {
            sim.bind_scalp_bones(&scalp, &start).expect("bind");
        }
        sim.run(1, |_| head_of(&start), None).expect("warm-up step");
        let before = ctx.recorded_work();
        sim.set_scalp_bones(&start).ok();
        sim.run(1, |_| head_of(&swinging(1, p.dt)), None).expect("step");
        let w = ctx.recorded_work() - before;
        work.push((w.dispatches, w.barriers));
    }
    assert_eq!(work[0].0, 1, "a step without a scalp: {:?}", work[0]);
    assert_eq!(work[1], work[0], "a bound scalp changed the recorded work");
}
