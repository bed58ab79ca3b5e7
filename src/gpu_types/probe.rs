//! Blocks of the core test shaders (`glsl/core/`): layout and pipeline probes.

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
