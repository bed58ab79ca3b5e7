//! Many characters in one frame ([`vkhair::crowd::Crowd`]): each member moves
//! as it would alone, a step is the same dispatches for any number of members,
//! overlapping members draw as one groom, every member's hair shadows the
//! others', and the crowd's bounds hold its hair.

use glam::{Mat4, Quat, Vec3};
use vkhair::crowd::{Crowd, Member, MemberPose};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::{Camera, Light, LodParams, RenderParams, Renderer, ShadowParams};
use vkhair::sim::scalp::{Scalp, VertexSkin};
use vkhair::sim::{Collider, HairSim, KeyHairs, RigidTransform, SimParams, SimState, VolumeMode, VolumeParams};
use vkhair::{GpuContext, Groom};

use crate::common::{self, Gpu};

fn at(x: f32, z: f32, turn: f32) -> RigidTransform {
    RigidTransform { rotation: Quat::from_rotation_y(turn), translation: Vec3::new(x, 0.0, z) }
}

/// The scalp of the thesis head on one bone, for a member whose roots ride a skin.
fn one_bone_scalp() -> Scalp {
    let mesh = TriMesh::uv_sphere(scenes::THESIS_HEAD_CENTER, scenes::THESIS_HEAD_RADIUS, 24, 32).expect("sphere");
    let skin = vec![VertexSkin { joints: [0; 4], weights: [1.0, 0.0, 0.0, 0.0] }; mesh.positions.len()];
    Scalp { skin, tolerance: 5e-3, ..Scalp::new(mesh) }
}

/// Records, submits and waits for one frame of `hairs` into `target`, then reads it.
fn draw(
    ctx: &GpuContext,
    hairs: KeyHairs<'_>,
    renderer: &mut Renderer,
    target: &Offscreen,
    camera: &Camera,
) -> Vec<u8> {
    let mut result = Ok(());
    ctx.run_commands("crowd frame", |cmd| {
        // SAFETY: a recording command buffer of the context's device.
        result = unsafe {
            target.record_clear(cmd, Vec3::ZERO);
            renderer
                .record_prepare(cmd, hairs, Some(camera), None)
                .and_then(|_| renderer.record_shadows(cmd, hairs, None))
                .and_then(|_| renderer.record_draw(cmd, common::next_frame(), &target.target(), camera, None))
        };
    })
    .expect("submit");
    result.expect("record");
    target.read_rgba8().expect("readback")
}

fn lit(renderer: &mut Renderer) {
    renderer
        .set_lights(&[Light::Directional { direction: Vec3::new(0.2, -1.0, -0.3), color: Vec3::ONE }])
        .expect("lights");
}

/// Two members standing in one another, drawn at rest, give the image of one
/// groom of both their key hairs: one set of per-pixel lists and one
/// composite, the two characters' fragments sorted together.
#[test]
fn two_overlapping_members_draw_as_one_groom_of_both() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let (a, b) = (common::grown_groom(48, 6, 1), common::grown_groom(48, 6, 2));
    let poses = [MemberPose::rigid(at(-0.03, 0.0, 0.0)), MemberPose::rigid(at(0.03, 0.02, 0.4))];
    let crowd = Crowd::new(ctx, &[Member::rigid(a.clone()), Member::rigid(b.clone())], &poses, &SimParams::default())
        .expect("crowd");
    let placed = |g: &Groom, p: &MemberPose| g.rigidly_moved(&p.head.matrix()).expect("placed");
    let (pa, pb) = (placed(&a, &poses[0]), placed(&b, &poses[1]));
    let positions: Vec<Vec3> = pa.positions().iter().chain(pb.positions()).copied().collect();
    let merged = Groom::new(positions, &vec![6; 96]).expect("merged");
    let one = HairSim::new(ctx, &merged, &SimParams::default(), &RigidTransform::default()).expect("one sim");
    let params = RenderParams { lod: LodParams { enabled: false, ..LodParams::default() }, ..RenderParams::default() };
    let (mut r_crowd, mut r_one) = (
        Renderer::new(ctx, crowd.key_hairs(), &params).expect("renderer"),
        Renderer::new(ctx, &one, &params).expect("renderer"),
    );
    lit(&mut r_crowd);
    lit(&mut r_one);
    let target = Offscreen::new(ctx, 96, 96).expect("target");
    let camera = common::front_camera(0.5, (96, 96));
    let crowd_image = draw(ctx, crowd.key_hairs(), &mut r_crowd, &target, &camera);
    let one_image = draw(ctx, one.key_hairs(), &mut r_one, &target, &camera);
    let covered = one_image.chunks(4).filter(|p| p[..3].iter().any(|&c| c > 0)).count();
    println!("{covered} of {} pixels show hair", 96 * 96);
    assert!(covered > 500, "the two members are in view ({covered} pixels)");
    let differing = crowd_image.iter().zip(&one_image).filter(|(x, y)| x != y).count();
    assert_eq!(differing, 0, "the crowd's frame differs from one groom's in {differing} channels");
}

