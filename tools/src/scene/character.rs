//! The `--gltf` scene: a skinned, animated character, key hairs grown on its
//! head in the head joint's frame, the head's region as the mesh collider
//! (it moves with the head), and a capsule per bone near the head as the
//! simulation's body colliders, placed in the world at every frame's pose.

use glam::{Mat4, Vec3};
use vkhair::character::{BoneCapsule, Character, Pose};
use vkhair::groom::grow::{grow, GrowParams, Scalp};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::Groom;
use vkhair::sim::scalp::VertexSkin;
use vkhair::sim::{Collider, RigidTransform, MAX_COLLIDERS};

use crate::args::input::InputArgs;
use crate::output::Error;
use crate::say;

/// Key hairs grown on the head.
const KEY_HAIRS: usize = 600;
/// Their length, meters.
const HAIR_LENGTH: f32 = 0.28;
/// Capsules kept: the nearest the head, up to the simulation's limit less a margin.
const CAPSULES: usize = MAX_COLLIDERS / 2;

/// A loaded `--gltf` character with what the tools need of it.
pub struct CharacterScene {
    pub character: Character,
    pub animation: usize,
    /// The skin joint the hair grows on.
    pub head: usize,
    pub capsules: Vec<BoneCapsule>,
}

impl CharacterScene {
    /// Reads the character, picks its animation and head, fits its capsules.
    pub fn load(a: &InputArgs) -> Result<Option<Self>, Error> {
        let Some(path) = &a.gltf else { return Ok(None) };
        let character = Character::load(path)?;
        let sk = &character.skeleton;
        if sk.animations.is_empty() {
            return Err(format!("{}: the character has no animation", path.display()).into());
        }
        let animation = match &a.animation {
            Some(name) => sk.animation_index(name)?,
            None => 0,
        };
        let head = match &a.head_joint {
            Some(name) => character.joint_named(name)?,
            None => character.head_joint(),
        };
        let rest = character.bind_pose();
        let origin = character.joint_transform(&rest, head).transform_point3(Vec3::ZERO);
        let mut capsules = character.fit_capsules(&[head]);
        let distance = |c: &BoneCapsule| {
            let m = character.joint_transform(&rest, c.joint);
            let (a, b) = (m.transform_point3(c.a), m.transform_point3(c.b));
            segment_distance(origin, a, b) - c.radius
        };
        // Only what the hair can reach: bones within one and a half hair lengths
        // of the head joint, the nearest first.
        capsules.retain(|c| distance(c) < 1.5 * HAIR_LENGTH);
        capsules.sort_by(|x, y| distance(x).total_cmp(&distance(y)));
        capsules.truncate(CAPSULES);
        let names = |j: usize| sk.nodes[sk.joints[j]].name.clone();
        say!(
            "character: {} vertices, {} joints, head joint {:?}, animation {:?} ({:.2} s), {} capsules ({})",
            character.positions.len(),
            sk.joints.len(),
            names(head),
            sk.animations[animation].name,
            sk.animations[animation].duration(),
            capsules.len(),
            capsules.iter().map(|c| names(c.joint)).collect::<Vec<_>>().join(", ")
        );
        Ok(Some(CharacterScene { character, animation, head, capsules }))
    }

    /// The pose at `time` seconds into the animation (looping).
    pub fn pose(&self, time: f32) -> Pose {
        self.character.pose(Some(self.animation), time)
    }

    /// The head's frame at `time`.
    pub fn head_at(&self, time: f32) -> RigidTransform {
        self.character.rigid_frame(&self.pose(time), self.head)
    }

    /// The capsules at `time`, in the world (the simulation's body colliders).
    pub fn colliders_at(&self, time: f32) -> Vec<Collider> {
        let pose = self.pose(time);
        self.capsules.iter().map(|c| c.in_world(&self.character, &pose)).collect()
    }

    /// The character's mesh in the bind pose, in the head's frame (the
    /// groom's), with its skin: the scalp the roots are bound to.
    pub fn scalp(&self) -> Result<vkhair::sim::scalp::Scalp, Error> {
        let to_head = self.bind_frame().inverse();
        let positions = self.character.positions.iter().map(|p| to_head.transform_point3(*p)).collect();
        let skin =
            self.character.weights.iter().map(|(j, w)| VertexSkin { joints: j.map(u32::from), weights: *w }).collect();
        Ok(vkhair::sim::scalp::Scalp {
            skin,
            ..vkhair::sim::scalp::Scalp::new(TriMesh::new(positions, self.character.triangles.clone())?)
        })
    }

    /// The scalp's bones at `time`: each joint's skinning matrix after the
    /// head frame's bind placement (head frame, bind pose → world).
    pub fn scalp_bones(&self, time: f32) -> Vec<Mat4> {
        let bind = self.bind_frame();
        self.pose(time).skin.iter().map(|m| *m * bind).collect()
    }

    /// The head's frame in the bind pose.
    pub fn bind_frame(&self) -> Mat4 {
        self.character.rigid_frame(&self.character.bind_pose(), self.head).matrix()
    }

    /// The whole character at `time`, in the world.
    pub fn body_at(&self, time: f32) -> Result<TriMesh, Error> {
        Ok(self.character.mesh(&self.pose(time))?)
    }

    /// The head's region at rest, in the head's frame (the mesh collider), and
    /// key hairs grown on its upper part, combed back (away from where the
    /// character faces).
    pub fn groom(&self, points: usize) -> Result<(Groom, TriMesh), Error> {
        let rest = self.character.bind_pose();
        let frame = self.character.rigid_frame(&rest, self.head).matrix();
        let to_head: Mat4 = frame.inverse();
        let region = self.character.region_mesh(self.head, &rest)?;
        let local =
            TriMesh::new(region.positions.iter().map(|p| to_head.transform_point3(*p)).collect(), region.triangles)?;
        // No roots on the face: triangles facing forward below the crown are left out.
        let facing = self.character.forward();
        let forward = to_head.transform_vector3(facing).normalize();
        let up_local = to_head.transform_vector3(Vec3::Y).normalize();
        let (lo, hi) = local
            .positions
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p.dot(up_local)), h.max(p.dot(up_local))));
        let crown = hi - 0.2 * (hi - lo);
        let scalp_triangles: Vec<[u32; 3]> = (0..local.triangles.len())
            .filter(|&i| {
                let n = local.scaled_normal(i).normalize_or_zero();
                let centroid = local.corners(i).iter().copied().sum::<Vec3>() / 3.0;
                n.dot(forward) < 0.25 || centroid.dot(up_local) > crown
            })
            .map(|i| local.triangles[i])
            .collect();
        let scalp_mesh = TriMesh::new(local.positions.clone(), scalp_triangles)?;
        let up = to_head.transform_vector3(Vec3::Y).normalize();
        let scalp = Scalp::Mesh { mesh: scalp_mesh, up, min_height: 0.45, min_up_dot: -0.2 };
        let params = GrowParams {
            strands: KEY_HAIRS,
            points_per_strand: points,
            length: HAIR_LENGTH,
            gravity: to_head.transform_vector3(Vec3::NEG_Y),
            droop: 5.0,
            comb: to_head.transform_vector3(0.2 * Vec3::Y - 0.8 * facing),
            ..GrowParams::default()
        };
        Ok((grow(&scalp, &params)?, local))
    }
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + ab * t)
}
