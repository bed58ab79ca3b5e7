//! Buffers allocated through gpu-allocator, each debug-named.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::device::Device;
use crate::error::{Error, Result};

/// What to create.
#[derive(Debug, Clone)]
pub(crate) struct BufferDesc<'a> {
    pub name: &'a str,
    pub size: u64,
    pub usage: vk::BufferUsageFlags,
    pub location: MemoryLocation,
}

/// A buffer and its memory; freed on drop.
pub(crate) struct Buffer {
    device: Arc<Device>,
    raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
    name: String,
}

impl Buffer {
    pub(crate) fn new(device: &Arc<Device>, desc: &BufferDesc<'_>) -> Result<Self> {
        if desc.size == 0 {
            return Err(Error::param("buffer size", format!("0 for {:?}", desc.name), "at least 1 byte"));
        }
        // With an async compute queue of another family every buffer may be used on
        // both queues: CONCURRENT sharing saves ownership transfers (see the schedule
        // module for the choice).
        let families = device.concurrent_families();
        let info = match &families {
            Some(f) => {
                vk::BufferCreateInfo::default().sharing_mode(vk::SharingMode::CONCURRENT).queue_family_indices(f)
            }
            None => vk::BufferCreateInfo::default().sharing_mode(vk::SharingMode::EXCLUSIVE),
        }
        .size(desc.size)
        .usage(desc.usage);
        // SAFETY: valid create info; the buffer is destroyed in Drop or below on error.
        let raw = unsafe { device.raw.create_buffer(&info, None) }.map_err(Error::vk("vkCreateBuffer"))?;
        // SAFETY: `raw` was just created from this device.
        let requirements = unsafe { device.raw.get_buffer_memory_requirements(raw) };
        let allocation = device.allocator().allocate(&AllocationCreateDesc {
            name: desc.name,
            requirements,
            location: desc.location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(source) => {
                // SAFETY: unused buffer of this device.
                unsafe { device.raw.destroy_buffer(raw, None) };
                return Err(Error::Allocation { name: desc.name.to_owned(), source });
            }
        };
        // SAFETY: memory and offset come from an allocation made for these requirements.
        if let Err(result) = unsafe { device.raw.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            let _ = device.allocator().free(allocation);
            // SAFETY: unused buffer of this device.
            unsafe { device.raw.destroy_buffer(raw, None) };
            return Err(Error::Vulkan { call: "vkBindBufferMemory", result });
        }
        device.set_name(raw, desc.name);
        Ok(Buffer {
            device: device.clone(),
            raw,
            allocation: Some(allocation),
            size: desc.size,
            name: desc.name.to_owned(),
        })
    }

    /// A GPU-only uniform buffer of `size` bytes, written by transfers
    /// (`vkCmdUpdateBuffer` or uploads).
    pub(crate) fn uniform(device: &Arc<Device>, name: &str, size: u64) -> Result<Self> {
        Buffer::new(
            device,
            &BufferDesc {
                name,
                size,
                usage: vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )
    }

    /// A GPU-only storage buffer that transfers can fill and read back.
    pub(crate) fn storage(device: &Arc<Device>, name: &str, size: u64) -> Result<Self> {
        Self::new(
            device,
            &BufferDesc {
                name,
                size,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC
                    | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )
    }

    pub(crate) fn raw(&self) -> vk::Buffer {
        self.raw
    }

    pub(crate) fn size(&self) -> u64 {
        self.size
    }

    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// The whole buffer as a descriptor.
    pub(crate) fn descriptor(&self) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo { buffer: self.raw, offset: 0, range: vk::WHOLE_SIZE }
    }

    /// The mapped bytes, for host-visible buffers.
    pub(crate) fn mapped(&self) -> Option<&[u8]> {
        let a = self.allocation.as_ref()?;
        let ptr = a.mapped_ptr()?;
        // SAFETY: gpu-allocator maps the whole allocation, which is at least `size` bytes;
        // the GPU does not write it while a shared borrow exists (callers synchronise
        // with fences before reading).
        Some(unsafe { std::slice::from_raw_parts(ptr.as_ptr() as *const u8, self.size as usize) })
    }

    /// The mapped bytes, mutably, for host-visible buffers.
    pub(crate) fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let a = self.allocation.as_mut()?;
        let ptr = a.mapped_ptr()?;
        // SAFETY: as in `mapped`, with exclusive access through `&mut self`.
        Some(unsafe { std::slice::from_raw_parts_mut(ptr.as_ptr() as *mut u8, self.size as usize) })
    }

    /// Checks an access range against the buffer's size.
    pub(crate) fn check_range(&self, what: &'static str, offset: u64, len: u64) -> Result<()> {
        match offset.checked_add(len) {
            Some(end) if end <= self.size => Ok(()),
            _ => Err(Error::OutOfBounds { what, name: self.name.clone(), offset, len, size: self.size }),
        }
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the buffer belongs to this device; callers keep GPU work that uses
        // it complete before dropping it (deferred destruction in frame-based code).
        unsafe { self.device.raw.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            if let Err(e) = self.device.allocator().free(a) {
                log::error!("freeing buffer {:?}: {e}", self.name);
            }
        }
    }
}
