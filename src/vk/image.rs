//! 2D images with one view, allocated through gpu-allocator and debug-named.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::device::Device;
use crate::error::{Error, Result};

/// What to create.
#[derive(Debug, Clone)]
pub(crate) struct ImageDesc<'a> {
    pub name: &'a str,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub usage: vk::ImageUsageFlags,
    pub samples: vk::SampleCountFlags,
    pub aspect: vk::ImageAspectFlags,
}

/// An image, its memory and a full view; freed on drop.
pub(crate) struct Image {
    device: Arc<Device>,
    raw: vk::Image,
    view: vk::ImageView,
    allocation: Option<Allocation>,
    pub extent: vk::Extent2D,
    pub aspect: vk::ImageAspectFlags,
}

impl Image {
    pub(crate) fn new(device: &Arc<Device>, desc: &ImageDesc<'_>) -> Result<Self> {
        if desc.extent.width == 0 || desc.extent.height == 0 {
            return Err(Error::param(
                "image extent",
                format!("{:?} for {:?}", desc.extent, desc.name),
                "non-zero width and height",
            ));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D { width: desc.extent.width, height: desc.extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(desc.samples)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info; destroyed in Drop or below on error.
        let raw = unsafe { device.raw.create_image(&info, None) }.map_err(Error::vk("vkCreateImage"))?;
        let mut image = Image {
            device: device.clone(),
            raw,
            view: vk::ImageView::null(),
            allocation: None,
            extent: desc.extent,
            aspect: desc.aspect,
        };
        // SAFETY: `raw` was just created from this device.
        let requirements = unsafe { device.raw.get_image_memory_requirements(raw) };
        let allocation = device
            .allocator()
            .allocate(&AllocationCreateDesc {
                name: desc.name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| Error::Allocation { name: desc.name.to_owned(), source })?;
        // SAFETY: the memory handle stays valid while the allocation lives (until Drop).
        let (memory, offset) = (unsafe { allocation.memory() }, allocation.offset());
        image.allocation = Some(allocation);
        // SAFETY: memory and offset come from an allocation made for these requirements.
        unsafe { device.raw.bind_image_memory(raw, memory, offset) }.map_err(Error::vk("vkBindImageMemory"))?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(image.full_range());
        // SAFETY: the image is bound to memory and the view matches its format.
        image.view =
            unsafe { device.raw.create_image_view(&view_info, None) }.map_err(Error::vk("vkCreateImageView"))?;
        device.set_name(raw, desc.name);
        device.set_name(image.view, &format!("{} view", desc.name));
        Ok(image)
    }

    pub(crate) fn raw(&self) -> vk::Image {
        self.raw
    }

    pub(crate) fn view(&self) -> vk::ImageView {
        self.view
    }

    /// The whole image (one mip, one layer).
    pub(crate) fn full_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        }
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: objects of this device; GPU work using them completed (callers'
        // contract, as for buffers). Null handles are ignored by Vulkan.
        unsafe {
            self.device.raw.destroy_image_view(self.view, None);
            self.device.raw.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            if let Err(e) = self.device.allocator().free(a) {
                log::error!("freeing image memory: {e}");
            }
        }
    }
}

/// A sampler; destroyed on drop.
pub(crate) struct Sampler {
    device: Arc<Device>,
    pub raw: vk::Sampler,
}

impl Sampler {
    /// A linear-filtering sampler that repeats (noise textures) or clamps.
    pub(crate) fn new(device: &Arc<Device>, name: &str, repeat: bool) -> Result<Self> {
        let mode = if repeat { vk::SamplerAddressMode::REPEAT } else { vk::SamplerAddressMode::CLAMP_TO_EDGE };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(mode)
            .address_mode_v(mode)
            .address_mode_w(mode)
            .max_lod(0.0);
        // SAFETY: valid create info; destroyed in Drop.
        let raw = unsafe { device.raw.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        device.set_name(raw, name);
        Ok(Sampler { device: device.clone(), raw })
    }
}

impl Sampler {
    /// A nearest-filtering, clamping sampler (depth images, exact texel reads).
    pub(crate) fn nearest(device: &Arc<Device>, name: &str) -> Result<Self> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        // SAFETY: valid create info; destroyed in Drop.
        let raw = unsafe { device.raw.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        device.set_name(raw, name);
        Ok(Sampler { device: device.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: sampler of this device, no longer used by pending work.
        unsafe { self.device.raw.destroy_sampler(self.raw, None) };
    }
}
