//! The CPU reference implementation of the simulation step: the oracle of the
//! GPU tests and the baseline of the benchmarks.
//!
//! Every function mirrors `glsl/include/sim.glsl` and `glsl/sim/*.comp` with
//! the same f32 operations in the same order; sets of independent constraints
//! are applied in the same sequence as the GPU's barrier-separated phases, so
//! the result matches the GPU up to how a driver rounds `sqrt` and division.

use glam::{Mat4, Vec3, Vec4};

pub(crate) use super::math::{cross, dot, rotate, transform_point};
use super::planner::SubstepInputs;
use super::scalp::CpuScalp;
use super::state::SimState;
use crate::codes::sim_flags as flags;
use crate::gpu_types::{ColliderShape, SimStep};

mod bodies;
mod constraints;
mod skin;

pub(crate) use bodies::MeshField;
use bodies::{collider_friction, Bodies};

/// A teleport or reset of the whole state (`glsl/sim/move.comp`); a reset with
/// a bound scalp places each key hair by its root's frame at the start of
/// `first`, the step's first sub-step.
pub(crate) fn move_state(state: &mut SimState, mv: &super::teleport::Move, scalp: Option<(&CpuScalp, &SimStep)>) {
    let m = &mv.transform;
    let frames = scalp.filter(|_| mv.reset).map(|(s, first)| s.frames(first, 0.0, m));
    for (i, (x, v)) in state.positions.iter_mut().zip(&mut state.velocities).enumerate() {
        if mv.reset {
            let placed = frames.as_ref().map_or(m, |f| &f[i / state.points]);
            *x = transform_point(placed, state.rest[i].truncate()).extend(x.w);
            *v = Vec4::new(0.0, 0.0, 0.0, v.w);
        } else {
            *x = transform_point(m, x.truncate()).extend(x.w);
            *v = rotate(m, v.truncate()).extend(v.w);
        }
    }
}

/// `sim_rotate_between`: v rotated by the smallest rotation taking a onto b.
fn rotate_between(a: Vec3, b: Vec3, v: Vec3) -> Vec3 {
    let c = dot(a, b);
    if c <= -0.999 {
        return v;
    }
    let axis = cross(a, b);
    (v * c + cross(axis, v)) + axis * (dot(axis, v) / (1.0 + c))
}

fn hash(x: u32) -> f32 {
    crate::hash::hash_unit(x) * 2.0 - 1.0
}

/// Smooth value noise in [-1, 1], as `sim_noise`.
pub(crate) fn noise(t: f32, strand: u32) -> f32 {
    let cell = t.floor();
    let f = t - cell;
    let s = f * f * (3.0 - 2.0 * f);
    let i = ((cell as i32).wrapping_add(1_048_576) as u32).wrapping_add(strand.wrapping_mul(7919));
    let a = hash(i);
    let b = hash(i.wrapping_add(1));
    a + (b - a) * s
}

/// Whether strand `s` is simulated (every strand without a level of detail).
fn simulated(active: Option<&[bool]>, s: usize) -> bool {
    active.is_none_or(|a| a[s])
}

/// Where key hair `strand`'s rest pose is placed: its root's frame with a bound
/// scalp (`frames`), else the head (`hair_frame` of glsl/sim/step.comp).
fn hair_frame<'a>(p: &'a SimStep, frames: Option<&'a [Mat4]>, strand: usize) -> &'a Mat4 {
    frames.map_or(&p.head, |f| &f[strand])
}

/// Stage 1: forces and prediction.
fn predict(p: &SimStep, frames: Option<&[Mat4]>, state: &SimState, active: Option<&[bool]>, predicted: &mut [Vec4]) {
    let points = p.points as usize;
    let (dt, flags, gravity, wind) = (p.dt, p.flags, p.gravity, p.wind);
    for (index, out) in predicted.iter_mut().enumerate() {
        if !simulated(active, index / points) {
            continue;
        }
        let strand = (index / points) as u32;
        let x = state.positions[index];
        let rest_world = transform_point(hair_frame(p, frames, index / points), state.rest[index].truncate());
        if x.w == 0.0 {
            *out = rest_world.extend(0.0);
            continue;
        }
        let mut a = Vec3::ZERO;
        if flags & flags::GRAVITY != 0 {
            a += gravity;
        }
        if flags & flags::WIND != 0 {
            let gust = 1.0 + p.wind_turbulence * noise(p.time * p.wind_frequency, strand);
            a += wind * gust;
        }
        if flags & flags::SPRING != 0 {
            a += (rest_world - x.truncate()) * p.spring_stiffness;
        }
        let v = state.velocities[index].truncate() + a * dt;
        *out = (x.truncate() + v * dt).extend(x.w);
    }
}

