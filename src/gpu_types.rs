//! Rust twins of the GLSL structs in `glsl/include/`, one definition each.
//!
//! Every struct is `#[repr(C)]` + `bytemuck::Pod` and implements
//! `GpuStruct`; `vk::tests` reflects the SPIR-V of every shader and checks
//! member offsets, sizes and array strides against these definitions.
//!
//! The GLSL side packs scalars into `vec4`/`uvec4` members (std140 alignment);
//! the named accessors below are the one place that knows which slot holds
//! what, so Rust call sites never index into the packing.

use bytemuck::{Pod, Zeroable};

use glam::Vec3;

use crate::limits;
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

/// Per-step parameters of the simulation stages (`SimStepParams` in `glsl/include/sim.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SimStepParams {
    /// World-from-head transform at the end of the step, column-major.
    pub head: [[f32; 4]; 4],
    /// xyz gravity (m/s²), w time step (s).
    pub gravity_dt: [f32; 4],
    /// xyz wind acceleration (m/s²), w turbulence.
    pub wind: [f32; 4],
    /// x noise frequency (1/s), y time (s), z spring stiffness (1/s²), w damping per step.
    pub wind_noise: [f32; 4],
    /// x bending stiffness per iteration at the root, y at the tip, z DFTL damping.
    pub bending: [f32; 4],
    /// x strands, y points per strand, z iterations, w flags.
    pub counts: [u32; 4],
    /// x colliders, y hairs per workgroup, z step index, w solver sync group size.
    pub layout_info: [u32; 4],
    /// x global shape stiffness per iteration at full strength, y its range
    /// (fraction of the strand from the root), z local shape stiffness per
    /// sub-step, w mesh collider friction.
    pub shape: [f32; 4],
    /// World-from-head transform at the start of the step, column-major.
    pub previous_head: [[f32; 4]; 4],
    /// Mesh collider: xyz grid point (0, 0, 0) in the head frame, w cell edge.
    pub mesh_grid: [f32; 4],
    /// Mesh collider: xyz grid points per axis, w 1 when set.
    pub mesh_dims: [u32; 4],
}
gpu_struct!(SimStepParams => "SimStepParams" {
    head, gravity_dt, wind, wind_noise, bending, counts, layout_info, shape, previous_head, mesh_grid, mesh_dims
});

/// Push constants of the simulation step kernel (`SimPush` in `glsl/include/sim.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SimPush {
    /// x first sub-step of the dispatch (index into the per-sub-step arrays), y how many.
    pub range: [u32; 4],
}
gpu_struct!(SimPush => "SimPush" { range });

impl SimStepParams {
    /// Gravity, m/s².
    pub fn gravity(&self) -> Vec3 {
        Vec3::new(self.gravity_dt[0], self.gravity_dt[1], self.gravity_dt[2])
    }
    /// Time step, s.
    pub fn dt(&self) -> f32 {
        self.gravity_dt[3]
    }
    /// Bending stiffness per iteration at the root and at the tip.
    pub fn bending_root_tip(&self) -> (f32, f32) {
        (self.bending[0], self.bending[1])
    }
    /// Damping of the DFTL velocity correction.
    pub fn dftl_damping(&self) -> f32 {
        self.bending[2]
    }
    /// Key hairs.
    pub fn strands(&self) -> u32 {
        self.counts[0]
    }
    /// Points per key hair.
    pub fn points(&self) -> u32 {
        self.counts[1]
    }
    /// Constraint iterations.
    pub fn iterations(&self) -> u32 {
        self.counts[2]
    }
    /// `SIM_*` flags.
    pub fn flags(&self) -> u32 {
        self.counts[3]
    }
    /// Global shape stiffness per iteration at full strength, and its range.
    pub fn global_shape(&self) -> (f32, f32) {
        (self.shape[0], self.shape[1])
    }
    /// Local shape stiffness per sub-step (one sweep after the last iteration).
    pub fn local_shape(&self) -> f32 {
        self.shape[2]
    }
    /// Friction against the mesh collider (0..=1).
    pub fn mesh_friction(&self) -> f32 {
        self.shape[3]
    }
}

