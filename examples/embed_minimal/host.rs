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