/// Every member simulates as it would alone: one moving by its head with a
/// head collider, one turning, one riding a skinned scalp; the crowd's state
/// agrees with three separate simulations within 0.1 mm after 12 steps.
#[test]
fn each_member_moves_as_it_would_alone() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let grooms = [common::grown_groom(24, 6, 3), common::grown_groom(24, 6, 4), common::grown_groom(24, 6, 5)];
    let sphere = Collider::Sphere { center: scenes::THESIS_HEAD_CENTER, radius: scenes::THESIS_HEAD_RADIUS };
    let members = [
        Member { colliders: vec![sphere], ..Member::rigid(grooms[0].clone()) },
        Member::rigid(grooms[1].clone()),
        Member { scalp: Some(one_bone_scalp()), ..Member::rigid(grooms[2].clone()) },
    ];
    let heads = |i: usize| {
        let t = i as f32 / 60.0;
        [at(-1.0 + 0.3 * t, 0.0, 0.0), at(0.0, 0.0, 2.0 * t), at(1.0, 0.0, 0.0)]
    };
    // The bone starts moving after the first step (the member alone starts
    // from its scalp on its first step).
    let bone = |i: usize| at(1.0, -0.2 * (i.saturating_sub(1) as f32 / 60.0), 0.0).matrix();
    let poses = |i: usize| {
        let h = heads(i);
        vec![
            MemberPose::rigid(h[0]),
            MemberPose::rigid(h[1]),
            MemberPose { bones: vec![bone(i)], ..MemberPose::rigid(h[2]) },
        ]
    };
    let params = SimParams::default();
    let mut crowd = Crowd::new(ctx, &members, &poses(0), &params).expect("crowd");
    let steps = 12;
    crowd.run(steps, |i| poses(i + 1)).expect("crowd run");
    let together = crowd.sim().read_state().expect("state");
    let mut worst = 0.0f32;
    for (m, member) in members.iter().enumerate() {
        let mut alone = HairSim::new(ctx, &member.groom, &params, &heads(0)[m]).expect("alone");
        alone.set_colliders(&member.colliders).expect("colliders");
        if let Some(scalp) = &member.scalp {
            alone.bind_scalp_bones(scalp, &[bone(0)]).expect("scalp");
            alone.reset();
        }
        for i in 0..steps {
            if member.scalp.is_some() {
                alone.set_scalp_bones(&[bone(i + 1)]).expect("bones");
            }
            alone.run(1, |_| heads(i + 1)[m], None).expect("alone step");
        }
        let state = alone.read_state().expect("state");
        let d = distance(&together, crowd.member_strands(m).start, &state);
        println!("member {m}: {d:e} m from where it moves alone");
        worst = worst.max(d);
    }
    println!("worst distance between a member in the crowd and alone: {worst:e} m");
    assert!(worst < 1e-4, "a member moved {worst} m away from where it moves alone");
}

