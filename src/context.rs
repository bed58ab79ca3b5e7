//! The GPU context: owned (headless) or borrowed from a host renderer.

use std::ffi::{CStr, CString};
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::Allocator;

use crate::error::{Error, Result};
use crate::requirements::{self, requirements, Support};
use crate::vk::device::{Device, DeviceInfo, DeviceParts, Owned, Queue};
use crate::vk::validation::{self, ValidationLog};

/// Environment variable that forces a device by (case-insensitive) name substring.
pub const DEVICE_ENV: &str = "VKHAIR_DEVICE";
/// Environment variable that turns validation on for headless contexts (`1`).
pub const VALIDATION_ENV: &str = "VKHAIR_VALIDATION";

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How a headless context is created.
#[derive(Debug, Clone)]
pub struct ContextOptions {
    /// Enable `VK_LAYER_KHRONOS_validation` with synchronization validation.
    /// Default: `false`, or `true` when `VKHAIR_VALIDATION=1`.
    pub validation: bool,
    /// Where validation warnings/errors go (also logged through `log`). Default: none.
    pub validation_log: Option<ValidationLog>,
    /// Device name substring to force; default: `VKHAIR_DEVICE` (a value that is
    /// not UTF-8 matches no device), else the best device (discrete > integrated >
    /// virtual > CPU).
    pub device_name: Option<String>,
    /// Application name reported to the driver. Default: `"vkhair"`.
    pub app_name: String,
}

impl Default for ContextOptions {
    fn default() -> Self {
        ContextOptions {
            validation: std::env::var(VALIDATION_ENV).is_ok_and(|v| v == "1"),
            validation_log: None,
            // Not UTF-8: kept (lossily), so that it matches no device and says so
            // rather than being ignored.
            device_name: std::env::var_os(DEVICE_ENV)
                .filter(|s| !s.is_empty())
                .map(|s| s.to_string_lossy().into_owned()),
            app_name: "vkhair".into(),
        }
    }
}

impl ContextOptions {
    /// Options for tests: validation and synchronization validation on, messages into `log`.
    pub fn validated(log: &ValidationLog) -> Self {
        ContextOptions { validation: true, validation_log: Some(log.clone()), ..Default::default() }
    }
}

/// A queue handed over by the host.
#[derive(Debug, Clone, Copy)]
pub struct HostQueue {
    /// Queue family index.
    pub family: u32,
    /// The queue. vkhair submits to it only from the calls documented as submitting
    /// (uploads at construction, readbacks); the host must not use it concurrently
    /// with those calls.
    pub queue: vk::Queue,
}

/// The host's Vulkan objects for [`GpuContext::from_host`].
pub struct HostDevice {
    /// The host's loader entry.
    pub entry: ash::Entry,
    /// The host's instance (created with at least [`requirements::API_VERSION`]).
    pub instance: ash::Instance,
    /// The physical device `device` was created from.
    pub physical_device: vk::PhysicalDevice,
    /// The host's device, created with everything in [`requirements()`].
    pub device: ash::Device,
    /// A graphics+compute queue.
    pub graphics_queue: HostQueue,
    /// A compute-capable queue other than `graphics_queue` (of another family, or a
    /// second queue of the same family) for async compute, if the host offers one.
    /// vkhair's [`crate::schedule::FrameScheduler`] then submits the simulation to
    /// it; the host must not use it concurrently with the scheduler's calls.
    pub compute_queue: Option<HostQueue>,
    /// The host's allocator to share; `None` makes vkhair create its own.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    /// Whether the host enabled `VK_EXT_debug_utils` on its instance (object names, labels).
    pub debug_utils: bool,
    /// Whether the host enabled the optional `subgroupSizeControl` and
    /// `computeFullSubgroups` features (see [`crate::Requirements::optional_features`]).
    pub compute_full_subgroups: bool,
    /// Whether the host enabled the optional `shaderInt64` and
    /// `shaderBufferInt64Atomics` features (see
    /// [`crate::Requirements::optional_features`]): the volume stage's
    /// transfer then adds with one 64-bit atomic a value instead of two 32-bit
    /// ones, to the same sums.
    pub buffer_int64_atomics: bool,
    /// Which of [`crate::Requirements::optional_device_extensions`] the host enabled
    /// (`VK_KHR_external_memory_fd` for the two-device hand-off without staging,
    /// `VK_EXT_calibrated_timestamps` for profiles on the host clock). Others are ignored.
    pub enabled_extensions: Vec<&'static CStr>,
}

