//! Buffers whose memory is shared between two logical devices through
//! `VK_KHR_external_memory_fd` (opaque file descriptors).
//!
//! One device allocates and exports ([`ExternalBuffer::export`]), the other
//! imports the descriptor ([`ExternalBuffer::import`]); both then bind a buffer
//! of the same size to the same memory. Opaque descriptors only work between
//! devices with equal device and driver UUIDs ([`compatible`]). The memory is a
//! dedicated allocation outside gpu-allocator, freed on drop on each side.

use std::os::fd::{FromRawFd, IntoRawFd, OwnedFd};
use std::sync::Arc;

use ash::vk;

use super::device::Device;
use crate::error::{Error, Result};

const HANDLE: vk::ExternalMemoryHandleTypeFlags = vk::ExternalMemoryHandleTypeFlags::OPAQUE_FD;
const USAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::TRANSFER_SRC.as_raw() | vk::BufferUsageFlags::TRANSFER_DST.as_raw(),
);

/// Whether `a` can export memory that `b` imports (both enable the extension,
/// same device and driver, and the driver can export and import such buffers).
pub(crate) fn compatible(a: &Device, b: &Device) -> bool {
    let same = a.info.device_uuid == b.info.device_uuid && a.info.driver_uuid == b.info.driver_uuid;
    if !(a.extensions.external_memory_fd && b.extensions.external_memory_fd && same) {
        return false;
    }
    let info = vk::PhysicalDeviceExternalBufferInfo::default().usage(USAGE).handle_type(HANDLE);
    let mut props = vk::ExternalBufferProperties::default();
    // SAFETY: the physical device belongs to the instance.
    unsafe { a.instance.get_physical_device_external_buffer_properties(a.physical, &info, &mut props) };
    let features = props.external_memory_properties.external_memory_features;
    features.contains(vk::ExternalMemoryFeatureFlags::EXPORTABLE | vk::ExternalMemoryFeatureFlags::IMPORTABLE)
}

/// A buffer bound to memory shared with another device.
pub(crate) struct ExternalBuffer {
    device: Arc<Device>,
    raw: vk::Buffer,
    memory: vk::DeviceMemory,
    /// Memory type and allocation size, which the importer must repeat.
    type_index: u32,
    allocation_size: u64,
    size: u64,
}

impl ExternalBuffer {
    /// Allocates `size` bytes of exportable memory on `device` and binds a buffer.
    pub(crate) fn export(device: &Arc<Device>, name: &str, size: u64) -> Result<Self> {
        let raw = create_buffer(device, name, size)?;
        let mut guard = ExternalBuffer {
            device: device.clone(),
            raw,
            memory: vk::DeviceMemory::null(),
            type_index: 0,
            allocation_size: 0,
            size,
        };
        // SAFETY: `raw` was created from this device.
        let req = unsafe { device.raw.get_buffer_memory_requirements(raw) };
        // SAFETY: the physical device belongs to the instance.
        let props = unsafe { device.instance.get_physical_device_memory_properties(device.physical) };
        let types = &props.memory_types[..props.memory_type_count as usize];
        let usable = |i: usize| req.memory_type_bits & (1 << i) != 0;
        let index = (0..types.len())
            .find(|&i| usable(i) && types[i].property_flags.contains(vk::MemoryPropertyFlags::DEVICE_LOCAL))
            .or_else(|| (0..types.len()).find(|&i| usable(i)))
            .ok_or_else(|| Error::MissingRequirement("a memory type for exportable buffers".into()))?;
        let mut export = vk::ExportMemoryAllocateInfo::default().handle_types(HANDLE);
        let mut dedicated = vk::MemoryDedicatedAllocateInfo::default().buffer(raw);
        let info = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(index as u32)
            .push_next(&mut export)
            .push_next(&mut dedicated);
        // SAFETY: valid allocate info; freed in Drop.
        guard.memory = unsafe { device.raw.allocate_memory(&info, None) }.map_err(Error::vk("vkAllocateMemory"))?;
        guard.type_index = index as u32;
        guard.allocation_size = req.size;
        guard.bind(name)?;
        Ok(guard)
    }

