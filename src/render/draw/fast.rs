//! Pass 4 with [`Transparency::Fast`](crate::render::Transparency::Fast):
//! weighted blended transparency (`glsl/render/oit_weighted*.frag`). Every
//! hair fragment adds its weighted, premultiplied colour and its absorbance
//! into two float images; the composite divides and blends them over the
//! target. The same two images take the exact mode's overflow (weight 1).

use std::sync::Arc;

use ash::vk;

use super::ModeShaders;
use crate::error::Result;
use crate::render::graph::Use;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc};
use crate::vk::rendering::{self, Load};
use crate::vk::shaders::{RENDER_OIT_WEIGHTED_FRAG, RENDER_OIT_WEIGHTED_RESOLVE_FRAG};

/// The build's and the composite's fragment stages.
pub(super) const SHADERS: ModeShaders =
    ModeShaders { build: &RENDER_OIT_WEIGHTED_FRAG, composite: &RENDER_OIT_WEIGHTED_RESOLVE_FRAG, resolve: None };

/// Format of the weighted colour and weight sums.
pub(super) const WEIGHTED_SUM: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Format of the absorbance sum.
pub(super) const ABSORBANCE: vk::Format = vk::Format::R32_SFLOAT;
/// Bytes per pixel of the two images.
pub(super) const BYTES_PER_PIXEL: u64 = 16 + 4;

/// The weighted sums and the absorbance, attachments of the build and
/// sampled by the composite.
pub(super) struct WeightedSums {
    pub sum: Image,
    pub absorbance: Image,
}

impl WeightedSums {
    pub(super) fn new(device: &Arc<Device>, extent: vk::Extent2D) -> Result<Self> {
        let image = |name, format| {
            Image::new(
                device,
                &ImageDesc {
                    name,
                    extent,
                    format,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
                    samples: vk::SampleCountFlags::TYPE_1,
                    aspect: vk::ImageAspectFlags::COLOR,
                },
            )
        };
        Ok(WeightedSums {
            sum: image("vkhair transparency weighted sums", WEIGHTED_SUM)?,
            absorbance: image("vkhair transparency absorbance", ABSORBANCE)?,
        })
    }

    /// The build's attachments: both cleared to zero.
    pub(super) fn attachments(&self) -> [vk::RenderingAttachmentInfo<'static>; 2] {
        [&self.sum, &self.absorbance].map(|i| rendering::color(i.view(), Load::color([0.0; 4])))
    }

    /// Both images as the build's attachments (their contents discarded: cleared).
    pub(super) fn attachment_uses(&self) -> [Use; 2] {
        let layout = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        [&self.sum, &self.absorbance].map(|i| Use::image(i, barrier::COLOR_ATTACHMENT, layout, SAMPLED).discarding())
    }

    /// Both images as the composite samples them (their layout at rest).
    pub(super) fn sampled_uses(&self) -> [Use; 2] {
        [&self.sum, &self.absorbance].map(|i| Use::image(i, &[AccessKind::FragmentSampledRead], SAMPLED, SAMPLED))
    }
}

/// The layout the sums rest in: sampled by the composite.
const SAMPLED: vk::ImageLayout = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
