// Body collisions, twin of `glsl/include/constraints/collisions.glsl`: each
// movable point projected out of the sub-step's bodies, keeping its radius.

use glam::Vec4;

use super::Strand;
use crate::codes::sim_flags;

/// Nothing beyond the sub-step's bodies.
pub(super) struct Loaded;

pub(super) fn load(_: &Strand<'_>) -> Loaded {
    Loaded
}

pub(super) fn on(c: &Strand<'_>, _iteration: u32) -> bool {
    c.p.flags & sim_flags::COLLISIONS != 0
}

pub(super) fn apply(_: &Loaded, _set: usize, s: &mut [Vec4], c: &Strand<'_>) {
    for (i, q) in s.iter_mut().enumerate() {
        if q.w > 0.0 {
            *q = c.bodies.collide(q.truncate(), c.rest[i].w).extend(q.w);
        }
    }
}
