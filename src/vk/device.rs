//! The device record every GPU object of the crate holds an `Arc` to.
//!
//! It is either OWNED (created headless by the crate: instance, messenger and
//! device are destroyed when the last `Arc` goes) or BORROWED from a host
//! (nothing but the crate's own allocator is dropped). Resources hold the
//! `Arc`, so the device can never be destroyed before them.

use std::sync::{Arc, Mutex, MutexGuard};

use ash::vk;
use gpu_allocator::vulkan::Allocator;

use super::validation::ValidationLog;
use crate::error::{Error, Result};

/// A queue the crate may submit to, with its family.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Queue {
    pub family: u32,
    pub raw: vk::Queue,
}

/// What the crate needs to know about the physical device.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    /// Device name as the driver reports it.
    pub name: String,
    /// Discrete, integrated, virtual, CPU, ...
    pub device_type: vk::PhysicalDeviceType,
    /// Vulkan API version the device supports.
    pub api_version: u32,
    /// Driver name and info string (e.g. "llvmpipe", "Mesa 22.3.6").
    pub driver: String,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period: f32,
    /// Valid bits of timestamps on the graphics queue family (0: no timestamps).
    pub timestamp_valid_bits: u32,
    /// Largest compute shared memory per workgroup, bytes.
    pub max_compute_shared_memory: u32,
    /// Largest workgroup invocation count.
    pub max_compute_invocations: u32,
    /// Largest tessellation level.
    pub max_tessellation_level: u32,
    /// Largest storage buffer range, bytes.
    pub max_storage_buffer_range: u32,
    /// Largest single memory allocation, bytes (`maxMemoryAllocationSize`).
    pub max_memory_allocation_size: u64,
    /// Invocations per subgroup (SPIR-V 1.5 modules always see this size).
    pub subgroup_size: u32,
    /// Whether compute shaders have subgroup arithmetic on subgroups of at least 4
    /// lanes: the pressure solve's reductions use it, else shared memory alone.
    pub subgroup_reductions: bool,
    /// Largest 2D image side, texels.
    pub max_image_dimension_2d: u32,
    /// Whether RGBA32 float color attachments can blend (the opacity-map atlas).
    pub rgba32f_blend: bool,
    /// `VkPhysicalDeviceIDProperties::deviceUUID`: devices with equal device and
    /// driver UUIDs can share memory through opaque file descriptors.
    pub device_uuid: [u8; 16],
    /// `VkPhysicalDeviceIDProperties::driverUUID`.
    pub driver_uuid: [u8; 16],
}

impl DeviceInfo {
    pub(crate) fn query(instance: &ash::Instance, physical: vk::PhysicalDevice, graphics_family: u32) -> Self {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut ids = vk::PhysicalDeviceIDProperties::default();
        let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver)
            .push_next(&mut maintenance3)
            .push_next(&mut subgroup)
            .push_next(&mut ids);
        // SAFETY: `physical` was enumerated from `instance`, which is alive.
        unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
        let props = props2.properties;
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let timestamp_valid_bits = families.get(graphics_family as usize).map(|f| f.timestamp_valid_bits).unwrap_or(0);
        let driver = format!(
            "{} {}",
            driver.driver_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
            driver.driver_info_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
        )
        .trim()
        .to_owned();
        DeviceInfo {
            name: props.device_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
            device_type: props.device_type,
            api_version: props.api_version,
            driver,
            timestamp_period: props.limits.timestamp_period,
            timestamp_valid_bits,
            max_compute_shared_memory: props.limits.max_compute_shared_memory_size,
            max_compute_invocations: props.limits.max_compute_work_group_invocations,
            max_tessellation_level: props.limits.max_tessellation_generation_level,
            max_storage_buffer_range: props.limits.max_storage_buffer_range,
            max_memory_allocation_size: maintenance3.max_memory_allocation_size,
            subgroup_size: subgroup.subgroup_size,
            subgroup_reductions: subgroup.supported_operations.contains(vk::SubgroupFeatureFlags::ARITHMETIC)
                && subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
                && subgroup.subgroup_size >= 4,
            max_image_dimension_2d: props.limits.max_image_dimension2_d,
            rgba32f_blend: {
                // SAFETY: as above.
                let f = unsafe {
                    instance.get_physical_device_format_properties(physical, vk::Format::R32G32B32A32_SFLOAT)
                };
                f.optimal_tiling_features.contains(vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND)
            },
            device_uuid: ids.device_uuid,
            driver_uuid: ids.driver_uuid,
        }
    }
}

/// Optional device extensions that are enabled on the device (the crate chooses
/// paths by them).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Extensions {
    /// `VK_KHR_external_memory_fd`: memory shared with a second device.
    pub external_memory_fd: bool,
    /// `VK_EXT_calibrated_timestamps`: timestamps placed on the host clock.
    pub calibrated_timestamps: bool,
}

impl Extensions {
    pub(crate) fn from_names(names: &[&std::ffi::CStr]) -> Self {
        Extensions {
            external_memory_fd: names.contains(&ash::khr::external_memory_fd::NAME),
            calibrated_timestamps: names.contains(&ash::ext::calibrated_timestamps::NAME),
        }
    }
}

/// Objects that exist only when the crate created the device itself.
pub(crate) struct Owned {
    pub debug_instance: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Keeps the messenger's user data alive until after `vkDestroyInstance`.
    pub log: Option<ValidationLog>,
}

