//! Pass 3 (before the draw) — self-shadowing of the hair, per shadow-casting
//! light by one of two methods ([`ShadowMethod`]):
//!
//! - **Deep opacity maps** ([`opacity_maps`]): two passes over the interpolated
//!   hairs into the light's tile of an atlas ([`atlas`]).
//! - **Density volume** ([`volume`]): transmittance toward the light at every
//!   cell of the simulation's density volume, no passes over the hair.
//!
//! The draw pass reads the maps through `shadow()` (`glsl/include/shadow.glsl`):
//! opacity interpolated linearly inside the three layers, transmittance
//! exp(−k · opacity), the opacity averaged over (2r+1)² texels first; density-volume lights look
//! their cell's transmittance up. Both passes reuse the strands the
//! interpolation pass captured, at the frame's level of detail.

mod atlas;
mod compute_maps;
mod opacity_maps;
#[cfg(test)]
mod tests;
mod volume;

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::graph::{FrameGraph, Use};
use super::shading::MAX_LIGHTS;
use super::Raster;
use crate::error::{Error, Result};
use crate::gpu_types::{GpuLight, GpuShadowParams};
use crate::profiler::Timing;
use crate::sim::KeyHairs;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use opacity_maps::OpacityMaps;
use volume::VolumeShadows;

pub(crate) use opacity_maps::{light_map, ShadowFootprint};

/// Most lights that cast shadows.
pub const MAX_SHADOW_MAPS: usize = crate::limits::MAX_SHADOW_MAPS as usize;

/// Format of the opacity atlas: three layer sums and z0.
pub const SHADOW_ATLAS_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// How a light's shadow is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadowMethod {
    /// Deep opacity maps: two passes over the rendered hairs per light.
    #[default]
    DeepOpacity,
    /// Ray-marching the simulation's density volume toward the light in the draw
    /// pass (seed 003): no extra passes, resolution of the volume grid; needs the
    /// simulation's volume stage.
    DensityVolume,
}

/// A shadow-casting light.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowCaster {
    /// Index into [`crate::render::Renderer::set_lights`]' list (a directional or spot light
    /// for deep opacity maps; any light for the density volume).
    pub light: usize,
    /// How its shadow is computed.
    pub method: ShadowMethod,
}

impl From<usize> for ShadowCaster {
    /// A light casting deep-opacity-map shadows.
    fn from(light: usize) -> Self {
        ShadowCaster { light, method: ShadowMethod::DeepOpacity }
    }
}

/// Refuses deep-opacity-map casters on point lights among `lights` (an
/// omnidirectional light would need a cube of maps).
pub(crate) fn check_casters(lights: &[GpuLight], params: &ShadowParams) -> Result<()> {
    for caster in params.casters.iter().filter(|c| c.method == ShadowMethod::DeepOpacity) {
        if lights.get(caster.light).is_some_and(GpuLight::is_point) {
            return Err(Error::unsupported(
                "deep opacity maps of point lights",
                format!(
                    "light {} is a point light; give it a density-volume caster \
                     (ShadowCaster::density_volume), or use a spot light",
                    caster.light
                ),
            ));
        }
    }
    Ok(())
}

impl ShadowCaster {
    /// A light whose shadow comes from the density volume.
    pub fn density_volume(light: usize) -> Self {
        ShadowCaster { light, method: ShadowMethod::DensityVolume }
    }
}

/// Self-shadowing through deep opacity maps or the density volume.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowParams {
    /// The lights that cast shadows, at most [`MAX_SHADOW_MAPS`]. Default: none.
    pub casters: Vec<ShadowCaster>,
    /// Side of each light's map, texels (16..=4096). Default: 512.
    pub resolution: u32,
    /// Where the three layers end behind the depth at which the hair starts, meters
    /// (increasing, in (0, 1000]). Default: 0.01, 0.03, 0.08.
    pub layers: [f32; 3],
    /// Opacity one hair's fragment adds (0..=1); a drawn strand standing for n
    /// hairs ([`super::Renderer::strand_hairs`]) adds n times it. Default: 0.05.
    pub opacity: f32,
    /// Extinction k of transmittance = exp(−k · opacity) (0..=100). Default: 1.
    pub extinction: f32,
    /// Radius of the filter averaging the opacity around a lookup, texels (0..=3;
    /// 1 = 3 × 3). Where each drawn strand stands for n > 1 hairs, a map's filter
    /// reaches the neighbouring strands: its radius is at least (1 − 1/n) × the
    /// strands' spacing half-way along them ([`super::Renderer::strand_spacing`])
    /// in texels, rounded to the nearest, up to 3. Default: 1.
    pub pcf_radius: u32,
    /// Density volume: shadowing cross-section of one simulated particle, m²
    /// (transmittance = exp(−σ ∫ particles per m³ ds); ≥ 0). It matches deep opacity
    /// maps when σ = extinction · opacity · represented hairs · hairs per key · map
    /// texel size · key segment length (0..=1000). Default: 1e-4 (the thesis scene at the defaults).
    pub volume_cross_section: f32,
    /// Density volume: ray-marching step, cells (0.1..=2). Default: 0.5.
    pub volume_step: f32,
}

