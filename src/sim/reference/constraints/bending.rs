// Bending constraints, twin of `glsl/include/constraints/bending.glsl`: points
// c − 1 and c + 1 held at their rest distance, stiffness per iteration from
// `bending_root` at the root to `bending_tip` at the tip; set 0 the centres c
// with c mod 4 in {0, 1}, set 1 those in {2, 3}.

use glam::Vec4;

use super::{project, Strand};
use crate::codes::sim_flags;
use crate::sim::reference::dot;

/// Per point c: the rest distance and stiffness of the constraint centred on
/// it (zero stiffness at the ends).
pub(super) struct Loaded(Vec<(f32, f32)>);

pub(super) fn load(c: &Strand<'_>) -> Loaded {
    let (points, knobs) = (c.rest.len(), &c.p.knobs);
    let centre = |i: usize| {
        if i == 0 || i + 1 >= points {
            return (0.0, 0.0);
        }
        let r = c.rest[i + 1].truncate() - c.rest[i - 1].truncate();
        let t = i as f32 / (points - 1) as f32;
        (dot(r, r).sqrt(), knobs.bending_root + (knobs.bending_tip - knobs.bending_root) * t)
    };
    Loaded((0..points).map(centre).collect())
}

pub(super) fn on(c: &Strand<'_>, _iteration: u32) -> bool {
    c.p.flags & sim_flags::BENDING != 0
}

pub(super) fn apply(loaded: &Loaded, set: usize, s: &mut [Vec4], _: &Strand<'_>) {
    let phase = set * 2;
    for (i, &(rest_d, k)) in loaded.0.iter().enumerate() {
        if k > 0.0 && (i & 3) >= phase && (i & 3) < phase + 2 {
            project(s, i - 1, i + 1, rest_d, k);
        }
    }
}
