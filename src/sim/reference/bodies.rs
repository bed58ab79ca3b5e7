//! The bodies of the CPU reference: the mesh collider's field, spheres and
//! capsules, and friction against them, each as its shader twin computes it
//! (`glsl/include/mesh_sdf.glsl`, `sim.glsl`, `sim_bodies.glsl`).

use glam::{Mat4, Vec3, Vec4};

use super::{dot, transform_point};
use crate::gpu_types::ColliderShape;
use crate::groom::sdf::MeshSdf;
use crate::sim::mesh_collider::MeshGrid;

/// `sim_to_head`: Rᵀ(p − t) for a rigid `m`.
pub(super) fn to_head(m: &Mat4, p: Vec3) -> Vec3 {
    let d = p - m.col(3).truncate();
    let row = |i: usize| (m.col(i).x * d.x + m.col(i).y * d.y) + m.col(i).z * d.z;
    Vec3::new(row(0), row(1), row(2))
}

/// `mesh_bone_base`'s bones of one sub-step: per slot, the rows at its end
/// then at its start.
pub(crate) type SubstepBones<'a> = &'a [[Vec4; 6]];

/// The mesh collider's field as the solver sees it.
#[derive(Clone, Copy)]
pub(crate) struct MeshField<'a> {
    pub grid: MeshGrid,
    pub values: &'a [f32],
    /// A skinned field's grid points' bones (`MeshSkin::words`).
    pub skin: Option<&'a [u32]>,
}

impl<'a> MeshField<'a> {
    pub(crate) fn new(sdf: &'a MeshSdf) -> Self {
        MeshField {
            grid: MeshGrid { origin: sdf.origin, cell: sdf.cell, dims: sdf.dims },
            values: &sdf.values,
            skin: None,
        }
    }

    /// The field following bones by `skin` (its grid points' words).
    pub(crate) fn with_skin(self, skin: Option<&'a [u32]>) -> Self {
        MeshField { skin, ..self }
    }

    /// `mesh_sample`: trilinear value and its gradient (per cell) at q, head frame.
    pub(crate) fn sample(&self, q: Vec3) -> (Vec3, f32) {
        let dims = self.grid.dims;
        let g = (q - self.grid.origin) / self.grid.cell;
        let top = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32) - 1.0;
        if g.cmplt(Vec3::ZERO).any() || g.cmpgt(top).any() {
            return (Vec3::ZERO, 1e30);
        }
        let base = g.floor().min(top - 1.0);
        let f = g - base;
        let (sx, sy, sz) = (1usize, dims[0] as usize, (dims[0] * dims[1]) as usize);
        let k = ((base.z as usize * dims[1] as usize) + base.y as usize) * dims[0] as usize + base.x as usize;
        let v = |o: usize| self.values[k + o];
        let (c000, c100, c010, c110) = (v(0), v(sx), v(sy), v(sx + sy));
        let (c001, c101, c011, c111) = (v(sz), v(sx + sz), v(sy + sz), v(sx + sy + sz));
        let x00 = c000 + (c100 - c000) * f.x;
        let x10 = c010 + (c110 - c010) * f.x;
        let x01 = c001 + (c101 - c001) * f.x;
        let x11 = c011 + (c111 - c011) * f.x;
        let y0 = x00 + (x10 - x00) * f.y;
        let y1 = x01 + (x11 - x01) * f.y;
        let value = y0 + (y1 - y0) * f.z;
        let gx0 = (c100 - c000) + ((c110 - c010) - (c100 - c000)) * f.y;
        let gx1 = (c101 - c001) + ((c111 - c011) - (c101 - c001)) * f.y;
        let gx = gx0 + (gx1 - gx0) * f.z;
        let gy = (x10 - x00) + ((x11 - x01) - (x10 - x00)) * f.z;
        let gz = y1 - y0;
        (Vec3::new(gx, gy, gz), value)
    }

    /// `mesh_push`: `q` pushed out to a gap of `radius`, `None` where it
    /// keeps it already (or the gradient vanishes).
    pub(super) fn push(&self, q: Vec3, radius: f32) -> Option<Vec3> {
        let (gradient, value) = self.sample(q);
        if value < radius {
            let len = dot(gradient, gradient).sqrt();
            if len > 0.0 {
                return Some(q + gradient * ((radius - value) / len));
            }
        }
        None
    }

    /// `mesh_hold`: `q` held against the surface (its motion along it since
    /// `from_q` cut by `friction`), `None` where it does not touch.
    pub(super) fn hold(&self, q: Vec3, from_q: Vec3, radius: f32, friction: f32) -> Option<Vec3> {
        let (gradient, value) = self.sample(q);
        let contact = radius + 0.1 * self.grid.cell;
        let len = dot(gradient, gradient).sqrt();
        // Written to treat NaN as the shader does: no contact.
        let held = value < contact && len > 0.0 && friction > 0.0;
        if !held {
            return None;
        }
        let n = gradient / len;
        let moved = q - from_q;
        let along = moved - n * dot(n, moved);
        Some(q - along * friction)
    }

    /// `mesh_collide`.
    fn collide(&self, head: &Mat4, p: Vec3, radius: f32) -> Vec3 {
        self.push(to_head(head, p), radius).map_or(p, |q| transform_point(head, q))
    }

    /// `mesh_friction`.
    #[allow(clippy::too_many_arguments, reason = "mirrors the shader function")]
    pub(super) fn friction(
        &self,
        head: &Mat4,
        previous_head: &Mat4,
        p: Vec3,
        from: Vec3,
        radius: f32,
        friction: f32,
    ) -> Vec3 {
        let held = self.hold(to_head(head, p), to_head(previous_head, from), radius, friction);
        held.map_or(p, |q| transform_point(head, q))
    }
}

