//! Hair on a character, the host side: which animation plays, which joint is
//! the head, the capsules that keep hair out of the body near it, the scalp the
//! key hairs' roots are bound to with the bones that skin it, and key hairs
//! grown on the head. What `vkhair render --gltf`, `simulate --gltf` and the
//! viewer share.

use glam::{Mat4, Vec3};

use super::{BoneCapsule, Character, Pose};
use crate::error::{Error, Result};
use crate::groom::binding::{bind_roots, RootBinding};
use crate::groom::grow::{grow, GrowParams, Scalp as GrowScalp};
use crate::groom::mesh::TriMesh;
use crate::groom::Groom;
use crate::sim::scalp::{Scalp, VertexSkin};
use crate::sim::{Collider, RigidTransform, SimState, MAX_COLLIDERS};

/// Key hairs [`HairRig::grow`] grows on the head: 600.
pub const RIG_KEY_HAIRS: usize = 600;
/// Their length: 0.28 m.
pub const RIG_HAIR_LENGTH: f32 = 0.28;
/// The face [`HairRig::face_region`] measures: triangles whose normal · the
/// character's forward is at least this (within 60°).
pub const FACE_FACING: f32 = 0.5;
/// The face [`HairRig::face_region`] measures lies within this share of the
/// head's half width of its middle (the ears, at the sides, are not face).
pub const FACE_HALF_WIDTH: f32 = 0.6;
/// Where [`HairRig::grow_with`] roots no hair: triangles below the crown whose
/// normal · the character's forward is at least this (within 75.5°).
pub const NO_ROOT_FACING: f32 = 0.25;
/// How far from the head joint, in the bind pose, the body of
/// [`HairRig::body_region`] reaches: 0.36 m (hair of [`RIG_HAIR_LENGTH`]
/// hanging from the crown reaches the shoulders and upper back, not past them).
pub const BODY_REACH: f32 = 0.36;
/// Capsules a rig keeps: the nearest the head, up to half the simulation's
/// collider limit (the rest is left to a host's own colliders).
pub const RIG_CAPSULES: usize = MAX_COLLIDERS / 2;

/// A character with hair on its head (see the module docs).
#[derive(Debug, Clone)]
pub struct HairRig {
    /// The character.
    pub character: Character,
    /// The animation played (index into the skeleton's animations).
    pub animation: usize,
    /// The skin joint the hair grows on.
    pub head: usize,
    /// A capsule per bone within reach of the hair, the nearest first (at
    /// most [`RIG_CAPSULES`]).
    pub capsules: Vec<BoneCapsule>,
}

/// Times over the animation at which [`HairRig::new`] checks the head has a
/// frame (its start and end included).
const HEAD_FRAME_SAMPLES: usize = 64;