impl Default for ShadowParams {
    fn default() -> Self {
        ShadowParams {
            casters: Vec::new(),
            resolution: 512,
            layers: [0.01, 0.03, 0.08],
            opacity: 0.05,
            extinction: 1.0,
            pcf_radius: 1,
            volume_cross_section: 1e-4,
            volume_step: 0.5,
        }
    }
}

impl ShadowParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if self.casters.len() > MAX_SHADOW_MAPS {
            return Err(Error::param("shadow casters", self.casters.len(), format!("at most {MAX_SHADOW_MAPS}")));
        }
        for (k, c) in self.casters.iter().enumerate() {
            if c.light >= MAX_LIGHTS || self.casters[..k].iter().any(|o| o.light == c.light) {
                return Err(Error::param(
                    "shadow casters",
                    format!("light {}", c.light),
                    format!("each light below {MAX_LIGHTS} listed once"),
                ));
            }
        }
        if !(16..=4096).contains(&self.resolution) {
            return Err(Error::param("shadow resolution", self.resolution, "16..=4096"));
        }
        let [a, b, c] = self.layers;
        if !(a.is_finite() && c.is_finite() && 0.0 < a && a < b && b < c && c <= 1e3) {
            return Err(Error::param("shadow layers", format!("{:?}", self.layers), "increasing, in (0, 1000] m"));
        }
        if !(self.opacity.is_finite() && (0.0..=1.0).contains(&self.opacity)) {
            return Err(Error::param("shadow opacity", self.opacity, "0..=1"));
        }
        if !(self.extinction.is_finite() && (0.0..=100.0).contains(&self.extinction)) {
            return Err(Error::param("shadow extinction", self.extinction, "0..=100"));
        }
        if self.pcf_radius > 3 {
            return Err(Error::param("shadow pcf_radius", self.pcf_radius, "at most 3"));
        }
        if !(self.volume_cross_section.is_finite() && (0.0..=1e3).contains(&self.volume_cross_section)) {
            return Err(Error::param("shadow volume_cross_section", self.volume_cross_section, "0..=1000 m²"));
        }
        if !(self.volume_step.is_finite() && (0.1..=2.0).contains(&self.volume_step)) {
            return Err(Error::param("shadow volume_step", self.volume_step, "0.1..=2"));
        }
        Ok(())
    }

    /// Lights with deep opacity maps, in atlas tile order.
    pub(crate) fn map_casters(&self) -> impl Iterator<Item = &ShadowCaster> {
        self.casters.iter().filter(|c| c.method == ShadowMethod::DeepOpacity)
    }

    /// Lights shadowed through the density volume.
    pub(crate) fn volume_casters(&self) -> u32 {
        self.casters.iter().filter(|c| c.method == ShadowMethod::DensityVolume).count() as u32
    }
}

/// The layer (0..=2) a fragment `d` meters behind z0 adds its opacity to (and to
/// every layer behind it), as `shadow_layer_of` in `glsl/include/shadow.glsl`.
pub fn layer_of(d: f32, layers: [f32; 3]) -> usize {
    if d <= layers[0] {
        0
    } else if d <= layers[1] {
        1
    } else {
        2
    }
}

/// Opacity in front of depth `d` behind z0 from the layer sums `o`, as
/// `shadow_layer_opacity` in `glsl/include/shadow.glsl`.
pub fn layer_opacity(d: f32, o: [f32; 3], ends: [f32; 3]) -> f32 {
    if d <= 0.0 {
        0.0
    } else if d < ends[0] {
        o[0] * (d / ends[0])
    } else if d < ends[1] {
        o[0] + (o[1] - o[0]) * ((d - ends[0]) / (ends[1] - ends[0]))
    } else if d < ends[2] {
        o[1] + (o[2] - o[1]) * ((d - ends[1]) / (ends[2] - ends[1]))
    } else {
        o[2]
    }
}

