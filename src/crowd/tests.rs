//! The crowd's layout on the CPU: where each member's key hairs, scalp and
//! bones land, and what a pose is refused for.

use glam::{Mat4, Quat, Vec3};

use super::layout::lay_out;
use super::{place, Member, MemberPose};
use crate::groom::mesh::TriMesh;
use crate::groom::Groom;
use crate::sim::scalp::{Scalp, VertexSkin};
use crate::sim::{Collider, RigidTransform};

fn strand(x: f32, points: usize) -> Vec<Vec3> {
    (0..points).map(|i| Vec3::new(x, 0.0, -0.02 * i as f32)).collect()
}

fn pose(x: f32) -> MemberPose {
    MemberPose::rigid(RigidTransform { rotation: Quat::from_rotation_y(0.3), translation: Vec3::new(x, 1.0, 0.0) })
}

#[test]
fn members_are_placed_by_their_first_poses_and_resampled_to_one_point_count() {
    let a = Groom::from_strands(&[strand(0.0, 4), strand(0.01, 4)]).expect("a");
    let b = Groom::from_strands(&[strand(0.0, 6)]).expect("b");
    let layout =
        lay_out(&[Member::rigid(a.clone()), Member::rigid(b)], &[pose(0.0), pose(2.0)], &[0, 1]).expect("layout");
    assert_eq!(layout.groom.strand_count(), 3);
    assert_eq!(layout.groom.uniform_points_per_strand(), Some(6), "the most points any member has");
    assert_eq!(layout.members[0].strands, 0..2);
    assert_eq!(layout.members[1].strands, 2..3);
    let sets: Vec<u32> = layout.binding.views.iter().map(|v| v.set).collect();
    assert_eq!(sets, [0, 0, 1], "each key hair names its member's parameter set");
    let m = pose(0.0).head.matrix();
    assert!(layout.groom.strand(1)[0].distance(m.transform_point3(a.strand(1)[0])) < 1e-6);
    let m = pose(2.0).head.matrix();
    let tip = layout.groom.strand(2)[5];
    assert!(tip.distance(m.transform_point3(Vec3::new(0.0, 0.0, -0.1))) < 1e-5, "{tip}");
}

#[test]
fn each_root_is_bound_within_its_own_member_even_where_members_overlap() {
    let g = Groom::from_strands(&[strand(0.0, 4), strand(0.01, 4)]).expect("groom");
    // Two members at the same place: a root bound to the other's scalp would
    // follow the wrong head.
    let layout =
        lay_out(&[Member::rigid(g.clone()), Member::rigid(g)], &[pose(0.0), pose(0.0)], &[0, 0]).expect("layout");
    assert_eq!(layout.binding.views.len(), 4);
    assert_eq!(layout.scalp.mesh.positions.len(), 6, "one triangle per rigid member");
    for (h, view) in layout.binding.views.iter().enumerate() {
        let own = if h < 2 { 0..3 } else { 3..6 };
        assert!(view.corners.iter().all(|c| own.contains(c)), "key hair {h} bound to {:?}", view.corners);
    }
    let joints: Vec<u32> = layout.scalp.skin.iter().map(|s| s.joints[0]).collect();
    assert_eq!(joints, [0, 0, 0, 1, 1, 1], "one bone per rigid member");
}

/// A member whose roots sit on a scalp of two separate triangles, skinned by
/// bones 0 and 1, with a third, far triangle no root uses.
fn skinned_member() -> Member {
    let positions = vec![
        Vec3::new(-0.01, 0.0, 0.01),
        Vec3::new(0.01, 0.0, 0.01),
        Vec3::new(0.0, 0.0, -0.01),
        Vec3::new(0.09, 0.0, 0.01),
        Vec3::new(0.11, 0.0, 0.01),
        Vec3::new(0.10, 0.0, -0.01),
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(5.1, 0.0, 0.0),
        Vec3::new(5.0, 0.0, 0.1),
    ];
    let mesh = TriMesh::new(positions, vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]]).expect("mesh");
    let bone = |j: u32| VertexSkin { joints: [j, 0, 0, 0], weights: [1.0, 0.0, 0.0, 0.0] };
    let skin = vec![bone(0), bone(0), bone(0), bone(1), bone(1), bone(1), bone(2), bone(2), bone(2)];
    let strands = [0.0f32, 0.1].map(|x| (0..4).map(|i| Vec3::new(x, -0.02 * i as f32, 0.0)).collect::<Vec<_>>());
    Member {
        groom: Groom::from_strands(&strands).expect("groom"),
        colliders: vec![Collider::Sphere { center: Vec3::ZERO, radius: 0.05 }],
        scalp: Some(Scalp { skin, ..Scalp::new(mesh) }),
        params: None,
    }
}

