//! What a host must enable on its device for vkhair, and a check of it.

use std::ffi::CStr;

use ash::vk;

use crate::error::{Error, Result};

/// Vulkan version vkhair needs (instance and device).
pub const API_VERSION: u32 = vk::API_VERSION_1_3;

/// One required or optional device feature, by Vulkan name.
struct Feature<T> {
    name: &'static str,
    get: fn(&T) -> vk::Bool32,
    set: fn(&mut T),
}

macro_rules! features {
    ($ty:ty: $($field:ident => $name:literal),* $(,)?) => {
        &[$(Feature::<$ty> { name: $name, get: |f| f.$field, set: |f| f.$field = vk::TRUE }),*]
    };
}

const CORE: &[Feature<vk::PhysicalDeviceFeatures>] = features!(vk::PhysicalDeviceFeatures:
    tessellation_shader => "tessellationShader",
    vertex_pipeline_stores_and_atomics => "vertexPipelineStoresAndAtomics",
    fragment_stores_and_atomics => "fragmentStoresAndAtomics",
);
const V12: &[Feature<vk::PhysicalDeviceVulkan12Features<'static>>] = features!(vk::PhysicalDeviceVulkan12Features<'static>:
    timeline_semaphore => "timelineSemaphore",
    host_query_reset => "hostQueryReset",
);
const V13: &[Feature<vk::PhysicalDeviceVulkan13Features<'static>>] = features!(vk::PhysicalDeviceVulkan13Features<'static>:
    dynamic_rendering => "dynamicRendering",
    synchronization2 => "synchronization2",
);
/// Features used when present, never required.
const CORE_OPTIONAL: &[Feature<vk::PhysicalDeviceFeatures>] = features!(vk::PhysicalDeviceFeatures:
    pipeline_statistics_query => "pipelineStatisticsQuery",
);

/// 64-bit integer atomics on storage buffers, used when present (with
/// `shaderInt64`): the volume stage's transfer adds each fixed-point value
/// with one 64-bit atomic instead of two 32-bit ones, to the same sums.
const CORE_OPTIONAL_INT64: &[Feature<vk::PhysicalDeviceFeatures>] = features!(vk::PhysicalDeviceFeatures:
    shader_int64 => "shaderInt64",
);
const V12_OPTIONAL_INT64: &[Feature<vk::PhysicalDeviceVulkan12Features<'static>>] = features!(vk::PhysicalDeviceVulkan12Features<'static>:
    shader_buffer_int64_atomics => "shaderBufferInt64Atomics",
);

/// Vulkan 1.3 features used when present: full subgroups in compute let the solver
/// synchronise hairs with subgroup barriers.
const V13_OPTIONAL: &[Feature<vk::PhysicalDeviceVulkan13Features<'static>>] = features!(vk::PhysicalDeviceVulkan13Features<'static>:
    subgroup_size_control => "subgroupSizeControl",
    compute_full_subgroups => "computeFullSubgroups",
);

/// Device extensions used when present (later stages choose paths by them).
const OPTIONAL_EXTENSIONS: &[&CStr] =
    &[ash::ext::transform_feedback::NAME, ash::khr::external_memory_fd::NAME, ash::ext::calibrated_timestamps::NAME];

/// The device features vkhair needs, as Vulkan structs ready to chain into
/// `VkDeviceCreateInfo` (see [`RequiredFeatures::chain`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct RequiredFeatures {
    /// Vulkan 1.0 features.
    pub core: vk::PhysicalDeviceFeatures,
    /// Vulkan 1.2 features.
    pub vulkan12: vk::PhysicalDeviceVulkan12Features<'static>,
    /// Vulkan 1.3 features.
    pub vulkan13: vk::PhysicalDeviceVulkan13Features<'static>,
}

impl RequiredFeatures {
    /// Links the structs into a `VkPhysicalDeviceFeatures2` chain for
    /// `VkDeviceCreateInfo::pNext`. Merge with the host's own features as needed.
    pub fn chain(&mut self) -> vk::PhysicalDeviceFeatures2<'_> {
        self.vulkan12.p_next = std::ptr::null_mut();
        self.vulkan13.p_next = std::ptr::null_mut();
        let RequiredFeatures { core, vulkan12, vulkan13 } = self;
        vk::PhysicalDeviceFeatures2::default().features(*core).push_next(vulkan13).push_next(vulkan12)
    }

    /// Sets every required feature.
    fn require_all(&mut self) {
        CORE.iter().for_each(|f| (f.set)(&mut self.core));
        V12.iter().for_each(|f| (f.set)(&mut self.vulkan12));
        V13.iter().for_each(|f| (f.set)(&mut self.vulkan13));
    }
}

/// Everything a host must provide for vkhair: the API version, device
/// features, device extensions and queue capabilities.
#[derive(Debug, Clone)]
pub struct Requirements {
    /// Minimum Vulkan API version of instance and device.
    pub api_version: u32,
    /// Features that must be enabled on the device.
    pub features: RequiredFeatures,
    /// Device extensions that must be enabled (none beyond Vulkan 1.3 today).
    pub device_extensions: Vec<&'static CStr>,
    /// Device extensions vkhair uses when enabled (transform feedback capture,
    /// external memory for the two-device path, calibrated timestamps).
    pub optional_device_extensions: Vec<&'static CStr>,
    /// Device features vkhair uses when the host enables them: `subgroupSizeControl`
    /// and `computeFullSubgroups` (subgroup-synchronised constraint solving; say so in
    /// [`crate::HostDevice::compute_full_subgroups`]), `pipelineStatisticsQuery`, and
    /// `shaderInt64` with `shaderBufferInt64Atomics` (the volume transfer's
    /// 64-bit atomics; say so in [`crate::HostDevice::buffer_int64_atomics`]).
    pub optional_features: Vec<&'static str>,
    /// Instance extensions vkhair uses when enabled: `VK_EXT_debug_utils` for
    /// object names and pass labels.
    pub optional_instance_extensions: Vec<&'static CStr>,
}

