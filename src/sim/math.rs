//! Vector math the simulation shares with its shaders and its CPU reference,
//! written out in the shaders' order of operations (`glsl/include/sim.glsl`)
//! so that both round alike: production code (`sim::scalp`) and the reference
//! use these, not glam's own, whose order differs.

use glam::{Mat4, Vec3};

/// a · b, summed as the shaders do.
pub(crate) fn dot(a: Vec3, b: Vec3) -> f32 {
    (a.x * b.x + a.y * b.y) + a.z * b.z
}

/// m · (p, 1).
pub(crate) fn transform_point(m: &Mat4, p: Vec3) -> Vec3 {
    let c = |i: usize| m.col(i).truncate();
    ((c(0) * p.x + c(1) * p.y) + c(2) * p.z) + c(3)
}

/// m · (v, 0).
pub(crate) fn rotate(m: &Mat4, v: Vec3) -> Vec3 {
    let c = |i: usize| m.col(i).truncate();
    (c(0) * v.x + c(1) * v.y) + c(2) * v.z
}

/// a × b.
pub(crate) fn cross(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)
}