/// Stage 2: constraint solve, hair by hair (`constraints::solve_strand`, or
/// the DFTL sweep).
fn solve(
    (p, frames): (&SimStep, Option<&[Mat4]>),
    (colliders, bones): (&[ColliderShape], &[[Vec4; 6]]),
    mesh: Option<MeshField<'_>>,
    state: &SimState,
    active: Option<&[bool]>,
    predicted: &mut [Vec4],
    correction: &mut [Vec4],
) {
    let points = p.points as usize;
    let flags = p.flags;
    let collisions = flags & flags::COLLISIONS != 0;
    let mesh = mesh.filter(|_| flags & flags::MESH != 0);
    let bones = if flags & flags::MESH_SKIN != 0 { bones } else { &[] };
    let bodies = Bodies { colliders, mesh, head: &p.head, bones };
    let mut s = vec![Vec4::ZERO; points];
    for strand in (0..p.strands as usize).filter(|&strand| simulated(active, strand)) {
        let base = strand * points;
        s.copy_from_slice(&predicted[base..base + points]);
        let lengths = &state.rest_lengths[base..base + points];
        let radius = |i: usize| state.rest[base + i].w;
        if flags & flags::DFTL != 0 {
            for k in 1..points {
                let parent = s[k - 1];
                let q = s[k];
                if q.w > 0.0 {
                    let d = q.truncate() - parent.truncate();
                    let len = dot(d, d).sqrt();
                    let mut placed =
                        if len > 0.0 { parent.truncate() + d * (lengths[k - 1] / len) } else { q.truncate() };
                    if collisions {
                        placed = bodies.collide(placed, radius(k));
                    }
                    s[k] = placed.extend(q.w);
                }
            }
            for i in 0..points {
                correction[base + i] = (s[i].truncate() - predicted[base + i].truncate()).extend(0.0);
                predicted[base + i] = s[i];
            }
            continue;
        }
        let strand_view = constraints::Strand {
            p,
            frame: hair_frame(p, frames, strand),
            rest: &state.rest[base..base + points],
            lengths,
            start: &state.positions[base..base + points],
            bodies: &bodies,
        };
        constraints::solve_strand(&strand_view, &mut s);
        predicted[base..base + points].copy_from_slice(&s);
    }
}

/// Stage 3: velocity update, friction against the sub-step's `colliders`,
/// damping, final state.
fn integrate(
    (p, colliders): (&SimStep, &[ColliderShape]),
    state: &mut SimState,
    active: Option<&[bool]>,
    predicted: &[Vec4],
    correction: &[Vec4],
) {
    let points = p.points as usize;
    let dt = p.dt;
    let dftl = p.flags & flags::DFTL != 0;
    let collisions = p.flags & flags::COLLISIONS != 0;
    for index in 0..predicted.len() {
        if !simulated(active, index / points) {
            continue;
        }
        let i = index % points;
        let solved = predicted[index];
        let mut v = (solved.truncate() - state.positions[index].truncate()) / dt;
        if dftl && i + 1 < points {
            v -= correction[index + 1].truncate() * (p.dftl_damping / dt);
        }
        if collisions && solved.w > 0.0 {
            for c in colliders {
                v = collider_friction(c, solved.truncate(), v, state.rest[index].w, dt);
            }
        }
        v *= 1.0 - p.damping;
        state.positions[index] = solved;
        state.velocities[index] = v.extend(0.0);
    }
}

/// Advances `state` by the given sub-steps, with the mesh collider's field when
/// set; with `active`, only the strands it marks (the others are left as they
/// are); with `scalp`, the rest pose placed per key hair by its root's frame.
pub(crate) fn step(
    state: &mut SimState,
    substeps: &[SubstepInputs],
    mesh: Option<MeshField<'_>>,
    active: Option<&[bool]>,
    scalp: Option<&CpuScalp>,
) {
    let n = state.positions.len();
    let mut predicted = vec![Vec4::ZERO; n];
    let mut correction = vec![Vec4::ZERO; n];
    for sub in substeps {
        let p = &sub.params;
        let frames = scalp.map(|s| s.frames(p, p.scalp_to, &p.head));
        let frames = frames.as_deref();
        predict(p, frames, state, active, &mut predicted);
        solve((p, frames), (&sub.colliders, &sub.bones), mesh, state, active, &mut predicted, &mut correction);
        integrate((&sub.params, &sub.colliders), state, active, &predicted, &correction);
    }
}

/// A frame of `follow`: three columns.
type Frame = [Vec3; 3];

