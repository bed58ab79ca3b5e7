//! What every mode of pass 4 shades with (`glsl/include/hair_shading.glsl`):
//! the frame's uniform block, the noise texture and the Marschner tables, and
//! their bindings beside the frame's inputs.

use std::sync::Arc;

use ash::vk;
use glam::Vec4;

use super::{DrawFrame, DrawInputs};
use crate::error::Result;
use crate::gpu_types::DrawParams;
use crate::render::graph::{FrameGraph, Use};
use crate::render::marschner::{MarschnerParams, MarschnerTables};
use crate::render::shading::{noise_texels, NOISE_SIZE};
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};

/// The shading stages' buffers and (view, sampler) images, by binding.
pub(super) type ShadingBindings<'a> = ([(u32, &'a Buffer); 6], [(u32, vk::ImageView, vk::Sampler); 4]);

/// The uniform block, the noise texture and the Marschner tables.
pub(super) struct ShadingResources {
    device: Arc<Device>,
    noise: Image,
    sampler: Sampler,
    /// The frame's [`DrawParams`], written by a transfer before the draw.
    params: Buffer,
    /// Marschner lookup tables, rebuilt when their parameters change.
    marschner: MarschnerTables,
}

impl ShadingResources {
    pub(super) fn new(device: &Arc<Device>) -> Result<Self> {
        let noise = Image::new(
            device,
            &ImageDesc {
                name: "vkhair hair noise",
                extent: vk::Extent2D { width: NOISE_SIZE, height: NOISE_SIZE },
                format: vk::Format::R8G8_UNORM,
                usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        device.upload_image(&noise, &noise_texels())?;
        let sampler = Sampler::new(device, "vkhair noise sampler", true)?;
        let params = Buffer::uniform(device, "vkhair draw params", std::mem::size_of::<DrawParams>() as u64)?;
        let marschner = MarschnerTables::new(device)?;
        Ok(ShadingResources { device: device.clone(), noise, sampler, params, marschner })
    }

    /// The shading stages' buffers and images by binding: the uniform block
    /// (binding 0, first), noise (binding 3, first image) and Marschner tables,
    /// and `inputs`. The ribbons' geometry reads the first three buffers only.
    pub(super) fn bindings<'a>(&'a self, inputs: &DrawInputs<'a>) -> ShadingBindings<'a> {
        let sampler = self.marschner.sampler.raw;
        (
            [
                (0, &self.params),
                (1, inputs.hairs.0),
                (2, inputs.hairs.1),
                (6, inputs.shadow_uniforms),
                (8, inputs.transmittance),
                (24, inputs.looks),
            ],
            [
                (3, self.noise.view(), self.sampler.raw),
                (4, self.marschner.m.view(), sampler),
                (5, self.marschner.n.view(), sampler),
                (7, inputs.atlas.0, inputs.atlas.1),
            ],
        )
    }

    /// Records the start of `frame`'s draw: the Marschner tables' rebuild if
    /// they changed and the update of the uniform block, then the barriers for
    /// what the draw reads ([`ShadingResources::uses`]) and for its target's
    /// attachments, each declared to `graph`.
    ///
    /// # Safety
    /// `frame.cmd` is a recording command buffer of this device outside a
    /// render pass; every earlier command on the resources since `graph` was
    /// made was declared to it.
    pub(super) unsafe fn record_updates(&mut self, graph: &mut FrameGraph, frame: &DrawFrame<'_>) {
        let (d, cmd) = (&self.device, frame.cmd);
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            // The draw pipeline may sample the Marschner tables: build them first.
            self.marschner.record_update(d, cmd, graph, &frame.marschner);
            graph.record(d, cmd, &[Use::buffer(&self.params, &[AccessKind::AnyTransferWrite])]);
            d.raw.cmd_update_buffer(cmd, self.params.raw(), 0, bytemuck::bytes_of(&frame.params));
            graph.record(d, cmd, &[self.uses(&frame.inputs), frame.target.uses.clone()].concat());
        }
    }

    /// What the draw's stages read of the shading's own resources (the uniform
    /// block, the Marschner tables) and of `inputs`, with every kind of
    /// access a mode may make of them (the ribbons' vertex stage, the fragment
    /// stages, the transparent modes' compute shading and rasterisers).
    fn uses(&self, inputs: &DrawInputs<'_>) -> Vec<Use> {
        use AccessKind::*;
        let uniform = &[VertexUniformRead, FragmentUniformRead, ComputeUniformRead];
        let storage = &[VertexRead, FragmentRead, ComputeRead];
        let mut uses = vec![
            Use::buffer(&self.params, uniform),
            Use::buffer(inputs.hairs.0, storage),
            Use::buffer(inputs.hairs.1, storage),
            Use::buffer(inputs.shadow_uniforms, uniform),
            Use::buffer(inputs.transmittance, storage),
            inputs.atlas_use,
        ];
        uses.extend(self.marschner.sampled_uses());
        uses
    }

    /// Builds the Marschner tables for `params` and reads them back (M, then N;
    /// submits and waits).
    pub(super) fn read_marschner_tables(&mut self, params: &MarschnerParams) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let device = self.device.clone();
        device.submit_once("vkhair marschner tables", |cmd| {
            // SAFETY: a recording command buffer of this device; earlier work completed.
            unsafe {
                let mut graph = FrameGraph::new();
                self.marschner.record_update(&device, cmd, &mut graph, params);
                graph.settle(&device, cmd);
            }
        })?;
        Ok((self.marschner.read(&device, false)?, self.marschner.read(&device, true)?))
    }
}
