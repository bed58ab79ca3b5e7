//! The public GPU context API: headless (owned) and borrowed from a host.
//!
//! The host in these tests creates its own instance (with the validation layer
//! and its own messenger), its own device with what `vkhair::requirements()`
//! lists, and lends both to vkhair. After vkhair is dropped the host's device
//! must still work and be destroyable cleanly by the host.

use std::ffi::CStr;
use std::sync::{Arc, Mutex};

use vkhair::ash::{self, vk};
use vkhair::headless::Submit;
use vkhair::{requirements, ContextOptions, GpuContext, GpuProfiler, HostDevice, HostQueue, ValidationLog};

use crate::common;

/// The helper every GPU test uses (`common::Gpu`) checks the validation log
/// after the context is dropped: a buffer leaked on purpose fails the test.
#[test]
fn the_shared_test_helper_catches_a_leaked_buffer() {
    let caught = std::panic::catch_unwind(|| {
        let gpu = common::Gpu::new();
        let info = vk::BufferCreateInfo::default().size(256).usage(vk::BufferUsageFlags::STORAGE_BUFFER);
        // SAFETY: a valid create info on a live device; the buffer is leaked on
        // purpose, so the device is destroyed with it still alive.
        let leaked = unsafe { gpu.ctx().raw_device().create_buffer(&info, None) }.expect("buffer");
        assert_ne!(leaked, vk::Buffer::null());
        drop(gpu);
    });
    let panic = caught.expect_err("the leaked buffer went unnoticed");
    let message = panic.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(message.contains("VkBuffer"), "the failure does not name the leaked buffer: {message}");
}

#[test]
fn headless_context_is_validation_clean() {
    let log = ValidationLog::new();
    let ctx = GpuContext::headless(&ContextOptions::validated(&log)).expect("headless context");
    assert!(ctx.is_owned());
    let info = ctx.info().clone();
    assert!(!info.name.is_empty());
    assert!(info.api_version >= vkhair::API_VERSION);
    assert!(info.max_compute_shared_memory >= 16 * 1024);
    let _profiler = GpuProfiler::new(&ctx, 2, 8).expect("profiler");
    ctx.wait_idle().expect("idle");
    drop(_profiler);
    drop(ctx);
    log.assert_clean();
}

#[test]
fn device_listing_marks_the_chosen_device() {
    let reports = vkhair::list_devices(&ContextOptions::default()).expect("list");
    assert!(!reports.is_empty());
    let chosen: Vec<_> = reports.iter().filter(|r| r.chosen).collect();
    assert_eq!(chosen.len(), 1, "exactly one device is chosen");
    assert!(chosen[0].usable.is_ok());
}

#[test]
fn forcing_an_unknown_device_is_a_typed_error() {
    let options = ContextOptions { device_name: Some("no such device 0xdeadbeef".into()), ..ContextOptions::default() };
    match GpuContext::headless(&options) {
        Err(vkhair::Error::DeviceNotUsable { name, .. }) => assert!(name.contains("deadbeef")),
        other => panic!("expected DeviceNotUsable, got {other:?}"),
    }
}

/// A minimal host: instance with validation + messenger, device made from `features`.
struct Host {
    entry: ash::Entry,
    instance: ash::Instance,
    utils: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    family: u32,
    log: Box<Mutex<Vec<String>>>,
    /// Whether `device` is still to be destroyed (see [`Host::finish`]).
    device_alive: bool,
}