/// Members with parameters of their own (stronger gravity, other damping,
/// bending and global shape) share the one dispatch and move as they would
/// alone with those parameters, within 0.1 mm after 12 steps; two members
/// with the same parameters share a set; a member whose parameters differ in
/// what the members must share (iterations) is refused, naming both.
#[test]
fn members_with_parameters_of_their_own_move_as_they_would_alone() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    // Three sub-steps: each set's blocks laid out one after another.
    let base = SimParams { global_shape_stiffness: 0.02, substeps: 3, ..SimParams::default() };
    let own = SimParams {
        gravity: Vec3::new(0.0, -19.6, 0.0),
        damping: 0.2,
        bending_root: 0.3,
        global_shape_stiffness: 0.05,
        ..base.clone()
    };
    let grooms = [common::grown_groom(24, 6, 10), common::grown_groom(24, 6, 11), common::grown_groom(24, 6, 12)];
    let members = [
        Member::rigid(grooms[0].clone()),
        Member { params: Some(own.clone()), ..Member::rigid(grooms[1].clone()) },
        Member { params: Some(own.clone()), ..Member::rigid(grooms[2].clone()) },
    ];
    let heads = |i: usize| {
        let t = i as f32 / 60.0;
        [at(-1.0, 0.0, 0.0), at(0.0, 0.0, 3.0 * t), at(1.0 + 0.5 * t, 0.0, 0.0)]
    };
    let poses = |i: usize| -> Vec<MemberPose> { heads(i).map(MemberPose::rigid).to_vec() };
    let mut crowd = Crowd::new(ctx, &members, &poses(0), &base).expect("crowd");
    assert_eq!(crowd.parameter_sets(), 2, "the crowd's and the two members' own");
    let before = ctx.recorded_work();
    crowd.run(1, |i| poses(i + 1)).expect("first step");
    let one_step = ctx.recorded_work() - before;
    crowd.run(11, |i| poses(i + 2)).expect("crowd run");
    let together = crowd.sim().read_state().expect("state");
    let mut worst = [0.0f32; 3];
    for (m, member) in members.iter().enumerate() {
        let params = member.params.clone().unwrap_or_else(|| base.clone());
        let mut alone = HairSim::new(ctx, &member.groom, &params, &heads(0)[m]).expect("alone");
        alone.run(12, |i| heads(i + 1)[m], None).expect("alone run");
        worst[m] = distance(&together, crowd.member_strands(m).start, &alone.read_state().expect("state"));
    }
    println!("members from where they move alone: {worst:?} m; a step: {one_step:?}");
    // The member's own parameters matter: with the crowd's it would be elsewhere.
    let mut with_base = HairSim::new(ctx, &members[1].groom, &base, &heads(0)[1]).expect("alone");
    with_base.run(12, |i| heads(i + 1)[1], None).expect("alone run");
    let apart = distance(&together, crowd.member_strands(1).start, &with_base.read_state().expect("state"));
    println!("member 1 from where the crowd's parameters would take it: {apart:e} m");
    assert!(apart > 1e-3, "member 1's own parameters made no difference ({apart} m)");
    assert!(worst.iter().all(|w| *w < 1e-4), "a member moved away from where it moves alone: {worst:?}");
    assert_eq!(one_step.dispatches, 1, "one dispatch for every set");
    let other = SimParams { iterations: base.iterations + 1, ..own };
    let refused =
        [Member::rigid(grooms[0].clone()), Member { params: Some(other), ..Member::rigid(grooms[1].clone()) }];
    let e = Crowd::new(ctx, &refused, &poses(0)[..2], &base).err().expect("refused").to_string();
    assert!(e.contains("member 1") && e.contains("iterations"), "{e}");
}

