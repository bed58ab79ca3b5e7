//! `--crowd N`: N characters in one vkhair simulation and one renderer
//! (`vkhair::crowd::Crowd`), standing in a grid: thesis heads swaying each at
//! its own phase and, with `--gltf`, the character between them (every other
//! place), all playing its animation. Each member's colliders move with it;
//! the host draws every thesis head's sphere and every character's skinned
//! body (one skinning pass, drawn at each member's place).

use glam::{Mat4, Vec3};
use vkhair::character::HairRig;
use vkhair::crowd::{Crowd, Member, MemberPose};
use vkhair::groom::{scenes, Groom};
use vkhair::sim::{motion, RigidTransform, SimParams, MAX_COLLIDERS};
use vkhair::GpuContext;

use crate::host::BoxError;

/// Most members `--crowd` takes.
pub const MAX_MEMBERS: usize = 64;

/// Metres between neighbouring members.
const SPACING: f32 = 1.0;

/// What stands at one place of the grid.
#[derive(Debug, Clone, Copy)]
enum Kind {
    /// A thesis head swaying by the reference motion from `phase` seconds on.
    Thesis { phase: f32 },
    /// The `--gltf` character.
    Character,
}

/// The crowd, where its members stand and what moves them.
pub struct CrowdScene {
    pub crowd: Crowd,
    kinds: Vec<Kind>,
    /// Each member's place (the world from its own frame).
    places: Vec<Mat4>,
    rig: Option<HairRig>,
    /// Each member's colliders kept (the nearest the head of the
    /// character's, at most its share of the simulation's).
    budget: usize,
    /// Centre and radius of the grid with the hair, for the camera and the floor.
    pub center: Vec3,
    pub radius: f32,
}

impl CrowdScene {
    /// `count` members (1..=[`MAX_MEMBERS`]) on a square grid; with `rig`
    /// (and its hair, `rig_groom`), every other one is the character.
    pub fn new(
        ctx: &GpuContext,
        count: usize,
        rig: Option<(&HairRig, &Groom)>,
        params: &SimParams,
    ) -> Result<CrowdScene, BoxError> {
        if !(1..=MAX_MEMBERS).contains(&count) {
            return Err(format!("--crowd {count}: 1 to {MAX_MEMBERS} members").into());
        }
        let thesis = scenes::thesis()?;
        let side = (count as f32).sqrt().ceil() as usize;
        let budget = (MAX_COLLIDERS / count).max(1);
        let mut kinds = Vec::with_capacity(count);
        let mut places = Vec::with_capacity(count);
        let mut members = Vec::with_capacity(count);
        // Thesis heads at the character's head height, when there is one.
        let lift = match rig {
            Some((r, _)) => {
                let (lo, hi) = vkhair::groom::bounding_box(r.head_region()?.positions.iter().copied());
                r.head_at(0.0).matrix().transform_point3(0.5 * (lo + hi)).y - scenes::THESIS_HEAD_CENTER.y
            }
            None => 0.0,
        };
        for m in 0..count {
            let (row, col) = ((m / side) as f32, (m % side) as f32);
            let half = 0.5 * (side as f32 - 1.0);
            places.push(Mat4::from_translation(Vec3::new((col - half) * SPACING, 0.0, (row - half) * SPACING)));
            match rig {
                Some((r, groom)) if (m / side + m % side) % 2 == 1 => {
                    // The character's head over its place at the animation's start.
                    let head = r.head_at(0.0).translation;
                    let place = places.last_mut().expect("pushed above");
                    *place *= Mat4::from_translation(Vec3::new(-head.x, 0.0, -head.z));
                    kinds.push(Kind::Character);
                    let scalp = r.scalp()?;
                    members.push(Member { scalp: Some(scalp), ..Member::rigid(groom.clone()) });
                }
                _ => {
                    let place = places.last_mut().expect("pushed above");
                    *place = Mat4::from_translation(Vec3::Y * lift) * *place;
                    kinds.push(Kind::Thesis { phase: 0.37 * m as f32 });
                    let colliders = motion::thesis_colliders().into_iter().take(budget).collect();
                    members.push(Member { colliders, ..Member::rigid(thesis.clone()) });
                }
            }
        }
        let rig = rig.map(|(r, _)| r.clone());
        let poses = poses(&kinds, &places, rig.as_ref(), budget, 0.0, false);
        let crowd = Crowd::new(ctx, &members, &poses, params)?;
        let (center, radius) = crowd.bounds();
        let characters = kinds.iter().filter(|k| matches!(k, Kind::Character)).count();
        println!(
            "viewer: crowd of {count} members ({characters} characters, {} thesis heads), {} key hairs in one simulation",
            count - characters,
            crowd.sim().key_hairs().size().0
        );
        Ok(CrowdScene { crowd, kinds, places, rig, budget, center, radius })
    }