#[test]
fn a_skinned_member_keeps_only_the_triangles_its_roots_ride_and_its_bones_follow_the_rigid_ones() {
    let skinned = skinned_member();
    let rigid = Member::rigid(Groom::from_strands(&[strand(0.0, 4)]).expect("rigid"));
    let poses = [pose(0.0), MemberPose { bones: vec![Mat4::IDENTITY; 3], ..pose(1.0) }];
    let layout = lay_out(&[rigid, skinned], &poses, &[0, 0]).expect("layout");
    assert_eq!(layout.scalp.mesh.positions.len(), 3 + 6, "the unused far triangle is left out");
    assert_eq!(layout.members[1].bones, 1..3, "bone 2 skins nothing kept");
    let joints: Vec<u32> = layout.scalp.skin.iter().map(|s| s.joints[0]).collect();
    assert_eq!(joints, [0, 0, 0, 1, 1, 1, 2, 2, 2]);
    // Bones: the rigid member's head, then the skinned member's bones after its placement.
    let moved = [pose(0.5), MemberPose { bones: vec![Mat4::from_translation(Vec3::Y); 3], ..pose(1.0) }];
    let super::Placing { bones, bounds: (centre, radius), colliders } = place(&layout.members, &moved).expect("place");
    assert_eq!(bones.len(), 3);
    let root = layout.groom.strand(0)[0];
    let expected = moved[0].head.matrix() * pose(0.0).head.matrix().inverse();
    assert!(bones[0].transform_point3(root).distance(expected.transform_point3(root)) < 1e-6);
    let skinned_root = layout.groom.strand(1)[0];
    let world = bones[1].transform_point3(skinned_root);
    let by_bone = Mat4::from_translation(Vec3::Y).transform_point3(Vec3::ZERO);
    assert!(world.distance(by_bone) < 1e-5, "{world}: bone 0 of the member moves its bind pose up");
    assert_eq!(colliders.len(), 1, "the skinned member's head sphere");
    for s in layout.members[0].strands.clone() {
        for p in layout.groom.strand(s) {
            let p = bones[0].transform_point3(*p);
            assert!(p.distance(centre) <= radius * (1.0 + 1e-6), "{p} outside the bounds {centre} {radius}");
        }
    }
}

#[test]
fn poses_are_refused_naming_the_member_and_the_problem() {
    let layout = lay_out(
        &[Member::rigid(Groom::from_strands(&[strand(0.0, 4)]).expect("g")), skinned_member()],
        &[pose(0.0), MemberPose { bones: vec![Mat4::IDENTITY; 3], ..pose(1.0) }],
        &[0, 0],
    )
    .expect("layout");
    let refused = |poses: &[MemberPose]| place(&layout.members, poses).err().expect("refused").to_string();
    let short = refused(&[pose(0.0), MemberPose { bones: vec![Mat4::IDENTITY; 1], ..pose(1.0) }]);
    assert!(short.contains("member 1") && short.contains("at least 2"), "{short}");
    let nan = refused(&[pose(0.0), MemberPose { bones: vec![Mat4::NAN; 2], ..pose(1.0) }]);
    assert!(nan.contains("member 1") && nan.contains("bone 0"), "{nan}");
    let head =
        refused(&[MemberPose::rigid(RigidTransform { translation: Vec3::INFINITY, ..Default::default() }), pose(0.0)]);
    assert!(head.contains("member 0") && head.contains("head transform"), "{head}");
    let count = refused(&[pose(0.0)]);
    assert!(count.contains("crowd poses") && count.contains("one per member"), "{count}");
    let body = vec![Collider::Sphere { center: Vec3::ZERO, radius: 0.1 }; crate::sim::MAX_COLLIDERS];
    let many = refused(&[MemberPose { body, ..pose(0.0) }, MemberPose { bones: vec![Mat4::IDENTITY; 2], ..pose(1.0) }]);
    assert!(many.contains("crowd colliders") && many.contains(&(crate::sim::MAX_COLLIDERS + 1).to_string()), "{many}");
}

#[test]
fn a_crowd_of_no_member_or_too_many_is_refused() {
    let none = lay_out(&[], &[], &[]).err().expect("refused").to_string();
    assert!(none.contains("crowd members"), "{none}");
    let g = Groom::from_strands(&[strand(0.0, 4)]).expect("g");
    let many = vec![Member::rigid(g); super::MAX_CROWD_MEMBERS + 1];
    let poses = vec![pose(0.0); many.len()];
    let e = lay_out(&many, &poses, &vec![0; poses.len()]).err().expect("refused").to_string();
    assert!(e.contains(&(super::MAX_CROWD_MEMBERS + 1).to_string()), "{e}");
}

#[test]
fn members_with_equal_parameters_share_a_set_and_others_are_refused_naming_what_differs() {
    let g = Groom::from_strands(&[strand(0.0, 4)]).expect("g");
    let base = crate::sim::SimParams { global_shape_stiffness: 0.1, ..Default::default() };
    let heavy = crate::sim::SimParams { gravity: Vec3::new(0.0, -20.0, 0.0), ..base.clone() };
    let stiff = crate::sim::SimParams { global_shape_stiffness: 0.5, damping: 0.3, ..base.clone() };
    let member = |p: Option<&crate::sim::SimParams>| Member { params: p.cloned(), ..Member::rigid(g.clone()) };
    let members = [member(None), member(Some(&heavy)), member(Some(&base)), member(Some(&stiff)), member(Some(&heavy))];
    let (sets, of_member) = super::parameter_sets(&base, &members).expect("sets");
    assert_eq!(sets, [heavy.clone(), base.clone(), stiff]);
    assert_eq!(
        of_member,
        [0, 1, 2, 3, 1],
        "a member's own parameters a set of theirs (kept through the crowd's changes), equal ones share"
    );
    let refused = |p: crate::sim::SimParams| {
        super::parameter_sets(&base, &[member(None), member(Some(&p))]).expect_err("refused").to_string()
    };
    let e = refused(crate::sim::SimParams { iterations: base.iterations + 1, substeps: 2, ..heavy.clone() });
    assert!(e.contains("member 1") && e.contains("iterations") && e.contains("substeps"), "{e}");
    assert!(e.contains("differ in iterations, substeps ("), "only what may not differ is named: {e}");
    let e = refused(crate::sim::SimParams { global_shape_stiffness: 0.0, ..base.clone() });
    assert!(e.contains("member 1") && e.contains("switches"), "{e}");
    let e = refused(crate::sim::SimParams { damping: f32::NAN, ..base.clone() });
    assert!(e.contains("member 1") && e.contains("damping"), "{e}");
}