impl HairRig {
    /// The rig of `character` playing `animation` (by name or index; the first
    /// when `None`) with the head at `head_joint` (by name; found by the
    /// weights of the mesh's top when `None`). Refuses a character without an
    /// animation.
    pub fn new(character: Character, animation: Option<&str>, head_joint: Option<&str>) -> Result<Self> {
        let sk = &character.skeleton;
        if sk.animations.is_empty() {
            return Err(Error::incompatible("character", "it has no animation"));
        }
        let animation = match animation {
            Some(name) => sk.animation_index(name)?,
            None => 0,
        };
        let head = match head_joint {
            Some(name) => character.joint_named(name)?,
            None => character.head_joint(),
        };
        let rest = character.bind_pose();
        // The head's frame must be a frame wherever the animation takes it: a
        // scale of zero (or next to it) on the way to the head collapses it.
        let duration = sk.animations[animation].duration();
        for k in 0..=HEAD_FRAME_SAMPLES {
            let time = duration * k as f32 / HEAD_FRAME_SAMPLES as f32;
            let m = character.joint_transform(&character.pose(Some(animation), time), head);
            let scales = [m.x_axis, m.y_axis, m.z_axis].map(|a| a.truncate().length());
            let most = super::gltf_read::MAX_TRANSFORM_COMPONENT;
            let (collapsed, grown) =
                (scales.iter().any(|&s| s.is_nan() || s <= 1e-4), scales.iter().any(|&s| s > most));
            if !m.is_finite() || collapsed || grown {
                let name = &sk.nodes[sk.joints[head]].name;
                // Scales within the bound at every node may multiply past it
                // on the way to the head (9,000 at six nodes: 5e23).
                let why = if grown {
                    format!("scales past {most} multiplied on the way to it")
                } else {
                    "a scale of zero on the way to it".to_owned()
                };
                return Err(Error::incompatible(
                    "character",
                    format!(
                        "the head joint {head} ({name:?}) has no frame at {time} s of animation {:?}: its \
                         transform scales by {scales:?} ({why})",
                        sk.animations[animation].name
                    ),
                ));
            }
        }
        // Between the samples: a scale channel on the way to the head that
        // comes near zero at a key or crosses it between two.
        let mut on_the_way = vec![false; sk.nodes.len()];
        let mut node = Some(sk.joints[head]);
        while let Some(n) = node.filter(|&n| !on_the_way[n]) {
            on_the_way[n] = true;
            node = sk.nodes[n].parent;
        }
        let channels = sk.animations[animation].channels.iter().filter(|c| on_the_way.get(c.node) == Some(&true));
        if let Some((c, time)) = channels.filter_map(|c| c.scale_near_zero().map(|t| (c, t))).next() {
            return Err(Error::incompatible(
                "character",
                format!(
                    "the head joint {head} ({:?}) has no frame at {time} s of animation {:?}: node {} ({:?}) on \
                     the way to it is scaled to zero there",
                    sk.nodes[sk.joints[head]].name, sk.animations[animation].name, c.node, sk.nodes[c.node].name
                ),
            ));
        }
        let origin = character.joint_transform(&rest, head).transform_point3(Vec3::ZERO);
        let mut capsules = character.fit_capsules(&[head]);
        let distance = |c: &BoneCapsule| {
            let m = character.joint_transform(&rest, c.joint);
            let (a, b) = (m.transform_point3(c.a), m.transform_point3(c.b));
            segment_distance(origin, a, b) - c.radius
        };
        // Only what the hair can reach: bones within one and a half hair lengths
        // of the head joint, the nearest first.
        capsules.retain(|c| distance(c) < 1.5 * RIG_HAIR_LENGTH);
        capsules.sort_by(|x, y| distance(x).total_cmp(&distance(y)));
        capsules.truncate(RIG_CAPSULES);
        Ok(HairRig { character, animation, head, capsules })
    }

