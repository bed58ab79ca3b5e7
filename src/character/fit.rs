//! Colliders fitted to a character: a capsule per bone, in the bone's own
//! frame, around the vertices the bone dominates in the bind pose.
//!
//! The capsule's axis runs from the joint toward its child joints (their mean,
//! when the bone has several; along the vertices' principal direction for a
//! bone without children), clipped to the span of its vertices along that
//! axis; its radius is the 90th percentile of those vertices' distances
//! from the axis: at the skin where the body is round, a little outside it
//! where it is flat, so that hair resting there floats rather than sinks.

use glam::{Mat4, Vec3};

use super::{Character, Pose};
use crate::sim::{Collider, RigidTransform};

/// The fewest vertices a bone must dominate to get a capsule.
pub const MIN_CAPSULE_VERTICES: usize = 24;

/// A capsule attached to a skin joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneCapsule {
    /// The skin joint it follows.
    pub joint: usize,
    /// First end, in the joint's frame.
    pub a: Vec3,
    /// Second end, in the joint's frame.
    pub b: Vec3,
    /// Radius, in the character's units.
    pub radius: f32,
}

impl BoneCapsule {
    /// The capsule in the world at `pose`.
    pub fn in_world(&self, character: &Character, pose: &Pose) -> Collider {
        let m = character.joint_transform(pose, self.joint);
        Collider::Capsule { a: m.transform_point3(self.a), b: m.transform_point3(self.b), radius: self.radius }
    }

    /// The capsule in the frame `frame` (world from that frame), e.g. the head's,
    /// at `pose`.
    pub fn in_frame(&self, character: &Character, pose: &Pose, frame: &RigidTransform) -> Collider {
        let to_frame = frame.matrix().inverse() * character.joint_transform(pose, self.joint);
        Collider::Capsule {
            a: to_frame.transform_point3(self.a),
            b: to_frame.transform_point3(self.b),
            radius: self.radius,
        }
    }
}

impl Character {
    /// A capsule for every bone that dominates at least
    /// [`MIN_CAPSULE_VERTICES`] vertices, except `skip` (e.g. the head, which
    /// gets the mesh collider's field instead), largest first.
    pub fn fit_capsules(&self, skip: &[usize]) -> Vec<BoneCapsule> {
        let rest = self.bind_pose();
        let world = &self.positions;
        let joints = &self.skeleton.joints;
        let mut owned: Vec<Vec<Vec3>> = vec![Vec::new(); joints.len()];
        for (v, p) in world.iter().enumerate() {
            owned[self.dominant_joint(v)].push(*p);
        }
        let mut capsules = Vec::new();
        for (j, points) in owned.iter().enumerate() {
            if points.len() < MIN_CAPSULE_VERTICES || skip.contains(&j) {
                continue;
            }
            let frame = self.joint_transform(&rest, j);
            let origin = frame.transform_point3(Vec3::ZERO);
            let children: Vec<Vec3> = joints
                .iter()
                .filter(|&&n| self.skeleton.nodes[n].parent == Some(joints[j]))
                .map(|&n| rest.nodes[n].transform_point3(Vec3::ZERO))
                .collect();
            let mean = points.iter().copied().sum::<Vec3>() / points.len() as f32;
            let toward = if children.is_empty() {
                principal_axis(points, mean)
            } else {
                children.iter().copied().sum::<Vec3>() / children.len() as f32 - origin
            };
            let Some(axis) = toward.try_normalize() else { continue };
            let along: Vec<f32> = points.iter().map(|p| (*p - origin).dot(axis)).collect();
            let (lo, hi) = along.iter().fold((f32::MAX, f32::MIN), |(l, h), &s| (l.min(s), h.max(s)));
            let mut radial: Vec<f32> =
                points.iter().zip(&along).map(|(p, &s)| (*p - origin - axis * s).length()).collect();
            radial.sort_by(f32::total_cmp);
            let radius = radial[radial.len() * 9 / 10];
            if !(radius.is_finite() && radius > 0.0) {
                continue;
            }
            // The ends pulled in by the radius: the caps end at the vertices' span.
            let (s0, s1) =
                if hi - lo > 2.0 * radius { (lo + radius, hi - radius) } else { (0.5 * (lo + hi), 0.5 * (lo + hi)) };
            let to_joint: Mat4 = frame.inverse();
            capsules.push(BoneCapsule {
                joint: j,
                a: to_joint.transform_point3(origin + axis * s0),
                b: to_joint.transform_point3(origin + axis * s1),
                radius,
            });
        }
        capsules.sort_by(|x, y| y.radius.total_cmp(&x.radius));
        capsules
    }
}

/// The direction of largest spread of `points` about `mean` (power iteration
/// on their covariance).
fn principal_axis(points: &[Vec3], mean: Vec3) -> Vec3 {
    let mut c = [Vec3::ZERO; 3];
    for p in points {
        let d = *p - mean;
        c[0] += d * d.x;
        c[1] += d * d.y;
        c[2] += d * d.z;
    }
    let m = glam::Mat3::from_cols(c[0], c[1], c[2]);
    let mut v = Vec3::new(0.577, 0.577, 0.577);
    for _ in 0..32 {
        v = (m * v).try_normalize().unwrap_or(Vec3::Y);
    }
    v
}