unsafe extern "system" fn host_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut std::ffi::c_void,
) -> vk::Bool32 {
    if severity
        .intersects(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
    {
        // SAFETY: the loader passes valid data; `user` is the host's boxed mutex.
        let text = unsafe { CStr::from_ptr((*data).p_message) }.to_string_lossy().into_owned();
        // SAFETY: as above.
        let log = unsafe { &*(user as *const Mutex<Vec<String>>) };
        log.lock().unwrap_or_else(|e| e.into_inner()).push(text);
    }
    vk::FALSE
}

impl Host {
    fn new() -> Host {
        // SAFETY: loading the system loader.
        let entry = unsafe { ash::Entry::load() }.expect("loader");
        let log = Box::new(Mutex::new(Vec::new()));
        let app = vk::ApplicationInfo::default().api_version(vkhair::API_VERSION);
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let exts = [ash::ext::debug_utils::NAME.as_ptr()];
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&exts);
        // SAFETY: valid create info.
        let instance = unsafe { entry.create_instance(&info, None) }.expect("instance");
        let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            )
            .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
            .pfn_user_callback(Some(host_callback))
            .user_data(&*log as *const Mutex<Vec<String>> as *mut std::ffi::c_void);
        // SAFETY: the boxed log outlives the messenger (destroyed in Drop first).
        let messenger = unsafe { utils.create_debug_utils_messenger(&messenger_info, None) }.expect("messenger");
        // SAFETY: instance is alive.
        let physical = unsafe { instance.enumerate_physical_devices() }.expect("devices")[0];
        // SAFETY: as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let family = families
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
            .expect("graphics family") as u32;
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        let mut req = requirements();
        let mut chain = req.features.chain();
        let info = vk::DeviceCreateInfo::default().queue_create_infos(&queues).push_next(&mut chain);
        // SAFETY: valid create info; features were checked by the driver.
        let device = unsafe { instance.create_device(physical, &info, None) }.expect("device");
        Host { entry, instance, utils, messenger, physical, device, family, log, device_alive: true }
    }

    fn lend(&self, allocator: Option<Arc<Mutex<vkhair::gpu_allocator::vulkan::Allocator>>>) -> HostDevice {
        HostDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical_device: self.physical,
            device: self.device.clone(),
            // SAFETY: the queue was created with the device.
            graphics_queue: HostQueue {
                family: self.family,
                queue: unsafe { self.device.get_device_queue(self.family, 0) },
            },
            compute_queue: None,
            allocator,
            debug_utils: true,
            compute_full_subgroups: false,
            buffer_int64_atomics: false,
            enabled_extensions: Vec::new(),
        }
    }

    fn messages(&self) -> Vec<String> {
        self.log.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

impl Host {
    /// Destroys the host's device (its messenger still listening) and returns
    /// every message, leaks reported at destruction included.
    fn finish(mut self) -> Vec<String> {
        // SAFETY: the device is idle and nothing of it is used afterwards.
        unsafe { self.device.destroy_device(None) };
        self.device_alive = false;
        self.messages()
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // SAFETY: the host destroys what it created, in order.
        unsafe {
            if self.device_alive {
                self.device.destroy_device(None);
            }
            self.utils.destroy_debug_utils_messenger(self.messenger, None);
            self.instance.destroy_instance(None);
        }
    }
}

#[test]
fn borrowed_context_never_destroys_host_objects() {
    let host = Host::new();
    for shared_allocator in [false, true] {
        let allocator = shared_allocator.then(|| {
            let desc = vkhair::gpu_allocator::vulkan::AllocatorCreateDesc {
                instance: host.instance.clone(),
                device: host.device.clone(),
                physical_device: host.physical,
                debug_settings: Default::default(),
                buffer_device_address: false,
                allocation_sizes: Default::default(),
            };
            Arc::new(Mutex::new(vkhair::gpu_allocator::vulkan::Allocator::new(&desc).expect("allocator")))
        });
        // SAFETY: the host's objects are valid, belong together, were created with
        // vkhair's requirements and outlive the context.
        let ctx = unsafe { GpuContext::from_host(host.lend(allocator.clone())) }.expect("from_host");
        assert!(!ctx.is_owned());
        let mut profiler = GpuProfiler::new(&ctx, 2, 4).expect("profiler");
        profiler.set_enabled(true);
        drop(profiler);
        drop(ctx);
        drop(allocator);
        // The host's device still works after vkhair is gone.
        let info = vk::BufferCreateInfo::default().size(256).usage(vk::BufferUsageFlags::STORAGE_BUFFER);
        // SAFETY: the host's device is still alive.
        unsafe {
            let buffer = host.device.create_buffer(&info, None).expect("host device still usable");
            host.device.destroy_buffer(buffer, None);
            host.device.device_wait_idle().expect("idle");
        }
    }
    // Checked after the host has destroyed its device too: an object vkhair left
    // on the host's device is reported there.
    let messages = host.finish();
    assert!(messages.is_empty(), "validation: {messages:#?}");
}

#[test]
fn requirement_chain_enables_what_is_listed() {
    let mut req = requirements();
    assert_eq!(req.features.core.tessellation_shader, vk::TRUE);
    // Ribbons are pulled in the vertex stage: no geometry shader is asked of the host.
    assert_eq!(req.features.core.geometry_shader, vk::FALSE);
    assert_eq!(req.features.vulkan12.timeline_semaphore, vk::TRUE);
    assert_eq!(req.features.vulkan13.dynamic_rendering, vk::TRUE);
    assert_eq!(req.features.vulkan13.synchronization2, vk::TRUE);
    // Building the chain twice must not make a cycle.
    let _ = req.features.chain();
    let chain = req.features.chain();
    let mut next = chain.p_next as *const vk::BaseOutStructure<'_>;
    let mut links = 0;
    while !next.is_null() && links < 8 {
        // SAFETY: the chain points into `req.features`, alive here.
        next = unsafe { (*next).p_next };
        links += 1;
    }
    assert_eq!(links, 2, "features2 → vulkan12 → vulkan13");
}