/// Push constants of the mesh collider's build kernels (`SdfPush` in `glsl/include/sdf.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SdfPush {
    /// xyz grid point (0, 0, 0) in the mesh frame, w cell edge.
    pub origin_cell: [f32; 4],
    /// xyz grid points per axis, w triangles.
    pub dims: [u32; 4],
    /// x seed mode (0 distance, 1 triangle) or flood step, y ray axis.
    pub pass_info: [u32; 4],
}
gpu_struct!(SdfPush => "SdfPush" { origin_cell, dims, pass_info });

/// A collider in world space (`Collider` in `glsl/include/sim.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuCollider {
    /// xyz centre or first end, w radius.
    pub a_radius: [f32; 4],
    /// xyz second end, w kind (0 sphere, 1 capsule).
    pub b_kind: [f32; 4],
}
gpu_struct!(GpuCollider => "Collider" { a_radius, b_kind });

impl GpuCollider {
    /// Centre (sphere) or first end (capsule).
    pub fn a(&self) -> Vec3 {
        Vec3::new(self.a_radius[0], self.a_radius[1], self.a_radius[2])
    }
    /// Second end (capsules).
    pub fn b(&self) -> Vec3 {
        Vec3::new(self.b_kind[0], self.b_kind[1], self.b_kind[2])
    }
    /// Radius, m.
    pub fn radius(&self) -> f32 {
        self.a_radius[3]
    }
    /// Whether it is a capsule (else a sphere).
    pub fn is_capsule(&self) -> bool {
        self.b_kind[3] > 0.5
    }
}

/// Push constants of the smoothing pass (`SmoothPush` in `glsl/include/render.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SmoothPush {
    /// Key hairs.
    pub strands: u32,
    /// Points per key hair.
    pub points: u32,
    /// Smoothed segments per key segment.
    pub level: u32,
    /// Smoothed vertices per key hair.
    pub stride: u32,
    /// Where between the state before the latest step (0) and the latest (1)
    /// the key hairs are drawn.
    pub alpha: f32,
}
gpu_struct!(SmoothPush => "SmoothPush" { strands, points, level, stride, alpha });

/// Push constants of the interpolation pass (`InterpolatePush` in `glsl/include/render.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct InterpolatePush {
    /// Head rotation quaternion (x, y, z, w).
    pub head_rotation: [f32; 4],
    /// Key hairs.
    pub strands: u32,
    /// Points per key hair.
    pub points: u32,
    /// Smoothed segments per key segment.
    pub level: u32,
    /// Smoothed vertices per hair.
    pub stride: u32,
    /// Interpolated hairs per key hair.
    pub hairs: u32,
    /// Offset radius scale, meters.
    pub clump_width: f32,
    /// Fraction of the clump width at the root.
    pub root_width: f32,
    /// Fraction of the clump width at the tip.
    pub tip_width: f32,
}
gpu_struct!(InterpolatePush => "InterpolatePush" {
    head_rotation, strands, points, level, stride, hairs, clump_width, root_width, tip_width
});

/// One light of the draw pass (`Light` in `glsl/include/render.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuLight {
    /// xyz position, w kind.
    pub position_kind: [f32; 4],
    /// xyz direction of travel, w cos(outer half-angle).
    pub direction_cone: [f32; 4],
    /// rgb radiance, w cos(inner half-angle).
    pub color_range: [f32; 4],
}
gpu_struct!(GpuLight => "Light" { position_kind, direction_cone, color_range });

impl GpuLight {
    /// `LIGHT_*` kind: 0 directional, 1 point, 2 spot.
    pub fn kind(&self) -> u32 {
        self.position_kind[3] as u32
    }
    /// Whether it is a point light (no direction: no single opacity map fits it).
    pub fn is_point(&self) -> bool {
        self.kind() == 1
    }
    /// Position (point and spot lights).
    pub fn position(&self) -> Vec3 {
        Vec3::new(self.position_kind[0], self.position_kind[1], self.position_kind[2])
    }
    /// Direction of travel (directional and spot lights).
    pub fn direction(&self) -> Vec3 {
        Vec3::new(self.direction_cone[0], self.direction_cone[1], self.direction_cone[2])
    }
    /// Cosine of a spot light's outer half-angle.
    pub fn cos_outer(&self) -> f32 {
        self.direction_cone[3]
    }
}

