//! Deep opacity maps by the compute rasteriser ([`Raster::Compute`](crate::render::Raster::Compute);
//! `glsl/render/shadow_raster.comp`, `shadow_resolve.comp`): the same two
//! passes as `opacity_maps.rs`, the hairs walked as one-texel lines by one
//! invocation a segment, into sums the last dispatch turns into the same atlas.
//!
//! 1. **Shadow depth** ([`RenderPass::ShadowDepth`]): per map, each segment's
//!    texels keep the nearest light-space depth z0 (an atomic minimum of its
//!    bits: depths in the map's range are positive);
//! 2. **Shadow opacity** ([`RenderPass::ShadowOpacity`]): per map, each
//!    segment's texels add its opacity to the layer its depth behind z0 falls in
//!    and to every layer behind it, in fixed point (integer atomics: the sums do
//!    not depend on the order the segments arrive in); then one dispatch writes
//!    every atlas texel from its sums, layers in RGB and z0 in A (zero where no
//!    strand reaches it), as the hardware passes leave it.

use std::sync::Arc;

use ash::vk;

use super::atlas::ShadowAtlas;
use crate::error::{Error, Result};
use crate::gpu_types::GpuShadowParams;
use crate::profiler::{PassScope, Timing};
use crate::render::graph::{FrameGraph, Use};
use crate::render::pass::RenderPass;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::{RENDER_SHADOW_RASTER_COMP, RENDER_SHADOW_RASTER_COMP_SHADOW_Z0, RENDER_SHADOW_RESOLVE_COMP};

/// `SHADOW_NO_HAIR` of `glsl/include/shadow_sums.glsl`: z0's key where no strand is.
const NO_HAIR: u32 = u32::MAX;

/// The passes' push constants (`Push` in `shadow_raster.comp`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct RasterPush {
    map: u32,
    atlas_width: u32,
}

/// The compute passes over one atlas: its sums and pipelines.
pub(super) struct ComputeMaps {
    device: Arc<Device>,
    /// Per atlas texel: z0's key.
    z0: Buffer,
    /// Per atlas texel: three layer sums.
    layers: Buffer,
    depth_pass: (ComputePipeline, vk::DescriptorSet),
    opacity_pass: (ComputePipeline, vk::DescriptorSet),
    resolve: (ComputePipeline, [vk::DescriptorSet; 2]),
}

