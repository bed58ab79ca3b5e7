//! Rust twins of the GLSL structs in `glsl/include/`, one definition each.
//!
//! Every struct is `#[repr(C)]` + `bytemuck::Pod` and implements
//! `GpuStruct`; `vk::tests` reflects the SPIR-V of every shader and checks
//! member offsets, sizes and array strides against these definitions.

use bytemuck::{Pod, Zeroable};

use crate::vk::reflect::gpu_struct;

/// Push constants of `core/scale_add.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct ScaleAddPush {
    pub count: u32,
    pub scale: f32,
    pub bias: f32,
    pub pad0: u32,
}
gpu_struct!(ScaleAddPush => "ScaleAddPush" { count, scale, bias, pad0 });

/// `LayoutProbe` of `glsl/include/common.glsl`: exercises std430 rules.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct LayoutProbe {
    pub position: [f32; 3],
    pub radius: f32,
    pub transform: [[f32; 4]; 4],
    pub ids: [u32; 2],
    pub weights: [f32; 2],
    pub color: [f32; 4],
}
gpu_struct!(LayoutProbe => "LayoutProbe" { position, radius, transform, ids, weights, color });

/// Every Rust GPU struct with the shader-side name, for the layout test.
#[cfg(test)]
pub(crate) fn check_all(reflection: &crate::vk::reflect::Reflection) -> Vec<String> {
    use crate::vk::reflect::{compare, GpuStruct};
    fn check<T: GpuStruct>(r: &crate::vk::reflect::Reflection, out: &mut Vec<String>) {
        for layout in r.structs_named(T::GLSL_NAME) {
            if let Err(e) = compare::<T>(layout) {
                out.push(e);
            }
        }
    }
    let mut problems = Vec::new();
    check::<ScaleAddPush>(reflection, &mut problems);
    check::<LayoutProbe>(reflection, &mut problems);
    problems
}
