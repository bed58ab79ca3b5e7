//! The mesh signed distance field against a brute-force distance to every
//! triangle, and its sign for a closed and an open mesh.

use glam::Vec3;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::sdf::MeshSdf;

/// Distance from `p` to the segment a–b.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

/// Brute-force distance to the triangle: the plane when the projection falls
/// inside (all three edge tests agree), else the nearest edge.
fn brute_triangle(p: Vec3, [a, b, c]: [Vec3; 3]) -> f32 {
    let n = (b - a).cross(c - a).normalize();
    let q = p - n * (p - a).dot(n);
    let inside = [(a, b), (b, c), (c, a)].iter().all(|&(s, e)| (e - s).cross(q - s).dot(n) >= 0.0);
    if inside {
        (p - q).length()
    } else {
        segment_distance(p, a, b).min(segment_distance(p, b, c)).min(segment_distance(p, c, a))
    }
}

fn brute(mesh: &TriMesh, p: Vec3) -> f32 {
    (0..mesh.triangles.len()).map(|t| brute_triangle(p, mesh.corners(t))).fold(f32::INFINITY, f32::min)
}

/// Deterministic points in the box (lo, hi).
fn points(lo: Vec3, hi: Vec3, count: usize) -> Vec<Vec3> {
    let mut state = 0x9e37_79b9_u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    (0..count).map(|_| lo + (hi - lo) * Vec3::new(next(), next(), next())).collect()
}

#[test]
fn distances_match_brute_force_within_half_a_voxel_diagonal() {
    let centre = Vec3::new(0.02, 1.5, -0.01);
    let mesh = TriMesh::uv_sphere(centre, 0.1, 12, 16).expect("sphere");
    let sdf = MeshSdf::build(&mesh, 48, 0.05).expect("sdf");
    let tolerance = 0.5 * sdf.cell * 3f32.sqrt();
    let lo = sdf.origin;
    let hi =
        sdf.origin + Vec3::new(sdf.dims[0] as f32 - 1.0, sdf.dims[1] as f32 - 1.0, sdf.dims[2] as f32 - 1.0) * sdf.cell;
    // The sphere mesh is convex: inside is the same side of every face's plane
    // (whichever way the faces are wound).
    let inside = |p: Vec3| {
        let sides: Vec<f32> = (0..mesh.triangles.len())
            .filter_map(|t| {
                let [a, b, c] = mesh.corners(t);
                let n = (b - a).cross(c - a);
                // The poles hold slivers of rounding-error size and any orientation.
                (n.length() > 1e-6).then(|| n.dot(p - a))
            })
            .collect();
        sides.iter().all(|s| *s <= 0.0) || sides.iter().all(|s| *s >= 0.0)
    };
    let mut worst = 0.0f32;
    for p in points(lo, hi, 400) {
        let exact = if inside(p) { -brute(&mesh, p) } else { brute(&mesh, p) };
        let got = sdf.sample(p);
        worst = worst.max((got - exact).abs());
        assert!((got - exact).abs() <= tolerance, "at {p}: sdf {got}, brute force {exact}, tolerance {tolerance}");
    }
    eprintln!("worst |sdf − brute force| = {worst:.5} (cell {:.5}, tolerance {tolerance:.5})", sdf.cell);
    assert!(sdf.sample(centre) < -0.09, "the centre is 0.1 inside: {}", sdf.sample(centre));
}

#[test]
fn an_open_mesh_has_the_right_inside_and_outside() {
    let centre = Vec3::new(0.0, 1.5, 0.0);
    let sphere = TriMesh::uv_sphere(centre, 0.1, 16, 24).expect("sphere");
    // Cut the bottom cap off, as a bust is cut at the chest.
    let kept: Vec<[u32; 3]> = (0..sphere.triangles.len())
        .filter(|&t| sphere.corners(t).iter().any(|p| p.y > centre.y - 0.07))
        .map(|t| sphere.triangles[t])
        .collect();
    assert!(kept.len() < sphere.triangles.len(), "the cap was removed");
    let open = TriMesh::new(sphere.positions.clone(), kept).expect("open mesh");
    let sdf = MeshSdf::build(&open, 40, 0.05).expect("sdf");
    let (mut checked, mut wrong) = (0, Vec::new());
    for p in points(centre - Vec3::splat(0.18), centre + Vec3::splat(0.18), 600) {
        let r = (p - centre).length();
        let expected_inside = if r < 0.075 && p.y > centre.y - 0.04 {
            true
        } else if r > 0.12 {
            false
        } else {
            continue;
        };
        checked += 1;
        if (sdf.sample(p) < 0.0) != expected_inside {
            wrong.push((p, sdf.sample(p)));
        }
    }
    assert!(checked > 200, "only {checked} points classified");
    assert!(
        wrong.is_empty(),
        "{} of {checked} points on the wrong side: {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(5)]
    );
}

