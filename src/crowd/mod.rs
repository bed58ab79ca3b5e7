//! Many characters in one frame: a [`Crowd`] simulates the key hairs of every
//! member in one [`HairSim`], so that a step is the same dispatches for one
//! character or a thousand (its cost follows the total hair), and a
//! [`crate::render::Renderer`] made from [`Crowd::key_hairs`] draws them all
//! through one set of per-pixel lists and one composite (two characters'
//! overlapping hair sorts as one groom's would) with every member's hair in
//! every light's shadow maps.
//!
//! How the members stay apart in one simulation:
//!
//! 1. **Key hairs** (`layout.rs`): each member's groom (its head frame) is
//!    resampled to the crowd's point count (the most any member has) and
//!    placed by its first pose's head; the members' strands follow one
//!    another in the order given ([`Crowd::member_strands`]).
//! 2. **Roots**: every member's roots are bound to a scalp of its own,
//!    gathered into the simulation's skinned scalp (see [`crate::sim::scalp`]):
//!    a member with a [`Scalp`] has its roots on the triangles of that scalp
//!    that carry them, skinned by its bones; a member without one, on one
//!    triangle its head transform moves rigidly. Each root is bound within its
//!    own member, never to a neighbour's scalp, however close they stand. The
//!    shape constraints, the rest-shape spring, the pinned roots and a reset
//!    all follow each member's own roots.
//! 3. **Colliders**: each member's head colliders are placed by its head and
//!    given, with its body colliders, to the simulation as body colliders (in
//!    the world, moving linearly across the sub-steps); together at most
//!    [`MAX_COLLIDERS`].
//! 4. **Bounds**: each member's hair lies within a sphere around its head
//!    (roots' centre, the farthest root plus its strand's length); the view
//!    [`Crowd::key_hairs`] carries the sphere around all of them
//!    ([`crate::sim::KeyHairs::with_bounds`]), which the renderer fits its
//!    shadow maps to and takes the level of detail's distance from.
//!
//! 5. **Parameters**: a member may have simulation parameters of its own
//!    ([`Member::params`]) where they differ from the crowd's only in
//!    [`MEMBER_PARAMS`] (gravity, wind, spring, damping, bending, global
//!    shape): each distinct set is one more block of per-sub-step parameters,
//!    and each key hair reads its member's block in the same dispatch (the
//!    step kernel's switches, iterations and the sweeps over other hairs stay
//!    the crowd's).
//!
//! A member's cut or respawn is [`Crowd::teleport`]: its key hairs alone
//! move rigidly before the next step (the move kernel over their points), and
//! their roots start that step from its scalp.
//!
//! The crowd's head is the identity, so [`SimParams::teleport_distance`]
//! never takes a member's jump for a teleport: call [`Crowd::teleport`].
//!
//! The members share the renderer's parameters. The volume stage
//! and the mesh collider are not available in a crowd (one grid cannot follow
//! characters apart; the mesh collider has one head frame): [`Crowd::new`]
//! and [`Crowd::set_params`] refuse a volume stage.
//!
//! ```
//! use glam::{Quat, Vec3};
//! use vkhair::crowd::{Crowd, Member, MemberPose};
//! use vkhair::render::{RenderParams, Renderer};
//! use vkhair::sim::{RigidTransform, SimParams};
//! use vkhair::{groom, ContextOptions, GpuContext, ValidationLog};
//!
//! let log = ValidationLog::new();
//! {
//!     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
//!     let grow = groom::grow::GrowParams { strands: 16, points_per_strand: 6, ..Default::default() };
//!     let head = groom::grow::grow(&groom::scenes::thesis_scalp(), &grow)?;
//!     let members = vec![Member::rigid(head.clone()), Member::rigid(head)];
//!     let at = |x: f32, turn: f32| MemberPose::rigid(RigidTransform {
//!         rotation: Quat::from_rotation_y(turn),
//!         translation: Vec3::new(x, 0.0, 0.0),
//!     });
//!     let mut crowd = Crowd::new(&ctx, &members, &[at(-0.5, 0.0), at(0.5, 0.0)], &SimParams::default())?;
//!     let mut renderer = Renderer::new(&ctx, crowd.key_hairs(), &RenderParams::default())?;
//!     // The second member turns while the first stands still: one step, one dispatch.
//!     crowd.run(4, |i| vec![at(-0.5, 0.0), at(0.5, 0.1 * (i + 1) as f32)])?;
//!     renderer.prepare_now(crowd.key_hairs(), None)?;
//!     // The turned member's first root is where its head put it.
//!     let state = crowd.sim().read_state()?;
//!     let first = crowd.member_strands(1).start * state.points;
//!     let expected = at(0.5, 0.4).head.matrix().transform_point3(members[1].groom.strand(0)[0]);
//!     assert!(state.positions[first].truncate().distance(expected) < 1e-5);
//! }
//! log.assert_clean();
//! # Ok::<(), vkhair::Error>(())
//! ```