/// A member teleported 4 m (by way of a first target given up before the
/// step) moves as it would alone after `HairSim::teleport`
/// (within 0.1 mm, its hair gaining no speed), while a member that jumps as
/// far without a teleport is dragged across the jump.
#[test]
fn a_member_teleports_on_its_own() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let grooms = [common::grown_groom(24, 6, 13), common::grown_groom(24, 6, 14)];
    let members = [Member::rigid(grooms[0].clone()), Member::rigid(grooms[1].clone())];
    let heads = |i: usize| {
        let t = i as f32 / 60.0;
        let jump = if i >= 6 { 4.0 } else { 0.0 };
        [at(-1.0 + jump, 0.0, 0.0), at(1.0 + jump + 0.5 * t, 0.0, 0.0)]
    };
    let poses = |i: usize| -> Vec<MemberPose> { heads(i).map(MemberPose::rigid).to_vec() };
    // Three sub-steps: a root swept across the jump would show between them.
    let params = SimParams { substeps: 3, ..SimParams::default() };
    let mut crowd = Crowd::new(ctx, &members, &poses(0), &params).expect("crowd");
    crowd.run(5, |i| poses(i + 1)).expect("before the jump");
    // A first target given up before the step: the teleports compose.
    crowd.teleport(1, &at(50.0, 0.0, 0.0)).expect("teleport");
    crowd.teleport(1, &heads(6)[1]).expect("teleport");
    crowd.run(3, |i| poses(i + 6)).expect("after the jump");
    let state = crowd.sim().read_state().expect("state");
    let mut alone = HairSim::new(ctx, &grooms[1], &params, &heads(0)[1]).expect("alone");
    alone.run(5, |i| heads(i + 1)[1], None).expect("alone before");
    alone.teleport(&heads(6)[1]).expect("alone teleport");
    alone.run(3, |i| heads(i + 6)[1], None).expect("alone after");
    let apart = distance(&state, crowd.member_strands(1).start, &alone.read_state().expect("state"));
    let speed = |m: usize| {
        let points = crowd.member_strands(m).start * state.points..crowd.member_strands(m).end * state.points;
        state.velocities[points].iter().map(|v| v.truncate().length()).fold(0.0f32, f32::max)
    };
    println!("teleported member {apart:e} m from alone, fastest {} m/s; dragged member {} m/s", speed(1), speed(0));
    assert!(apart < 1e-4, "the teleported member is {apart} m from where it is alone");
    assert!(speed(1) < 5.0 && speed(0) > 10.0, "speeds {} and {} m/s", speed(1), speed(0));
    let e = crowd.teleport(2, &heads(0)[0]).expect_err("refused").to_string();
    assert!(e.contains("crowd member") && e.contains("below 2"), "{e}");
}

/// The largest distance between the particles of `alone` and those of
/// `together` from key hair `first` on.
fn distance(together: &SimState, first: usize, alone: &SimState) -> f32 {
    let base = first * together.points;
    alone
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| p.truncate().distance(together.positions[base + i].truncate()))
        .fold(0.0, f32::max)
}

/// A step records the same dispatches and barriers for one member as for
/// nine: the cost follows the hair, not the number of characters.
#[test]
fn a_step_is_the_same_dispatches_for_any_number_of_members() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let groom = common::grown_groom(8, 4, 6);
    let work = |count: usize| {
        let members = vec![Member::rigid(groom.clone()); count];
        let poses = |i: usize| -> Vec<MemberPose> {
            (0..count).map(|m| MemberPose::rigid(at(m as f32, 0.0, 0.01 * i as f32))).collect()
        };
        let mut crowd = Crowd::new(ctx, &members, &poses(0), &SimParams::default()).expect("crowd");
        crowd.run(1, poses).expect("warm");
        let before = ctx.recorded_work();
        crowd.run(3, poses).expect("run");
        ctx.recorded_work() - before
    };
    let (one, nine) = (work(1), work(9));
    println!("3 steps of 1 member: {one:?}; of 9: {nine:?}");
    assert!(one.dispatches >= 3, "a step dispatches");
    assert_eq!((one.dispatches, one.barriers), (nine.dispatches, nine.barriers));
}

