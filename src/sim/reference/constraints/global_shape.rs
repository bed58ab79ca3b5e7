// The global shape constraint, twin of
// `glsl/include/constraints/global_shape.glsl`: each point pulled toward its
// rest position placed by the hair's frame.

use glam::{Vec3, Vec4};

use super::Strand;
use crate::codes::sim_flags;
use crate::sim::reference::transform_point;

/// Weight of the global shape constraint at strand parameter `t`, as
/// `sim_shape_weight` in `glsl/include/sim.glsl`.
fn shape_weight(t: f32, range: f32) -> f32 {
    if t <= range {
        1.0
    } else {
        ((range + 0.25 - t) * 4.0).max(0.0)
    }
}

/// The target for a particle whose rest position is `target`, as
/// `sim_shape_target` in `glsl/include/sim.glsl` (raised against gravity by
/// the static sag with `SAG_FREE`).
fn shape_target(target: Vec3, k: f32, iterations: u32, flags: u32, gravity: Vec3, dt: f32) -> Vec3 {
    if flags & sim_flags::SAG_FREE == 0 || flags & sim_flags::GRAVITY == 0 || k <= 0.0 {
        return target;
    }
    let mut keep = 1.0f32;
    for _ in 0..iterations {
        keep *= 1.0 - k;
    }
    let s = 1.0 - keep;
    if s < 0.01 {
        return target;
    }
    let f = 1.0 / s - 1.0;
    let step_sag = gravity * (dt * dt);
    let sag = step_sag * f;
    target - sag
}

/// Per point: the sub-step's target and stiffness.
pub(super) struct Loaded(Vec<(Vec3, f32)>);

pub(super) fn load(c: &Strand<'_>) -> Loaded {
    let (p, points) = (c.p, c.rest.len());
    if p.flags & sim_flags::GLOBAL_SHAPE == 0 {
        return Loaded(vec![(Vec3::ZERO, 0.0); points]);
    }
    let point = |i: usize| {
        let t = i as f32 / (points - 1) as f32;
        let k = p.knobs.global_shape * shape_weight(t, p.knobs.global_shape_range);
        let at_rest = transform_point(c.frame, c.rest[i].truncate());
        (shape_target(at_rest, k, p.iterations, p.flags, p.gravity, p.dt), k)
    };
    Loaded((0..points).map(point).collect())
}

pub(super) fn on(c: &Strand<'_>, _iteration: u32) -> bool {
    c.p.flags & sim_flags::GLOBAL_SHAPE != 0
}

pub(super) fn apply(loaded: &Loaded, _set: usize, s: &mut [Vec4], _: &Strand<'_>) {
    for (q, &(target, k)) in s.iter_mut().zip(&loaded.0) {
        if q.w > 0.0 && k > 0.0 {
            *q = (q.truncate() + (target - q.truncate()) * k).extend(q.w);
        }
    }
}
