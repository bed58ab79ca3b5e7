//! The simulation step kernel (`glsl/sim/step.comp`): prediction, the
//! constraint solve and the velocity update of one or more sub-steps in one
//! dispatch, one 64-invocation workgroup per `hairs_per_group` key hairs,
//! positions in shared memory.

use super::params::MAX_SIM_POINTS;
use crate::vk::shaders::{ShaderSource, SIM_STEP_COMP};

pub(super) const SHADER: &ShaderSource = &SIM_STEP_COMP;

/// Invocations: a whole workgroup for each group of hairs.
pub(super) fn threads(strands: u32, hairs_per_group: u32) -> u32 {
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
    // Lanes doing work: hairs never straddle a sync group, so its tail idles.
    let used = |group: u32| (group / points) * points * (wg / group);
    let subgroup_fits =
        subgroup_sync && subgroup_size >= points && subgroup_size > 0 && wg.is_multiple_of(subgroup_size);
    // Subgroup barriers are cheaper, but only worth it when they keep as many lanes busy
    // (on lavapipe, 8-wide subgroups fit one 6-point hair: 75 % against 94 %).
    let sync_group = if subgroup_fits && used(subgroup_size) >= used(wg) { subgroup_size } else { wg };
    let fit = (wg / sync_group) * (sync_group / points).max(1);
    let hairs_per_group = if requested == 0 { fit } else { requested.min(fit) };
    Packing { sync_group, hairs_per_group }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packing_prefers_busy_lanes() {
        // lavapipe: 8-wide subgroups.
        assert_eq!(packing(6, 8, 0, true), Packing { sync_group: 64, hairs_per_group: 10 });
        assert_eq!(packing(4, 8, 0, true), Packing { sync_group: 8, hairs_per_group: 16 });
        assert_eq!(packing(32, 8, 0, true), Packing { sync_group: 64, hairs_per_group: 2 });
        // 32-wide subgroups: 5 six-point hairs per subgroup, 10 per workgroup either way.
        assert_eq!(packing(6, 32, 0, true), Packing { sync_group: 32, hairs_per_group: 10 });
        assert_eq!(packing(6, 32, 0, false), Packing { sync_group: 64, hairs_per_group: 10 });
        assert_eq!(packing(64, 32, 0, true), Packing { sync_group: 64, hairs_per_group: 1 });
        assert_eq!(packing(6, 0, 3, true), Packing { sync_group: 64, hairs_per_group: 3 });
    }
}