mod layout;
#[cfg(test)]
mod tests;

use std::ops::Range;

use ash::vk;
use glam::{Mat4, Vec3};

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::groom::Groom;
use crate::profiler::GpuProfiler;
use crate::sim::scalp::{frames_at, Scalp};
use crate::sim::{
    check_set, Collider, HairSim, KeyHairs, RigidTransform, SimParams, SimState, VolumeMode, MAX_COLLIDERS,
};
use layout::Placed;

/// Members a crowd holds at most.
pub const MAX_CROWD_MEMBERS: usize = 4096;

/// One character of a crowd: its key hairs, what carries their roots and the
/// colliders that move with its head.
#[derive(Debug, Clone)]
pub struct Member {
    /// Key hairs in the member's head frame (meters), resampled to the
    /// crowd's point count when they have fewer points.
    pub groom: Groom,
    /// Spheres and capsules in the head frame (meters), moved by the
    /// member's head.
    pub colliders: Vec<Collider>,
    /// A skinned scalp (bind pose, head frame) whose bones
    /// ([`MemberPose::bones`]) carry the roots, bound within
    /// `scalp.tolerance` of its triangles; `None`: the roots ride the head.
    pub scalp: Option<Scalp>,
    /// The member's own simulation parameters, `None`: the crowd's. They may
    /// differ from the crowd's only in [`MEMBER_PARAMS`] (the members still
    /// share one dispatch); members with equal parameters share a set.
    pub params: Option<SimParams>,
}

/// The simulation parameters a member may have of its own: gravity, wind
/// (its direction, turbulence and frequency), the rest-shape spring, damping,
/// bending at root and tip, and the global shape's stiffness and range — as
/// long as the switches stay the crowd's (a global shape stiffness of 0
/// turns the constraint off, so 0 against a stiffness above 0 is refused).
/// The others (time step, sub-steps, iterations, solver, switches, local
/// shape, stretch limit, friction, pearl radii, the volume stage) are the
/// crowd's.
pub const MEMBER_PARAMS: [&str; 10] = crate::sim::SET_FIELDS;

impl Member {
    /// A member whose roots ride its head rigidly, without colliders.
    pub fn rigid(groom: Groom) -> Member {
        Member { groom, colliders: Vec::new(), scalp: None, params: None }
    }
}

/// Where a member is at the end of a step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MemberPose {
    /// The head transform: places the member's head colliders and where its
    /// hair is taken to be for the crowd's bounds (for a skinned member, its
    /// head joint's transform) and, without a scalp, carries its roots.
    pub head: RigidTransform,
    /// With a scalp: its bone matrices (bind pose, head frame → world), at
    /// least one past the highest joint the scalp's skin names; else empty.
    pub bones: Vec<Mat4>,
    /// The colliders of the member's body in the world (meters; shoulders,
    /// arms), as [`HairSim::set_body_colliders`] takes them.
    pub body: Vec<Collider>,
}

impl MemberPose {
    /// The pose of a member whose roots ride its head.
    pub fn rigid(head: RigidTransform) -> MemberPose {
        MemberPose { head, ..MemberPose::default() }
    }
}

