//! The skinned mesh collider of the CPU reference, each function as its
//! shader twin in `glsl/include/mesh_sdf.glsl` (`VKHAIR_MESH_SKIN`) computes
//! it, in the same order of operations.

use glam::{Mat4, Vec3, Vec4};

use super::bodies::{to_head, MeshField, SubstepBones};
use super::{cross, dot};

/// `mesh_skin_rows`: the blend of `word`'s two bones, at the end of the
/// sub-step (`start` 0) or its start (3).
fn skin_rows(bones: SubstepBones<'_>, word: u32, start: usize) -> [Vec4; 3] {
    let (a, b) = (&bones[(word & 0xFF) as usize], &bones[((word >> 8) & 0xFF) as usize]);
    let w0 = (word >> 16) as f32 / 65535.0;
    let w1 = 1.0 - w0;
    [0, 1, 2].map(|i| a[start + i] * w0 + b[start + i] * w1)
}

/// `mesh_rows_apply`.
fn apply(m: &[Vec4; 3], q: Vec3) -> Vec3 {
    let r = |m: Vec4| ((m.x * q.x + m.y * q.y) + m.z * q.z) + m.w;
    Vec3::new(r(m[0]), r(m[1]), r(m[2]))
}

/// `mesh_rows_invert`.
fn invert(m: &[Vec4; 3], p: Vec3) -> Vec3 {
    let d = p - Vec3::new(m[0].w, m[1].w, m[2].w);
    let (r0, r1, r2) = (m[0].truncate(), m[1].truncate(), m[2].truncate());
    let (c0, c1, c2) = (cross(r1, r2), cross(r2, r0), cross(r0, r1));
    let det = dot(r0, c0);
    // Written to treat NaN as the shader does: no inverse.
    let invertible = det.abs() > 1e-12;
    if !invertible {
        return Vec3::splat(1e30);
    }
    ((c0 * d.x + c1 * d.y) + c2 * d.z) / det
}

impl MeshField<'_> {
    /// `mesh_nearest_point`.
    fn nearest_point(&self, q: Vec3) -> usize {
        let [nx, ny, _] = self.grid.dims;
        let g = ((q - self.grid.origin) / self.grid.cell + 0.5).floor();
        let b: [u32; 3] = std::array::from_fn(|a| {
            let top = self.grid.dims[a] as f32 - 1.0;
            let v = if g[a] >= 0.0 { g[a] } else { 0.0 };
            (if v <= top { v } else { top }) as u32
        });
        ((b[2] * ny + b[1]) * nx + b[0]) as usize
    }

    /// `mesh_point_word`.
    fn point_word(&self, words: &[u32], head: &Mat4, bones: SubstepBones<'_>, p: Vec3) -> u32 {
        let word = words[self.nearest_point(to_head(head, p))];
        let q = invert(&skin_rows(bones, word, 0), p);
        words[self.nearest_point(q)]
    }

    /// `mesh_collide_skinned`.
    pub(super) fn collide_skinned(
        &self,
        words: &[u32],
        head: &Mat4,
        bones: SubstepBones<'_>,
        p: Vec3,
        radius: f32,
    ) -> Vec3 {
        let r = skin_rows(bones, self.point_word(words, head, bones, p), 0);
        self.push(invert(&r, p), radius).map_or(p, |q| apply(&r, q))
    }

    /// `mesh_friction_skinned`.
    #[allow(clippy::too_many_arguments, reason = "mirrors the shader function")]
    pub(super) fn friction_skinned(
        &self,
        words: &[u32],
        head: &Mat4,
        bones: SubstepBones<'_>,
        p: Vec3,
        from: Vec3,
        radius: f32,
        friction: f32,
    ) -> Vec3 {
        let word = self.point_word(words, head, bones, p);
        let r = skin_rows(bones, word, 0);
        let from_q = invert(&skin_rows(bones, word, 3), from);
        self.hold(invert(&r, p), from_q, radius, friction).map_or(p, |q| apply(&r, q))
    }
}
