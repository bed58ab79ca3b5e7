//! Blocks of the volume stage (`glsl/include/volume.glsl`). The parameter
//! block's and the push constants' members are private to `gpu_types`: the
//! rest of the crate uses their views.

use bytemuck::{Pod, Zeroable};

use crate::vk::reflect::gpu_struct;

/// Per-sub-step parameters of the volume stage (`VolumeParams`); view: [`super::VolumeStep`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuVolumeParams {
    pub(super) grid_from_world: [[f32; 4]; 4],
    pub(super) world_from_grid: [[f32; 4]; 4],
    pub(super) axes: [[f32; 4]; 4],
    pub(super) solid_velocity: [[f32; 4]; 4],
    pub(super) dims: [u32; 4],
    pub(super) counts: [u32; 4],
    pub(super) transfer: [f32; 4],
    pub(super) solve: [f32; 4],
    pub(super) config: [u32; 4],
    pub(super) mesh_from_grid: [[f32; 4]; 4],
    pub(super) mesh_grid: [f32; 4],
    pub(super) mesh_dims: [u32; 4],
}
gpu_struct!(GpuVolumeParams => "VolumeParams" {
    grid_from_world, world_from_grid, axes, solid_velocity, dims, counts, transfer, solve, config, mesh_from_grid,
    mesh_grid, mesh_dims
});

/// Push constants of the volume kernels (`VolumePush`); one view per kernel
/// family: [`super::ReducePass`], [`super::LevelPass`],
/// [`super::SmoothingPass`], [`super::CoarsestPass`],
/// [`super::WorkgroupSolvePass`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct VolumePush {
    pub(super) dims: [u32; 4],
    pub(super) coarse: [u32; 4],
    pub(super) op: [u32; 4],
}
gpu_struct!(VolumePush => "VolumePush" { dims, coarse, op });

/// Scalars of the pressure solve (`PcgScalars` in `glsl/include/volume.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct PcgScalars {
    pub sigma: f32,
    pub alpha: f32,
    pub beta: f32,
    pub bmax: f32,
    pub rmax: f32,
    pub iterations: u32,
    pub converged: u32,
    pub status: u32,
}
gpu_struct!(PcgScalars => "PcgScalars" { sigma, alpha, beta, bmax, rmax, iterations, converged, status });