/// Uniform block of the draw pass (`DrawParams` in `glsl/include/render.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct DrawParams {
    /// World → clip, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// xyz camera position, w world size of one pixel at distance 1.
    pub camera: [f32; 4],
    /// rgb root albedo, a ambient.
    pub root_color: [f32; 4],
    /// rgb tip albedo, a diffuse wrap.
    pub tip_color: [f32; 4],
    /// rgb primary highlight, w exponent.
    pub primary: [f32; 4],
    /// rgb secondary highlight, w exponent.
    pub secondary: [f32; 4],
    /// Primary shift, secondary shift, shift jitter, highlight breakup.
    pub shifts: [f32; 4],
    /// Root width, tip width (m), least width (pixels).
    pub widths: [f32; 4],
    /// 1 for transparent strands (coverage, no least width), opacity, hairs a
    /// strand stands for.
    pub coverage: [f32; 4],
    /// Hairs, vertices per hair, lights.
    pub counts: [u32; 4],
    /// The lights.
    pub lights: [GpuLight; limits::MAX_LIGHTS as usize],
}
gpu_struct!(DrawParams => "DrawParams" {
    view_proj, camera, root_color, tip_color, primary, secondary, shifts, widths, coverage, counts, lights
});

/// The transparency passes' per-frame words (`OitCounters` in `glsl/include/oit.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct OitCounters {
    /// Fragments offered this frame (stored: the smaller of this and `capacity`).
    pub used: u32,
    /// Nodes in the pool.
    pub capacity: u32,
    /// Pixels per row of the lists' image.
    pub width: u32,
    /// Fragments sorted exactly per pixel (K).
    pub sorted: u32,
}
gpu_struct!(OitCounters => "OitCounters" { used, capacity, width, sorted });

/// Push constants of the Marschner table builder (`MarschnerPush` in `glsl/include/marschner.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct MarschnerPush {
    /// Index of refraction.
    pub eta: f32,
    /// Longitudinal shift of R, radians.
    pub alpha: f32,
    /// Longitudinal width of R, radians.
    pub beta: f32,
    /// Azimuthal width of TT, radians.
    pub gamma_tt: f32,
    /// Azimuthal width of TRT, radians.
    pub gamma_trt: f32,
    /// Azimuth of the glints, radians.
    pub glint: f32,
    /// Table side, texels.
    pub size: u32,
    /// Padding.
    pub pad0: u32,
}
gpu_struct!(MarschnerPush => "MarschnerPush" { eta, alpha, beta, gamma_tt, gamma_trt, glint, size, pad0 });

/// Per-sub-step parameters of the volume stage (`VolumeParams` in `glsl/include/volume.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuVolumeParams {
    /// World position → grid coordinates (cells), column-major.
    pub grid_from_world: [[f32; 4]; 4],
    /// Grid coordinates → world position.
    pub world_from_grid: [[f32; 4]; 4],
    /// Upper 3×3: world vector → grid axes.
    pub axes: [[f32; 4]; 4],
    /// Grid coordinates → velocity of the colliders' rigid motion along the grid axes (affine).
    pub solid_velocity: [[f32; 4]; 4],
    /// xyz cells per axis, w cell count.
    pub dims: [u32; 4],
    /// x particles, y first v face, z first w face, w face count.
    pub counts: [u32; 4],
    /// x FLIP ratio, y friction, z repulsion (m/s²), w repulsion threshold density.
    pub transfer: [f32; 4],
    /// x tolerance, y cell size (m), z time step (s), w mode.
    pub solve: [f32; 4],
    /// x iteration cap, y preconditioner, z multigrid levels, w colliders.
    pub config: [u32; 4],
    /// Grid coordinates → the mesh collider's frame (the head frame).
    pub mesh_from_grid: [[f32; 4]; 4],
    /// Mesh collider: xyz grid point (0, 0, 0), w cell edge.
    pub mesh_grid: [f32; 4],
    /// Mesh collider: xyz grid points per axis, w 1 when its cells count as solid.
    pub mesh_dims: [u32; 4],
}
gpu_struct!(GpuVolumeParams => "VolumeParams" {
    grid_from_world, world_from_grid, axes, solid_velocity, dims, counts, transfer, solve, config, mesh_from_grid,
    mesh_grid, mesh_dims
});

