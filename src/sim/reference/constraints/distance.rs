// Distance constraints, twin of `glsl/include/constraints/distance.glsl`:
// each segment (j, j + 1) held at its rest length, stiffness 1; set 0 the
// segments with j even, set 1 those with j odd.

use glam::Vec4;

use super::{project, Strand};

/// Nothing beyond the strand's rest lengths.
pub(super) struct Loaded;

pub(super) fn load(_: &Strand<'_>) -> Loaded {
    Loaded
}

pub(super) fn on(_: &Strand<'_>, _iteration: u32) -> bool {
    true
}

pub(super) fn apply(_: &Loaded, set: usize, s: &mut [Vec4], c: &Strand<'_>) {
    for i in (set..s.len().saturating_sub(1)).step_by(2) {
        project(s, i, i + 1, c.lengths[i], 1.0);
    }
}
