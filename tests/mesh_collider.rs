//! The mesh collider on the GPU: its field against the CPU reference
//! ([`MeshSdf::build`]), the simulation colliding with it, and the local shape
//! constraint.

use crate::common;

use common::{curls, mohawk, p, tip_drift_of, Gpu};
use glam::Vec3;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::sdf::MeshSdf;
use vkhair::sim::{
    motion, Collider, CpuHairSim, HairSim, MeshCollider, MeshColliderParams, RigidTransform, SimParams, SimState,
};

/// The GPU field against the CPU reference: every grid point within `tolerance`
/// (both measure the same triangle exactly; only `sqrt` and division may round
/// differently), and the same sign everywhere.
/// The GPU field against the CPU reference: within 1e-5 of the grid's extent,
/// and on lavapipe bit for bit, as the README says.
fn assert_field_matches(gpu: &MeshSdf, cpu: &MeshSdf, lavapipe: bool) {
    assert_eq!((gpu.origin, gpu.cell, gpu.dims), (cpu.origin, cpu.cell, cpu.dims));
    if lavapipe {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(bits(&gpu.values) == bits(&cpu.values), "the field is not bit for bit on lavapipe");
    }
    let tolerance = 1e-5 * cpu.cell * cpu.dims[0] as f32;
    let mut worst = 0.0f32;
    for (k, (g, c)) in gpu.values.iter().zip(&cpu.values).enumerate() {
        assert_eq!(g.is_sign_negative(), c.is_sign_negative(), "sign differs at grid point {k}: GPU {g}, CPU {c}");
        worst = worst.max((g - c).abs());
        assert!((g - c).abs() <= tolerance, "grid point {k}: GPU {g}, CPU {c}, tolerance {tolerance}");
    }
    eprintln!("{:?} grid: worst |GPU − CPU| = {worst:e} (tolerance {tolerance:e})", cpu.dims);
}

#[test]
fn the_gpu_field_matches_the_cpu_reference_for_closed_open_and_carded_meshes() {
    let gpu = Gpu::new();
    let centre = Vec3::new(0.02, 1.5, -0.01);
    let sphere = TriMesh::uv_sphere(centre, 0.1, 12, 16).expect("sphere");
    let kept: Vec<[u32; 3]> = (0..sphere.triangles.len())
        .filter(|&t| sphere.corners(t).iter().any(|p| p.y > centre.y - 0.07))
        .map(|t| sphere.triangles[t])
        .collect();
    let open = TriMesh::new(sphere.positions.clone(), kept).expect("open mesh");
    let carded = crate::sdf::sphere_with_cards();
    for (mesh, resolution) in [(&sphere, 32), (&open, 40), (&carded, 40)] {
        let params = MeshColliderParams { resolution, margin: 0.03 };
        let collider = MeshCollider::new(gpu.ctx(), mesh, &params).expect("collider");
        let field = collider.read_field().expect("read back");
        let reference = MeshSdf::build(mesh, resolution, 0.03).expect("reference");
        assert_field_matches(&field, &reference, common::on_lavapipe(gpu.ctx()));
        // The carded sphere's inside, 3 cm from the cards, where no axis ray crosses one.
        let (middle, depth) =
            if std::ptr::eq(mesh, &carded) { (Vec3::new(-0.03, -0.03, 0.0), 0.025) } else { (centre, 0.09) };
        assert!(field.sample(middle) < -depth, "the centre is inside: {}", field.sample(middle));
    }
}

#[test]
fn the_gpu_field_of_the_sintel_bust_matches_the_cpu_reference() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/sintel/sintel_bust.obj");
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return;
    }
    let gpu = Gpu::new();
    let mesh = TriMesh::load_obj(&path).expect("bust");
    let params = MeshColliderParams { resolution: 32, margin: 1.0 };
    let collider = MeshCollider::new(gpu.ctx(), &mesh, &params).expect("collider");
    let reference = MeshSdf::build(&mesh, 32, 1.0).expect("reference");
    assert_field_matches(&collider.read_field().expect("read back"), &reference, common::on_lavapipe(gpu.ctx()));
}