#[test]
fn bad_sdf_parameters_are_rejected() {
    let mesh = TriMesh::uv_sphere(Vec3::ZERO, 1.0, 4, 4).expect("sphere");
    assert!(matches!(
        MeshSdf::build(&mesh, 4, 0.1),
        Err(vkhair::Error::InvalidParameter { name: "sdf resolution", .. })
    ));
    assert!(matches!(MeshSdf::build(&mesh, 4096, 0.1), Err(vkhair::Error::InvalidParameter { .. })));
    assert!(matches!(
        MeshSdf::build(&mesh, 32, f32::NAN),
        Err(vkhair::Error::InvalidParameter { name: "sdf margin", .. })
    ));
}

#[test]
fn the_sintel_bust_has_an_inside() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/sintel/sintel_bust.obj");
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return;
    }
    let mesh = TriMesh::load_obj(&path).expect("bust");
    let started = std::time::Instant::now();
    let sdf = MeshSdf::build(&mesh, 64, 0.05 * (mesh.bounds().1 - mesh.bounds().0).max_element()).expect("sdf");
    eprintln!(
        "sintel bust: {} triangles, {:?} grid built in {:.2?}",
        mesh.triangles.len(),
        sdf.dims,
        started.elapsed()
    );
    let inside = sdf.values.iter().filter(|v| **v < 0.0).count() as f32 / sdf.values.len() as f32;
    eprintln!("share of grid points inside: {:.3}", inside);
    assert!((0.01..0.6).contains(&inside), "{inside}");
    // A corner of the grid is outside and at least the margin away.
    assert!(sdf.values[0] > 0.0);
    // Every vertex of the mesh lies on its surface: |sdf| within a voxel diagonal.
    let worst = mesh.positions.iter().map(|p| sdf.sample(*p).abs()).fold(0.0f32, f32::max);
    assert!(worst <= sdf.cell * 3f32.sqrt(), "a vertex {worst} away from the surface (cell {})", sdf.cell);
}

/// A sphere with two open cards inside it (planes x = 0 and y = 0, one-sided,
/// as a character's inner mouth or eyelashes are): the cards flip the parity
/// of two of the three axis rays of points beside them.
pub fn sphere_with_cards() -> TriMesh {
    let sphere = TriMesh::uv_sphere(Vec3::ZERO, 0.1, 24, 32).expect("sphere");
    let mut positions = sphere.positions.clone();
    let mut triangles = sphere.triangles.clone();
    let mut card = |corners: [Vec3; 4]| {
        let base = positions.len() as u32;
        positions.extend(corners);
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base, base + 2, base + 3]);
    };
    card([
        Vec3::new(0.0, -0.05, -0.05),
        Vec3::new(0.0, 0.05, -0.05),
        Vec3::new(0.0, 0.05, 0.05),
        Vec3::new(0.0, -0.05, 0.05),
    ]);
    card([
        Vec3::new(-0.05, 0.0, -0.03),
        Vec3::new(0.093, 0.0, -0.03),
        Vec3::new(0.093, 0.0, 0.03),
        Vec3::new(-0.05, 0.0, 0.03),
    ]);
    TriMesh::new(positions, triangles).expect("sphere with cards")
}

/// Points just under the sphere's skin beside the cards are inside: within
/// `SDF_FACE_BAND_CELLS` of the skin the field takes the side of its face,
/// where two of the three axis rays (crossing a card) vote outside. (Farther
/// in, the vote decides, and the cards do mislead it there.) The same sphere
/// wound the other way has the same field.
#[test]
fn cards_inside_a_mesh_do_not_turn_its_skin_inside_out() {
    let mesh = sphere_with_cards();
    let sdf = MeshSdf::build(&mesh, 48, 0.03).expect("sdf");
    // Under the skin on the +x side, 4 to 7 mm deep: the -x ray crosses the
    // x = 0 card, the -y ray the y = 0 card.
    for p in [Vec3::new(0.09, 0.02, 0.02), Vec3::new(0.088, 0.03, 0.01), Vec3::new(0.093, 0.015, -0.02)] {
        let depth = 0.1 - p.length();
        assert!(depth > 0.003, "{p} is {depth} deep");
        let value = sdf.sample(p);
        assert!(value < 0.0, "{p}, {depth:.4} under the skin, has field value {value}");
    }
    // Just outside, the same points pushed out.
    for p in [Vec3::new(0.1, 0.022, 0.022), Vec3::new(0.098, 0.033, 0.011)] {
        assert!(sdf.sample(p) > 0.0, "{p} outside has field value {}", sdf.sample(p));
    }
    let flipped = TriMesh::new(mesh.positions.clone(), mesh.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect())
        .expect("flipped");
    let other = MeshSdf::build(&flipped, 48, 0.03).expect("sdf of the flipped mesh");
    // The corners in another order round the distances differently (grid
    // points on a card, at distance 0, may take either sign)
    let sides = |v: f32| (v.abs() > 1e-6).then_some(v < 0.0);
    let differ = sdf.values.iter().zip(&other.values).filter(|(a, b)| sides(**a) != sides(**b)).count();
    assert_eq!(differ, 0, "{differ} grid points change sides with the faces wound the other way");
    let worst = sdf.values.iter().zip(&other.values).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    // (and jump flooding may then settle on another triangle as near).
    assert!(worst < 0.01 * sdf.cell, "the fields differ by {worst}");
}
