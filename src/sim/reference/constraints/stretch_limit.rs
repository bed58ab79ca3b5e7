// The stretch limit, twin of `glsl/include/constraints/stretch_limit.glsl`: in
// the last iteration, one sweep root to tip shortening each segment longer than
// (1 + stretch_limit) × its rest length to that length, the child moved only.

use glam::Vec4;

use super::Strand;
use crate::sim::reference::dot;

/// Nothing beyond the strand's rest lengths.
pub(super) struct Loaded;

pub(super) fn load(_: &Strand<'_>) -> Loaded {
    Loaded
}

pub(super) fn on(c: &Strand<'_>, iteration: u32) -> bool {
    c.p.knobs.stretch_limit > 0.0 && iteration + 1 == c.p.iterations
}

pub(super) fn apply(_: &Loaded, _set: usize, s: &mut [Vec4], c: &Strand<'_>) {
    for j in 1..s.len() {
        let (parent, child) = (s[j - 1], s[j]);
        let d = child.truncate() - parent.truncate();
        let len = dot(d, d).sqrt();
        let most = c.lengths[j - 1] * (1.0 + c.p.knobs.stretch_limit);
        if child.w > 0.0 && len > most {
            s[j] = (parent.truncate() + d * (most / len)).extend(child.w);
        }
    }
}