/// A member beside another, between it and a light from the side: the
/// member in view is darker with the other there, so every member's hair is
/// in the shadow maps of the crowd's light; the bounds the renderer fits them
/// to hold every particle as the members walk apart.
#[test]
fn members_shadow_one_another_and_the_bounds_hold_every_member() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let groom = common::grown_groom(64, 6, 7);
    let seen = MemberPose::rigid(at(0.0, 0.0, 0.0));
    // Out of the camera's view, toward the light.
    let beside = MemberPose::rigid(at(0.6, 0.0, 0.0));
    let camera = common::front_camera(0.4, (64, 64));
    let target = Offscreen::new(ctx, 64, 64).expect("target");
    let brightness = |members: &[Member], poses: &[MemberPose]| {
        let crowd = Crowd::new(ctx, members, poses, &SimParams::default()).expect("crowd");
        let mut renderer = Renderer::new(ctx, crowd.key_hairs(), &RenderParams::default()).expect("renderer");
        let light = Light::Directional { direction: Vec3::new(-1.0, -0.1, 0.0), color: Vec3::ONE };
        renderer.set_lights(&[light]).expect("lights");
        let shadows = ShadowParams { casters: vec![0.into()], resolution: 256, ..Default::default() };
        renderer.set_shadows(crowd.key_hairs(), &shadows).expect("shadows");
        let image = draw(ctx, crowd.key_hairs(), &mut renderer, &target, &camera);
        image.chunks(4).map(|p| u64::from(p[0]) + u64::from(p[1]) + u64::from(p[2])).sum::<u64>()
    };
    let member = Member::rigid(groom.clone());
    let alone = brightness(std::slice::from_ref(&member), std::slice::from_ref(&seen));
    let only_beside = brightness(std::slice::from_ref(&member), std::slice::from_ref(&beside));
    let shaded = brightness(&[member.clone(), member.clone()], &[seen.clone(), beside]);
    println!("the member in view: {alone} alone, {shaded} beside the other (which alone shows {only_beside})");
    assert_eq!(only_beside, 0, "the other member is out of view");
    assert!(shaded * 10 < alone * 9, "the other member casts no shadow on the one in view ({shaded} vs {alone})");

    let members = vec![member.clone(), member];
    let apart = |i: usize| {
        vec![MemberPose::rigid(at(-0.2 * i as f32, 0.0, 0.0)), MemberPose::rigid(at(0.2 * i as f32, 0.0, 0.0))]
    };
    let mut crowd = Crowd::new(ctx, &members, &apart(0), &SimParams::default()).expect("crowd");
    crowd.run(20, |i| apart(i + 1)).expect("walk apart");
    let (centre, radius) = crowd.bounds();
    let state = crowd.sim().read_state().expect("state");
    let outside = state.positions.iter().filter(|p| p.truncate().distance(centre) > radius).count();
    assert!(radius > 4.0, "the members are 8 m apart: the bounds ({radius} m) grew with them");
    assert_eq!(outside, 0, "{outside} particles outside the crowd's bounds");
}

/// A crowd refuses the volume stage, on creation and as a change of
/// parameters, naming it; a member's bad pose names the member.
#[test]
fn a_crowd_refuses_a_volume_stage_and_names_a_bad_member() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let groom = common::grown_groom(8, 4, 8);
    let members = [Member::rigid(groom.clone()), Member { scalp: Some(one_bone_scalp()), ..Member::rigid(groom) }];
    let volume = SimParams {
        volume: VolumeParams { mode: VolumeMode::Friction, ..VolumeParams::default() },
        ..SimParams::default()
    };
    let poses =
        [MemberPose::rigid(at(0.0, 0.0, 0.0)), MemberPose { bones: vec![Mat4::IDENTITY], ..Default::default() }];
    let e = Crowd::new(ctx, &members, &poses, &volume).err().expect("refused").to_string();
    assert!(e.contains("volume.mode"), "{e}");
    let mut crowd = Crowd::new(ctx, &members, &poses, &SimParams::default()).expect("crowd");
    let e = crowd.set_params(&volume).expect_err("refused").to_string();
    assert!(e.contains("volume.mode"), "{e}");
    let e = crowd.set_poses(&[poses[0].clone(), MemberPose::default()]).expect_err("refused").to_string();
    assert!(e.contains("member 1") && e.contains("scalp bones"), "{e}");
}

