//! A minimal host embedding vkhair.
//!
//! The host owns everything Vulkan: it creates its instance (with validation
//! and a messenger of its own), picks a device and enables what
//! `vkhair::requirements()` lists, creates its allocator, its color and depth
//! images and its command buffer, and draws its own head mesh with its own
//! pipeline and vertex buffer. It lends the device, queue and allocator to
//! vkhair with `GpuContext::from_host`, then every frame records vkhair's
//! simulation step and hair passes into its own command buffer between its
//! own work, and submits. vkhair never destroys the host's objects.
//!
//! `cargo run --example embed_minimal` writes `embed_minimal.png`; the test
//! `tests/embed_example.rs` runs the same code under validation.

use std::ffi::c_void;
use std::sync::{Arc, Mutex};

use ash::vk;
use glam::Vec3;
use gpu_allocator::vulkan::{Allocation, Allocator, AllocatorCreateDesc};
use gpu_allocator::MemoryLocation;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;
use vkhair::render::{Camera, Light, RenderParams, RenderTarget, Renderer};
use vkhair::sim::{motion, HairSim, RigidTransform, SimParams};
use vkhair::{ash, gpu_allocator, requirements, GpuContext, GpuProfiler, HostDevice, HostQueue};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;
const COLOR: vk::Format = vk::Format::R8G8B8A8_UNORM;
const DEPTH: vk::Format = vk::Format::D32_SFLOAT;
const HEAD_RGB: [u8; 3] = [140, 105, 85];

#[path = "host.rs"]
mod host;

use host::{
    allocate, cleared, graphics_pipeline, on_message, transition, BoxError, Memory, PipelineDesc, HEAD_FRAG, HEAD_VERT,
    MESH_VERTEX_ATTRIBUTES, MESH_VERTEX_BINDINGS,
};

/// What a run produced.
pub struct Outcome {
    /// RGBA8 pixels, rows top to bottom.
    pub pixels: Vec<u8>,
    /// Validation warnings and errors the host's messenger received.
    pub validation_messages: Vec<String>,
    /// The per-pass timings of the last frame.
    pub timings: String,
}

/// Runs `frames` frames of the `thesis` scene; `validation` enables the layer.
pub fn run(frames: usize, validation: bool) -> Result<Outcome, BoxError> {
    // ---- The host's instance, device, queue and allocator -------------------
    // SAFETY: loading the system Vulkan loader.
    let entry = unsafe { ash::Entry::load() }?;
    let log: Box<Mutex<Vec<String>>> = Box::new(Mutex::new(Vec::new()));
    let app = vk::ApplicationInfo::default().api_version(vkhair::API_VERSION);
    let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
    let extensions = [ash::ext::debug_utils::NAME.as_ptr(), ash::ext::validation_features::NAME.as_ptr()];
    let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
    let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
        .message_type(vk::DebugUtilsMessageTypeFlagsEXT::GENERAL | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION)
        .pfn_user_callback(Some(on_message))
        .user_data(&*log as *const Mutex<Vec<String>> as *mut c_void);
    let mut instance_info =
        vk::InstanceCreateInfo::default().application_info(&app).enabled_extension_names(&extensions[..1]);
    if validation {
        // The layer with synchronization validation, its messages into `log`.
        instance_info = instance_info
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions)
            .push_next(&mut features)
            .push_next(&mut messenger_info);
    }
    // SAFETY: valid create info; everything is destroyed at the end of `run`.
    let instance = unsafe { entry.create_instance(&instance_info, None) }?;
    let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
    // SAFETY: the boxed log outlives the messenger.
    let messenger = unsafe { utils.create_debug_utils_messenger(&messenger_info, None) }?;
    // SAFETY: the instance is alive.
    let physical = unsafe { instance.enumerate_physical_devices() }?.into_iter().next().ok_or("no Vulkan device")?;
    // SAFETY: as above.
    let family = unsafe { instance.get_physical_device_queue_family_properties(physical) }
        .iter()
        .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
        .ok_or("no graphics queue")? as u32;
    let mut req = requirements();
    let priorities = [1.0];
    let queue_infos = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
    let mut features = req.features.chain();
    let device_info = vk::DeviceCreateInfo::default().queue_create_infos(&queue_infos).push_next(&mut features);
    // SAFETY: the features come from vkhair::requirements(); the driver checks them.
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

    let result = frames_with(&entry, &instance, physical, &device, family, queue, &allocator, frames);

    // ---- Teardown: the host destroys what it created, after vkhair is gone ---
    drop(allocator);
    // SAFETY: every object made from these handles is destroyed by now.
    unsafe {
        device.destroy_device(None);
        utils.destroy_debug_utils_messenger(messenger, None);
        instance.destroy_instance(None);
    }
    let (pixels, timings) = result?;
    let validation_messages = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
    Ok(Outcome { pixels, validation_messages, timings })
}