    /// A joint's node name (empty when it has none).
    pub fn joint_name(&self, joint: usize) -> &str {
        let sk = &self.character.skeleton;
        &sk.nodes[sk.joints[joint]].name
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

    /// The sphere (centre, radius) a camera frames at the animation's start:
    /// around `groom` (key hairs in the head's frame) placed by the head then,
    /// and the vertices of `body` (the character at that time,
    /// [`HairRig::body_at`]`(0.0)`) within 0.45 m of the head joint.
    pub fn framing(&self, groom: &Groom, body: &TriMesh) -> (Vec3, f32) {
        let m = self.head_at(0.0).matrix();
        let origin = m.transform_point3(Vec3::ZERO);
        let near = body.positions.iter().copied().filter(|p| p.distance(origin) < 0.45);
        let hair = groom.positions().iter().map(|p| m.transform_point3(*p));
        crate::groom::bounding_sphere(crate::groom::bounding_box(hair.chain(near)))
    }

    /// The character's mesh in the bind pose, in the head's frame (the
    /// groom's), with its skin: the scalp the roots are bound to. Vertex `v` is
    /// the character's vertex `v`, so a host's skinned copy of the character
    /// is its source.
    pub fn scalp(&self) -> Result<Scalp> {
        let to_head = self.bind_frame().inverse();
        let positions = self.character.positions.iter().map(|p| to_head.transform_point3(*p)).collect();
        let skin = self.character.weights.iter().map(vertex_skin).collect();
        Ok(Scalp { skin, ..Scalp::new(TriMesh::new(positions, self.character.triangles.clone())?) })
    }

    /// The scalp's bones at `time`: each joint's skinning matrix after the
    /// head frame's bind placement (head frame, bind pose → world).
    pub fn scalp_bones(&self, time: f32) -> Vec<Mat4> {
        let bind = self.bind_frame();
        self.pose(time).skin.iter().map(|m| *m * bind).collect()
    }

    /// Each key hair's root of `groom` (in the head's frame) bound to the
    /// character's mesh in the bind pose: its triangle and weights. A root
    /// farther than `tolerance` (m) from the mesh is refused, naming the strand.
    pub fn bind_roots(&self, groom: &Groom, tolerance: f32) -> Result<Vec<RootBinding>> {
        let bind = self.bind_frame();
        let roots: Vec<Vec3> = (0..groom.strand_count())
            .filter_map(|s| groom.strand(s).first().map(|r| bind.transform_point3(*r)))
            .collect();
        let mesh = TriMesh::new(self.character.positions.clone(), self.character.triangles.clone())?;
        bind_roots(&roots, &mesh, tolerance)
    }

    /// The largest distance of a root of `state` (the first point of each
    /// strand) from its point `bound` on the mesh as `skinned` (the
    /// character's vertices deformed, [`Character::skin`]) places it.
    pub fn root_error(&self, state: &SimState, bound: &[RootBinding], skinned: &[Vec3]) -> f32 {
        bound
            .iter()
            .enumerate()
            .map(|(s, b)| {
                state.positions[s * state.points].truncate().distance(b.point(&self.character.triangles, skinned))
            })
            .fold(0.0, f32::max)
    }

    /// The head's frame in the bind pose.
    pub fn bind_frame(&self) -> Mat4 {
        self.character.rigid_frame(&self.character.bind_pose(), self.head).matrix()
    }

    /// The whole character at `time`, in the world.
    pub fn body_at(&self, time: f32) -> Result<TriMesh> {
        self.character.mesh(&self.pose(time))
    }

    /// The character's body within [`BODY_REACH`] of the head joint at rest
    /// (the triangles whose corners all lie within it: head, neck, shoulders,
    /// upper back and chest), in the head's frame, with each vertex's bones:
    /// the skinned mesh collider (`MeshCollider::skinned`), moved by
    /// [`HairRig::scalp_bones`]. Triangles the rest of that region encloses
    /// (an inner layer under the skin, eyes, a mouth's inside:
    /// [`crate::groom::enclosed`]) are left out, so the field's zero lies on
    /// the skin.
    pub fn body_region(&self) -> Result<(TriMesh, Vec<VertexSkin>)> {
        let bind = self.bind_frame();
        let to_head = bind.inverse();
        let origin = bind.transform_point3(Vec3::ZERO);
        let c = &self.character;
        let in_head: Vec<Vec3> = c.positions.iter().map(|p| to_head.transform_point3(*p)).collect();
        let near = |v: usize| c.positions[v].distance(origin) <= BODY_REACH;
        let none = || Error::incompatible("character", format!("no triangle lies within {BODY_REACH} m of the head"));
        let (region, vertices) = c.sub_mesh(near, &in_head)?.ok_or_else(none)?;
        let (mesh, kept) = crate::groom::enclosed::without_enclosed(&region)?.ok_or_else(none)?;
        Ok((mesh, kept.iter().map(|&k| vertex_skin(&c.weights[vertices[k]])).collect()))
    }

    /// The head's region at rest, in the head's frame: the scalp hair is grown
    /// on and the mesh collider. Triangles the rest of the region encloses (an
    /// inner layer under the skin, eyes: [`crate::groom::enclosed`]) are left
    /// out, so no root is grown under the skin.
    pub fn head_region(&self) -> Result<TriMesh> {
        let to_head: Mat4 = self.bind_frame().inverse();
        let region = self.character.region_mesh(self.head, &self.character.bind_pose())?;
        let local =
            TriMesh::new(region.positions.iter().map(|p| to_head.transform_point3(*p)).collect(), region.triangles)?;
        let skin = crate::groom::enclosed::without_enclosed(&local)?;
        skin.map(|(mesh, _)| mesh).ok_or_else(|| Error::incompatible("character", "its head's region is all enclosed"))
    }

    /// The head's region at rest, in the head's frame (the mesh collider), and
    /// [`RIG_KEY_HAIRS`] key hairs of `points` points, [`RIG_HAIR_LENGTH`]
    /// long, grown on its upper part (see [`HairRig::grow_with`]).
    pub fn grow(&self, points: usize) -> Result<(Groom, TriMesh)> {
        let params = GrowParams {
            strands: RIG_KEY_HAIRS,
            points_per_strand: points,
            length: RIG_HAIR_LENGTH,
            droop: 5.0,
            ..GrowParams::default()
        };
        self.grow_with(&params)
    }

    /// Hair grown on the upper part of the head's region by `params`, in the
    /// head's frame, framing the face: combed back (away from where the
    /// character faces, the given comb and face replaced), parted at the middle
    /// with the front hair turned to its side ([`GrowParams::face`]), under the
    /// character's gravity; no roots on the face. With the head's region at
    /// rest (the mesh collider).
    pub fn grow_with(&self, params: &GrowParams) -> Result<(Groom, TriMesh)> {
        let to_head: Mat4 = self.bind_frame().inverse();
        let local = self.head_region()?;
        let facing = self.character.forward();
        let (forward, up) = self.head_axes();
        let face = face_triangles(&local, (forward, up), NO_ROOT_FACING);
        let scalp_triangles: Vec<[u32; 3]> =
            local.triangles.iter().zip(&face).filter(|&(_, &f)| !f).map(|(t, _)| *t).collect();
        let scalp_mesh = TriMesh::new(local.positions.clone(), scalp_triangles)?;
        let scalp = GrowScalp::Mesh { mesh: scalp_mesh, up, min_height: 0.45, min_up_dot: -0.2 };
        let params = GrowParams {
            gravity: to_head.transform_vector3(Vec3::NEG_Y),
            comb: to_head.transform_vector3(0.2 * Vec3::Y - 0.8 * facing),
            face: forward,
            ..params.clone()
        };
        Ok((grow(&scalp, &params)?, local))
    }
}

impl HairRig {
    /// The face: the triangles of the head's region at rest (head frame)
    /// below the crown (the top fifth of the region's height) that face
    /// forward, within 60° of the character's forward ([`FACE_FACING`]),
    /// between the ears (their corners within [`FACE_HALF_WIDTH`] of the
    /// region's half width of the middle): what hair should leave visible.
    /// [`HairRig::grow_with`] roots no hair on a wider band, within 75°
    /// ([`NO_ROOT_FACING`]).
    pub fn face_region(&self) -> Result<TriMesh> {
        let local = self.head_region()?;
        let (forward, up) = self.head_axes();
        let face = face_triangles(&local, (forward, up), FACE_FACING);
        let across = forward.cross(up).normalize_or_zero();
        let sides = local.positions.iter().map(|p| p.dot(across));
        let (lo, hi) = sides.fold((f32::MAX, f32::MIN), |(l, h), x| (l.min(x), h.max(x)));
        let (middle, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let triangles = (0..local.triangles.len())
            .filter(|&i| {
                face[i] && local.corners(i).iter().all(|p| (p.dot(across) - middle).abs() <= FACE_HALF_WIDTH * half)
            })
            .map(|i| local.triangles[i])
            .collect();
        TriMesh::new(local.positions, triangles)
    }

    /// The character's forward and the world's up, unit, in the head's frame
    /// in the bind pose.
    fn head_axes(&self) -> (Vec3, Vec3) {
        let to_head: Mat4 = self.bind_frame().inverse();
        let along = |v: Vec3| to_head.transform_vector3(v).normalize();
        (along(self.character.forward()), along(Vec3::Y))
    }
}

/// Per triangle of `local` (the head's region at rest, head frame): whether
/// it lies below the crown (the top fifth of its height along `up`) facing
/// `forward` by at least `min_facing` (its normal · forward).
fn face_triangles(local: &TriMesh, (forward, up): (Vec3, Vec3), min_facing: f32) -> Vec<bool> {
    let (lo, hi) = local.positions.iter().fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p.dot(up)), h.max(p.dot(up))));
    let crown = hi - 0.2 * (hi - lo);
    (0..local.triangles.len())
        .map(|i| {
            let n = local.scaled_normal(i).normalize_or_zero();
            let centroid = local.corners(i).iter().copied().sum::<Vec3>() / 3.0;
            n.dot(forward) >= min_facing && centroid.dot(up) <= crown
        })
        .collect()
}

/// A character vertex's joints and weights as the simulation takes them.
fn vertex_skin((joints, weights): &([u16; 4], [f32; 4])) -> VertexSkin {
    VertexSkin { joints: joints.map(u32::from), weights: *weights }
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + ab * t)
}