/// Many characters' key hairs in one simulation (see the module docs).
pub struct Crowd {
    sim: HairSim,
    members: Vec<Placed>,
    /// Each member's own parameters ([`Member::params`]).
    own: Vec<Option<SimParams>>,
    /// Each member's head at the latest poses.
    heads: Vec<RigidTransform>,
    /// Centre (world) and radius of the sphere holding every member's hair.
    bounds: (Vec3, f32),
}

impl Crowd {
    /// Lays out `members` (at most [`MAX_CROWD_MEMBERS`]) at their `poses`
    /// (one each) and uploads them at rest: each member's rest shape placed
    /// by its head, or by its roots' frames on its scalp as the poses' bones
    /// skin it; the first step moves every root from there. Errors name the member whose
    /// groom, scalp, colliders or pose is refused; a volume stage in `params`
    /// is refused (see the module docs). This submits and waits.
    pub fn new(ctx: &GpuContext, members: &[Member], poses: &[MemberPose], params: &SimParams) -> Result<Crowd> {
        refuse_volume(params)?;
        let (sets, member_sets) = parameter_sets(params, members)?;
        let layout = layout::lay_out(members, poses, &member_sets)?;
        let Placing { bones, bounds, colliders } = place(&layout.members, poses)?;
        let head = RigidTransform::default();
        let mut state = SimState::from_groom(&layout.groom, params, &head)?;
        if layout.members.iter().any(|m| m.skinned) {
            // Skinned members start on their scalps as the first bones place them.
            let skinned = layout.scalp.skin(&bones)?;
            let frames = frames_at(&layout.binding, &[], &skinned, 1.0, true, &Mat4::IDENTITY);
            let points = state.points;
            for member in layout.members.iter().filter(|m| m.skinned) {
                for (h, frame) in member.strands.clone().zip(&frames[member.strands.clone()]) {
                    for i in h * points..(h + 1) * points {
                        let w = state.positions[i].w;
                        state.positions[i] = frame.transform_point3(state.rest[i].truncate()).extend(w);
                    }
                }
            }
        }
        let mut sim = HairSim::from_state(ctx, &state, params, &head)?;
        sim.bind_scalp_bones_as(&layout.scalp, layout.binding, &bones, true)?;
        sim.set_parameter_sets(sets)?;
        sim.set_body_colliders(&colliders)?;
        let own = members.iter().map(|m| m.params.clone()).collect();
        let heads = poses.iter().map(|p| p.head).collect();
        Ok(Crowd { sim, members: layout.members, own, heads, bounds })
    }

    /// The simulation of every member (its state, parameters and level of
    /// detail; key hairs [`Crowd::member_strands`] are one member's).
    pub fn sim(&self) -> &HairSim {
        &self.sim
    }

    /// Members in the crowd.
    pub fn members(&self) -> usize {
        self.members.len()
    }

    /// Parameter sets the members are simulated with: the crowd's, and one
    /// more for each distinct [`Member::params`] (a member with parameters
    /// of its own keeps them whatever [`Crowd::set_params`] gives the crowd).
    pub fn parameter_sets(&self) -> usize {
        let mut distinct: Vec<&SimParams> = Vec::new();
        for own in self.own.iter().flatten() {
            if !distinct.contains(&own) {
                distinct.push(own);
            }
        }
        1 + distinct.len()
    }

    /// Member `m`'s key hairs in the simulation (empty past the last member).
    pub fn member_strands(&self, m: usize) -> Range<usize> {
        self.members.get(m).map_or(0..0, |p| p.strands.clone())
    }

    /// The sphere (world centre, radius in meters) holding every member's hair
    /// at the latest poses.
    pub fn bounds(&self) -> (Vec3, f32) {
        self.bounds
    }

