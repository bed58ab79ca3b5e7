//! A small synchronization2 barrier helper.

use ash::vk;

use super::buffer::Buffer;
use super::device::Device;
use super::image::Image;

/// A pipeline stage together with the accesses made there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Access {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
}

impl Access {
    pub const NONE: Access = Access { stage: vk::PipelineStageFlags2::NONE, access: vk::AccessFlags2::NONE };
    pub const COMPUTE_WRITE: Access =
        Access { stage: vk::PipelineStageFlags2::COMPUTE_SHADER, access: vk::AccessFlags2::SHADER_STORAGE_WRITE };
    pub const COMPUTE_READ_WRITE: Access = Access {
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw() | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
    };
    pub const TRANSFER_READ: Access =
        Access { stage: vk::PipelineStageFlags2::COPY, access: vk::AccessFlags2::TRANSFER_READ };
    pub const TRANSFER_WRITE: Access =
        Access { stage: vk::PipelineStageFlags2::COPY, access: vk::AccessFlags2::TRANSFER_WRITE };
    pub const HOST_READ: Access = Access { stage: vk::PipelineStageFlags2::HOST, access: vk::AccessFlags2::HOST_READ };
    pub const COLOR_ATTACHMENT_WRITE: Access = Access {
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw() | vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw(),
        ),
    };
    pub const DEPTH_ATTACHMENT: Access = Access {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
        ),
    };
    /// Every earlier write, for one-shot submissions that know nothing about prior use.
    pub const ANY_WRITE: Access =
        Access { stage: vk::PipelineStageFlags2::ALL_COMMANDS, access: vk::AccessFlags2::MEMORY_WRITE };
    /// Any later access, for one-shot submissions that know nothing about later use.
    pub const ANY: Access = Access {
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::MEMORY_READ.as_raw() | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
        ),
    };
}

/// A barrier on a whole buffer.
pub(crate) fn buffer(buffer: &Buffer, src: Access, dst: Access) -> vk::BufferMemoryBarrier2<'static> {
    ownership(buffer.raw(), src, dst, vk::QUEUE_FAMILY_IGNORED, vk::QUEUE_FAMILY_IGNORED)
}

/// A barrier on a whole buffer that also moves it from queue family `from` to `to`
/// (a release on the `from` side, an acquire on the `to` side; `VK_QUEUE_FAMILY_EXTERNAL`
/// for memory shared with another device).
pub(crate) fn ownership(
    buffer: vk::Buffer,
    src: Access,
    dst: Access,
    from: u32,
    to: u32,
) -> vk::BufferMemoryBarrier2<'static> {
    vk::BufferMemoryBarrier2::default()
        .src_stage_mask(src.stage)
        .src_access_mask(src.access)
        .dst_stage_mask(dst.stage)
        .dst_access_mask(dst.access)
        .src_queue_family_index(from)
        .dst_queue_family_index(to)
        .buffer(buffer)
        .offset(0)
        .size(vk::WHOLE_SIZE)
}

/// A barrier and layout transition on a whole image.
pub(crate) fn image(
    image: &Image,
    src: Access,
    dst: Access,
    old: vk::ImageLayout,
    new: vk::ImageLayout,
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.stage)
        .src_access_mask(src.access)
        .dst_stage_mask(dst.stage)
        .dst_access_mask(dst.access)
        .old_layout(old)
        .new_layout(new)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.raw())
        .subresource_range(image.full_range())
}

/// A global memory barrier.
pub(crate) fn memory(src: Access, dst: Access) -> vk::MemoryBarrier2<'static> {
    vk::MemoryBarrier2::default()
        .src_stage_mask(src.stage)
        .src_access_mask(src.access)
        .dst_stage_mask(dst.stage)
        .dst_access_mask(dst.access)
}

impl Device {
    /// Records one `vkCmdPipelineBarrier2` with the given barriers.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device; the resources belong to it.
    pub(crate) unsafe fn cmd_barrier(
        &self,
        cmd: vk::CommandBuffer,
        memory: &[vk::MemoryBarrier2<'_>],
        buffers: &[vk::BufferMemoryBarrier2<'_>],
        images: &[vk::ImageMemoryBarrier2<'_>],
    ) {
        let info = vk::DependencyInfo::default()
            .memory_barriers(memory)
            .buffer_memory_barriers(buffers)
            .image_memory_barriers(images);
        // SAFETY: guaranteed by the caller.
        unsafe { self.raw.cmd_pipeline_barrier2(cmd, &info) };
    }
}
