//! Blocks of the simulation step and the mesh collider build
//! (`glsl/include/sim.glsl`, `sdf.glsl`). Their members are private to
//! `gpu_types`: the rest of the crate writes and reads them through their
//! views ([`super::SimStep`], [`super::StepRange`], [`super::ColliderShape`],
//! [`super::SdfPass`]), which name every lane.

use bytemuck::{Pod, Zeroable};

use crate::vk::reflect::gpu_struct;

/// Per-sub-step parameters of the simulation stages (`SimStepParams`); view: [`super::SimStep`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SimStepParams {
    pub(super) head: [[f32; 4]; 4],
    pub(super) gravity_dt: [f32; 4],
    pub(super) wind: [f32; 4],
    pub(super) wind_noise: [f32; 4],
    pub(super) solver: [f32; 4],
    pub(super) counts: [u32; 4],
    pub(super) layout_info: [u32; 4],
    pub(super) knobs: [[f32; 4]; super::SIM_KNOB_VEC4S],
    pub(super) previous_head: [[f32; 4]; 4],
    pub(super) mesh_grid: [f32; 4],
    pub(super) mesh_dims: [u32; 4],
    pub(super) scalp_lerp: [f32; 4],
    pub(super) scalp_source: [u32; 4],
}
gpu_struct!(SimStepParams => "SimStepParams" {
    head, gravity_dt, wind, wind_noise, solver, counts, layout_info, knobs, previous_head, mesh_grid, mesh_dims,
    scalp_lerp, scalp_source
});

/// Push constants of the simulation step kernel (`SimPush`); view: [`super::StepRange`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SimPush {
    pub(super) range: [u32; 4],
}
gpu_struct!(SimPush => "SimPush" { range });

/// Push constants of the state move kernel (`MovePush`); view: [`super::StateMove`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct MovePush {
    pub(super) transform: [[f32; 4]; 4],
    pub(super) info: [u32; 4],
}
gpu_struct!(MovePush => "MovePush" { transform, info });

/// Push constants of the mesh collider's build kernels (`SdfPush`); view: [`super::SdfPass`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SdfPush {
    pub(super) origin_cell: [f32; 4],
    pub(super) dims: [u32; 4],
    pub(super) pass_info: [u32; 4],
}
gpu_struct!(SdfPush => "SdfPush" { origin_cell, dims, pass_info });

/// A key hair's root bound to a scalp triangle (`ScalpRoot`); view: [`super::ScalpRootView`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuScalpRoot {
    pub(super) corners: [u32; 4],
    pub(super) weights: [f32; 4],
    pub(super) unbind: [[f32; 4]; 4],
}
gpu_struct!(GpuScalpRoot => "ScalpRoot" { corners, weights, unbind });

/// A collider in world space (`Collider`); view: [`super::ColliderShape`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuCollider {
    pub(super) a_radius: [f32; 4],
    pub(super) b_kind: [f32; 4],
    pub(super) moved_a_friction: [f32; 4],
    pub(super) moved_b: [f32; 4],
}
gpu_struct!(GpuCollider => "Collider" { a_radius, b_kind, moved_a_friction, moved_b });