impl ComputeMaps {
    /// The passes into `atlas`, reading the frame's `uniforms` and hairs from `hair_positions`.
    pub(super) fn new(
        device: &Arc<Device>,
        atlas: &ShadowAtlas,
        uniforms: &Buffer,
        hair_positions: &Buffer,
    ) -> Result<Self> {
        let extent = atlas.extent();
        let texels = u64::from(extent.width) * u64::from(extent.height);
        if 12 * texels > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::incompatible(
                "shadow resolution",
                format!(
                    "the compute rasteriser's layer sums of a {}×{} atlas take {} bytes in one buffer, more than \
                     this device's storage buffer range ({} bytes): lower ShadowParams::resolution, or draw the \
                     maps with Raster::Hardware",
                    extent.width,
                    extent.height,
                    12 * texels,
                    device.info.max_storage_buffer_range
                ),
            ));
        }
        let z0 = Buffer::storage(device, "vkhair shadow z0 keys", 4 * texels)?;
        let layers = Buffer::storage(device, "vkhair shadow layer sums", 12 * texels)?;
        let buffers = [(0, uniforms), (1, hair_positions), (3, &z0), (4, &layers)];
        let pass = |shader| -> Result<(ComputePipeline, vk::DescriptorSet)> {
            let pipeline = ComputePipeline::new(device, shader, 1)?;
            let set = pipeline.declared_buffer_set(0, &buffers)?;
            Ok((pipeline, set))
        };
        let depth_pass = pass(&RENDER_SHADOW_RASTER_COMP_SHADOW_Z0)?;
        let opacity_pass = pass(&RENDER_SHADOW_RASTER_COMP)?;
        let resolve = ComputePipeline::new(device, &RENDER_SHADOW_RESOLVE_COMP, 1)?;
        let sums = resolve.declared_buffer_set(0, &buffers)?;
        let image = resolve.storage_image_set(1, &[(0, atlas.storage_view())])?;
        Ok(ComputeMaps {
            device: device.clone(),
            z0,
            layers,
            depth_pass,
            opacity_pass,
            resolve: (resolve, [sums, image]),
        })
    }

    /// Records both passes for the maps of `uniforms` into `atlas`, each in its
    /// scope, declaring to `graph` what each dispatch reads and writes
    /// (`inputs`: the uniform buffer and the hair positions the passes were made with).
    ///
    /// # Safety
    /// As `OpacityMaps::record`; `atlas` is the one the passes were made for.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        uniforms: &GpuShadowParams,
        atlas: &ShadowAtlas,
        (uniform_buffer, hairs): (&Buffer, &Buffer),
        timing: Timing<'_>,
    ) {
        use AccessKind::{AnyTransferWrite, ComputeRead, ComputeUniformRead, ComputeWrite};
        let d = &self.device;
        let extent = atlas.extent();
        let inputs = [Use::buffer(hairs, &[ComputeRead]), Use::buffer(uniform_buffer, &[ComputeUniformRead])];
        let (z0, layers) = (&self.z0, &self.layers);
        let cleared = [Use::buffer(z0, &[AnyTransferWrite]), Use::buffer(layers, &[AnyTransferWrite])];
        let depth = [Use::buffer(z0, &[ComputeRead, ComputeWrite])];
        let opacity = [Use::buffer(z0, &[ComputeRead]), Use::buffer(layers, &[ComputeRead, ComputeWrite])];
        let resolve = [Use::buffer(z0, &[ComputeRead]), Use::buffer(layers, &[ComputeRead]), atlas.storage_write()];
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            graph.record(d, cmd, &cleared);
            d.raw.cmd_fill_buffer(cmd, self.z0.raw(), 0, vk::WHOLE_SIZE, NO_HAIR);
            d.raw.cmd_fill_buffer(cmd, self.layers.raw(), 0, vk::WHOLE_SIZE, 0);
            let scope = RenderPass::ShadowDepth.open(d, cmd, timing);
            graph.record(d, cmd, &[&inputs[..], &depth].concat());
            self.run(cmd, &self.depth_pass, RenderPass::ShadowDepth, uniforms, extent.width, timing);
            scope.close(d, cmd, timing);
            let scope = RenderPass::ShadowOpacity.open(d, cmd, timing);
            graph.record(d, cmd, &[&inputs[..], &opacity].concat());
            self.run(cmd, &self.opacity_pass, RenderPass::ShadowOpacity, uniforms, extent.width, timing);
            graph.record(d, cmd, &[&inputs[..], &resolve].concat());
            let (resolve, sets) = &self.resolve;
            resolve.bind(cmd, sets);
            resolve.dispatch_threads(cmd, [extent.width, extent.height, 1]);
            scope.close(d, cmd, timing);
        }
    }

    /// Records `pass` over every opacity map of `uniforms` (an atlas
    /// `atlas_width` texels wide), each map in a nested scope named by `stage`
    /// and the map's light.
    ///
    /// # Safety
    /// As [`ComputeMaps::record`], within it: the pass's inputs were made
    /// visible to compute shaders before.
    unsafe fn run(
        &self,
        cmd: vk::CommandBuffer,
        pass: &(ComputePipeline, vk::DescriptorSet),
        stage: RenderPass,
        uniforms: &GpuShadowParams,
        atlas_width: u32,
        timing: Timing<'_>,
    ) {
        let d = &self.device;
        let segments = uniforms.counts[0].saturating_mul(uniforms.counts[1].saturating_sub(1));
        let light_of = |map: usize| (0..8).find(|&i| uniforms.light_map[i / 4][i % 4] == map as u32).unwrap_or(map);
        let threads = pass.0.grid_stride_threads(segments);
        // SAFETY: guaranteed by the caller.
        unsafe {
            pass.0.bind(cmd, &[pass.1]);
            for (k, map) in uniforms.maps.iter().enumerate().take(uniforms.map_count()) {
                if map.is_density_volume() {
                    continue; // density volume: no map
                }
                let label = format!("{}, light {}", stage.label(), light_of(k));
                let scope = PassScope::open(d, cmd, timing, &label, LabelColor::Compute);
                pass.0.push(cmd, &RasterPush { map: k as u32, atlas_width });
                pass.0.dispatch_threads(cmd, [threads, 1, 1]);
                scope.close(d, cmd, timing);
            }
        }
    }
}
