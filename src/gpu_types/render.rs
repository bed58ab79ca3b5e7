//! Blocks of the render passes (`glsl/include/render.glsl`, `oit.glsl`, `marschner.glsl`, `shadow.glsl`).

use bytemuck::{Pod, Zeroable};

use crate::vk::reflect::gpu_struct;

use glam::Vec3;

use crate::limits;

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

/// One follower's guides and weights (`FollowerBinding` in
/// `glsl/include/render.glsl`; [`crate::render::Followers`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct FollowerBinding {
    /// Three guide indices (the fourth unused).
    pub guides: [u32; 4],
    /// Their weights, summing to 1 (the fourth unused).
    pub weights: [f32; 4],
}
gpu_struct!(FollowerBinding => "FollowerBinding" { guides, weights });

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
        self.kind() == crate::codes::light_kind::POINT
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
    /// Root width, tip width (m), least width (pixels), 1 when the hairs
    /// have their own albedo (`hair_looks`).
    pub widths: [f32; 4],
    /// 1 for transparent strands (coverage, no least width), opacity, hairs a
    /// strand stands for.
    pub coverage: [f32; 4],
    /// Spacing of the drawn strands at the root and at the tip (m), which a
    /// transparent strand's band spreads over (`reference::strand_band`).
    pub band: [f32; 4],
    /// Hairs, vertices per hair, lights.
    pub counts: [u32; 4],
    /// The lights.
    pub lights: [GpuLight; limits::MAX_LIGHTS as usize],
}
gpu_struct!(DrawParams => "DrawParams" {
    view_proj, camera, root_color, tip_color, primary, secondary, shifts, widths, coverage, band, counts, lights
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
    /// Nodes per buffer of the pool (node n is entry n mod this of buffer n / this).
    pub pool_nodes: u32,
    /// Pixel rows of the target.
    pub height: u32,
    /// The pixels the frame's ribbons can reach (`hair_rect.comp`): first
    /// column, first row (from NDC y = −1), and the column and row past the
    /// last; `u32::MAX, u32::MAX, 0, 0` before the vertex shading.
    pub hair_x0: u32,
    /// See `hair_x0`.
    pub hair_y0: u32,
    /// See `hair_x0`.
    pub hair_x1: u32,
    /// See `hair_x0`.
    pub hair_y1: u32,
    /// How the compute rasteriser's copy of the target's depth is encoded
    /// (`codes::scene_depth`; `NONE` for no depth test).
    pub scene_depth: u32,
    /// 1 when the target's depth is reversed (near = 1): the lists keep
    /// depths forward (`oit_forward` in `glsl/include/oit_counters.glsl`).
    pub reverse_z: u32,
    /// The accumulated opacity at which a pixel's motion vector takes its
    /// hair (the exact mode's composite writes that depth); 0 when the frame
    /// writes no motion vectors.
    pub motion_threshold: f32,
}
gpu_struct!(OitCounters => "OitCounters" {
    used, capacity, width, sorted, pool_nodes, height, hair_x0, hair_y0, hair_x1, hair_y1, scene_depth, reverse_z,
    motion_threshold
});

/// The motion vectors' block (`MotionBlock` in `glsl/include/motion.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct GpuMotion {
    /// World → clip of this frame, without its jitter.
    pub now: [[f32; 4]; 4],
    /// World → clip of the previous frame, without its jitter.
    pub before: [[f32; 4]; 4],
    /// xy: an NDC difference (now − before) to the host's units and sign;
    /// z: the world size of a target pixel at distance 1.
    pub scale: [f32; 4],
    /// This frame's projection: clip z = x·z_view + y, clip w = z·z_view + w.
    pub depth: [f32; 4],
    /// x: hairs (a prefix) whose previous positions are kept; y: drawn
    /// pixels per target pixel along each axis.
    pub counts: [u32; 4],
}
gpu_struct!(GpuMotion => "MotionBlock" { now, before, scale, depth, counts });

/// The tiled rasteriser's per-frame words (`TileCounters` in `glsl/include/tile_lists.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct TileCounters {
    /// Tile entries the frame's segments asked for (written by the scan).
    pub entries: u32,
    /// Entries the list holds; those past it are not drawn.
    pub capacity: u32,
    /// Tiles per row.
    pub tiles_x: u32,
    /// Rows of tiles.
    pub tiles_y: u32,
}
gpu_struct!(TileCounters => "TileCounters" { entries, capacity, tiles_x, tiles_y });

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
    /// x opacity per drawn strand's fragment (per hair × hairs it stands for),
    /// y radius of the opacity-averaging filter (texels).
    pub params: [f32; 4],
}
gpu_struct!(GpuShadowMap => "ShadowMap" { view_proj, view_z, layers, tile, params });

impl GpuShadowMap {
    /// Whether the entry is a density-volume light rather than a map.
    pub fn is_density_volume(&self) -> bool {
        self.params[2] == crate::codes::shadow_kind::DENSITY_VOLUME as f32
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
