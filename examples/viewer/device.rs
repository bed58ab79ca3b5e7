//! The viewer's own Vulkan objects that live as long as the window: instance
//! (with the window system's surface extensions, and validation when asked),
//! surface, device (swapchain extension plus what vkhair requires), queue and
//! `gpu-allocator` allocator. Nothing here is vkhair's; vkhair borrows them.

use std::ffi::c_void;
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use vkhair::{ash, gpu_allocator, requirements};

use crate::host::{on_message, BoxError};

/// The host's device and what it was made from.
pub struct HostGpu {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub surface_fn: ash::khr::surface::Instance,
    pub surface: vk::SurfaceKHR,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub family: u32,
    pub queue: vk::Queue,
    /// `None` only while dropping.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    utils: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Validation warnings and errors, when the layer is on.
    pub messages: Arc<Mutex<Vec<String>>>,
}

impl HostGpu {
    /// Creates everything for `window`; `validation` turns on the Khronos layer
    /// with synchronization validation, its messages collected in `messages`.
    pub fn new(window: &winit::window::Window, validation: bool) -> Result<HostGpu, BoxError> {
        // SAFETY: loading the system Vulkan loader.
        let entry = unsafe { ash::Entry::load() }?;
        let messages: Arc<Mutex<Vec<String>>> = Arc::new(Mutex::new(Vec::new()));
        let display = window.display_handle()?.as_raw();
        let mut extensions = ash_window::enumerate_required_extensions(display)?.to_vec();
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        if validation {
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            )
            .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
            .pfn_user_callback(Some(on_message))
            .user_data(Arc::as_ptr(&messages) as *mut c_void);
        let app = vk::ApplicationInfo::default().application_name(c"vkhair viewer").api_version(vkhair::API_VERSION);
        let mut info = vk::InstanceCreateInfo::default().application_info(&app).enabled_extension_names(&extensions);
        if validation {
            info = info.enabled_layer_names(&layers).push_next(&mut features).push_next(&mut messenger_info);
        }
        // SAFETY: valid create info; destroyed in Drop.
        let instance = unsafe { entry.create_instance(&info, None) }?;
        let utils = if validation {
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // The instance's chain linked `messenger_info` to the features: a fresh copy.
            let create = vk::DebugUtilsMessengerCreateInfoEXT { p_next: std::ptr::null(), ..messenger_info };
            // SAFETY: `messages` (held here and by the app) outlives the messenger (destroyed in Drop).
            let messenger = unsafe { utils.create_debug_utils_messenger(&create, None) }?;
            Some((utils, messenger))
        } else {
            None
        };
        let surface_fn = ash::khr::surface::Instance::new(&entry, &instance);
        // SAFETY: the window outlives the surface (the app drops the GPU first).
        let surface =
            unsafe { ash_window::create_surface(&entry, &instance, display, window.window_handle()?.as_raw(), None) }?;
        let (physical, family) = pick(&instance, &surface_fn, surface)?;
        let mut req = requirements();
        let priorities = [1.0];
        let queue_infos =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        let device_extensions = [ash::khr::swapchain::NAME.as_ptr()];
        let mut chain = req.features.chain();
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_extension_names(&device_extensions)
            .push_next(&mut chain);
        // SAFETY: vkhair's required features plus the swapchain extension; destroyed in Drop.
        let device = unsafe { instance.create_device(physical, &device_info, None) }?;
        // SAFETY: the queue was requested above.
        let queue = unsafe { device.get_device_queue(family, 0) };
        let allocator = Arc::new(Mutex::new(Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })?));
        Ok(HostGpu {
            entry,
            instance,
            surface_fn,
            surface,
            physical,
            device,
            family,
            queue,
            allocator: Some(allocator),
            utils,
            messages,
        })
    }

    /// The allocator (always there until drop).
    pub fn allocator(&self) -> &Arc<Mutex<Allocator>> {
        self.allocator.as_ref().expect("the allocator lives until drop")
    }
}

/// The first device with a queue family that does graphics, compute and
/// presents to `surface`.
fn pick(
    instance: &ash::Instance,
    surface_fn: &ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
) -> Result<(vk::PhysicalDevice, u32), BoxError> {
    // SAFETY: the instance is alive.
    for physical in unsafe { instance.enumerate_physical_devices() }? {
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        for (i, f) in families.iter().enumerate() {
            let i = i as u32;
            // SAFETY: a valid family index of this device and a live surface.
            let presents = unsafe { surface_fn.get_physical_device_surface_support(physical, i, surface) }?;
            if presents && f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE) {
                return Ok((physical, i));
            }
        }
    }
    Err("no Vulkan device presents to this window with a graphics and compute queue".into())
}

impl Drop for HostGpu {
    fn drop(&mut self) {
        // SAFETY: the app destroyed every object of this device first and the
        // device is idle (see `App::shutdown`).
        unsafe {
            let _ = self.device.device_wait_idle();
            drop(self.allocator.take());
            self.device.destroy_device(None);
            self.surface_fn.destroy_surface(self.surface, None);
            if let Some((utils, messenger)) = self.utils.take() {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