impl GpuVolumeParams {
    /// FLIP ratio (0 PIC, 1 FLIP).
    pub fn flip_ratio(&self) -> f32 {
        self.transfer[0]
    }
    /// Friction of the friction mode.
    pub fn friction(&self) -> f32 {
        self.transfer[1]
    }
    /// Repulsion, m/s².
    pub fn repulsion(&self) -> f32 {
        self.transfer[2]
    }
    /// Density above which repulsion acts.
    pub fn repulsion_threshold(&self) -> f32 {
        self.transfer[3]
    }
    /// Pressure solve tolerance.
    pub fn tolerance(&self) -> f32 {
        self.solve[0]
    }
    /// Time step, s.
    pub fn dt(&self) -> f32 {
        self.solve[2]
    }
    /// `VOL_MODE_*` mode, as stored.
    pub fn mode(&self) -> f32 {
        self.solve[3]
    }
    /// Colliders the stage sees.
    pub fn colliders(&self) -> u32 {
        self.config[3]
    }
}

/// Push constants of the volume kernels (`VolumePush` in `glsl/include/volume.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct VolumePush {
    /// xyz cells of the level worked on, w its first cell.
    pub dims: [u32; 4],
    /// xyz cells of the next coarser level, w its first cell.
    pub coarse: [u32; 4],
    /// Kernel-specific.
    pub op: [u32; 4],
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

/// One light's deep opacity map (`ShadowMap` in `glsl/include/shadow.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuShadowMap {
    /// World → the light's clip space, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// Light-space depth: dot(xyz, p) + w (m).
    pub view_z: [f32; 4],
    /// xyz layer ends behind z0 (m), w extinction k.
    pub layers: [f32; 4],
    /// xy first texel of the tile, zw its size (texels).
    pub tile: [f32; 4],
    /// x opacity per strand fragment, y PCF radius (texels).
    pub params: [f32; 4],
}
gpu_struct!(GpuShadowMap => "ShadowMap" { view_proj, view_z, layers, tile, params });

impl GpuShadowMap {
    /// Whether the entry is a density-volume light rather than a map.
    pub fn is_density_volume(&self) -> bool {
        self.params[2] != 0.0
    }
}

/// The shadow maps of a frame (`ShadowParams` in `glsl/include/shadow.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuShadowParams {
    pub maps: [GpuShadowMap; limits::MAX_SHADOW_MAPS as usize],
    /// Map index per light (0xffffffff: none), four lights per vector.
    pub light_map: [[u32; 4]; 2],
    /// x hairs, y vertices per hair, z maps.
    pub counts: [u32; 4],
    /// The density volume: world → grid coordinates.
    pub grid_from_world: [[f32; 4]; 4],
    /// xyz cells, w 1 when present.
    pub grid_dims: [u32; 4],
    /// x cell size (m), y cross-section per particle / cell volume (1/m), z step (cells).
    pub grid: [f32; 4],
}
gpu_struct!(GpuShadowParams => "ShadowParams" { maps, light_map, counts, grid_from_world, grid_dims, grid });

impl GpuShadowParams {
    /// Entries of `maps` in use.
    pub fn map_count(&self) -> usize {
        self.counts[2] as usize
    }
}

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
    check::<SimStepParams>(reflection, &mut problems);
    check::<SimPush>(reflection, &mut problems);
    check::<GpuCollider>(reflection, &mut problems);
    check::<SdfPush>(reflection, &mut problems);
    check::<SmoothPush>(reflection, &mut problems);
    check::<InterpolatePush>(reflection, &mut problems);
    check::<GpuLight>(reflection, &mut problems);
    check::<DrawParams>(reflection, &mut problems);
    check::<OitCounters>(reflection, &mut problems);
    check::<MarschnerPush>(reflection, &mut problems);
    check::<GpuVolumeParams>(reflection, &mut problems);
    check::<VolumePush>(reflection, &mut problems);
    check::<PcgScalars>(reflection, &mut problems);
    check::<GpuShadowMap>(reflection, &mut problems);
    check::<GpuShadowParams>(reflection, &mut problems);
    problems
}
