//! Stage 2 — constraint solve (`glsl/sim/solve.comp`): one 64-invocation
//! workgroup per `hairs_per_group` key hairs, positions in shared memory.

use super::params::MAX_SIM_POINTS;
use crate::vk::shaders::{ShaderSource, SIM_SOLVE_COMP};

pub(super) const SHADER: &ShaderSource = &SIM_SOLVE_COMP;

/// Invocations: a whole workgroup for each group of hairs.
pub(super) fn threads(strands: u32, _points: u32, hairs_per_group: u32) -> u32 {
    strands.div_ceil(hairs_per_group) * MAX_SIM_POINTS as u32
}

/// How the solver packs hairs into its 64-invocation workgroup.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Packing {
    /// Invocations that synchronise together: the subgroup when every hair fits into
    /// one and no hair straddles two, else the whole workgroup.
    pub sync_group: u32,
    /// Hairs per workgroup.
    pub hairs_per_group: u32,
}

/// Chooses the packing for hairs of `points` points on a device with `subgroup_size`.
/// `requested` hairs per workgroup (0 = as many as fit); `subgroup_sync` allows the
/// subgroup scope.
pub(crate) fn packing(points: u32, subgroup_size: u32, requested: u32, subgroup_sync: bool) -> Packing {
    let wg = MAX_SIM_POINTS as u32;
    let sync_group = if subgroup_sync && subgroup_size >= points && subgroup_size > 0 && wg % subgroup_size == 0 {
        subgroup_size
    } else {
        wg
    };
    let fit = (wg / sync_group) * (sync_group / points).max(1);
    let hairs_per_group = if requested == 0 { fit } else { requested.min(fit) };
    Packing { sync_group, hairs_per_group }
}