/// What vkhair needs from a device. Enable these when creating the device that
/// is passed to [`crate::GpuContext::from_host`].
///
/// ```
/// let req = vkhair::requirements();
/// assert!(req.api_version >= ash::vk::API_VERSION_1_2);
/// for name in &req.device_extensions {
///     println!("enable {}", name.to_string_lossy());
/// }
/// ```
pub fn requirements() -> Requirements {
    let mut features = RequiredFeatures::default();
    features.require_all();
    Requirements {
        api_version: API_VERSION,
        features,
        device_extensions: Vec::new(),
        optional_device_extensions: OPTIONAL_EXTENSIONS.to_vec(),
        optional_features: V13_OPTIONAL
            .iter()
            .map(|f| f.name)
            .chain(CORE_OPTIONAL.iter().map(|f| f.name))
            .chain(CORE_OPTIONAL_INT64.iter().map(|f| f.name))
            .chain(V12_OPTIONAL_INT64.iter().map(|f| f.name))
            .collect(),
        optional_instance_extensions: vec![ash::ext::debug_utils::NAME],
    }
}

/// What a physical device offers of the optional parts, decided at device creation.
#[derive(Debug, Clone, Default)]
pub(crate) struct Support {
    pub optional_extensions: Vec<&'static CStr>,
    pub pipeline_statistics: bool,
    pub full_subgroups: bool,
    pub int64_atomics: bool,
}

impl Requirements {
    /// Checks that `physical` supports everything vkhair needs; the error names each
    /// missing item. Returns which optional parts are available.
    ///
    /// # Safety
    /// `physical` must have been enumerated from `instance`, which must be alive.
    pub(crate) unsafe fn check(&self, instance: &ash::Instance, physical: vk::PhysicalDevice) -> Result<Support> {
        let mut missing = Vec::new();
        // SAFETY: guaranteed by the caller.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        if props.api_version < self.api_version {
            missing.push(format!(
                "Vulkan {}.{} (device has {}.{})",
                vk::api_version_major(self.api_version),
                vk::api_version_minor(self.api_version),
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version)
            ));
            return Err(Error::MissingRequirement(missing.join(", ")));
        }
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut v12).push_next(&mut v13);
        // SAFETY: guaranteed by the caller; the chain lives on this stack frame.
        unsafe { instance.get_physical_device_features2(physical, &mut f2) };
        let core = f2.features;
        missing.extend(CORE.iter().filter(|f| (f.get)(&core) == vk::FALSE).map(|f| f.name.to_owned()));
        missing.extend(V12.iter().filter(|f| (f.get)(&v12) == vk::FALSE).map(|f| f.name.to_owned()));
        missing.extend(V13.iter().filter(|f| (f.get)(&v13) == vk::FALSE).map(|f| f.name.to_owned()));
        // SAFETY: guaranteed by the caller.
        let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }
            .map_err(Error::vk("vkEnumerateDeviceExtensionProperties"))?;
        let has = |name: &CStr| extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
        missing.extend(self.device_extensions.iter().filter(|n| !has(n)).map(|n| n.to_string_lossy().into_owned()));
        // SAFETY: guaranteed by the caller.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        if graphics_family(&families).is_none() {
            missing.push("a graphics+compute queue family".into());
        }
        if !missing.is_empty() {
            return Err(Error::MissingRequirement(missing.join(", ")));
        }
        Ok(Support {
            optional_extensions: self.optional_device_extensions.iter().copied().filter(|n| has(n)).collect(),
            pipeline_statistics: CORE_OPTIONAL.iter().all(|f| (f.get)(&core) == vk::TRUE),
            full_subgroups: V13_OPTIONAL.iter().all(|f| (f.get)(&v13) == vk::TRUE),
            int64_atomics: CORE_OPTIONAL_INT64.iter().all(|f| (f.get)(&core) == vk::TRUE)
                && V12_OPTIONAL_INT64.iter().all(|f| (f.get)(&v12) == vk::TRUE),
        })
    }
}

/// The first queue family with graphics and compute.
pub(crate) fn graphics_family(families: &[vk::QueueFamilyProperties]) -> Option<u32> {
    families
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
        .map(|i| i as u32)
}

/// A compute-capable family other than `graphics` (prefers compute-only families).
pub(crate) fn async_compute_family(families: &[vk::QueueFamilyProperties], graphics: u32) -> Option<u32> {
    let candidates = || {
        families
            .iter()
            .enumerate()
            .filter(move |(i, f)| *i as u32 != graphics && f.queue_flags.contains(vk::QueueFlags::COMPUTE))
    };
    candidates()
        .find(|(_, f)| !f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
        .or_else(|| candidates().next())
        .map(|(i, _)| i as u32)
}

/// Sets the optional features vkhair uses when present.
pub(crate) fn enable_optional(features: &mut RequiredFeatures, support: &Support) {
    if support.pipeline_statistics {
        CORE_OPTIONAL.iter().for_each(|f| (f.set)(&mut features.core));
    }
    if support.full_subgroups {
        V13_OPTIONAL.iter().for_each(|f| (f.set)(&mut features.vulkan13));
    }
    if support.int64_atomics {
        CORE_OPTIONAL_INT64.iter().for_each(|f| (f.set)(&mut features.core));
        V12_OPTIONAL_INT64.iter().for_each(|f| (f.set)(&mut features.vulkan12));
    }
}
