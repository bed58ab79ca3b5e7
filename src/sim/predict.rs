//! Stage 1 — forces and prediction (`glsl/sim/predict.comp`): one invocation per particle.

use crate::vk::shaders::{ShaderSource, SIM_PREDICT_COMP};

pub(super) const SHADER: &ShaderSource = &SIM_PREDICT_COMP;

/// Invocations: one per particle.
pub(super) fn threads(strands: u32, points: u32, _hairs_per_group: u32) -> u32 {
    strands * points
}
