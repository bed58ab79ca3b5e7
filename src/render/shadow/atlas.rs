//! The opacity atlas: one tile per deep-opacity-map caster, two tiles per row,
//! with the light-space depth (z0) image and the depth buffer its first pass
//! draws into.

use std::sync::Arc;

use ash::vk;

use super::{ShadowParams, SHADOW_ATLAS_FORMAT};
use crate::error::{Error, Result};
use crate::render::graph::{FrameGraph, Use};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::rendering::{self, Load};

/// Format of the z0 atlas the depth pass writes.
pub(super) const Z0_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
/// Format of the depth pass's depth buffer.
pub(super) const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

impl ShadowParams {
    /// Atlas size in texels: two tiles per row (1 × 1 without map casters).
    pub(crate) fn atlas_extent(&self) -> vk::Extent2D {
        let maps = self.map_casters().count() as u32;
        let res = if maps == 0 { 1 } else { self.resolution };
        let n = maps.max(1);
        vk::Extent2D { width: n.min(2) * res, height: n.div_ceil(2) * res }
    }

    /// Tile `index` of the atlas: x, y, width, height in texels.
    pub(crate) fn tile(&self, index: usize) -> [f32; 4] {
        let res = self.resolution as f32;
        [(index % 2) as f32 * res, (index / 2) as f32 * res, res, res]
    }
}

/// The atlas images and the sampler the draw reads the atlas with.
pub(super) struct ShadowAtlas {
    device: Arc<Device>,
    z0: Image,
    depth: Image,
    atlas: Image,
    sampler: Sampler,
}

impl ShadowAtlas {
    /// The images for `params`' atlas size; the opacity atlas starts cleared and
    /// ready for sampling (this submits and waits).
    pub(super) fn new(device: &Arc<Device>, params: &ShadowParams) -> Result<Self> {
        let extent = params.atlas_extent();
        let limit = device.info.max_image_dimension_2d;
        if extent.width > limit || extent.height > limit {
            return Err(Error::device(
                "the shadow atlas",
                format!("{extent:?} exceeds the device's image limit {limit}"),
            ));
        }
        let image = |name: &str, format, usage, aspect| {
            Image::new(
                device,
                &ImageDesc { name, extent, format, usage, samples: vk::SampleCountFlags::TYPE_1, aspect },
            )
        };
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let z0 = image("vkhair shadow z0 atlas", Z0_FORMAT, color, vk::ImageAspectFlags::COLOR)?;
        let depth = image(
            "vkhair shadow depth atlas",
            DEPTH_FORMAT,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            vk::ImageAspectFlags::DEPTH,
        )?;
        let atlas = image(
            "vkhair shadow opacity atlas",
            SHADOW_ATLAS_FORMAT,
            // Storage: the compute rasteriser's last dispatch writes it.
            color
                | vk::ImageUsageFlags::TRANSFER_DST
                | vk::ImageUsageFlags::TRANSFER_SRC
                | vk::ImageUsageFlags::STORAGE,
            vk::ImageAspectFlags::COLOR,
        )?;
        let sampler = Sampler::nearest(device, "vkhair shadow atlas sampler")?;
        let atlas = ShadowAtlas { device: device.clone(), z0, depth, atlas, sampler };
        atlas.clear()?;
        Ok(atlas)
    }

    /// The opacity atlas's view and the nearest sampler.
    pub(super) fn sampled(&self) -> (vk::ImageView, vk::Sampler) {
        (self.atlas.view(), self.sampler.raw)
    }

    /// The opacity atlas's view, for the compute rasteriser's storage writes (in GENERAL).
    pub(super) fn storage_view(&self) -> vk::ImageView {
        self.atlas.view()
    }

    /// The opacity atlas as the compute rasteriser's resolve writes it
    /// (storage, GENERAL; its earlier contents discarded).
    pub(super) fn storage_write(&self) -> Use {
        Use::image(&self.atlas, &[AccessKind::ComputeWrite], vk::ImageLayout::GENERAL, SAMPLED).discarding()
    }