    /// Every member's pose at `time` seconds (the thesis heads still and the
    /// character in its first pose unless `moving`).
    pub fn poses(&self, time: f32, moving: bool) -> Vec<MemberPose> {
        poses(&self.kinds, &self.places, self.rig.as_ref(), self.budget, time, moving)
    }

    /// Where the host draws a thesis head's sphere (its head frame in the
    /// world) and the character's skinned body (its place) at `time`.
    pub fn drawn(&self, time: f32, moving: bool) -> (Vec<Mat4>, Vec<Mat4>) {
        let mut heads = Vec::new();
        let mut bodies = Vec::new();
        for (kind, place) in self.kinds.iter().zip(&self.places) {
            match kind {
                Kind::Thesis { phase } => heads.push(*place * thesis_head(*phase, time, moving).matrix()),
                Kind::Character => bodies.push(*place),
            }
        }
        (heads, bodies)
    }

    /// The character's animation time at `time` (its first pose unless `moving`).
    pub fn character_time(time: f32, moving: bool) -> f32 {
        if moving {
            time
        } else {
            0.0
        }
    }

    /// Whether the `--gltf` character is among the members.
    pub fn has_character(&self) -> bool {
        self.kinds.iter().any(|k| matches!(k, Kind::Character))
    }

    /// The character's skinning matrices as shown at `time`, when it is among
    /// the members.
    pub fn drawn_bones(&self, time: f32, moving: bool) -> Option<Vec<Mat4>> {
        let rig = self.rig.as_ref().filter(|_| self.has_character())?;
        Some(rig.pose(Self::character_time(time.max(0.0), moving)).skin)
    }

    /// Members in the crowd.
    pub fn members(&self) -> usize {
        self.kinds.len()
    }
}

fn thesis_head(phase: f32, time: f32, moving: bool) -> RigidTransform {
    if moving {
        motion::reference_motion(phase + time)
    } else {
        RigidTransform::default()
    }
}

/// Every member's pose at `time`: a thesis head by the reference motion at
/// its phase, the character by its animation, each at its place.
fn poses(
    kinds: &[Kind],
    places: &[Mat4],
    rig: Option<&HairRig>,
    budget: usize,
    time: f32,
    moving: bool,
) -> Vec<MemberPose> {
    let character_time = CrowdScene::character_time(time, moving);
    let character =
        rig.map(|r| (r.head_at(character_time), r.scalp_bones(character_time), r.colliders_at(character_time)));
    kinds
        .iter()
        .zip(places)
        .map(|(kind, place)| {
            let placed = |h: RigidTransform| {
                let (_, rotation, translation) = (*place * h.matrix()).to_scale_rotation_translation();
                RigidTransform { rotation, translation }
            };
            match (kind, &character) {
                (Kind::Character, Some((head, bones, colliders))) => MemberPose {
                    head: placed(*head),
                    bones: bones.iter().map(|b| *place * *b).collect(),
                    body: colliders.iter().take(budget).map(|c| c.moved(place)).collect(),
                },
                (Kind::Thesis { phase }, _) => MemberPose::rigid(placed(thesis_head(*phase, time, moving))),
                (Kind::Character, None) => MemberPose::rigid(placed(RigidTransform::default())),
            }
        })
        .collect()
}
