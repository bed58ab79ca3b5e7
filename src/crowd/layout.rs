//! Laying a crowd's members out as one simulation: their key hairs one after
//! another in the crowd frame, and one scalp whose parts carry each member's
//! roots (see the [module docs](super)).

use std::ops::Range;

use glam::{Mat4, Vec3};

use super::{Member, MemberPose, MAX_CROWD_MEMBERS};

/// Most bones one member's scalp may name (its skin's highest weighted
/// joint below this).
pub const MAX_MEMBER_BONES: usize = 1 << 16;
use crate::error::{Error, Result};
use crate::groom::mesh::TriMesh;
use crate::groom::{Attributes, Groom};
use crate::sim::scalp::ScalpBinding;
use crate::sim::scalp::{Scalp, VertexSkin};

/// What the crowd keeps of one member.
#[derive(Debug, Clone)]
pub(super) struct Placed {
    /// Its key hairs in the crowd's simulation.
    pub strands: Range<usize>,
    /// Its bones' place among the crowd's bone matrices.
    pub bones: Range<usize>,
    /// Whether its roots ride a skinned scalp (else its head).
    pub skinned: bool,
    /// The inverse of its head matrix at creation: the crowd frame of its
    /// key hairs back to its head frame.
    pub unplace: Mat4,
    /// Its colliders, head frame.
    pub colliders: Vec<crate::sim::Collider>,
    /// Centre (head frame) and radius of a sphere its hair cannot leave.
    pub sphere: (Vec3, f32),
}

/// Every member merged: the key hairs, the scalp with its binding, the members.
pub(super) struct Layout {
    pub groom: Groom,
    pub scalp: Scalp,
    pub binding: ScalpBinding,
    pub members: Vec<Placed>,
}

/// Lays out `members` placed by their `poses` (see [`super::Crowd::new`]).
/// `sets`: each member's parameter set.
pub(super) fn lay_out(members: &[Member], poses: &[MemberPose], sets: &[u32]) -> Result<Layout> {
    if members.is_empty() {
        return Err(Error::param("crowd members", 0, format!("1 to {MAX_CROWD_MEMBERS}")));
    }
    if members.len() > MAX_CROWD_MEMBERS {
        return Err(Error::param("crowd members", members.len(), format!("1 to {MAX_CROWD_MEMBERS}")));
    }
    if poses.len() != members.len() {
        return Err(Error::param("crowd poses", poses.len(), format!("{}, one per member", members.len())));
    }
    let points = members.iter().map(|m| m.groom.stats().points_per_strand.2).max().unwrap_or(2).max(2);
    let mut strands: Vec<Vec<Vec3>> = Vec::new();
    let mut grooms = Vec::with_capacity(members.len());
    let mut parts = Vec::with_capacity(members.len());
    let mut scalps = Vec::with_capacity(members.len());
    let mut placed = Vec::with_capacity(members.len());
    let mut bone_base = 0usize;
    for (i, ((member, pose), &set)) in members.iter().zip(poses).zip(sets).enumerate() {
        let named = |e: Error| Error::incompatible("crowd member", format!("member {i}: {e}"));
        pose.head.validate().map_err(named)?;
        member.colliders.iter().try_for_each(|c| c.validate()).map_err(named)?;
        let groom = match member.groom.uniform_points_per_strand() {
            Some(n) if n == points => member.groom.clone(),
            _ => member.groom.resampled(points).map_err(named)?,
        };
        let place = pose.head.matrix();
        let first = strands.len();
        strands.extend(
            (0..groom.strand_count()).map(|s| groom.strand(s).iter().map(|p| place.transform_point3(*p)).collect()),
        );
        let roots: Vec<Vec3> = strands[first..].iter().map(|s| s[0]).collect();
        let sphere = rest_sphere(&groom);
        let (scalp, bone_count) = match &member.scalp {
            Some(s) => {
                let mesh = TriMesh::new(
                    s.mesh.positions.iter().map(|p| place.transform_point3(*p)).collect(),
                    s.mesh.triangles.clone(),
                )
                .map_err(named)?;
                let scalp = Scalp { mesh, skin: s.skin.clone(), tolerance: s.tolerance };
                if scalp.skin.is_empty() {
                    return Err(named(Error::incompatible(
                        "scalp bones",
                        "the scalp has no vertex bones (Scalp::skin)",
                    )));
                }
                let binding = ScalpBinding::new(&scalp, &roots).map_err(named)?;
                let (scalp, binding) = compact(&scalp, binding).map_err(named)?;
                // Bones the skin weights (a joint of weight 0 moves nothing).
                let weighted = scalp.skin.iter().flat_map(|v| v.joints.into_iter().zip(v.weights));
                let highest = weighted.filter(|&(_, w)| w != 0.0).map(|(j, _)| j).max().unwrap_or(0);
                if highest as usize >= MAX_MEMBER_BONES {
                    let e = Error::param("scalp joint", highest, format!("below {MAX_MEMBER_BONES} bones a member"));
                    return Err(named(e));
                }
                let bones = highest as usize + 1;
                parts.push(binding);
                (scalp, bones)
            }
            None => {
                let scalp = rigid_scalp(place.transform_point3(sphere.0), sphere.1, &roots).map_err(named)?;
                parts.push(ScalpBinding::new(&scalp, &roots).map_err(named)?);
                (scalp, 1)
            }
        };
        if let Some(part) = parts.last_mut() {
            part.views.iter_mut().for_each(|v| v.set = set);
        }
        scalps.push((scalp, bone_base as u32));
        placed.push(Placed {
            strands: first..strands.len(),
            bones: bone_base..bone_base + bone_count,
            skinned: member.scalp.is_some(),
            unplace: place.inverse(),
            colliders: member.colliders.clone(),
            sphere,
        });
        bone_base += bone_count;
        grooms.push(groom);
    }
    let groom = merged_groom(&grooms, &strands)?;
    let scalp = merged_scalp(&scalps)?;
    Ok(Layout { groom, scalp, binding: ScalpBinding::concat(parts), members: placed })
}