/// `sim_collider_t`.
fn collider_t(c: &ColliderShape, p: Vec3) -> f32 {
    if !c.is_capsule() {
        return 0.0;
    }
    let ab = c.b - c.a;
    let len2 = dot(ab, ab);
    if len2 > 0.0 {
        (dot(p - c.a, ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `sim_collider_point`.
fn collider_point(c: &ColliderShape, t: f32) -> Vec3 {
    if c.is_capsule() {
        c.a + (c.b - c.a) * t
    } else {
        c.a
    }
}

/// `sim_collide`.
fn collide(c: &ColliderShape, p: Vec3, radius: f32) -> Vec3 {
    let closest = collider_point(c, collider_t(c, p));
    let d = p - closest;
    let dist = dot(d, d).sqrt();
    let reach = c.radius + radius;
    if dist < reach && dist > 0.0 {
        closest + d * (reach / dist)
    } else {
        p
    }
}

/// `sim_collider_friction`.
pub(super) fn collider_friction(c: &ColliderShape, p: Vec3, v: Vec3, radius: f32, dt: f32) -> Vec3 {
    let friction = c.friction;
    // Written to treat NaN as the shader does: no friction, no contact.
    let rubs = friction > 0.0;
    if !rubs {
        return v;
    }
    let t = collider_t(c, p);
    let d = p - collider_point(c, t);
    let dist = dot(d, d).sqrt();
    let reach = c.radius + radius;
    let contact = reach + radius;
    let touching = dist < contact && dist > 0.0;
    if !touching {
        return v;
    }
    let surface = c.moved_a + (c.moved_b - c.moved_a) * t;
    let share = if dist > reach { (contact - dist) / radius } else { 1.0 };
    let n = d / dist;
    let relative = v - surface / dt;
    let along = relative - n * dot(n, relative);
    v - along * (friction * share)
}

/// The bodies a particle collides with: spheres and capsules, and the mesh
/// collider when `SIM_MESH` is set.
#[derive(Clone, Copy)]
pub(super) struct Bodies<'a> {
    pub colliders: &'a [ColliderShape],
    pub mesh: Option<MeshField<'a>>,
    pub head: &'a Mat4,
    /// A skinned field's bones of the sub-step (`SIM_MESH_SKIN`; else empty).
    pub bones: SubstepBones<'a>,
}

impl Bodies<'_> {
    pub(super) fn collide(&self, mut p: Vec3, radius: f32) -> Vec3 {
        for c in self.colliders {
            p = collide(c, p, radius);
        }
        match &self.mesh {
            Some(mesh @ MeshField { skin: Some(words), .. }) if !self.bones.is_empty() => {
                mesh.collide_skinned(words, self.head, self.bones, p, radius)
            }
            Some(mesh) => mesh.collide(self.head, p, radius),
            None => p,
        }
    }

    /// `mesh_friction` (or `mesh_friction_skinned`) against the mesh collider.
    pub(super) fn mesh_friction(&self, previous_head: &Mat4, p: Vec3, from: Vec3, radius: f32, friction: f32) -> Vec3 {
        match &self.mesh {
            Some(mesh @ MeshField { skin: Some(words), .. }) if !self.bones.is_empty() => {
                mesh.friction_skinned(words, self.head, self.bones, p, from, radius, friction)
            }
            Some(mesh) => mesh.friction(self.head, previous_head, p, from, radius, friction),
            None => p,
        }
    }
}