#[allow(clippy::too_many_arguments)]
fn frames_with(
    entry: &ash::Entry,
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    device: &ash::Device,
    family: u32,
    queue: vk::Queue,
    allocator: &Arc<Mutex<Allocator>>,
    frames: usize,
) -> Result<(Vec<u8>, String), BoxError> {
    // ---- vkhair on the host's device -------------------------------------
    // SAFETY: the handles are valid, belong together, were created with vkhair's
    // requirements and outlive every vkhair object (dropped before this returns).
    let ctx = unsafe {
        GpuContext::from_host(HostDevice {
            entry: entry.clone(),
            instance: instance.clone(),
            physical_device: physical,
            device: device.clone(),
            graphics_queue: HostQueue { family, queue },
            compute_queue: None,
            allocator: Some(allocator.clone()),
            debug_utils: true,
            compute_full_subgroups: false,
            buffer_int64_atomics: false,
            enabled_extensions: Vec::new(),
        })
    }?;
    let params = SimParams::default();
    let mut sim = HairSim::new(&ctx, &scenes::thesis()?, &params, &RigidTransform::default())?;
    sim.set_colliders(&motion::thesis_colliders())?;
    let mut renderer = Renderer::new(&ctx, &sim, &RenderParams::default())?;
    renderer.set_lights(&[
        Light::Directional { direction: Vec3::new(0.3, -0.4, -1.0), color: Vec3::splat(0.9) },
        Light::Directional { direction: Vec3::new(-0.7, -0.2, -0.4), color: Vec3::splat(0.3) },
    ])?;
    let mut profiler = GpuProfiler::new(&ctx, 1, 32)?;
    let center = scenes::THESIS_HEAD_CENTER;
    let camera = Camera::look_at(
        center + Vec3::new(0.0, -0.05, 0.7),
        center - Vec3::new(0.0, 0.1, 0.0),
        0.8,
        WIDTH as f32 / HEIGHT as f32,
        0.05,
        10.0,
    )?;

    // ---- The host's own resources ------------------------------------------
    let mut owned_memory = Vec::new();
    let mut make_image = |format: vk::Format,
                          usage: vk::ImageUsageFlags,
                          aspect: vk::ImageAspectFlags,
                          name: &str|
     -> Result<(vk::Image, vk::ImageView), BoxError> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: WIDTH, height: HEIGHT, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .usage(usage);
        // SAFETY: valid create info; destroyed below.
        let image = unsafe { device.create_image(&info, None) }?;
        // SAFETY: the image is alive.
        let a = allocate(
            allocator,
            name,
            unsafe { device.get_image_memory_requirements(image) },
            MemoryLocation::GpuOnly,
            false,
        )?;
        // SAFETY: memory from an allocation for this image.
        unsafe { device.bind_image_memory(image, a.memory(), a.offset()) }?;
        owned_memory.push(Memory(Some(a)));
        let range = vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(range);
        // SAFETY: valid create info; destroyed below.
        let view = unsafe { device.create_image_view(&view_info, None) }?;
        Ok((image, view))
    };
    let (color, color_view) = make_image(
        COLOR,
        vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
        vk::ImageAspectFlags::COLOR,
        "host color",
    )?;
    // Transfer source: vkhair's compute rasteriser copies the depth out.
    let depth_usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let (depth, depth_view) = make_image(DEPTH, depth_usage, vk::ImageAspectFlags::DEPTH, "host depth")?;
    let make_buffer = |size: u64,
                       usage: vk::BufferUsageFlags,
                       location: MemoryLocation,
                       name: &str|
     -> Result<(vk::Buffer, Allocation), BoxError> {
        // SAFETY: valid create info; destroyed below.
        let buffer = unsafe { device.create_buffer(&vk::BufferCreateInfo::default().size(size).usage(usage), None) }?;
        // SAFETY: the buffer is alive.
        let a = allocate(allocator, name, unsafe { device.get_buffer_memory_requirements(buffer) }, location, true)?;
        // SAFETY: memory from an allocation for this buffer.
        unsafe { device.bind_buffer_memory(buffer, a.memory(), a.offset()) }?;
        Ok((buffer, a))
    };
    // The head: interleaved position + normal, in host-visible memory.
    let mesh = TriMesh::uv_sphere(center, 0.097, 24, 32)?;
    let mut vertices: Vec<f32> = Vec::new();
    for t in 0..mesh.triangles.len() {
        let n = mesh.scaled_normal(t).normalize_or_zero();
        for p in mesh.corners(t) {
            vertices.extend_from_slice(&[p.x, p.y, p.z, n.x, n.y, n.z]);
        }
    }
    let (vertex_buffer, mut vertex_memory) = make_buffer(
        (vertices.len() * 4) as u64,
        vk::BufferUsageFlags::VERTEX_BUFFER,
        MemoryLocation::CpuToGpu,
        "host head vertices",
    )?;
    vertex_memory.mapped_slice_mut().ok_or("vertex memory not mapped")?[..vertices.len() * 4]
        .copy_from_slice(bytemuck::cast_slice(&vertices));
    let (readback, readback_memory) = make_buffer(
        u64::from(WIDTH * HEIGHT * 4),
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
        "host readback",
    )?;

    // The head pipeline (the host's own shaders).
    let push_range = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::VERTEX, offset: 0, size: 128 }];
    // SAFETY: valid create info; destroyed below.
    let layout = unsafe {
        device.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push_range), None)
    }?;
    let head = PipelineDesc {
        vert: HEAD_VERT,
        frag: HEAD_FRAG,
        names: ("head.vert", "head.frag"),
        vertex_input: vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&MESH_VERTEX_BINDINGS)
            .vertex_attribute_descriptions(&MESH_VERTEX_ATTRIBUTES),
        cull: vk::CullModeFlags::BACK,
        colors: &[COLOR],
        depth: Some(DEPTH),
        viewport: Some(vk::Extent2D { width: WIDTH, height: HEIGHT }),
    };
    let pipeline = graphics_pipeline(device, layout, &head)?;
    let scissor = vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width: WIDTH, height: HEIGHT } };

    // SAFETY: valid create infos; destroyed below.
    let pool = unsafe {
        device.create_command_pool(
            &vk::CommandPoolCreateInfo::default()
                .queue_family_index(family)
                .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
            None,
        )
    }?;
    // SAFETY: the pool is alive.
    let cmd = unsafe {
        device.allocate_command_buffers(
            &vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(1),
        )
    }?[0];
    // SAFETY: valid create info.
    let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }?;

    let color_range = vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    };
    let depth_range = vk::ImageSubresourceRange { aspect_mask: vk::ImageAspectFlags::DEPTH, ..color_range };
    let mut timings = String::new();
    for frame in 0..frames {
        let head = motion::reference_motion((frame + 1) as f32 * 2.0 * params.dt);
        // SAFETY: the host records its own command buffer; vkhair's calls get it in
        // the recording state, outside render passes; the previous frame completed.
        unsafe {
            device.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )?;
            if let Some(report) = profiler.begin_frame(cmd, frame as u64) {
                timings = report.to_string();
            }
            // vkhair: two simulation steps and the geometry passes.
            sim.record_step(cmd, &motion::reference_motion((frame * 2 + 1) as f32 * params.dt), Some(&mut profiler))?;
            sim.record_step(cmd, &head, Some(&mut profiler))?;
            renderer.record_prepare(cmd, &sim, Some(&camera), Some(&mut profiler))?;
            // Host: clear and draw the head.
            let depth_tests =
                vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
            let depth_access =
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ;
            let to_attachment = [
                transition(
                    (color, color_range),
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_READ),
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                ),
                transition(
                    (depth, depth_range),
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                    (depth_tests, depth_access),
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL),
                ),
            ];
            device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
            let clear_color = vk::ClearValue { color: vk::ClearColorValue { float32: [0.05, 0.06, 0.08, 1.0] } };
            let clear_depth = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
            let color_attachment = [cleared(color_view, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, clear_color)];
            let depth_attachment = cleared(depth_view, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL, clear_depth);
            let rendering = vk::RenderingInfo::default()
                .render_area(scissor)
                .layer_count(1)
                .color_attachments(&color_attachment)
                .depth_attachment(&depth_attachment);
            device.cmd_begin_rendering(cmd, &rendering);
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            device.cmd_bind_vertex_buffers(cmd, 0, &[vertex_buffer], &[0]);
            let model = head.matrix();
            let push: [[[f32; 4]; 4]; 2] =
                [(camera.projection * camera.view * model).to_cols_array_2d(), model.to_cols_array_2d()];
            device.cmd_push_constants(cmd, layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::cast_slice(&push));
            device.cmd_draw(cmd, (vertices.len() / 6) as u32, 1, 0, 0);
            device.cmd_end_rendering(cmd);
            // vkhair: the hair into the host's images, depth-tested against the head.
            let target = RenderTarget {
                color: color_view,
                color_format: COLOR,
                depth: depth_view,
                depth_format: DEPTH,
                depth_image: depth,
                velocity: vk::ImageView::null(),
                velocity_format: vk::Format::UNDEFINED,
                extent: scissor.extent,
                samples: vk::SampleCountFlags::TYPE_1,
            };
            renderer.record_draw(cmd, frame as u64, &target, &camera, Some(&mut profiler))?;
            // Host: copy the image out.
            let to_copy = [transition(
                (color, color_range),
                (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE),
                (vk::PipelineStageFlags2::COPY, vk::AccessFlags2::TRANSFER_READ),
                (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
            )];
            device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_copy));
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D { width: WIDTH, height: HEIGHT, depth: 1 });
            device.cmd_copy_image_to_buffer(cmd, color, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, readback, &[region]);
            let to_host = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)];
            device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&to_host));
            device.end_command_buffer(cmd)?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            device.queue_submit2(queue, &[vk::SubmitInfo2::default().command_buffer_infos(&cmds)], fence)?;
            device.wait_for_fences(&[fence], true, 60_000_000_000)?;
            device.reset_fences(&[fence])?;
        }
    }
    if let Some(report) = profiler.drain().pop() {
        timings = report.to_string();
    }
    let pixels = readback_memory.mapped_slice().ok_or("readback not mapped")?[..(WIDTH * HEIGHT * 4) as usize].to_vec();

    // vkhair's objects go first; then the host's own.
    drop((renderer, sim, profiler, ctx));
    // SAFETY: the last submission completed (its fence was waited on).
    unsafe {
        device.destroy_fence(fence, None);
        device.destroy_command_pool(pool, None);
        device.destroy_pipeline(pipeline, None);
        device.destroy_pipeline_layout(layout, None);
        device.destroy_image_view(color_view, None);
        device.destroy_image_view(depth_view, None);
        device.destroy_image(color, None);
        device.destroy_image(depth, None);
        device.destroy_buffer(vertex_buffer, None);
        device.destroy_buffer(readback, None);
    }
    let mut allocations = vec![Memory(Some(vertex_memory)), Memory(Some(readback_memory))];
    allocations.extend(owned_memory);
    allocations.iter_mut().for_each(|m| m.free(allocator));
    Ok((pixels, timings))
}