/// A sphere (head frame) the hair of `groom` cannot leave: around the centre
/// of its roots, as far as a root plus its strand's length.
fn rest_sphere(groom: &Groom) -> (Vec3, f32) {
    let roots: Vec<Vec3> = (0..groom.strand_count()).map(|s| groom.strand(s)[0]).collect();
    let (lo, hi) = crate::groom::bounding_box(roots.iter().copied());
    let centre = 0.5 * (lo + hi);
    let radius =
        roots.iter().enumerate().map(|(s, r)| (*r - centre).length() + groom.strand_length(s)).fold(0.0f32, f32::max);
    (centre, radius.max(1e-3))
}

/// The scalp of a member whose roots ride its head: one triangle at `centre`
/// (crowd frame) `size` wide, on one bone, and every root bound to it (the
/// roots lie off it: a root's frame is the triangle's, which the head turns
/// and moves rigidly, so the root keeps its place in the head frame).
fn rigid_scalp(centre: Vec3, size: f32, roots: &[Vec3]) -> Result<Scalp> {
    let positions = vec![centre, centre + Vec3::X * size, centre + Vec3::Z * size];
    let farthest = roots.iter().map(|r| r.distance(centre)).fold(0.0f32, f32::max);
    let skin = vec![VertexSkin { joints: [0; 4], weights: [1.0, 0.0, 0.0, 0.0] }; 3];
    let tolerance = 2.0 * (farthest + size) + 1.0;
    Ok(Scalp { mesh: TriMesh::new(positions, vec![[0, 1, 2]])?, skin, tolerance })
}

/// `scalp` reduced to the triangles `binding` uses and their vertices (the
/// bones then skin only those), with the binding renumbered to match.
fn compact(scalp: &Scalp, binding: ScalpBinding) -> Result<(Scalp, ScalpBinding)> {
    let mut index = vec![u32::MAX; scalp.mesh.positions.len()];
    let mut kept = Vec::new();
    let mut triangles = Vec::new();
    let mut views = binding.views;
    for view in &mut views {
        view.corners = view.corners.map(|v| {
            let slot = &mut index[v as usize];
            if *slot == u32::MAX {
                *slot = kept.len() as u32;
                kept.push(v as usize);
            }
            *slot
        });
        triangles.push(view.corners);
    }
    triangles.sort_unstable();
    triangles.dedup();
    let positions = kept.iter().map(|&v| scalp.mesh.positions[v]).collect();
    let skin = kept.iter().map(|&v| scalp.skin[v]).collect();
    let binding = ScalpBinding::concat(vec![ScalpBinding { roots: Vec::new(), views, vertices: kept.len() }]);
    Ok((Scalp { mesh: TriMesh::new(positions, triangles)?, skin, tolerance: scalp.tolerance }, binding))
}

/// The members' key hairs (`strands`, crowd frame; `grooms`, each member's
/// at the crowd's point count) as one groom, with the per-point attributes
/// every member has.
fn merged_groom(grooms: &[Groom], strands: &[Vec<Vec3>]) -> Result<Groom> {
    let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
    let positions: Vec<Vec3> = strands.iter().flatten().copied().collect();
    fn all<T: Clone>(grooms: &[Groom], f: impl Fn(&Groom) -> Option<&[T]>) -> Option<Vec<T>> {
        grooms.iter().map(|g| f(g).map(<[T]>::to_vec)).collect::<Option<Vec<_>>>().map(|v| v.concat())
    }
    let attributes = Attributes {
        thickness: all(grooms, Groom::thickness),
        transparency: all(grooms, Groom::transparency),
        colors: all(grooms, Groom::colors),
    };
    Groom::with_attributes(positions, &counts, attributes)
}

/// The members' scalps (crowd frame; joints each from its base) as one.
fn merged_scalp(parts: &[(Scalp, u32)]) -> Result<Scalp> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut skin = Vec::new();
    for (scalp, base) in parts {
        let first = positions.len() as u32;
        positions.extend_from_slice(&scalp.mesh.positions);
        triangles.extend(scalp.mesh.triangles.iter().map(|t| t.map(|v| v + first)));
        // Weighted joints move past the bones of the members before; a joint
        // of weight 0 moves nothing and is set to the member's first bone.
        let moved = |v: &VertexSkin| {
            let mut joints = [*base; 4];
            for (k, (&j, &w)) in v.joints.iter().zip(&v.weights).enumerate() {
                if w != 0.0 {
                    joints[k] = j + base;
                }
            }
            VertexSkin { joints, weights: v.weights }
        };
        skin.extend(scalp.skin.iter().map(moved));
    }
    let tolerance = parts.iter().map(|(s, _)| s.tolerance).fold(0.0f32, f32::max);
    Ok(Scalp { mesh: TriMesh::new(positions, triangles)?, skin, tolerance })
}
