//! One-shot submissions and staging upload/readback helpers.
//!
//! These SUBMIT to the graphics queue and wait on a fence: they are for setup
//! (uploading grooms, tables) and for tests/tools reading results back, never
//! for per-frame work, which is recorded into the host's command buffers.
//! Each one-shot command buffer starts with a barrier after any earlier write
//! and ends with one before any later access, so it can be used without
//! knowing what ran before or after it.

use std::sync::Arc;
use std::time::Duration;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::barrier::{self, AccessKind};
use super::buffer::{Buffer, BufferDesc};
use super::device::Device;
use super::image::Image;
use crate::error::{Error, Result};

/// How long a one-shot submission may take before it is reported as a timeout.
const ONE_SHOT_TIMEOUT: Duration = Duration::from_secs(120);

/// Destroys the pool and fence of a one-shot submission on every path.
struct OneShot<'a> {
    device: &'a Device,
    pool: vk::CommandPool,
    fence: vk::Fence,
}

impl Drop for OneShot<'_> {
    fn drop(&mut self) {
        // SAFETY: both belong to this device; the fence was waited on (or the
        // submission never happened) before this runs, except on timeout, where we
        // wait for idle first.
        unsafe {
            if self.fence != vk::Fence::null() && self.device.raw.get_fence_status(self.fence) != Ok(true) {
                let _ = self.device.raw.device_wait_idle();
            }
            self.device.raw.destroy_fence(self.fence, None);
            self.device.raw.destroy_command_pool(self.pool, None);
        }
    }
}

impl Device {
    /// Records `record` into a fresh command buffer, submits it to the graphics
    /// queue and waits for it.
    pub(crate) fn submit_once(&self, name: &str, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        self.submit_once_waiting(name, |cmd| {
            record(cmd);
            Vec::new()
        })
    }

    /// As [`Device::submit_once`], with the submission waiting on the semaphores
    /// `record` returns.
    pub(crate) fn submit_once_waiting(
        &self,
        name: &str,
        record: impl FnOnce(vk::CommandBuffer) -> Vec<vk::SemaphoreSubmitInfo<'static>>,
    ) -> Result<()> {
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.graphics.family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: valid create info for this device.
        let pool =
            unsafe { self.raw.create_command_pool(&pool_info, None) }.map_err(Error::vk("vkCreateCommandPool"))?;
        let mut guard = OneShot { device: self, pool, fence: vk::Fence::null() };
        self.set_name(pool, &format!("{name} pool"));
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device.
        let cmd =
            unsafe { self.raw.allocate_command_buffers(&alloc) }.map_err(Error::vk("vkAllocateCommandBuffers"))?[0];
        self.set_name(cmd, name);
        // SAFETY: valid create info.
        guard.fence = unsafe { self.raw.create_fence(&vk::FenceCreateInfo::default(), None) }
            .map_err(Error::vk("vkCreateFence"))?;
        self.set_name(guard.fence, &format!("{name} fence"));
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: freshly allocated command buffer; recorded and submitted once here.
        let waits = unsafe {
            self.raw.begin_command_buffer(cmd, &begin).map_err(Error::vk("vkBeginCommandBuffer"))?;
            self.cmd_barrier(cmd, &[barrier::memory(&[AccessKind::AnyWrite], barrier::ANY)], &[], &[]);
            let waits = record(cmd);
            self.cmd_barrier(cmd, &[barrier::memory(&[AccessKind::AnyWrite], barrier::ANY)], &[], &[]);
            self.raw.end_command_buffer(cmd).map_err(Error::vk("vkEndCommandBuffer"))?;
            waits
        };
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().wait_semaphore_infos(&waits).command_buffer_infos(&cmds);
        {
            let _lock = self.lock_submit();
            // SAFETY: queue access is serialised by the lock (and the host contract of
            // `from_host`); the command buffer is executable.
            unsafe { self.raw.queue_submit2(self.graphics.raw, &[submit], guard.fence) }
                .map_err(Error::vk("vkQueueSubmit2"))?;
        }
        // SAFETY: the fence belongs to this device.
        unsafe { self.raw.wait_for_fences(&[guard.fence], true, ONE_SHOT_TIMEOUT.as_nanos() as u64) }
            .map_err(Error::vk("vkWaitForFences"))?;
        Ok(())
    }

