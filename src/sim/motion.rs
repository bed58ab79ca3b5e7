//! The reference motion (a character shaking her head) and the `thesis`
//! scene's collision bodies.

use glam::{Quat, Vec3};

use super::body::{Collider, RigidTransform};
use crate::groom::scenes::{THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS};

/// The neck pivot the head turns about, meters (world = head frame at rest).
pub const NECK_PIVOT: Vec3 = Vec3::new(0.0, 1.5, 0.0);

/// The head shaking "no" with a nod: a turn about the vertical axis of
/// `amplitude` radians at `frequency` Hz plus a nod of a third of it at twice the
/// frequency, both about the neck pivot.
pub fn shaking_head(time: f32, amplitude: f32, frequency: f32) -> RigidTransform {
    shaking_head_about(time, amplitude, frequency, NECK_PIVOT)
}

/// [`shaking_head`] about another pivot (for grooms placed elsewhere).
pub fn shaking_head_about(time: f32, amplitude: f32, frequency: f32, pivot: Vec3) -> RigidTransform {
    let phase = std::f32::consts::TAU * frequency * time;
    let rotation =
        Quat::from_rotation_y(amplitude * phase.sin()) * Quat::from_rotation_x(amplitude / 3.0 * (2.0 * phase).sin());
    RigidTransform { rotation, translation: pivot - rotation * pivot }
}

/// The default reference motion: ±0.6 rad at 1 Hz.
pub fn reference_motion(time: f32) -> RigidTransform {
    shaking_head(time, 0.6, 1.0)
}

/// A violent version for collision tests: ±1.2 rad at 3 Hz plus a vertical jolt.
pub fn violent_motion(time: f32) -> RigidTransform {
    let mut t = shaking_head(time, 1.2, 3.0);
    t.translation.y += 0.05 * (std::f32::consts::TAU * 5.0 * time).sin();
    t
}

/// A violent motion about `pivot` for soak runs: ±1.2 rad at 3 Hz with a nod of
/// a third of that, and the whole head jolted by up to `jolt` (its units) at 5 Hz
/// vertically and 2 Hz sideways.
pub fn violent_about(time: f32, pivot: Vec3, jolt: f32) -> RigidTransform {
    let mut t = shaking_head_about(time, 1.2, 3.0, pivot);
    let tau = std::f32::consts::TAU;
    t.translation += jolt * Vec3::new((tau * 2.0 * time).sin(), (tau * 5.0 * time).sin(), 0.0);
    t
}

/// The `thesis` scene's bodies in the head frame: the head sphere, the neck and
/// the shoulders as capsules.
pub fn thesis_colliders() -> Vec<Collider> {
    vec![
        Collider::Sphere { center: THESIS_HEAD_CENTER, radius: THESIS_HEAD_RADIUS },
        Collider::Capsule { a: Vec3::new(0.0, 1.38, 0.0), b: Vec3::new(0.0, 1.52, 0.0), radius: 0.05 },
        Collider::Capsule { a: Vec3::new(-0.2, 1.33, 0.0), b: Vec3::new(0.2, 1.33, 0.0), radius: 0.06 },
    ]
}