/// A renderer fits its shadow maps to the bounds a view carries
/// ([`KeyHairs::with_bounds`]): the rest shape's own sphere gives the frame
/// drawn without bounds, bit for bit; a sphere elsewhere leaves the hair out
/// of the maps, and, 5 m from the camera, lowers the level of detail. Bounds
/// that are not finite or not above 0 are refused.
#[test]
fn a_renderer_fits_its_shadows_to_the_bounds_of_the_view() {
    let gpu = Gpu::new();
    let ctx = gpu.ctx();
    let groom = common::grown_groom(64, 6, 9);
    let sim = HairSim::new(ctx, &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    // Without a level of detail: the bounds' distance from the camera would change it.
    let params = RenderParams { lod: LodParams { enabled: false, ..LodParams::default() }, ..RenderParams::default() };
    let mut renderer = Renderer::new(ctx, &sim, &params).expect("renderer");
    renderer
        .set_lights(&[Light::Directional { direction: Vec3::new(-1.0, -0.3, 0.0), color: Vec3::ONE }])
        .expect("lights");
    let shadows = ShadowParams { casters: vec![0.into()], resolution: 128, ..Default::default() };
    renderer.set_shadows(&sim, &shadows).expect("shadows");
    let camera = common::front_camera(0.4, (64, 64));
    let target = Offscreen::new(ctx, 64, 64).expect("target");
    // The sphere the renderer takes from the rest shape: around the centre of
    // its bounds, as far as a root plus its strand's length.
    let (lo, hi) = vkhair::groom::bounding_box(groom.positions().iter().copied());
    let centre = 0.5 * (lo + hi);
    let radius = (0..groom.strand_count())
        .map(|s| groom.strand(s)[0].distance(centre) + groom.strand_length(s))
        .fold(0.0, f32::max);
    let plain = draw(ctx, sim.key_hairs(), &mut renderer, &target, &camera);
    let same = draw(ctx, sim.key_hairs().with_bounds(centre, radius).expect("bounds"), &mut renderer, &target, &camera);
    // 5 m aside, across the light.
    let elsewhere = sim.key_hairs().with_bounds(centre + Vec3::Z * 5.0, radius).expect("bounds");
    let away = draw(ctx, elsewhere, &mut renderer, &target, &camera);
    let sum = |image: &[u8]| image.iter().map(|&c| u64::from(c)).sum::<u64>();
    println!(
        "brightness: {} without bounds, {} with the rest sphere, {} with a sphere 5 m away",
        sum(&plain),
        sum(&same),
        sum(&away)
    );
    assert!(plain == same, "the rest shape's own sphere changed the frame");
    assert!(sum(&away) > sum(&plain), "shadow maps fitted 5 m aside still shadow the hair");
    // The level of detail follows the bounds' distance from the camera too.
    renderer.set_params(&RenderParams::default()).expect("with a level of detail");
    let hairs = |view: KeyHairs<'_>, renderer: &mut Renderer| {
        renderer.prepare_now(view, Some(&camera)).expect("prepare");
        renderer.hair_counts().0
    };
    let near = hairs(sim.key_hairs().with_bounds(centre, radius).expect("bounds"), &mut renderer);
    let far = hairs(sim.key_hairs().with_bounds(centre + Vec3::Z * 5.0, radius).expect("bounds"), &mut renderer);
    println!("hairs drawn: {near} with the rest sphere, {far} with a sphere 5 m away");
    assert!(far < near, "a sphere 5 m away kept the detail ({far} of {near} hairs)");
    for (c, r) in [(Vec3::NAN, 1.0), (Vec3::ZERO, 0.0), (Vec3::ZERO, f32::INFINITY)] {
        let e = sim.key_hairs().with_bounds(c, r).expect_err("refused").to_string();
        assert!(e.contains("bounds"), "{e}");
    }
}