/// The shared device record (see the module docs).
pub(crate) struct Device {
    /// Keeps the Vulkan loader library loaded for as long as the device lives.
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub raw: ash::Device,
    pub graphics: Queue,
    pub compute: Option<Queue>,
    pub info: DeviceInfo,
    pub debug_utils: Option<ash::ext::debug_utils::Device>,
    /// Whether `computeFullSubgroups` is enabled (pipelines may require full subgroups).
    pub full_subgroups: bool,
    /// Optional extensions enabled on the device.
    pub extensions: Extensions,
    allocator: Option<Arc<Mutex<Allocator>>>,
    /// Serialises the crate's own submissions to `graphics` (queue access must be
    /// externally synchronised).
    pub submit_lock: Mutex<()>,
    /// Whether the volume transfer adds with 64-bit atomics: where
    /// `shaderInt64` and `shaderBufferInt64Atomics` are enabled, unless
    /// switched off (tests run both ways).
    pub int64_atomics: std::sync::atomic::AtomicBool,
    /// Whether kernels with a reduction use their shared-memory variant: where
    /// [`DeviceInfo::subgroup_reductions`] is false, or forced (tests).
    pub shared_reductions: std::sync::atomic::AtomicBool,
    /// What has been recorded on this device.
    pub counters: super::counters::Counters,
    owned: Option<Owned>,
}

pub(crate) struct DeviceParts {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub raw: ash::Device,
    pub graphics: Queue,
    pub compute: Option<Queue>,
    pub debug_utils: bool,
    pub full_subgroups: bool,
    pub int64_atomics: bool,
    pub extensions: Extensions,
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    pub owned: Option<Owned>,
}

impl Device {
    /// What `format` supports in optimal tiling on this device.
    pub(crate) fn optimal_tiling_features(&self, format: vk::Format) -> vk::FormatFeatureFlags {
        // SAFETY: `physical` belongs to `instance`, which outlives this record.
        unsafe { self.instance.get_physical_device_format_properties(self.physical, format) }.optimal_tiling_features
    }

    /// Assembles the record; creates an allocator when none is given.
    pub(crate) fn new(parts: DeviceParts) -> Result<Arc<Self>> {
        let info = DeviceInfo::query(&parts.instance, parts.physical, parts.graphics.family);
        let debug_utils = parts.debug_utils.then(|| ash::ext::debug_utils::Device::new(&parts.instance, &parts.raw));
        let shared_reductions = std::sync::atomic::AtomicBool::new(!info.subgroup_reductions);
        let mut record = Device {
            entry: parts.entry,
            instance: parts.instance,
            physical: parts.physical,
            raw: parts.raw,
            graphics: parts.graphics,
            compute: parts.compute,
            info,
            debug_utils,
            full_subgroups: parts.full_subgroups,
            int64_atomics: std::sync::atomic::AtomicBool::new(parts.int64_atomics),
            extensions: parts.extensions,
            allocator: parts.allocator,
            submit_lock: Mutex::new(()),
            shared_reductions,
            counters: Default::default(),
            owned: parts.owned,
        };
        if record.allocator.is_none() {
            let desc = gpu_allocator::vulkan::AllocatorCreateDesc {
                instance: record.instance.clone(),
                device: record.raw.clone(),
                physical_device: record.physical,
                debug_settings: {
                    let mut d = gpu_allocator::AllocatorDebugSettings::default();
                    d.log_leaks_on_shutdown = true;
                    d
                },
                buffer_device_address: false,
                allocation_sizes: gpu_allocator::AllocationSizes::default(),
            };
            // On failure, dropping the record tears down what it owns before reporting.
            let allocator =
                Allocator::new(&desc).map_err(|source| Error::Allocation { name: "allocator".into(), source })?;
            record.allocator = Some(Arc::new(Mutex::new(allocator)));
        }
        Ok(Arc::new(record))
    }

    /// True when the crate created (and will destroy) instance and device.
    pub(crate) fn is_owned(&self) -> bool {
        self.owned.is_some()
    }

    /// Locks the allocator (poisoning is ignored: the allocator holds plain data).
    pub(crate) fn allocator(&self) -> MutexGuard<'_, Allocator> {
        let a = self.allocator.as_ref().expect("allocator lives until Device::drop");
        a.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The queue families whose queues share the crate's buffers: graphics and the
    /// async compute family when that is a different one (buffers are then created
    /// with `CONCURRENT` sharing, see `Buffer::new`).
    pub(crate) fn concurrent_families(&self) -> Option<[u32; 2]> {
        self.compute.filter(|c| c.family != self.graphics.family).map(|c| [self.graphics.family, c.family])
    }

    /// Waits until the queue has finished all submitted work.
    pub(crate) fn wait_idle(&self) -> Result<()> {
        let _lock = self.lock_submit();
        // SAFETY: the queue belongs to this device; access is serialised by the lock.
        unsafe { self.raw.queue_wait_idle(self.graphics.raw) }.map_err(Error::vk("vkQueueWaitIdle"))
    }

    /// Locks the crate's own submissions to the graphics queue.
    pub(crate) fn lock_submit(&self) -> MutexGuard<'_, ()> {
        self.submit_lock.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // The allocator must go before the device (its memory blocks are freed here).
        self.allocator = None;
        let Some(owned) = self.owned.take() else {
            // Borrowed: the host owns device and instance.
            return;
        };
        // SAFETY: we created these objects; every resource holding this record is
        // gone (they hold an Arc), and we wait for the device to go idle first.
        unsafe {
            let _ = self.raw.device_wait_idle();
            self.raw.destroy_device(None);
            if let Some((utils, messenger)) = owned.debug_instance {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
        drop(owned.log);
    }
}
