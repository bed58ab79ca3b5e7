//! The viewer's swapchain: its images and views, a depth image of the same size,
//! and one "rendering finished" semaphore per image. Recreated on resize and
//! when presentation says it is out of date.

use std::sync::Mutex;

use ash::vk;
use gpu_allocator::vulkan::Allocator;
use gpu_allocator::MemoryLocation;
use vkhair::{ash, gpu_allocator};

use crate::device::HostGpu;
use crate::host::{allocate, BoxError, Memory};

pub const DEPTH: vk::Format = vk::Format::D32_SFLOAT;

/// A full single-mip, single-layer range of `aspect`.
pub fn range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

pub struct Swapchain {
    pub loader: ash::khr::swapchain::Device,
    pub handle: vk::SwapchainKHR,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub images: Vec<vk::Image>,
    pub views: Vec<vk::ImageView>,
    /// Signalled by the frame's submission, waited on by its presentation.
    pub finished: Vec<vk::Semaphore>,
    pub depth: vk::Image,
    pub depth_view: vk::ImageView,
    depth_memory: Memory,
}

impl Swapchain {
    /// A swapchain for `gpu`'s surface at `size` (clamped to what the surface
    /// allows).
    pub fn new(gpu: &HostGpu, size: (u32, u32)) -> Result<Swapchain, BoxError> {
        let s = &gpu.surface_fn;
        // SAFETY: live physical device and surface.
        let caps = unsafe { s.get_physical_device_surface_capabilities(gpu.physical, gpu.surface) }?;
        // SAFETY: as above.
        let formats = unsafe { s.get_physical_device_surface_formats(gpu.physical, gpu.surface) }?;
        let srgb = [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB];
        let chosen = formats
            .iter()
            .find(|f| srgb.contains(&f.format) && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .or(formats.first())
            .ok_or("the surface offers no format")?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: size.0.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size.1.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut count = (caps.min_image_count + 1).max(3);
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let loader = ash::khr::swapchain::Device::new(&gpu.instance, &gpu.device);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(gpu.surface)
            .min_image_count(count)
            .image_format(chosen.format)
            .image_color_space(chosen.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            // Transfer source: `--screenshot` copies the last presented image out.
            .image_usage(vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true);
        // SAFETY: valid create info; destroyed in `destroy`.
        let handle = unsafe { loader.create_swapchain(&info, None) }?;
        // SAFETY: the swapchain is alive.
        let images = unsafe { loader.get_swapchain_images(handle) }?;
        let device = &gpu.device;
        let mut views = Vec::with_capacity(images.len());
        let mut finished = Vec::with_capacity(images.len());
        for &image in &images {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(chosen.format)
                .subresource_range(range(vk::ImageAspectFlags::COLOR));
            // SAFETY: valid create infos; destroyed in `destroy`.
            unsafe {
                views.push(device.create_image_view(&view_info, None)?);
                finished.push(device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None)?);
            }
        }
        let depth_info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(DEPTH)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            // Transfer source: vkhair's compute rasteriser copies the depth out;
            // sampled: the TAA resolve reprojects the host's pixels by it.
            .usage(
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::SAMPLED,
            );
        // SAFETY: valid create info; destroyed in `destroy`.
        let depth = unsafe { device.create_image(&depth_info, None) }?;
        // SAFETY: the image is alive.
        let requirements = unsafe { device.get_image_memory_requirements(depth) };
        let memory = allocate(gpu.allocator(), "viewer depth", requirements, MemoryLocation::GpuOnly, false)?;
        // SAFETY: memory allocated for this image.
        unsafe { device.bind_image_memory(depth, memory.memory(), memory.offset()) }?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(depth)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(DEPTH)
            .subresource_range(range(vk::ImageAspectFlags::DEPTH));
        // SAFETY: valid create info; destroyed in `destroy`.
        let depth_view = unsafe { device.create_image_view(&view_info, None) }?;
        Ok(Swapchain {
            loader,
            handle,
            format: chosen.format,
            extent,
            images,
            views,
            finished,
            depth,
            depth_view,
            depth_memory: Memory(Some(memory)),
        })
    }

    /// Destroys everything (the caller made sure no pending work uses it).
    pub fn destroy(&mut self, device: ash::Device, allocator: &Mutex<Allocator>) {
        // SAFETY: the caller waited for the work that used these objects.
        unsafe {
            for (&view, &semaphore) in self.views.iter().zip(&self.finished) {
                device.destroy_image_view(view, None);
                device.destroy_semaphore(semaphore, None);
            }
            device.destroy_image_view(self.depth_view, None);
            device.destroy_image(self.depth, None);
            self.loader.destroy_swapchain(self.handle, None);
        }
        self.depth_memory.free(allocator);
        self.views.clear();
        self.finished.clear();
    }
}
