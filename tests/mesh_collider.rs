//! The mesh collider on the GPU: its field against the CPU reference
//! ([`MeshSdf::build`]), and the simulation colliding with it.

mod common;

use common::Gpu;
use glam::Vec3;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::sdf::MeshSdf;
use vkhair::sim::{MeshCollider, MeshColliderParams};

/// The GPU field against the CPU reference: every grid point within `tolerance`
/// (both measure the same triangle exactly; only `sqrt` and division may round
/// differently), and the same sign everywhere.
fn assert_field_matches(gpu: &MeshSdf, cpu: &MeshSdf) {
    assert_eq!((gpu.origin, gpu.cell, gpu.dims), (cpu.origin, cpu.cell, cpu.dims));
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
fn the_gpu_field_matches_the_cpu_reference_for_a_closed_and_an_open_mesh() {
    let gpu = Gpu::new();
    let centre = Vec3::new(0.02, 1.5, -0.01);
    let sphere = TriMesh::uv_sphere(centre, 0.1, 12, 16).expect("sphere");
    let kept: Vec<[u32; 3]> = (0..sphere.triangles.len())
        .filter(|&t| sphere.corners(t).iter().any(|p| p.y > centre.y - 0.07))
        .map(|t| sphere.triangles[t])
        .collect();
    let open = TriMesh::new(sphere.positions.clone(), kept).expect("open mesh");
    for (mesh, resolution) in [(&sphere, 32), (&open, 40)] {
        let params = MeshColliderParams { resolution, margin: 0.03 };
        let collider = MeshCollider::new(gpu.ctx(), mesh, &params).expect("collider");
        let field = collider.read_field().expect("read back");
        let reference = MeshSdf::build(mesh, resolution, 0.03).expect("reference");
        assert_field_matches(&field, &reference);
        assert!(field.sample(centre) < -0.09, "the centre is inside: {}", field.sample(centre));
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
    assert_field_matches(&collider.read_field().expect("read back"), &reference);
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
