//! Stage 3 — velocity update, damping and final state (`glsl/sim/integrate.comp`):
//! one invocation per particle, into the other half of the double buffer.

use crate::vk::shaders::{ShaderSource, SIM_INTEGRATE_COMP};

pub(super) const SHADER: &ShaderSource = &SIM_INTEGRATE_COMP;

/// Invocations: one per particle.
pub(super) fn threads(strands: u32, points: u32, _hairs_per_group: u32) -> u32 {
    strands * points
}