#[test]
fn bad_meshes_are_rejected_before_gpu_work() {
    let gpu = Gpu::new();
    let mut mesh = TriMesh::uv_sphere(Vec3::ZERO, 1.0, 4, 4).expect("sphere");
    mesh.positions[3].x = f32::NAN;
    let err = MeshCollider::new(gpu.ctx(), &mesh, &MeshColliderParams::default()).expect_err("NaN vertex");
    assert!(err.to_string().contains("vertex 3"), "{err}");
    let mesh = TriMesh::uv_sphere(Vec3::ZERO, 1.0, 4, 4).expect("sphere");
    let params = MeshColliderParams { resolution: 1000, ..MeshColliderParams::default() };
    assert!(matches!(
        MeshCollider::new(gpu.ctx(), &mesh, &params),
        Err(vkhair::Error::InvalidParameter { name: "sdf resolution", .. })
    ));
}

/// A 10 cm head sphere at the origin as a mesh (fine enough that its facets
/// stay within 0.3 mm of the true sphere).
fn sphere_mesh() -> TriMesh {
    TriMesh::uv_sphere(Vec3::ZERO, 0.1, 32, 48).expect("sphere")
}

/// The shake of `vkhair simulate --motion shake` about the sphere's centre.
fn shake(step: usize, params: &SimParams) -> RigidTransform {
    motion::shaking_head_about((step + 1) as f32 * params.dt, 0.6, 1.0, Vec3::new(0.0, -0.1, 0.0))
}

/// GPU and CPU agree with the mesh collider, its friction and the local shape
/// constraint, through a shake: positions within 1e-4 m (as `tests/sim.rs`:
/// drivers may round `sqrt` and division differently; lavapipe agrees bit for bit).
#[test]
fn gpu_matches_cpu_with_the_mesh_collider_and_the_local_shape_constraint() {
    let gpu = Gpu::new();
    let mesh = sphere_mesh();
    let collider_params = MeshColliderParams { resolution: 40, margin: 0.02 };
    let params = SimParams { local_shape_stiffness: 0.3, ..SimParams::default() };
    let groom = mohawk(60, 12);
    let start = RigidTransform::default();
    let mut sim = HairSim::new(gpu.ctx(), &groom, &params, &start).expect("gpu sim");
    let mut cpu = CpuHairSim::new(&groom, &params, &start).expect("cpu sim");
    sim.set_mesh_collider(Some(MeshCollider::new(gpu.ctx(), &mesh, &collider_params).expect("collider"))).expect("set");
    cpu.set_mesh_collider(Some(MeshSdf::build(&mesh, 40, 0.02).expect("reference field")));
    let mut done = 0;
    for target in [1, 30, 60] {
        let from = done;
        sim.run(target - done, |i| shake(from + i, &params), None).expect("gpu run");
        for i in done..target {
            cpu.step(&shake(i, &params)).expect("cpu step");
        }
        done = target;
        let g = sim.read_state().expect("readback");
        let (mut worst, mut equal) = (0.0f32, 0);
        for (a, b) in g.positions.iter().zip(&cpu.state().positions) {
            assert!(a.is_finite(), "NaN or Inf on the GPU");
            worst = worst.max((*a - *b).length());
            equal += usize::from(a == b);
        }
        eprintln!("step {target}: max |gpu − cpu| = {worst:e}, {equal}/{} bitwise equal", g.positions.len());
        assert!(worst <= 1e-4, "step {target}: GPU and CPU differ by {worst} m");
        if common::on_lavapipe(gpu.ctx()) {
            assert!(common::bits(&g) == common::bits(cpu.state()), "step {target}: not bit for bit on lavapipe");
        }
    }
}