    /// The opacity atlas as the draw, the compute rasterisers and a host's
    /// shading sample it: its layout between entry points.
    pub(super) fn sampled_use(&self) -> Use {
        Use::image(&self.atlas, FRAGMENT_SAMPLED, SAMPLED, SAMPLED)
    }

    /// The z0 atlas's view and the nearest sampler (what the opacity pass reads).
    pub(super) fn z0_sampled(&self) -> (vk::ImageView, vk::Sampler) {
        (self.z0.view(), self.sampler.raw)
    }

    /// Size in texels.
    pub(super) fn extent(&self) -> vk::Extent2D {
        self.atlas.extent
    }

    /// Clears the opacity atlas (no hair anywhere) and leaves it ready for sampling.
    fn clear(&self) -> Result<()> {
        let d = &self.device;
        let dst = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
        let clear = Use::image(&self.atlas, &[AccessKind::ClearWrite], dst, SAMPLED).discarding();
        d.submit_once("vkhair shadow atlas clear", |cmd| {
            let mut graph = FrameGraph::new();
            // SAFETY: a recording command buffer of this device; the atlas is new.
            unsafe {
                graph.record(d, cmd, &[clear]);
                d.raw.cmd_clear_color_image(
                    cmd,
                    self.atlas.raw(),
                    dst,
                    &vk::ClearColorValue { float32: [0.0; 4] },
                    &[self.atlas.full_range()],
                );
                graph.settle(d, cmd);
            }
        })
    }

    /// Reads the opacity atlas back, row after row (submits and waits): per texel
    /// the opacity summed to the end of each layer and z0 (0 where no hair is).
    pub(super) fn read(&self) -> Result<(vk::Extent2D, Vec<[f32; 4]>)> {
        let bytes = self.device.readback_image(&self.atlas, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, 16)?;
        let texels = bytes
            .chunks_exact(16)
            .map(|t| std::array::from_fn(|k| f32::from_le_bytes([t[4 * k], t[4 * k + 1], t[4 * k + 2], t[4 * k + 3]])))
            .collect();
        Ok((self.atlas.extent, texels))
    }

    /// The depth pass's attachments as it uses them (earlier contents discarded).
    pub(super) fn depth_pass_uses(&self) -> [Use; 2] {
        let z0 = Use::image(&self.z0, barrier::COLOR_ATTACHMENT, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, SAMPLED);
        let depth_layout = vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL;
        let depth = Use::image(&self.depth, barrier::DEPTH_ATTACHMENT, depth_layout, depth_layout);
        [z0.discarding(), depth.discarding()]
    }

    /// The opacity pass's images as it uses them: z0 sampled, the atlas an
    /// attachment (its earlier contents discarded).
    pub(super) fn opacity_pass_uses(&self) -> [Use; 2] {
        let atlas_layout = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        [
            Use::image(&self.z0, &[AccessKind::FragmentSampledRead], SAMPLED, SAMPLED),
            Use::image(&self.atlas, barrier::COLOR_ATTACHMENT, atlas_layout, SAMPLED).discarding(),
        ]
    }

    /// The depth pass's attachments: z0 cleared to 0, depth to 1 (not stored).
    pub(super) fn depth_pass_attachments(
        &self,
    ) -> ([vk::RenderingAttachmentInfo<'static>; 1], vk::RenderingAttachmentInfo<'static>) {
        (
            [rendering::color(self.z0.view(), Load::color([0.0; 4]))],
            rendering::depth(self.depth.view(), Load::depth(1.0)).store_op(vk::AttachmentStoreOp::DONT_CARE),
        )
    }

    /// The opacity pass's attachment: the atlas cleared to 0.
    pub(super) fn opacity_pass_attachment(&self) -> [vk::RenderingAttachmentInfo<'static>; 1] {
        [rendering::color(self.atlas.view(), Load::color([0.0; 4]))]
    }
}

/// The layout the sampled images (the opacity atlas, z0) rest in.
const SAMPLED: vk::ImageLayout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;

/// How the draw (fragment stages; the transparent modes' vertex shading, a
/// compute dispatch) and the opacity pass read the images.
const FRAGMENT_SAMPLED: &[AccessKind] = &[AccessKind::FragmentSampledRead, AccessKind::ComputeSampledRead];