/// Uniforms meaning "no light casts a shadow".
pub(crate) fn no_shadows() -> GpuShadowParams {
    GpuShadowParams { light_map: [[u32::MAX; 4]; 2], ..GpuShadowParams::default() }
}

/// The hairs a frame draws: how many, of how many vertices, and what each
/// stands for.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DrawnHairs {
    /// Hairs and vertices per hair.
    pub counts: (u32, u32),
    /// The real hairs each stands for and their spacing.
    pub footprint: ShadowFootprint,
}

/// The hair's bounding sphere in the world at the frame: what a map is fitted to.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bounds {
    pub centre: Vec3,
    pub radius: f32,
}

/// The shadow pass: the frame's uniform block, the opacity maps and the
/// density-volume shadows, for the casters of [`ShadowParams`].
pub(super) struct Shadows {
    device: Arc<Device>,
    params: ShadowParams,
    /// The frame's `ShadowParams` block (`glsl/include/shadow.glsl`; std140).
    uniforms: Buffer,
    maps: OpacityMaps,
    /// Placeholder buffers while no light uses the density volume.
    volume: VolumeShadows,
}

impl Shadows {
    /// No casters yet, reading hairs from `hair_positions`.
    pub(super) fn new(device: &Arc<Device>, hair_positions: &Buffer) -> Result<Self> {
        let params = ShadowParams::default();
        let uniforms = Buffer::uniform(device, "vkhair shadow params", std::mem::size_of::<GpuShadowParams>() as u64)?;
        device.upload_pod(&uniforms, &[no_shadows()])?;
        let maps = OpacityMaps::new(device, &params, &uniforms, hair_positions)?;
        let volume = VolumeShadows::new(device, &uniforms, 0, 0)?;
        Ok(Shadows { device: device.clone(), params, uniforms, maps, volume })
    }

    /// The parameters.
    pub(super) fn params(&self) -> &ShadowParams {
        &self.params
    }

    /// Sets the casters for the key hairs `sim` (validated first); returns whether
    /// GPU resources were replaced (descriptor sets reading them must be made
    /// again). A new atlas size or a larger density volume waits for the device
    /// to be idle first.
    pub(super) fn set(&mut self, sim: &KeyHairs<'_>, params: &ShadowParams, hair_positions: &Buffer) -> Result<bool> {
        params.validate()?;
        let volume_lights = params.volume_casters();
        let cells = if volume_lights > 0 {
            let grid = sim.volume_grid().ok_or_else(|| {
                Error::incompatible(
                    "shadow casters",
                    "density-volume shadows need the simulation's volume stage (SimParams::volume)",
                )
            })?;
            grid.dims.iter().product::<u32>()
        } else {
            0
        };
        let new_atlas = params.atlas_extent() != self.params.atlas_extent();
        let new_volume = self.volume.cells != cells
            || self.volume.transmittance.size() < u64::from(cells) * u64::from(volume_lights) * 4;
        if new_atlas || new_volume {
            self.device.wait_idle()?;
            if new_atlas {
                self.maps = OpacityMaps::new(&self.device, params, &self.uniforms, hair_positions)?;
            }
            if new_volume {
                self.volume = VolumeShadows::new(&self.device, &self.uniforms, cells, volume_lights)?;
            }
            // No map is drawn into the new resources yet.
            self.device.upload_pod(&self.uniforms, &[no_shadows()])?;
        }
        self.params = params.clone();
        Ok(new_atlas || new_volume)
    }

