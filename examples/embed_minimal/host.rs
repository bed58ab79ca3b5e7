//! The host's own helpers: its validation messenger, its head shaders and
//! their compilation, its allocations, barriers and attachments. Nothing here
//! is vkhair's.

use std::ffi::{c_void, CStr};
use std::sync::Mutex;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::MemoryLocation;
use vkhair::{ash, gpu_allocator};

pub type BoxError = Box<dyn std::error::Error>;

/// The host's validation messenger: warnings and errors into a `Mutex<Vec<String>>`.
pub unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    if severity
        .intersects(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
    {
        // SAFETY: the loader passes valid data; `user` is the host's boxed mutex.
        let text = unsafe { CStr::from_ptr((*data).p_message) }.to_string_lossy().into_owned();
        // SAFETY: as above; the box outlives the messenger.
        let log = unsafe { &*(user as *const Mutex<Vec<String>>) };
        log.lock().unwrap_or_else(|e| e.into_inner()).push(text);
    }
    vk::FALSE
}

pub const HEAD_VERT: &str = r#"#version 460
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(push_constant) uniform Push { mat4 mvp; mat4 model; } pc;
layout(location = 0) out vec3 v_normal;
void main() {
    v_normal = mat3(pc.model) * normal;
    gl_Position = pc.mvp * vec4(position, 1.0);
}
"#;

pub const HEAD_FRAG: &str = r#"#version 460
layout(location = 0) in vec3 v_normal;
layout(location = 0) out vec4 color;
void main() {
    float l = max(dot(normalize(v_normal), normalize(vec3(0.3, 0.4, 0.9))), 0.0);
    color = vec4(vec3(0.55, 0.41, 0.33) * (0.35 + 0.65 * l), 1.0);
}
"#;

/// Compiles a head shader.
pub fn compile(source: &str, kind: shaderc::ShaderKind, name: &str) -> Result<Vec<u32>, BoxError> {
    let compiler = shaderc::Compiler::new()?;
    let mut options = shaderc::CompileOptions::new()?;
    options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
    Ok(compiler.compile_into_spirv(source, kind, name, "main", Some(&options))?.as_binary().to_vec())
}

/// A host graphics pipeline: a vertex and a fragment shader (GLSL), drawing
/// triangles into `colors` (written whole, no blending) and, with a depth
/// format, testing (`LESS`) and writing depth.
pub struct PipelineDesc<'a> {
    pub vert: &'a str,
    pub frag: &'a str,
    /// Names for the compiler's messages.
    pub names: (&'a str, &'a str),
    pub vertex_input: vk::PipelineVertexInputStateCreateInfo<'a>,
    pub cull: vk::CullModeFlags,
    pub colors: &'a [vk::Format],
    pub depth: Option<vk::Format>,
    /// A fixed viewport and scissor of this extent, else both dynamic state.
    pub viewport: Option<vk::Extent2D>,
}

/// The pipeline `desc` describes, with `layout` (the shader modules are
/// destroyed once it exists).
pub fn graphics_pipeline(
    device: &ash::Device,
    layout: vk::PipelineLayout,
    desc: &PipelineDesc<'_>,
) -> Result<vk::Pipeline, BoxError> {
    let vert = compile(desc.vert, shaderc::ShaderKind::Vertex, desc.names.0)?;
    let frag = compile(desc.frag, shaderc::ShaderKind::Fragment, desc.names.1)?;
    // SAFETY: SPIR-V from shaderc; destroyed below once the pipeline exists.
    let modules = unsafe {
        [
            device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&vert), None)?,
            device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&frag), None)?,
        ]
    };
    let stage = |stage, module| vk::PipelineShaderStageCreateInfo::default().stage(stage).module(module).name(c"main");
    let stages = [stage(vk::ShaderStageFlags::VERTEX, modules[0]), stage(vk::ShaderStageFlags::FRAGMENT, modules[1])];
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let (viewports, scissors) = match desc.viewport {
        Some(extent) => (vec![full_viewport(extent)], vec![vk::Rect2D { offset: vk::Offset2D::default(), extent }]),
        None => (Vec::new(), Vec::new()),
    };
    let viewport_state = match desc.viewport {
        Some(_) => vk::PipelineViewportStateCreateInfo::default().viewports(&viewports).scissors(&scissors),
        None => vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1),
    };
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(desc.cull)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample =
        vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth_state = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(desc.depth.is_some())
        .depth_write_enable(desc.depth.is_some())
        .depth_compare_op(vk::CompareOp::LESS);
    let blend_attachments: Vec<_> = desc
        .colors
        .iter()
        .map(|_| vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA))
        .collect();
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dynamic: &[vk::DynamicState] =
        if desc.viewport.is_some() { &[] } else { &[vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR] };
    let dynamic_state = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(dynamic);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(desc.colors)
        .depth_attachment_format(desc.depth.unwrap_or(vk::Format::UNDEFINED));
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&desc.vertex_input)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport_state)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth_state)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic_state)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: every pointer refers to locals alive for the call.
    let created = unsafe { device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
    // SAFETY: the modules are no longer needed once the pipeline exists (or failed).
    unsafe { modules.iter().for_each(|m| device.destroy_shader_module(*m, None)) };
    Ok(created.map_err(|(_, e)| e)?[0])
}

/// A viewport over the whole of `extent`, depths 0 to 1.
pub fn full_viewport(extent: vk::Extent2D) -> vk::Viewport {
    vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    }
}

/// The vertex input of a mesh of interleaved positions and normals (three
/// floats each), at locations 0 and 1.
pub const MESH_VERTEX_BINDINGS: [vk::VertexInputBindingDescription; 1] =
    [vk::VertexInputBindingDescription { binding: 0, stride: 24, input_rate: vk::VertexInputRate::VERTEX }];
/// See [`MESH_VERTEX_BINDINGS`].
pub const MESH_VERTEX_ATTRIBUTES: [vk::VertexInputAttributeDescription; 2] = [
    vk::VertexInputAttributeDescription { location: 0, binding: 0, format: vk::Format::R32G32B32_SFLOAT, offset: 0 },
    vk::VertexInputAttributeDescription { location: 1, binding: 0, format: vk::Format::R32G32B32_SFLOAT, offset: 12 },
];

/// A host buffer or image with its allocation.
pub struct Memory(pub Option<Allocation>);

impl Memory {
    pub fn free(&mut self, allocator: &Mutex<Allocator>) {
        if let Some(a) = self.0.take() {
            let _ = allocator.lock().unwrap_or_else(|e| e.into_inner()).free(a);
        }
    }
}

/// Allocates memory for a host buffer or image.
pub fn allocate(
    allocator: &Mutex<Allocator>,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation, BoxError> {
    Ok(allocator.lock().unwrap_or_else(|e| e.into_inner()).allocate(&AllocationCreateDesc {
        name,
        requirements,
        location,
        linear,
        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
    })?)
}

/// The host's image barrier: `image` moves from `src` (stage, access) and layout
/// `layouts.0` to `dst` and `layouts.1`.
pub fn transition(
    (image, range): (vk::Image, vk::ImageSubresourceRange),
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    layouts: (vk::ImageLayout, vk::ImageLayout),
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .image(image)
        .subresource_range(range)
}

/// An attachment the host clears and stores.
pub fn cleared(
    view: vk::ImageView,
    layout: vk::ImageLayout,
    clear: vk::ClearValue,
) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(layout)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(clear)
}