    /// The latest key hairs as a renderer reads them, with the crowd's bounds.
    pub fn key_hairs(&self) -> KeyHairs<'_> {
        KeyHairs { bounds: Some(self.bounds), ..self.sim.key_hairs() }
    }

    /// Where every member is at the end of the next step (one pose per member,
    /// in the order of [`Crowd::new`]'s members); members keep their poses
    /// when not set again. Errors name the member whose pose is refused (a
    /// head that is not finite, too few or non-finite bones) or the colliders'
    /// total past [`MAX_COLLIDERS`]; nothing changes then.
    pub fn set_poses(&mut self, poses: &[MemberPose]) -> Result<()> {
        let Placing { bones, bounds, colliders } = place(&self.members, poses)?;
        self.sim.set_scalp_bones(&bones)?;
        self.sim.set_body_colliders(&colliders)?;
        self.bounds = bounds;
        self.heads = poses.iter().map(|p| p.head).collect();
        Ok(())
    }

    /// A cut or a respawn of member `m` alone: the next recorded step starts
    /// with its key hairs moved rigidly from its head at the latest poses to
    /// `to` (positions, and velocities turned with the head, adding none), and
    /// its roots start that step from where the step's poses put them, not
    /// swept across the jump. Call it, then [`Crowd::set_poses`] with member
    /// `m` at `to` (or wherever it goes next), then record the step. The
    /// other members move on as usual. Refuses a member past the last or a
    /// head that is not finite.
    pub fn teleport(&mut self, m: usize, to: &RigidTransform) -> Result<()> {
        let (Some(member), Some(from)) = (self.members.get(m), self.heads.get(m)) else {
            return Err(Error::param("crowd member", m, format!("below {}", self.members.len())));
        };
        to.validate().map_err(|e| member_error(m, e))?;
        self.sim.teleport_hairs(member.strands.clone(), to.matrix() * from.matrix().inverse())?;
        // A second teleport before the step moves on from here.
        self.heads[m] = *to;
        Ok(())
    }

    /// Records one step of every member into `cmd`: [`HairSim::record_step`]
    /// with the crowd's poses (the same dispatches and barriers, whatever the
    /// number of members).
    ///
    /// # Safety
    /// As for [`HairSim::record_step`].
    pub unsafe fn record_step(&mut self, cmd: vk::CommandBuffer, profiler: Option<&mut GpuProfiler>) -> Result<()> {
        // SAFETY: guaranteed by the caller.
        unsafe { self.sim.record_step(cmd, &RigidTransform::default(), profiler) }
    }

    /// Records `steps` steps in one submission and waits (headless use),
    /// step `i` ending at `poses(i)`. A pose refused part way ends the
    /// recording there: the steps recorded before it are still submitted.
    pub fn run(&mut self, steps: usize, mut poses: impl FnMut(usize) -> Vec<MemberPose>) -> Result<()> {
        let device = self.sim.device().clone();
        let mut result = Ok(());
        device.submit_once("vkhair crowd run", |cmd| {
            for i in 0..steps {
                // SAFETY: submit_once hands over a recording command buffer of this
                // device and waits for the previous one.
                result = self.set_poses(&poses(i)).and_then(|_| unsafe { self.record_step(cmd, None) });
                if result.is_err() {
                    return;
                }
            }
        })?;
        result
    }

    /// Changes the crowd's parameters from the next step on (validated first;
    /// a volume stage, and a change of what a member with parameters of its
    /// own must share, are refused, naming the member). Members with their
    /// own parameters keep them.
    pub fn set_params(&mut self, params: &SimParams) -> Result<()> {
        refuse_volume(params)?;
        for (m, own) in self.own.iter().enumerate() {
            if let Some(own) = own {
                check_set(params, own).map_err(|e| member_error(m, e))?;
            }
        }
        self.sim.set_params(params)
    }

    /// Simulates only `count` key hairs of the whole crowd (see
    /// [`HairSim::set_simulated_hairs`]): the others follow the nearest
    /// simulated key hair at rest — in a crowd of members standing apart,
    /// one of their own member's; members laid out within reach of each
    /// other may lend each other guides.
    pub fn set_simulated_hairs(&mut self, count: usize) -> Result<()> {
        self.sim.set_simulated_hairs(count)
    }

    /// The next recorded step starts every member from its rest shape placed
    /// by its roots, velocities zero.
    pub fn reset(&mut self) {
        self.sim.reset();
    }
}

