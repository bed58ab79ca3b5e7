//! Triangles enclosed by the rest of a mesh: an inner layer under a
//! character's skin, a part inside a part, cards inside a head. A signed
//! distance field takes the distance to the nearest triangle, so an enclosed
//! triangle puts a zero inside the body and turns the field's slope toward it
//! (`MeshSdf`, the mesh collider); the body as a solid is the union of its
//! parts, whose surface is the triangles that are not enclosed.

use glam::Vec3;

use super::mesh::TriMesh;
use super::sdf::facing;
use crate::error::Result;

/// The rest of a mesh's winding number at a triangle's centroid past which
/// the triangle is enclosed: on the outer surface of a closed mesh the rest
/// winds 0.5 around it, on a closed layer inside another 1.5, on a card
/// inside a closed mesh 1.
pub const ENCLOSED_WINDING: f32 = 0.75;

/// Per triangle of `mesh`, whether the rest of the mesh winds around its
/// centroid more than [`ENCLOSED_WINDING`] times (generalised winding number,
/// Jacobson et al. 2013, read by the mesh's overall winding). It measures every
/// triangle against every other: a cost in the square of the triangle count
/// (a few thousand triangles take a fraction of a second).
pub fn enclosed_triangles(mesh: &TriMesh) -> Vec<bool> {
    let facing = facing(mesh);
    let corners: Vec<[Vec3; 3]> = (0..mesh.triangles.len()).map(|t| mesh.corners(t)).collect();
    corners
        .iter()
        .enumerate()
        .map(|(t, [a, b, c])| {
            let rest = corners.iter().enumerate().filter(|&(other, _)| other != t).map(|(_, corners)| *corners);
            winding(rest, facing, (*a + *b + *c) / 3.0) > ENCLOSED_WINDING
        })
        .collect()
}

/// The generalised winding number of `mesh` at `p`, read by the mesh's overall
/// winding: 1 inside a closed mesh, 0 outside, 0.5 on its surface, 1.5 on a
/// closed layer inside it.
pub fn winding_number(mesh: &TriMesh, p: Vec3) -> f32 {
    winding((0..mesh.triangles.len()).map(|t| mesh.corners(t)), facing(mesh), p)
}

/// The winding number at `p` of `triangles` (their corners) wound `facing`:
/// the solid angles they subtend, summed in order, over 4π.
fn winding(triangles: impl Iterator<Item = [Vec3; 3]>, facing: f32, p: Vec3) -> f32 {
    let sum: f32 = triangles.map(|[a, b, c]| solid_angle(a - p, b - p, c - p)).sum();
    sum * facing / (4.0 * std::f32::consts::PI)
}

/// `mesh` without its enclosed triangles ([`enclosed_triangles`]) and, per
/// vertex of the result, its index in `mesh`; `None` when every triangle is
/// enclosed.
pub fn without_enclosed(mesh: &TriMesh) -> Result<Option<(TriMesh, Vec<usize>)>> {
    let enclosed = enclosed_triangles(mesh);
    let open = mesh.triangles.iter().zip(&enclosed).filter(|(_, e)| !**e).map(|(t, _)| *t);
    super::mesh::compact(&mesh.positions, open)
}

/// The signed solid angle of the triangle (a, b, c) seen from the origin (van
/// Oosterom and Strackee 1983), positive for a triangle wound outward around it.
fn solid_angle(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let det = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * det.atan2(den)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nested(inner_radius: f32) -> (TriMesh, usize) {
        let outer = TriMesh::uv_sphere(Vec3::ZERO, 0.1, 12, 16).expect("outer");
        let inner = TriMesh::uv_sphere(Vec3::new(0.0, 0.005, 0.0), inner_radius, 12, 16).expect("inner");
        let base = outer.positions.len() as u32;
        let positions = outer.positions.iter().chain(&inner.positions).copied().collect();
        let triangles =
            outer.triangles.iter().copied().chain(inner.triangles.iter().map(|t| t.map(|v| v + base))).collect();
        (TriMesh::new(positions, triangles).expect("nested"), outer.triangles.len())
    }

    /// A layer inside a sphere is enclosed, the sphere's own skin is not; the
    /// same meshes wound the other way give the same answer; a card inside is
    /// enclosed; the mesh without them keeps the skin's triangles and vertices.
    #[test]
    fn an_inner_layer_and_a_card_are_enclosed_and_the_skin_is_not() {
        let (mesh, skin) = nested(0.092);
        let enclosed = enclosed_triangles(&mesh);
        assert!(enclosed[..skin].iter().all(|&e| !e), "a skin triangle is taken as enclosed");
        assert!(enclosed[skin..].iter().all(|&e| e), "an inner-layer triangle is not taken as enclosed");
        let flipped = TriMesh::new(mesh.positions.clone(), mesh.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect())
            .expect("f");
        assert_eq!(enclosed_triangles(&flipped), enclosed);
        let (kept, vertices) = without_enclosed(&mesh).expect("mesh").expect("some triangles");
        assert_eq!(kept.triangles.len(), skin);
        for (t, original) in kept.triangles.iter().zip(&mesh.triangles) {
            assert_eq!(t.map(|v| kept.positions[v as usize]), original.map(|v| mesh.positions[v as usize]));
        }
        let TriMesh { mut positions, mut triangles } = TriMesh::uv_sphere(Vec3::ZERO, 0.1, 12, 16).expect("sphere");
        assert!(vertices.iter().all(|&v| v < positions.len()), "a kept vertex is an inner one");
        // A card (two triangles) across the inside.
        let base = positions.len() as u32;
        positions.extend([
            Vec3::new(-0.05, 0.01, -0.05),
            Vec3::new(0.05, 0.01, -0.05),
            Vec3::new(0.05, 0.01, 0.05),
            Vec3::new(-0.05, 0.01, 0.05),
        ]);
        triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        let carded = TriMesh::new(positions, triangles).expect("carded");
        let enclosed = enclosed_triangles(&carded);
        assert_eq!(enclosed.iter().filter(|&&e| e).count(), 2, "the card's two triangles");
        assert!(enclosed[enclosed.len() - 2..].iter().all(|&e| e));
    }

    /// Inside, outside and between two nested spheres.
    #[test]
    fn the_winding_number_counts_the_layers_around_a_point() {
        let (mesh, _) = nested(0.05);
        for (p, w) in [(Vec3::ZERO, 2.0), (Vec3::new(0.08, 0.0, 0.0), 1.0), (Vec3::new(0.0, 0.2, 0.0), 0.0)] {
            assert!((winding_number(&mesh, p) - w).abs() < 1e-3, "{p}: {}", winding_number(&mesh, p));
        }
    }

    /// A sphere alone keeps every triangle.
    #[test]
    fn a_closed_mesh_alone_has_nothing_enclosed() {
        let sphere = TriMesh::uv_sphere(Vec3::ZERO, 0.1, 12, 16).expect("sphere");
        assert!(enclosed_triangles(&sphere).iter().all(|&e| !e));
    }
}
