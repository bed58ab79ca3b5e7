//! How much of a region of the picture hair hides: the pixels a mesh's
//! front-facing triangles project to (the region), and the share of them the
//! hair's passes changed, from the target read before the hair was drawn
//! ([`super::Offscreen::record_snapshot`]) and after.

use glam::{Mat4, Vec2, Vec3};

use crate::groom::mesh::TriMesh;

/// A pixel counts as covered by hair where the hair's passes changed one of
/// its sRGB-encoded 8-bit channels by more than this many steps: where a wisp
/// can be seen (a hair layer of about a tenth of the opacity of brown hair
/// over skin).
pub const COVERED_STEPS: u8 = 8;

/// The pixels of an `extent` image (rows from the top, as
/// [`super::Offscreen::read_rgba8`] reads them) whose centres lie inside a
/// triangle of `mesh` (placed by `to_world`) that faces `eye`, projected by
/// `view_proj`; triangles reaching behind the eye are left out.
pub fn front_facing_pixels(
    mesh: &TriMesh,
    to_world: Mat4,
    view_proj: Mat4,
    eye: Vec3,
    extent: (u32, u32),
) -> Vec<bool> {
    let (w, h) = extent;
    let mut mask = vec![false; w as usize * h as usize];
    for t in &mesh.triangles {
        let world = t.map(|v| to_world.transform_point3(mesh.positions[v as usize]));
        let normal = (world[1] - world[0]).cross(world[2] - world[0]);
        if normal.dot(eye - world[0]) <= 0.0 {
            continue;
        }
        let clip = world.map(|p| view_proj * p.extend(1.0));
        if clip.iter().any(|c| c.w <= 0.0 || !c.is_finite()) {
            continue;
        }
        let screen = clip.map(|c| Vec2::new((c.x / c.w * 0.5 + 0.5) * w as f32, (c.y / c.w * 0.5 + 0.5) * h as f32));
        let area = (screen[1] - screen[0]).perp_dot(screen[2] - screen[0]);
        if area == 0.0 {
            continue;
        }
        let lo = screen[0].min(screen[1]).min(screen[2]).max(Vec2::ZERO);
        let hi = screen[0].max(screen[1]).max(screen[2]).min(Vec2::new(w as f32, h as f32));
        for y in lo.y.floor() as u32..hi.y.ceil().max(0.0) as u32 {
            for x in lo.x.floor() as u32..hi.x.ceil().max(0.0) as u32 {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let b = [
                    (screen[2] - screen[1]).perp_dot(q - screen[1]) / area,
                    (screen[0] - screen[2]).perp_dot(q - screen[2]) / area,
                    (screen[1] - screen[0]).perp_dot(q - screen[0]) / area,
                ];
                if b.iter().all(|&x| x >= 0.0) {
                    mask[(y * w + x) as usize] = true;
                }
            }
        }
    }
    mask
}

/// Of the pixels of `mask`, how many the hair covers ([`COVERED_STEPS`]: a
/// channel of `after` differs from `before` by more than that), and how many
/// there are. `before` and `after` are RGBA8 images of `mask`'s pixels; a
/// length that does not match gives `None`.
pub fn covered_pixels(before: &[u8], after: &[u8], mask: &[bool]) -> Option<(usize, usize)> {
    if before.len() != after.len() || before.len() != 4 * mask.len() {
        return None;
    }
    let covered = before
        .chunks_exact(4)
        .zip(after.chunks_exact(4))
        .zip(mask)
        .filter(|&((b, a), &m)| m && b[..3].iter().zip(&a[..3]).any(|(x, y)| x.abs_diff(*y) > COVERED_STEPS))
        .count();
    Some((covered, mask.iter().filter(|&&m| m).count()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the z = 0 plane facing +z, as two triangles.
    fn square() -> TriMesh {
        let positions = vec![
            Vec3::new(-0.5, -0.5, 0.0),
            Vec3::new(0.5, -0.5, 0.0),
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(-0.5, 0.5, 0.0),
        ];
        TriMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]]).expect("square")
    }

    #[test]
    fn a_square_seen_from_the_front_covers_its_pixels_and_from_behind_none() {
        // From 2 along +z, a view 2 wide at the square onto 8×8 pixels: the
        // square covers the middle 4×4 pixels.
        let eye = 2.0 * Vec3::Z;
        let camera =
            crate::render::Camera::look_at(eye, Vec3::ZERO, 2.0 * 0.5f32.atan(), 1.0, 0.1, 10.0).expect("camera");
        let view_proj = camera.projection * camera.view;
        let mask = front_facing_pixels(&square(), Mat4::IDENTITY, view_proj, eye, (8, 8));
        let expected: Vec<bool> = (0..64).map(|i| (2..6).contains(&(i % 8)) && (2..6).contains(&(i / 8))).collect();
        assert_eq!(mask, expected);
        let flipped = Mat4::from_rotation_y(std::f32::consts::PI);
        let mask = front_facing_pixels(&square(), flipped, view_proj, eye, (8, 8));
        assert!(mask.iter().all(|&m| !m), "a square facing away covers nothing");
    }

    #[test]
    fn only_pixels_changed_past_the_threshold_inside_the_mask_count() {
        let before = vec![100u8; 4 * 4];
        let mut after = before.clone();
        after[0] = 100 + COVERED_STEPS + 1; // pixel 0: covered
        after[5] = 100 + COVERED_STEPS; // pixel 1: at the threshold, not covered
        after[10] = 0; // pixel 2: covered, but outside the mask
        let mask = [true, true, false, true];
        assert_eq!(covered_pixels(&before, &after, &mask), Some((1, 3)));
        assert_eq!(covered_pixels(&before, &after[..12], &mask), None);
    }
}