/// Checks `poses` (one per member) against `members`: the crowd's bone
/// matrices (crowd frame → world), the sphere holding every member's hair and
/// the colliders in the world.
fn place(members: &[Placed], poses: &[MemberPose]) -> Result<Placing> {
    if poses.len() != members.len() {
        return Err(Error::param("crowd poses", poses.len(), format!("{}, one per member", members.len())));
    }
    let mut bones = Vec::with_capacity(members.last().map_or(0, |m| m.bones.end));
    let mut colliders = Vec::new();
    let mut spheres = Vec::with_capacity(poses.len());
    for (i, (member, pose)) in members.iter().zip(poses).enumerate() {
        let named = |e: Error| Error::incompatible("crowd member", format!("member {i}: {e}"));
        pose.head.validate().map_err(named)?;
        let head = pose.head.matrix();
        let wanted = member.bones.len();
        if member.skinned {
            if pose.bones.len() < wanted {
                let e =
                    Error::param("scalp bones", pose.bones.len(), format!("at least {wanted} (the scalp's joints)"));
                return Err(named(e));
            }
            if let Some(j) = pose.bones[..wanted].iter().position(|m| !m.is_finite()) {
                return Err(named(Error::param("scalp bone matrix", format!("bone {j}"), "finite")));
            }
            bones.extend(pose.bones[..wanted].iter().map(|b| *b * member.unplace));
        } else {
            bones.push(head * member.unplace);
        }
        pose.body.iter().try_for_each(Collider::validate).map_err(named)?;
        colliders.extend(member.colliders.iter().map(|c| c.moved(&head)));
        colliders.extend_from_slice(&pose.body);
        spheres.push((head.transform_point3(member.sphere.0), member.sphere.1));
    }
    if colliders.len() > MAX_COLLIDERS {
        let allowed = format!("at most {MAX_COLLIDERS} head and body colliders of all members together");
        return Err(Error::param("crowd colliders", colliders.len(), allowed));
    }
    Ok(Placing { bones, bounds: enclosing(&spheres), colliders })
}

/// What a set of poses places ([`place`]).
struct Placing {
    /// The crowd's bone matrices (crowd frame → world).
    bones: Vec<Mat4>,
    /// The sphere (world centre, radius) holding every member's hair.
    bounds: (Vec3, f32),
    /// Every member's colliders in the world.
    colliders: Vec<Collider>,
}

/// The members' parameter sets beyond the crowd's own (`params`, set 0):
/// one per distinct [`Member::params`], and each member's set.
fn parameter_sets(params: &SimParams, members: &[Member]) -> Result<(Vec<SimParams>, Vec<u32>)> {
    let mut sets: Vec<SimParams> = Vec::new();
    let mut of_member = Vec::with_capacity(members.len());
    for (m, member) in members.iter().enumerate() {
        let set = match &member.params {
            None => 0,
            Some(own) => {
                check_set(params, own).map_err(|e| member_error(m, e))?;
                match sets.iter().position(|s| s == own) {
                    Some(s) => s + 1,
                    None => {
                        sets.push(own.clone());
                        sets.len()
                    }
                }
            }
        };
        of_member.push(set as u32);
    }
    Ok((sets, of_member))
}

/// `e` said of member `m`.
fn member_error(m: usize, e: Error) -> Error {
    Error::incompatible("crowd member", format!("member {m}: {e}"))
}

/// Refuses a volume stage in a crowd's parameters.
fn refuse_volume(params: &SimParams) -> Result<()> {
    if params.volume.mode != VolumeMode::Off {
        let mode = format!("{:?}", params.volume.mode);
        return Err(Error::param("volume.mode", mode, "Off in a crowd (one grid cannot follow characters apart)"));
    }
    Ok(())
}

/// A sphere holding every sphere of `spheres` (centre, radius): around the
/// centre of their bounding box.
fn enclosing(spheres: &[(Vec3, f32)]) -> (Vec3, f32) {
    let (lo, hi) = spheres
        .iter()
        .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), (c, r)| (lo.min(*c - *r), hi.max(*c + *r)));
    let centre = 0.5 * (lo + hi);
    let radius = spheres.iter().map(|(c, r)| c.distance(centre) + r).fold(0.0f32, f32::max);
    (centre, radius)
}
