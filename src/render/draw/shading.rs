//! What every mode of pass 4 shades with (`glsl/include/hair_shading.glsl`):
//! the frame's uniform block, the noise texture and the Marschner tables, and
//! their bindings beside the frame's inputs.

use std::sync::Arc;

use ash::vk;
use glam::Vec4;

use super::DrawInputs;
use crate::error::Result;
use crate::gpu_types::DrawParams;
use crate::render::marschner::{MarschnerParams, MarschnerTables};
use crate::render::shading::{noise_texels, NOISE_SIZE};
use crate::vk::barrier::{self, AccessKind, Barriers};
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

    /// Records `before` (the barriers that make the target ready), the Marschner
    /// tables' rebuild if `marschner` changed and the update of the uniform block
    /// to `params`, with the barriers that make both visible to the draw's stages.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass;
    /// draws recorded earlier that read the uniform block are ordered before by the
    /// recorded barrier.
    pub(super) unsafe fn record_updates(
        &mut self,
        cmd: vk::CommandBuffer,
        before: &Barriers,
        params: &DrawParams,
        marschner: &MarschnerParams,
    ) {
        let d = &self.device;
        let before_update = barrier::memory(&[AccessKind::AnyWrite], &[AccessKind::TransferWrite]);
        let updated = barrier::memory(&[AccessKind::TransferWrite], UNIFORM_READERS);
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            d.cmd_barriers(cmd, before);
            // The draw pipeline may sample the Marschner tables: build them first.
            self.marschner.record_update(d, cmd, marschner);
            d.cmd_barrier(cmd, &[before_update], &[], &[]);
            d.raw.cmd_update_buffer(cmd, self.params.raw(), 0, bytemuck::bytes_of(params));
            d.cmd_barrier(cmd, &[updated], &[], &[]);
        }
    }

    /// Builds the Marschner tables for `params` and reads them back (M, then N;
    /// submits and waits).
    pub(super) fn read_marschner_tables(&mut self, params: &MarschnerParams) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let device = self.device.clone();
        device.submit_once("vkhair marschner tables", |cmd| {
            // SAFETY: a recording command buffer of this device; earlier work completed.
            unsafe { self.marschner.record_update(&device, cmd, params) };
        })?;
        Ok((self.marschner.read(&device, false)?, self.marschner.read(&device, true)?))
    }
}

/// Stages that read the draw's uniform block (the transparent modes' vertex
/// shading is a compute dispatch).
const UNIFORM_READERS: &[AccessKind] =
    &[AccessKind::VertexUniformRead, AccessKind::FragmentUniformRead, AccessKind::ComputeUniformRead];