/// Counts (hair, head) pixels: hair is anything neither background nor head-coloured.
pub fn classify(pixels: &[u8]) -> (usize, usize) {
    let background = [13u8, 15, 20];
    let near = |p: &[u8], c: [u8; 3]| p.iter().zip(c).all(|(a, b)| a.abs_diff(b) <= 40);
    let mut hair = 0;
    let mut head = 0;
    for p in pixels.chunks_exact(4) {
        if near(&p[..3], background) && p[2] >= p[0] {
            continue;
        }
        if near(&p[..3], HEAD_RGB) && p[0] > p[2] + 20 && p[0] > 100 {
            head += 1;
        } else {
            hair += 1;
        }
    }
    (hair, head)
}

#[allow(dead_code)]
fn main() -> Result<(), BoxError> {
    let outcome = run(12, std::env::var("VKHAIR_VALIDATION").is_ok_and(|v| v == "1"))?;
    let file = std::io::BufWriter::new(std::fs::File::create("embed_minimal.png")?);
    let mut encoder = png::Encoder::new(file, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&outcome.pixels)?;
    let (hair, head) = classify(&outcome.pixels);
    println!("{}\nhair pixels {hair}, head pixels {head}; wrote embed_minimal.png", outcome.timings);
    for m in &outcome.validation_messages {
        eprintln!("validation: {m}");
    }
    Ok(())
}