/// vkhair's handle on a Vulkan device: owned (headless) or borrowed from a host.
///
/// Every vkhair GPU object keeps the context's device record alive, so dropping the
/// `GpuContext` while objects still exist is safe: the device goes with the last one.
///
/// A headless context with validation on (a host wraps its own device with
/// [`GpuContext::from_host`]; `examples/embed_minimal/`, run as a test, does it):
///
/// ```
/// use vkhair::{ContextOptions, GpuContext, ValidationLog};
///
/// let log = ValidationLog::new();
/// let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
/// println!("{} ({})", ctx.info().name, ctx.info().driver);
/// assert!(ctx.is_owned());
/// drop(ctx);
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
#[derive(Clone)]
pub struct GpuContext {
    pub(crate) device: Arc<Device>,
}

impl std::fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuContext")
            .field("device", &self.device.info.name)
            .field("owned", &self.device.is_owned())
            .finish()
    }
}

impl GpuContext {
    /// Creates an instance and device of its own (no window, no surface).
    pub fn headless(options: &ContextOptions) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; its initialisation has no
        // preconditions beyond being a conforming loader.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        let instance_parts = create_instance(&entry, options)?;
        let (instance, debug_instance, debug_utils) = instance_parts;
        let log = options.validation_log.clone();
        let owned = Owned { debug_instance, log };
        // From here on `owned` and `instance` must be destroyed on error.
        let guard = InstanceGuard { instance: Some(instance), owned: Some(owned) };
        let chosen = choose_device(guard.instance_ref(), options.device_name.as_deref())?;
        let (physical, support) = chosen;
        let (raw, graphics, compute) = create_device(guard.instance_ref(), physical, &support)?;
        let full_subgroups = support.full_subgroups;
        let int64_atomics = support.int64_atomics;
        let (instance, owned) = guard.release();
        let device = Device::new(DeviceParts {
            entry,
            instance,
            physical,
            raw,
            graphics,
            compute,
            debug_utils,
            full_subgroups,
            int64_atomics,
            extensions: crate::vk::device::Extensions::from_names(&support.optional_extensions),
            allocator: None,
            owned: Some(owned),
        })?;
        for (handle, name) in [(device.graphics.raw, "vkhair graphics queue")]
            .into_iter()
            .chain(device.compute.map(|c| (c.raw, "vkhair compute queue")))
        {
            device.set_name(handle, name);
        }
        log::info!("vkhair: using {} ({})", device.info.name, device.info.driver);
        Ok(GpuContext { device })
    }

    /// Wraps a host's device. Nothing the host passes is ever destroyed by vkhair.
    ///
    /// # Safety
    /// - All handles in `host` are valid, belong together (the device was created from
    ///   `physical_device` of `instance`) and outlive every vkhair object made from
    ///   the returned context.
    /// - The device was created with [`requirements::API_VERSION`] and every feature in
    ///   [`requirements()`] enabled; the queues exist in the named families with the
    ///   graphics queue supporting graphics and compute.
    /// - The host does not access `graphics_queue` concurrently with a vkhair call
    ///   documented as submitting work, and does not use a shared `allocator` in a
    ///   way that breaks `gpu_allocator`'s own rules.
    pub unsafe fn from_host(host: HostDevice) -> Result<Self> {
        // SAFETY: the caller guarantees the physical device belongs to the instance.
        let support = unsafe { requirements().check(&host.instance, host.physical_device) }?;
        log::debug!("vkhair: host device offers optional {:?}", support.optional_extensions);
        let device = Device::new(DeviceParts {
            entry: host.entry,
            instance: host.instance,
            physical: host.physical_device,
            raw: host.device,
            graphics: Queue { family: host.graphics_queue.family, raw: host.graphics_queue.queue },
            compute: host.compute_queue.map(|q| Queue { family: q.family, raw: q.queue }),
            debug_utils: host.debug_utils,
            full_subgroups: host.compute_full_subgroups && support.full_subgroups,
            int64_atomics: host.buffer_int64_atomics && support.int64_atomics,
            extensions: crate::vk::device::Extensions::from_names(
                &host
                    .enabled_extensions
                    .iter()
                    .copied()
                    .filter(|n| support.optional_extensions.contains(n))
                    .collect::<Vec<_>>(),
            ),
            allocator: host.allocator,
            owned: None,
        })?;
        Ok(GpuContext { device })
    }

    /// What vkhair has recorded on this context's device so far (dispatches,
    /// barriers, bytes bound): subtract two readings to count a step or a frame.
    pub fn recorded_work(&self) -> crate::vk::counters::RecordedWork {
        self.device.counters.read()
    }

    /// Starts logging every compute dispatch vkhair records on this device
    /// (emptying a log already kept): its kernel, workgroups and loop trips,
    /// the counts that predict a kernel's cost on a GPU. For benchmarks and
    /// tools; a host leaves it off (nothing is kept then).
    pub fn start_dispatch_log(&self) {
        self.device.counters.start_log();
    }

    /// The dispatches recorded since [`GpuContext::start_dispatch_log`], in
    /// recording order, and stops the log (empty when none was started).
    pub fn take_dispatch_log(&self) -> Vec<crate::vk::counters::DispatchRecord> {
        self.device.counters.take_log()
    }

    /// The device's name, type, driver and limits.
    pub fn info(&self) -> &DeviceInfo {
        &self.device.info
    }

    /// True for a headless context that owns its instance and device.
    pub fn is_owned(&self) -> bool {
        self.device.is_owned()
    }

    /// The raw device, for hosts that want to record around vkhair's work.
    pub fn raw_device(&self) -> &ash::Device {
        &self.device.raw
    }

    /// The graphics queue family index vkhair records for.
    pub fn graphics_queue_family(&self) -> u32 {
        self.device.graphics.family
    }
}