    /// Records the frame's shadows: the uniforms for `lights` and the casters,
    /// then the opacity maps of the `drawn` hairs fitted to `bounds`, then the
    /// density-volume transmittance from `sim`'s volume.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass,
    /// after the interpolation pass (and `sim`'s step) in submission order.
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        sim: &KeyHairs<'_>,
        lights: &[GpuLight],
        bounds: Bounds,
        drawn: DrawnHairs,
        (raster, hair_positions): (Raster, &Buffer),
        graph: &mut FrameGraph,
        timing: Timing<'_>,
    ) -> Result<()> {
        let DrawnHairs { counts: (hairs, per_hair), footprint } = drawn;
        let params = &self.params;
        let mut uniforms = no_shadows();
        let (mut tile, mut slot) = (0, 0);
        let mut volume_maps = Vec::new();
        let cells = self.volume.cells;
        for (k, caster) in params.casters.iter().enumerate() {
            let gpu = lights.get(caster.light).ok_or_else(|| {
                Error::incompatible(
                    "shadow casters",
                    format!("light {} does not exist ({} lights)", caster.light, lights.len()),
                )
            })?;
            uniforms.maps[k] = match caster.method {
                ShadowMethod::DeepOpacity => {
                    tile += 1;
                    light_map(gpu, caster.light, bounds, params, tile - 1, footprint)?
                }
                ShadowMethod::DensityVolume => {
                    slot += 1;
                    volume_maps.push(k as u32);
                    volume::volume_map(gpu, slot - 1, cells)
                }
            };
            uniforms.light_map[caster.light / 4][caster.light % 4] = k as u32;
        }
        uniforms.counts = [hairs, per_hair, params.casters.len() as u32, 0];
        let mut copy = None;
        if !volume_maps.is_empty() {
            let (grid, buffer) = sim.volume.map(|(g, b)| (g, b.raw())).ok_or_else(|| {
                Error::incompatible("shadow casters", "density-volume shadows need the simulation's volume stage")
            })?;
            if grid.dims.iter().product::<u32>() != cells {
                return Err(Error::incompatible(
                    "shadow casters",
                    "the simulation's volume grid changed; call set_shadows again",
                ));
            }
            let h = grid.cell_size;
            uniforms.grid_from_world = grid.world_from_grid.inverse().to_cols_array_2d();
            uniforms.grid_dims = [grid.dims[0], grid.dims[1], grid.dims[2], 1];
            uniforms.grid = [h, params.volume_cross_section / (h * h * h), params.volume_step, 0.0];
            copy = Some((buffer, u64::from(cells) * 16));
        }
        let d = &self.device;
        let any_map = uniforms.maps.iter().take(params.casters.len()).any(|m| !m.is_density_volume());
        // SAFETY: guaranteed by the caller.
        unsafe {
            // `vkCmdUpdateBuffer` runs in the clear stage: any transfer write.
            graph.record(d, cmd, &[Use::buffer(&self.uniforms, &[AccessKind::AnyTransferWrite])]);
            d.raw.cmd_update_buffer(cmd, self.uniforms.raw(), 0, bytemuck::bytes_of(&uniforms));
            if any_map {
                let vertices = hairs * (per_hair - 1) * 2;
                let inputs = (raster, (&self.uniforms, hair_positions));
                self.maps.record_with(cmd, graph, &uniforms, vertices, inputs, timing)?;
            }
            if let Some(source) = copy {
                self.volume.record(cmd, graph, source, (&self.uniforms, &volume_maps), timing);
            }
            // What the draw and a host read, as `Renderer::record_shadows` promises.
            let uniform_readers =
                [AccessKind::VertexUniformRead, AccessKind::FragmentUniformRead, AccessKind::ComputeUniformRead];
            let exports = [
                Use::buffer(&self.uniforms, &uniform_readers),
                self.maps.atlas.sampled_use(),
                Use::buffer(&self.volume.transmittance, &[AccessKind::FragmentRead, AccessKind::ComputeRead]),
            ];
            graph.record(d, cmd, &exports);
        }
        Ok(())
    }

    /// The opacity atlas's view and nearest sampler.
    pub(super) fn atlas(&self) -> (vk::ImageView, vk::Sampler) {
        self.maps.atlas.sampled()
    }

    /// The opacity atlas as the draw samples it.
    pub(super) fn atlas_use(&self) -> Use {
        self.maps.atlas.sampled_use()
    }

    /// Reads the opacity atlas back (submits and waits).
    pub(super) fn read_atlas(&self) -> Result<(vk::Extent2D, Vec<[f32; 4]>)> {
        self.maps.atlas.read()
    }

    /// The uniform buffer of the frame's shadow parameters.
    pub(super) fn uniforms(&self) -> &Buffer {
        &self.uniforms
    }

    /// Per light and cell, the transmittance of density-volume lights.
    pub(super) fn transmittance(&self) -> &Buffer {
        &self.volume.transmittance
    }
}
