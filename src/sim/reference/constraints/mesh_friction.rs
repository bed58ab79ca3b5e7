// Friction against the mesh collider, twin of
// `glsl/include/constraints/mesh_friction.glsl`: once per sub-step after the
// iterations, each movable point's motion over the sub-step along the surface
// braked by `mesh_friction`.

use glam::Vec4;

use super::Strand;
use crate::codes::sim_flags;

/// Nothing beyond the sub-step's mesh collider.
pub(super) struct Loaded;

pub(super) fn load(_: &Strand<'_>) -> Loaded {
    Loaded
}

pub(super) fn on(c: &Strand<'_>, _iteration: u32) -> bool {
    c.bodies.mesh.is_some() && c.p.flags & sim_flags::COLLISIONS != 0
}

pub(super) fn apply(_: &Loaded, _set: usize, s: &mut [Vec4], c: &Strand<'_>) {
    let p = c.p;
    for (i, q) in s.iter_mut().enumerate() {
        if q.w > 0.0 {
            let from = c.start[i].truncate();
            let held = c.bodies.mesh_friction(&p.previous_head, q.truncate(), from, c.rest[i].w, p.knobs.mesh_friction);
            *q = held.extend(q.w);
        }
    }
}