/// Destroys instance-level objects if device creation fails half way.
struct InstanceGuard {
    instance: Option<ash::Instance>,
    owned: Option<Owned>,
}

impl InstanceGuard {
    fn instance_ref(&self) -> &ash::Instance {
        self.instance.as_ref().expect("instance present until release")
    }
    fn release(mut self) -> (ash::Instance, Owned) {
        let instance = self.instance.take().expect("instance present until release");
        let owned = self.owned.take().expect("owned present until release");
        (instance, owned)
    }
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        let (Some(instance), Some(owned)) = (self.instance.take(), self.owned.take()) else { return };
        // SAFETY: created by `create_instance` and not shared with anything else yet.
        unsafe {
            if let Some((utils, messenger)) = owned.debug_instance {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            instance.destroy_instance(None);
        }
    }
}

type InstanceParts = (ash::Instance, Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>, bool);

fn create_instance(entry: &ash::Entry, options: &ContextOptions) -> Result<InstanceParts> {
    // SAFETY: plain enumeration through a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .map_err(Error::vk("vkEnumerateInstanceLayerProperties"))?;
    // SAFETY: as above.
    let extensions = unsafe { entry.enumerate_instance_extension_properties(None) }
        .map_err(Error::vk("vkEnumerateInstanceExtensionProperties"))?;
    let has_ext = |name: &CStr| extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
    let debug_utils = has_ext(ash::ext::debug_utils::NAME) || options.validation;
    let mut layer_names = Vec::new();
    let mut ext_names = Vec::new();
    if options.validation {
        if !layers.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)) {
            return Err(Error::LayerMissing(VALIDATION_LAYER.to_string_lossy().into_owned()));
        }
        layer_names.push(VALIDATION_LAYER.as_ptr());
        ext_names.push(ash::ext::validation_features::NAME.as_ptr());
    }
    if debug_utils {
        ext_names.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    let app_name = CString::new(options.app_name.replace('\0', " ")).unwrap_or_default();
    let app = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .engine_name(c"vkhair")
        .engine_version(vk::make_api_version(0, 0, 1, 0))
        .api_version(requirements::API_VERSION);
    let enabled_validation = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut validation_features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_validation);
    let fallback_log = ValidationLog::new();
    let log = options.validation_log.as_ref().unwrap_or(&fallback_log);
    let mut messenger_info = validation::messenger_info(log);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layer_names)
        .enabled_extension_names(&ext_names);
    if options.validation {
        info = info.push_next(&mut validation_features);
        if options.validation_log.is_some() {
            // Covers vkCreateInstance/vkDestroyInstance themselves.
            info = info.push_next(&mut messenger_info);
        }
    }
    // SAFETY: every pointer in `info` refers to locals that outlive the call.
    let instance = unsafe { entry.create_instance(&info, None) }.map_err(Error::vk("vkCreateInstance"))?;
    let mut messenger = None;
    if debug_utils && options.validation_log.is_some() {
        let utils = ash::ext::debug_utils::Instance::new(entry, &instance);
        let info = validation::messenger_info(log);
        // SAFETY: the log's user data outlives the messenger (the device record keeps
        // a clone until after the instance is destroyed).
        match unsafe { utils.create_debug_utils_messenger(&info, None) } {
            Ok(m) => messenger = Some((utils, m)),
            Err(result) => {
                // SAFETY: nothing else was created from the instance yet.
                unsafe { instance.destroy_instance(None) };
                return Err(Error::Vulkan { call: "vkCreateDebugUtilsMessengerEXT", result });
            }
        }
    }
    Ok((instance, messenger, debug_utils))
}