    /// A file descriptor for [`ExternalBuffer::import`] on another device (each call
    /// makes a new one; the importer takes ownership).
    pub(crate) fn export_fd(&self) -> Result<OwnedFd> {
        let fns = ash::khr::external_memory_fd::Device::new(&self.device.instance, &self.device.raw);
        let info = vk::MemoryGetFdInfoKHR::default().memory(self.memory).handle_type(HANDLE);
        // SAFETY: the memory was allocated exportable as an opaque descriptor.
        let fd = unsafe { fns.get_memory_fd(&info) }.map_err(Error::vk("vkGetMemoryFdKHR"))?;
        // SAFETY: vkGetMemoryFdKHR returns a new descriptor that the caller owns.
        Ok(unsafe { OwnedFd::from_raw_fd(fd) })
    }

    /// Imports `exported`'s memory on `device` through `fd` and binds a buffer of the
    /// same size.
    pub(crate) fn import(device: &Arc<Device>, name: &str, exported: &ExternalBuffer, fd: OwnedFd) -> Result<Self> {
        let raw = create_buffer(device, name, exported.size)?;
        let mut guard = ExternalBuffer {
            device: device.clone(),
            raw,
            memory: vk::DeviceMemory::null(),
            type_index: exported.type_index,
            allocation_size: exported.allocation_size,
            size: exported.size,
        };
        // SAFETY: `raw` was created from this device.
        let req = unsafe { device.raw.get_buffer_memory_requirements(raw) };
        if req.size > exported.allocation_size || req.memory_type_bits & (1 << exported.type_index) == 0 {
            return Err(Error::MissingRequirement("importable memory matching the exporting device's".into()));
        }
        let raw_fd = fd.into_raw_fd();
        let mut import = vk::ImportMemoryFdInfoKHR::default().handle_type(HANDLE).fd(raw_fd);
        let mut dedicated = vk::MemoryDedicatedAllocateInfo::default().buffer(raw);
        let info = vk::MemoryAllocateInfo::default()
            .allocation_size(exported.allocation_size)
            .memory_type_index(exported.type_index)
            .push_next(&mut import)
            .push_next(&mut dedicated);
        // SAFETY: valid allocate info; on success the driver owns the descriptor.
        match unsafe { device.raw.allocate_memory(&info, None) } {
            Ok(memory) => guard.memory = memory,
            Err(result) => {
                // SAFETY: the import failed, so the descriptor is still ours to close.
                drop(unsafe { OwnedFd::from_raw_fd(raw_fd) });
                return Err(Error::Vulkan { call: "vkAllocateMemory (import)", result });
            }
        }
        guard.bind(name)?;
        Ok(guard)
    }

    fn bind(&self, name: &str) -> Result<()> {
        // SAFETY: dedicated memory allocated for this buffer.
        unsafe { self.device.raw.bind_buffer_memory(self.raw, self.memory, 0) }
            .map_err(Error::vk("vkBindBufferMemory"))?;
        self.device.set_name(self.memory, &format!("{name} memory"));
        Ok(())
    }

    pub(crate) fn raw(&self) -> vk::Buffer {
        self.raw
    }
}

fn create_buffer(device: &Device, name: &str, size: u64) -> Result<vk::Buffer> {
    let mut external = vk::ExternalMemoryBufferCreateInfo::default().handle_types(HANDLE);
    let info = vk::BufferCreateInfo::default()
        .size(size)
        .usage(USAGE)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .push_next(&mut external);
    // SAFETY: valid create info; destroyed by the owner's Drop.
    let raw = unsafe { device.raw.create_buffer(&info, None) }.map_err(Error::vk("vkCreateBuffer"))?;
    device.set_name(raw, name);
    Ok(raw)
}

impl Drop for ExternalBuffer {
    fn drop(&mut self) {
        // SAFETY: both belong to this device; the owner keeps GPU work that uses them
        // complete before dropping (each device frees its own handle to the memory).
        unsafe {
            self.device.raw.destroy_buffer(self.raw, None);
            if self.memory != vk::DeviceMemory::null() {
                self.device.raw.free_memory(self.memory, None);
            }
        }
    }
}