/// `frame_apply` of `glsl/sim/follow.comp`.
fn frame_apply(q: &Frame, v: Vec3) -> Vec3 {
    (q[0] * v.x + q[1] * v.y) + q[2] * v.z
}

/// `transport` of `glsl/sim/follow.comp`.
fn transport(q: Frame, rest_segment: Vec3, segment: Vec3) -> Frame {
    let carried = frame_apply(&q, rest_segment);
    let rest_len = dot(carried, carried).sqrt();
    let len = dot(segment, segment).sqrt();
    if rest_len > 0.0 && len > 0.0 {
        let (a, b) = (carried / rest_len, segment / len);
        return q.map(|column| rotate_between(a, b, column));
    }
    q
}

/// The followers of a level of detail after sub-steps `substeps` (as
/// `glsl/sim/follow.comp`, whose header gives the rule): each strand whose
/// guide (`guides`) is another one takes its own rest segments turned by its
/// guide's frames (transported down the guide from the head's), plus its
/// deviation from that shape before the sub-steps (`before`: the positions
/// then) times the fade, each point placed at its segment's rest length from
/// the one before and out of the bodies of the last sub-step (`mesh`: the
/// mesh collider's field); roots stay pinned to the head; the velocity is the
/// motion over the sub-steps.
pub(crate) fn follow(
    state: &mut SimState,
    before: &[Vec4],
    guides: &[u32],
    substeps: &[SubstepInputs],
    mesh: Option<MeshField<'_>>,
    scalp: Option<&CpuScalp>,
) {
    let (Some(first), Some(last)) = (substeps.first(), substeps.last()) else {
        return;
    };
    let (start, end) = (&first.params, &last.params);
    let collisions = end.flags & flags::COLLISIONS != 0;
    let mesh = mesh.filter(|_| end.flags & flags::MESH != 0);
    let bones: &[[Vec4; 6]] = if end.flags & flags::MESH_SKIN != 0 { &last.bones } else { &[] };
    let bodies = Bodies { colliders: &last.colliders, mesh, head: &end.head, bones };
    let points = state.points;
    let span = end.dt * substeps.len() as f32;
    let columns = |m: &Mat4| [m.col(0).truncate(), m.col(1).truncate(), m.col(2).truncate()];
    // Each follower's own root frames with a bound scalp, else the head's.
    let starts = scalp.map(|s| s.frames(start, start.scalp_from, &start.previous_head));
    let ends = scalp.map(|s| s.frames(end, end.scalp_to, &end.head));
    for (f, &g) in guides.iter().enumerate() {
        let g = g as usize;
        if g == f {
            continue;
        }
        let before_head = starts.as_ref().map_or(&start.previous_head, |frames| &frames[f]);
        let head = ends.as_ref().map_or(&end.head, |frames| &frames[f]);
        let (mut q_old, mut q_new) = (columns(before_head), columns(head));
        let (mut y_old, mut y_new) = (Vec3::ZERO, Vec3::ZERO);
        let (mut placed_before, mut rest_length) = (Vec3::ZERO, 0.0f32);
        for i in 0..points {
            let (fi, gi) = (f * points + i, g * points + i);
            let old = before[fi];
            let rest = state.rest[fi].truncate();
            if i == 0 {
                y_old = transform_point(before_head, rest);
                y_new = transform_point(head, rest);
            } else {
                let rest_segment = state.rest[gi].truncate() - state.rest[gi - 1].truncate();
                let old_segment = before[gi].truncate() - before[gi - 1].truncate();
                let new_segment = state.positions[gi].truncate() - state.positions[gi - 1].truncate();
                q_old = transport(q_old, rest_segment, old_segment);
                q_new = transport(q_new, rest_segment, new_segment);
                let own_segment = rest - state.rest[fi - 1].truncate();
                rest_length = dot(own_segment, own_segment).sqrt();
                y_old += frame_apply(&q_old, own_segment);
                y_new += frame_apply(&q_new, own_segment);
            }
            let x = if old.w == 0.0 || i == 0 {
                y_new.extend(old.w)
            } else {
                let kept = (old.truncate() - y_old) * end.follow_fade;
                let target = y_new + kept;
                let d = target - placed_before;
                let len = dot(d, d).sqrt();
                let mut p = if len > 0.0 { placed_before + d * (rest_length / len) } else { target };
                if collisions {
                    p = bodies.collide(p, state.rest[fi].w);
                }
                p.extend(old.w)
            };
            placed_before = x.truncate();
            state.positions[fi] = x;
            state.velocities[fi] = ((x.truncate() - old.truncate()) / span).extend(0.0);
        }
    }
}