    fn staging(self: &Arc<Self>, name: &str, size: u64, location: MemoryLocation) -> Result<Buffer> {
        Buffer::new(
            self,
            &BufferDesc {
                name,
                size,
                usage: vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
                location,
            },
        )
    }

    /// Copies `bytes` into `dst` at `offset` through a staging buffer.
    pub(crate) fn upload(self: &Arc<Self>, dst: &Buffer, offset: u64, bytes: &[u8]) -> Result<()> {
        if bytes.is_empty() {
            return Ok(());
        }
        dst.check_range("upload", offset, bytes.len() as u64)?;
        let mut staging =
            self.staging(&format!("{} upload staging", dst.name()), bytes.len() as u64, MemoryLocation::CpuToGpu)?;
        let mapped = staging
            .mapped_mut()
            .ok_or_else(|| Error::device("staging memory", "host-visible memory could not be mapped"))?;
        mapped.copy_from_slice(bytes);
        let region = vk::BufferCopy { src_offset: 0, dst_offset: offset, size: bytes.len() as u64 };
        self.submit_once(&format!("upload {}", dst.name()), |cmd| {
            // SAFETY: both buffers belong to this device and the region is in range.
            unsafe { self.raw.cmd_copy_buffer(cmd, staging.raw(), dst.raw(), &[region]) };
        })
    }

    /// Reads `len` bytes of `src` at `offset` back through a staging buffer.
    pub(crate) fn readback(self: &Arc<Self>, src: &Buffer, offset: u64, len: u64) -> Result<Vec<u8>> {
        if len == 0 {
            return Ok(Vec::new());
        }
        src.check_range("readback", offset, len)?;
        let staging = self.staging(&format!("{} readback staging", src.name()), len, MemoryLocation::GpuToCpu)?;
        let region = vk::BufferCopy { src_offset: offset, dst_offset: 0, size: len };
        self.submit_once(&format!("readback {}", src.name()), |cmd| {
            // SAFETY: both buffers belong to this device and the region is in range;
            // the barrier makes the copy visible to the host read below.
            unsafe {
                self.raw.cmd_copy_buffer(cmd, src.raw(), staging.raw(), &[region]);
                self.cmd_barrier(
                    cmd,
                    &[],
                    &[barrier::buffer(&staging, &[AccessKind::TransferWrite], &[AccessKind::HostRead])],
                    &[],
                );
            }
        })?;
        staging
            .mapped()
            .map(<[u8]>::to_vec)
            .ok_or_else(|| Error::device("staging memory", "host-visible memory could not be mapped"))
    }

    /// Uploads a slice of plain-old-data values at element offset 0.
    pub(crate) fn upload_pod<T: bytemuck::Pod>(self: &Arc<Self>, dst: &Buffer, values: &[T]) -> Result<()> {
        self.upload(dst, 0, bytemuck::cast_slice(values))
    }

    /// Reads `count` plain-old-data values from the start of `src`.
    pub(crate) fn readback_pod<T: bytemuck::Pod>(self: &Arc<Self>, src: &Buffer, count: usize) -> Result<Vec<T>> {
        let bytes = self.readback(src, 0, (count * std::mem::size_of::<T>()) as u64)?;
        // The staging copy is not necessarily aligned for T: copy element-wise.
        Ok(bytes.chunks_exact(std::mem::size_of::<T>()).map(bytemuck::pod_read_unaligned).collect())
    }

