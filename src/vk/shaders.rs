//! The shaders compiled by `build.rs` from `glsl/`.

/// Pipeline stage of a compiled shader.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ShaderStage {
    Compute,
    Vertex,
    TessControl,
    TessEvaluation,
    Fragment,
}

impl ShaderStage {
    pub(crate) fn flags(self) -> ash::vk::ShaderStageFlags {
        use ash::vk::ShaderStageFlags as F;
        match self {
            ShaderStage::Compute => F::COMPUTE,
            ShaderStage::Vertex => F::VERTEX,
            ShaderStage::TessControl => F::TESSELLATION_CONTROL,
            ShaderStage::TessEvaluation => F::TESSELLATION_EVALUATION,
            ShaderStage::Fragment => F::FRAGMENT,
        }
    }
}

/// One SPIR-V module (SPIR-V 1.5, entry point `main`).
#[derive(Debug)]
pub(crate) struct ShaderSource {
    /// Path under `glsl/`, e.g. `core/scale_add.comp`.
    pub name: &'static str,
    pub stage: ShaderStage,
    pub words: &'static [u32],
}

// The table also holds the shaders only the tests use (glsl/core/).
#[allow(dead_code)]
mod table {
    use super::{ShaderSource, ShaderStage};
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
pub(crate) use table::*;