/// Share of free particles deeper than 1 mm inside the 10 cm sphere.
fn share_inside(state: &SimState, head: &RigidTransform) -> f32 {
    let to_head = head.matrix().inverse();
    let free: Vec<Vec3> = state.positions.iter().filter(|p| p.w > 0.0).map(|p| p.truncate()).collect();
    let deep = free.iter().filter(|p| to_head.transform_point3(**p).length() < 0.1 - 0.001).count();
    deep as f32 / free.len() as f32
}

/// During the shake, an unstyled mohawk (which falls onto the head) stays out of
/// a sphere given only as a mesh: at most 0.1 % of the points more than 1 mm
/// inside at any of the checked steps. Without the collider most of it sinks in.
#[test]
fn points_stay_out_of_the_mesh_during_the_shake() {
    let gpu = Gpu::new();
    let params = SimParams::default();
    let groom = mohawk(200, 12);
    let start = RigidTransform::default();
    let run = |with_mesh: bool| {
        let mut sim = HairSim::new(gpu.ctx(), &groom, &params, &start).expect("sim");
        if with_mesh {
            let collider = MeshCollider::new(gpu.ctx(), &sphere_mesh(), &MeshColliderParams::default()).expect("mesh");
            sim.set_mesh_collider(Some(collider)).expect("set");
        }
        let mut worst = 0.0f32;
        for chunk in 0..12 {
            sim.run(8, |i| shake(chunk * 8 + i, &params), None).expect("run");
            let state = sim.read_state().expect("readback");
            worst = worst.max(share_inside(&state, &shake(chunk * 8 + 7, &params)));
        }
        worst
    };
    let with = run(true);
    let without = run(false);
    eprintln!(
        "points > 1 mm inside, worst of 12 checks: {:.4} % with the mesh collider, {:.1} % without",
        with * 100.0,
        without * 100.0
    );
    assert!(without > 0.2, "the test needs a groom that falls into the head: {without}");
    assert!(with <= 0.001, "{} % of the points are more than 1 mm inside", with * 100.0);
}

/// Mean over interior points of |cos θ − cos θ_rest|, θ the angle between a
/// point's two segments: how far the strands' curvature is from the rest shape's.
fn curvature_error(state: &SimState) -> f32 {
    let mut sum = 0.0;
    let mut count = 0;
    let cos = |a: Vec3, b: Vec3, c: Vec3| (b - a).normalize().dot((c - b).normalize());
    for s in 0..state.strands {
        let at = |i: usize| state.positions[s * state.points + i].truncate();
        let rest = |i: usize| state.rest[s * state.points + i].truncate();
        for i in 1..state.points - 1 {
            sum += (cos(at(i - 1), at(i), at(i + 1)) - cos(rest(i - 1), rest(i), rest(i + 1))).abs();
            count += 1;
        }
    }
    sum / count as f32
}

/// The local shape constraint keeps curls curled along the half of the strand
/// the global shape constraint leaves free, and its effect does not depend on
/// the iteration count (within 5 %). It conserves momentum, so it keeps the
/// curls' shape rather than carrying their weight, which the global constraint
/// and the root do.
#[test]
fn the_local_shape_constraint_keeps_curls_curled() {
    let gpu = Gpu::new();
    let still = RigidTransform::default();
    let run = |groom: &vkhair::Groom, params: &SimParams| {
        let mut sim = HairSim::new(gpu.ctx(), groom, params, &still).expect("sim");
        sim.set_colliders(&[Collider::Sphere { center: Vec3::ZERO, radius: 0.1 }]).expect("colliders");
        sim.run(200, |_| still, None).expect("run");
        sim.read_state().expect("readback")
    };
    let root_half = SimParams {
        spring_enabled: false,
        global_shape_stiffness: 0.15,
        global_shape_range: 0.5,
        ..SimParams::default()
    };
    let local = SimParams { local_shape_stiffness: 0.99, ..root_half.clone() };
    let curled = curvature_error(&run(&curls(60), &local));
    let loose = curvature_error(&run(&curls(60), &root_half));
    eprintln!("curls: curvature error {curled:.4} with the local shape constraint, {loose:.4} without");
    assert!(curled < 0.3 * loose, "curls lost their shape: {curled} against {loose} without the constraint");
    let drift = |params: &SimParams| p(&tip_drift_of(&run(&curls(60), params), &still), 50);
    let (held, fallen) = (drift(&local), drift(&root_half));
    let held_60 = drift(&SimParams { iterations: 60, ..local.clone() });
    eprintln!(
        "curls tip drift p50: {held:.4} with it (20 iterations), {held_60:.4} (60 iterations), {fallen:.4} without"
    );
    assert!(held < 0.5 * fallen, "the curls' tips fell: {held} against {fallen}");
    assert!((held - held_60).abs() < 0.05 * held, "iteration count changed the sag: {held} against {held_60}");
}

