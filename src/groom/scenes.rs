//! The reference scenes of the design (SPEC.md, "Reference scenes").

use glam::Vec3;

use super::grow::{grow, GrowParams, Scalp};
use super::Groom;
use crate::error::Result;

/// Radius of the `thesis` scene's head sphere, meters.
pub const THESIS_HEAD_RADIUS: f32 = 0.1;
/// Centre of the `thesis` scene's head sphere, meters.
pub const THESIS_HEAD_CENTER: Vec3 = Vec3::new(0.0, 1.6, 0.0);
/// Radius of the sphere around the `thesis` scene's head and hair, meters: the
/// size its lights are laid out for (`render::Light::thesis_rig`).
pub const THESIS_BOUNDING_RADIUS: f32 = 0.465;

/// The scalp of the `thesis` scene: a head-sized sphere, crown and back covered, face free.
pub fn thesis_scalp() -> Scalp {
    Scalp::sphere_cap(THESIS_HEAD_CENTER, THESIS_HEAD_RADIUS, 1.9)
}

/// The `thesis` scene's key hairs: 1750 strands × 6 points (10,500 particles) of
/// long hair (0.35 m) on a head-sized sphere, as in the thesis' shaking-head test,
/// combed back from the face.
pub fn thesis() -> Result<Groom> {
    grow(
        &thesis_scalp(),
        &GrowParams {
            strands: 1750,
            points_per_strand: 6,
            length: 0.35,
            length_jitter: 0.1,
            droop: 2.5,
            gravity: Vec3::NEG_Y,
            direction_jitter: 0.15,
            segment_growth: 1.5,
            comb: Vec3::new(0.0, 0.2, -0.8),
            // The thesis' own groom: combed back, not parted.
            face: Vec3::ZERO,
            seed: 2011,
        },
    )
}
