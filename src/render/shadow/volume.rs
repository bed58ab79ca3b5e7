//! Density-volume shadows (seed 003): the simulation's density volume copied
//! each frame, and the transmittance toward every density-volume light computed
//! at each cell centre ([`RenderPass::ShadowVolume`]); the draw pass looks it up
//! per fragment. No extra passes over the hair; the resolution is the volume
//! grid's.

use std::sync::Arc;

use ash::vk;

use crate::codes::shadow_kind;
use crate::error::Result;
use crate::gpu_types::{GpuLight, GpuShadowMap};
use crate::profiler::Timing;
use crate::render::graph::{FrameGraph, Use};
use crate::render::pass::RenderPass;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::RENDER_SHADOW_VOLUME_COMP;

/// A density-volume caster's entry: the light's direction (directional) or
/// position, and where its transmittance starts in the per-cell array (`slot` ·
/// `cells`).
pub(super) fn volume_map(light: &GpuLight, slot: usize, cells: u32) -> GpuShadowMap {
    let view_z = match light.kind() {
        0 => light.direction().extend(0.0).to_array(),
        _ => light.position().extend(1.0).to_array(),
    };
    GpuShadowMap {
        view_z,
        tile: [(slot as u32 * cells) as f32, 0.0, 0.0, 0.0],
        params: [0.0, 0.0, shadow_kind::DENSITY_VOLUME as f32, 0.0],
        ..GpuShadowMap::default()
    }
}

/// Density-volume shadows: a copy of the simulation's density volume and the
/// transmittance toward every volume light at each of its cell centres.
pub(super) struct VolumeShadows {
    device: Arc<Device>,
    /// Cells the buffers hold per light.
    pub(super) cells: u32,
    /// The copy of the simulation's density.
    pub(super) density: Buffer,
    /// Per light and cell, the transmittance toward the light.
    pub(super) transmittance: Buffer,
    pipeline: ComputePipeline,
    set: vk::DescriptorSet,
}

impl VolumeShadows {
    /// Buffers for `lights` volume lights over `cells` cells (16-byte placeholders for
    /// none) reading the frame's shadow uniforms from `uniforms`.
    pub(super) fn new(device: &Arc<Device>, uniforms: &Buffer, cells: u32, lights: u32) -> Result<Self> {
        let density = Buffer::storage(device, "vkhair shadow density volume", (u64::from(cells) * 16).max(16))?;
        let transmittance = Buffer::storage(
            device,
            "vkhair shadow volume transmittance",
            (u64::from(cells) * u64::from(lights) * 4).max(16),
        )?;
        let pipeline = ComputePipeline::new(device, &RENDER_SHADOW_VOLUME_COMP, 1)?;
        let set = pipeline.buffer_set(0, &[(0, uniforms), (1, &density), (2, &transmittance)])?;
        Ok(VolumeShadows { device: device.clone(), cells, density, transmittance, pipeline, set })
    }

    /// Copies `bytes` of the simulation's density from `source`, then computes the
    /// transmittance of volume maps `maps` (indices into `uniforms`), declaring
    /// to `graph` what the copy and the dispatches read and write.
    ///
    /// # Safety
    /// `cmd` is recording outside a render pass; `source` is the simulation's cell
    /// buffer of this device holding at least `bytes`; `uniforms` is the buffer
    /// the pass was made with.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        (source, bytes): (vk::Buffer, u64),
        (uniforms, maps): (&Buffer, &[u32]),
        timing: Timing<'_>,
    ) {
        use AccessKind::{ComputeRead, ComputeUniformRead, ComputeWrite, TransferRead, TransferWrite};
        let d = &self.device;
        let copy = [Use::raw_buffer(source, &[TransferRead]), Use::buffer(&self.density, &[TransferWrite])];
        let compute = [
            Use::buffer(uniforms, &[ComputeUniformRead]),
            Use::buffer(&self.density, &[ComputeRead]),
            Use::buffer(&self.transmittance, &[ComputeWrite]),
        ];
        // SAFETY: guaranteed by the caller; the buffers belong to this device.
        unsafe {
            let scope = RenderPass::ShadowVolume.open(d, cmd, timing);
            graph.record(d, cmd, &copy);
            let region = vk::BufferCopy { src_offset: 0, dst_offset: 0, size: bytes };
            d.raw.cmd_copy_buffer(cmd, source, self.density.raw(), &[region]);
            graph.record(d, cmd, &compute);
            self.pipeline.bind(cmd, &[self.set]);
            for &map in maps {
                self.pipeline.push(cmd, &map);
                self.pipeline.dispatch_threads(cmd, [self.cells, 1, 1]);
            }
            scope.close(d, cmd, timing);
        }
    }
}