/// Sintel's bob on her bust (the `vkhair render --input … --obj …` scene):
/// through 24 frames of the shake (48 steps) with the tool's styled parameters
/// and the bust as the mesh collider, no key-hair point ends up inside the bust
/// (at most 0.1 %, checked every 4 steps), and the style holds (tip drift p95
/// under 10 % of the strand length). Skips visibly without the data.
#[test]
fn sintels_bob_stays_out_of_her_face_through_the_shake() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/sintel");
    if !dir.join("sintel_hair.tfx").exists() || !dir.join("sintel_bust.obj").exists() {
        eprintln!("skipped: the Sintel data is absent from {}", dir.display());
        return;
    }
    let tfx = vkhair::groom::tfx::TfxFile::open(dir.join("sintel_hair.tfx")).expect("hair");
    let counts: Vec<u32> = (0..tfx.groom.strand_count()).map(|i| tfx.groom.strand_len(i) as u32).collect();
    let scaled: Vec<Vec3> = tfx.groom.positions().iter().map(|p| *p * 0.01).collect();
    let groom = vkhair::Groom::new(scaled, &counts).expect("groom").resampled(16).expect("resampled");
    let bust = TriMesh::load_obj(dir.join("sintel_bust.obj")).expect("bust");
    let bust = TriMesh::new(bust.positions.iter().map(|p| *p * 0.01).collect(), bust.triangles).expect("scaled");
    let field = MeshSdf::build(&bust, 64, 0.02).expect("field");
    let params = SimParams::styled();
    let (lo, hi) = groom.bounds();
    let pivot = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    let head = |i: usize| motion::shaking_head_about((i + 1) as f32 * params.dt, 0.6, 1.0, pivot);
    let gpu = Gpu::new();
    let mut sim = HairSim::new(gpu.ctx(), &groom, &params, &RigidTransform::default()).expect("sim");
    sim.set_mesh(Some(&bust), &MeshColliderParams::default()).expect("mesh collider");
    let mut worst = 0.0f32;
    for chunk in 0..12 {
        sim.run(4, |i| head(chunk * 4 + i), None).expect("run");
        let state = sim.read_state().expect("readback");
        let back = head(chunk * 4 + 3).matrix().inverse();
        let free: Vec<Vec3> = state.positions.iter().filter(|p| p.w > 0.0).map(|p| p.truncate()).collect();
        let inside = free.iter().filter(|p| field.sample(back.transform_point3(**p)) < -0.001).count();
        worst = worst.max(inside as f32 / free.len() as f32);
    }
    let state = sim.read_state().expect("readback");
    let drift = tip_drift_of(&state, &head(47));
    eprintln!(
        "sintel: points > 1 mm inside the bust at most {:.3} %, tip drift p50 {:.3} p95 {:.3}",
        worst * 100.0,
        p(&drift, 50),
        p(&drift, 95)
    );
    assert!(worst <= 0.001, "{} % of the points inside the bust", worst * 100.0);
    assert!(p(&drift, 95) < 0.1, "the bob lost its shape: tip drift p95 {}", p(&drift, 95));
}
