// Local shape constraints, twin of `glsl/include/constraints/local_shape.glsl`:
// in the last iteration, one sweep root to tip pulling each segment toward its
// rest offset carried along by its parent segment.

use glam::{Vec3, Vec4};

use super::Strand;
use crate::codes::sim_flags;
use crate::sim::reference::{dot, rotate, rotate_between};

/// Per point i ≥ 1: the parent segment's rest direction (world, unit; zero
/// for the first segment and degenerate ones) and the rest offset of i from
/// i − 1 (world).
pub(super) struct Loaded(Vec<(Vec3, Vec3)>);

pub(super) fn load(c: &Strand<'_>) -> Loaded {
    let mut local = vec![(Vec3::ZERO, Vec3::ZERO); c.rest.len()];
    if c.p.flags & sim_flags::LOCAL_SHAPE == 0 {
        return Loaded(local);
    }
    let offset = |j: usize| rotate(c.frame, c.rest[j].truncate() - c.rest[j - 1].truncate());
    for (i, slot) in local.iter_mut().enumerate().skip(1) {
        let mut dir = Vec3::ZERO;
        if i >= 2 {
            let d = offset(i - 1);
            let len = dot(d, d).sqrt();
            dir = if len > 0.0 { d / len } else { Vec3::ZERO };
        }
        *slot = (dir, offset(i));
    }
    Loaded(local)
}

pub(super) fn on(c: &Strand<'_>, iteration: u32) -> bool {
    c.p.flags & sim_flags::LOCAL_SHAPE != 0 && iteration + 1 == c.p.iterations
}

pub(super) fn apply(loaded: &Loaded, _set: usize, s: &mut [Vec4], c: &Strand<'_>) {
    for (j, &(dir, offset)) in loaded.0.iter().enumerate().skip(1) {
        let (parent, child) = (s[j - 1], s[j]);
        let mut carried = offset;
        if j >= 2 && dot(dir, dir) > 0.0 {
            let d = parent.truncate() - s[j - 2].truncate();
            let len = dot(d, d).sqrt();
            if len > 0.0 {
                carried = rotate_between(dir, d / len, carried);
            }
        }
        let w = parent.w + child.w;
        if w > 0.0 {
            let delta = (carried - (child.truncate() - parent.truncate())) * c.p.knobs.local_shape;
            s[j - 1] = (parent.truncate() - delta * (parent.w / w)).extend(parent.w);
            s[j] = (child.truncate() + delta * (child.w / w)).extend(child.w);
        }
    }
}