    /// Uploads tightly packed texels into a whole single-sample color image and leaves
    /// it in SHADER_READ_ONLY_OPTIMAL (this submits and waits).
    pub(crate) fn upload_image(self: &Arc<Self>, image: &Image, texels: &[u8]) -> Result<()> {
        let mut staging = self.staging("image upload staging", texels.len() as u64, MemoryLocation::CpuToGpu)?;
        staging
            .mapped_mut()
            .ok_or_else(|| Error::device("staging memory", "host-visible memory could not be mapped"))?
            .copy_from_slice(texels);
        let region = whole_image_region(image);
        self.submit_once("upload image", |cmd| {
            // SAFETY: resources of this device; layouts are transitioned around the copy.
            unsafe {
                self.cmd_transition(
                    cmd,
                    image,
                    barrier::NOTHING,
                    &[AccessKind::TransferWrite],
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
                );
                self.raw.cmd_copy_buffer_to_image(
                    cmd,
                    staging.raw(),
                    image.raw(),
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[region],
                );
                self.cmd_transition(
                    cmd,
                    image,
                    &[AccessKind::TransferWrite],
                    barrier::ANY,
                    (vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
                );
            }
        })
    }

    /// Reads a whole single-sample color image in `layout` back as tightly packed texels
    /// (`texel_size` bytes each); the image is left in `layout`.
    pub(crate) fn readback_image(
        self: &Arc<Self>,
        image: &Image,
        layout: vk::ImageLayout,
        texel_size: u64,
    ) -> Result<Vec<u8>> {
        let len = image.extent.width as u64 * image.extent.height as u64 * texel_size;
        let staging = self.readback_staging("image readback staging", len)?;
        let mut out = Vec::new();
        self.readback_image_via(image, layout, &staging, &mut out)?;
        Ok(out)
    }

    /// A host-visible buffer of `size` bytes for [`Device::readback_image_via`].
    pub(crate) fn readback_staging(self: &Arc<Self>, name: &str, size: u64) -> Result<Buffer> {
        self.staging(name, size, MemoryLocation::GpuToCpu)
    }

    /// [`Device::readback_image`] through a staging buffer the caller keeps
    /// (exactly the image's size in bytes), into `out` (its memory reused).
    pub(crate) fn readback_image_via(
        self: &Arc<Self>,
        image: &Image,
        layout: vk::ImageLayout,
        staging: &Buffer,
        out: &mut Vec<u8>,
    ) -> Result<()> {
        let len = staging.size();
        let region = whole_image_region(image);
        self.submit_once("readback image", |cmd| {
            // SAFETY: resources of this device; layouts are transitioned around the copy.
            unsafe {
                self.cmd_transition(
                    cmd,
                    image,
                    &[AccessKind::AnyWrite],
                    &[AccessKind::TransferRead],
                    (layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
                );
                self.raw.cmd_copy_image_to_buffer(
                    cmd,
                    image.raw(),
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    staging.raw(),
                    &[region],
                );
                self.cmd_barrier(
                    cmd,
                    &[],
                    &[barrier::buffer(staging, &[AccessKind::TransferWrite], &[AccessKind::HostRead])],
                    &[barrier::image(
                        image,
                        &[AccessKind::TransferRead],
                        barrier::ANY,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        layout,
                    )],
                );
            }
        })?;
        let bytes = staging
            .mapped()
            .ok_or_else(|| Error::device("staging memory", "host-visible memory could not be mapped"))?;
        let bytes = bytes
            .get(..len as usize)
            .ok_or_else(|| Error::device("staging memory", "the mapped range is smaller than the buffer"))?;
        out.clear();
        out.extend_from_slice(bytes);
        Ok(())
    }
}

/// A buffer ↔ image copy of a whole single-layer, single-mip image, tightly packed.
pub(crate) fn whole_image_region(image: &Image) -> vk::BufferImageCopy {
    vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: image.aspect,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        })
        .image_extent(vk::Extent3D { width: image.extent.width, height: image.extent.height, depth: 1 })
}
