//! The bodies the hair meets: [`Collider`]s (spheres and capsules in the
//! head's frame) and the head's [`RigidTransform`].

use glam::{Mat4, Quat, Vec3};

use super::params::finite_vec;
use crate::codes::collider_kind;
use crate::error::{Error, Result};
use crate::gpu_types::ColliderShape;

/// Most colliders a simulation may have.
pub const MAX_COLLIDERS: usize = crate::limits::SIM_MAX_COLLIDERS as usize;

/// A collision shape: in the head's frame, moving with the head transform
/// ([`super::HairSim::set_colliders`]), or in the world for a body that moves
/// on its own ([`super::HairSim::set_body_colliders`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Collider {
    /// A sphere.
    Sphere {
        /// Centre in the head frame.
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
    },
    /// A capsule: the points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end in the head frame.
        a: Vec3,
        /// Second end in the head frame.
        b: Vec3,
        /// Radius (> 0).
        radius: f32,
    },
}

/// Refuses more head and body colliders together than a sub-step holds
/// ([`MAX_COLLIDERS`]).
pub(crate) fn validate_collider_total(head: usize, body: usize) -> Result<()> {
    if head + body > MAX_COLLIDERS {
        let allowed = format!("at most {MAX_COLLIDERS} head and body colliders together");
        return Err(Error::param("colliders", format!("{head} head + {body} body"), allowed));
    }
    Ok(())
}

/// Checks a collider list: at most [`MAX_COLLIDERS`], each valid.
pub(crate) fn validate_colliders(colliders: &[Collider]) -> Result<()> {
    if colliders.len() > MAX_COLLIDERS {
        return Err(Error::param("colliders", colliders.len(), format!("at most {MAX_COLLIDERS}")));
    }
    colliders.iter().try_for_each(Collider::validate)
}

impl Collider {
    pub(crate) fn validate(&self) -> Result<()> {
        let (points, radius) = match *self {
            Collider::Sphere { center, radius } => ([center, center], radius),
            Collider::Capsule { a, b, radius } => ([a, b], radius),
        };
        finite_vec("collider position", points[0])?;
        finite_vec("collider position", points[1])?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::param("collider radius", radius, "finite and > 0"));
        }
        Ok(())
    }

    /// The collider moved by `m` (a rigid transform: a head's, or a
    /// character's place in the world); the radius is kept.
    pub fn moved(&self, m: &Mat4) -> Collider {
        match *self {
            Collider::Sphere { center, radius } => Collider::Sphere { center: m.transform_point3(center), radius },
            Collider::Capsule { a, b, radius } => {
                Collider::Capsule { a: m.transform_point3(a), b: m.transform_point3(b), radius }
            }
        }
    }

    /// The collider `t` of the way from `self` to `to` (ends and radius
    /// linearly; `to` itself when the two are not the same kind).
    pub(crate) fn lerp(&self, to: &Collider, t: f32) -> Collider {
        match (*self, *to) {
            (Collider::Sphere { center: c0, radius: r0 }, Collider::Sphere { center: c1, radius: r1 }) => {
                Collider::Sphere { center: c0.lerp(c1, t), radius: r0 + (r1 - r0) * t }
            }
            (Collider::Capsule { a: a0, b: b0, radius: r0 }, Collider::Capsule { a: a1, b: b1, radius: r1 }) => {
                Collider::Capsule { a: a0.lerp(a1, t), b: b0.lerp(b1, t), radius: r0 + (r1 - r0) * t }
            }
            _ => *to,
        }
    }

    /// The collider in world space with the head at `head`, as the step kernel
    /// (and the CPU reference) sees it, at rest (no motion, no friction).
    pub(crate) fn in_world(self, head: &Mat4) -> ColliderShape {
        match self {
            Collider::Sphere { center, radius } => {
                let c = head.transform_point3(center);
                ColliderShape { a: c, radius, b: c, kind: collider_kind::SPHERE as f32, ..ColliderShape::default() }
            }
            Collider::Capsule { a, b, radius } => ColliderShape {
                a: head.transform_point3(a),
                radius,
                b: head.transform_point3(b),
                kind: collider_kind::CAPSULE as f32,
                ..ColliderShape::default()
            },
        }
    }
}

/// The head's rigid motion: rotation then translation (world from head).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidTransform {
    /// Rotation (normalised on use).
    pub rotation: Quat,
    /// Translation, meters.
    pub translation: Vec3,
}

impl Default for RigidTransform {
    fn default() -> Self {
        RigidTransform { rotation: Quat::IDENTITY, translation: Vec3::ZERO }
    }
}

impl RigidTransform {
    /// Checks for NaN/Inf and a degenerate rotation.
    pub fn validate(&self) -> Result<()> {
        if !self.translation.is_finite() || !self.rotation.is_finite() || self.rotation.length_squared() < 1e-12 {
            return Err(Error::param("head transform", format!("{self:?}"), "a finite rigid transform"));
        }
        Ok(())
    }

    /// The matrix (world from head).
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_rotation_translation(self.rotation.normalize(), self.translation)
    }

    /// Interpolates rotation (slerp) and translation (lerp).
    pub fn lerp(&self, to: &RigidTransform, t: f32) -> RigidTransform {
        RigidTransform {
            rotation: self.rotation.normalize().slerp(to.rotation.normalize(), t),
            translation: self.translation.lerp(to.translation, t),
        }
    }
}