/// A physical device as `vkhair devices` shows it.
#[derive(Debug, Clone)]
pub struct DeviceReport {
    /// Name, type, driver and limits.
    pub info: DeviceInfo,
    /// `Ok` when vkhair can use it, else what is missing.
    pub usable: std::result::Result<(), String>,
    /// Optional extensions it offers.
    pub optional_extensions: Vec<String>,
    /// Whether a separate compute queue family exists (async compute).
    pub async_compute: bool,
    /// Whether [`GpuContext::headless`] with these options would choose it.
    pub chosen: bool,
}

/// Lists every physical device with what vkhair can use of it.
pub fn list_devices(options: &ContextOptions) -> Result<Vec<DeviceReport>> {
    // SAFETY: see GpuContext::headless.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
    let quiet = ContextOptions { validation: false, validation_log: None, ..options.clone() };
    let (instance, _, _) = create_instance(&entry, &quiet)?;
    let guard = InstanceGuard { instance: Some(instance), owned: Some(Owned { debug_instance: None, log: None }) };
    let instance = guard.instance_ref();
    let chosen = choose_device(instance, options.device_name.as_deref()).ok().map(|(p, _)| p);
    // SAFETY: the instance is alive.
    let physicals =
        unsafe { instance.enumerate_physical_devices() }.map_err(Error::vk("vkEnumeratePhysicalDevices"))?;
    let mut reports = Vec::new();
    for physical in physicals {
        // SAFETY: enumerated from this instance.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let graphics = requirements::graphics_family(&families).unwrap_or(0);
        // SAFETY: enumerated from this instance.
        let check = unsafe { requirements().check(instance, physical) };
        reports.push(DeviceReport {
            info: DeviceInfo::query(instance, physical, graphics),
            optional_extensions: check
                .as_ref()
                .map(|s| s.optional_extensions.iter().map(|e| e.to_string_lossy().into_owned()).collect())
                .unwrap_or_default(),
            usable: check.map(|_| ()).map_err(|e| e.to_string()),
            async_compute: requirements::async_compute_family(&families, graphics).is_some(),
            chosen: chosen == Some(physical),
        });
    }
    Ok(reports)
}

fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

fn choose_device(instance: &ash::Instance, forced: Option<&str>) -> Result<(vk::PhysicalDevice, Support)> {
    // SAFETY: the instance is alive.
    let physicals =
        unsafe { instance.enumerate_physical_devices() }.map_err(Error::vk("vkEnumeratePhysicalDevices"))?;
    if physicals.is_empty() {
        return Err(Error::NoSuitableDevice(
            "the Vulkan loader reports no devices (install mesa-vulkan-drivers for lavapipe)".into(),
        ));
    }
    let mut rejected = Vec::new();
    let mut best: Option<(u32, vk::PhysicalDevice, Support)> = None;
    for physical in physicals {
        // SAFETY: enumerated from this instance.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let name = props.device_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if let Some(forced) = forced {
            if !name.to_lowercase().contains(&forced.to_lowercase()) {
                continue;
            }
        }
        // SAFETY: enumerated from this instance.
        match unsafe { requirements().check(instance, physical) } {
            Ok(support) => {
                let rank = type_rank(props.device_type);
                if best.as_ref().is_none_or(|(r, _, _)| rank < *r) {
                    best = Some((rank, physical, support));
                }
            }
            Err(e) => rejected.push(format!("{name}: {e}")),
        }
    }
    match (best, forced) {
        (Some((_, physical, support)), _) => Ok((physical, support)),
        (None, Some(name)) => Err(Error::DeviceNotUsable {
            name: name.to_owned(),
            reason: if rejected.is_empty() { "no device has that name".into() } else { rejected.join("; ") },
        }),
        (None, None) => Err(Error::NoSuitableDevice(rejected.join("; "))),
    }
}

fn create_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    support: &Support,
) -> Result<(ash::Device, Queue, Option<Queue>)> {
    // SAFETY: `physical` was enumerated from `instance`.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let graphics = requirements::graphics_family(&families)
        .ok_or_else(|| Error::MissingRequirement("a graphics+compute queue family".into()))?;
    // Async compute: a compute family of its own, else a second queue of the graphics
    // family, else none (lavapipe: one family with one queue).
    let compute = requirements::async_compute_family(&families, graphics);
    let second_in_family = compute.is_none() && families[graphics as usize].queue_count >= 2;
    let priorities = [1.0f32, 1.0];
    let graphics_count = if second_in_family { 2 } else { 1 };
    let mut queue_infos = vec![vk::DeviceQueueCreateInfo::default()
        .queue_family_index(graphics)
        .queue_priorities(&priorities[..graphics_count])];
    if let Some(c) = compute {
        queue_infos.push(vk::DeviceQueueCreateInfo::default().queue_family_index(c).queue_priorities(&priorities[..1]));
    }
    let req = requirements();
    let mut features = req.features;
    requirements::enable_optional(&mut features, support);
    let ext_names: Vec<_> =
        req.device_extensions.iter().chain(support.optional_extensions.iter()).map(|n| n.as_ptr()).collect();
    let mut chain = features.chain();
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_infos)
        .enabled_extension_names(&ext_names)
        .push_next(&mut chain);
    // SAFETY: all pointers refer to locals alive for the call; features were checked.
    let device = unsafe { instance.create_device(physical, &info, None) }.map_err(Error::vk("vkCreateDevice"))?;
    // SAFETY: the queues were requested above.
    let graphics_queue = Queue { family: graphics, raw: unsafe { device.get_device_queue(graphics, 0) } };
    let compute_queue = match compute {
        Some(family) => Some(Queue {
            family,
            // SAFETY: requested above.
            raw: unsafe { device.get_device_queue(family, 0) },
        }),
        // SAFETY: requested above (two queues of the graphics family).
        None if second_in_family => {
            Some(Queue { family: graphics, raw: unsafe { device.get_device_queue(graphics, 1) } })
        }
        None => None,
    };
    Ok((device, graphics_queue, compute_queue))
}
