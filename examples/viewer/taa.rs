//! The viewer as a TAA host (key J, `--taa`): the scene drawn into an image of
//! its own through a camera jittered by a Halton(2, 3) sequence of eight
//! sub-pixel offsets, vkhair's hair with it writing motion vectors into a
//! velocity image (key V, `--no-motion-vectors` to leave them out), and a
//! resolve that blends each pixel with the history — the previous output,
//! fetched where the pixel was in the previous frame — clamped to the pixel's
//! 3 × 3 neighbourhood, into the swapchain image.
//!
//! Where the hair wrote no motion, the host's own: its floor and head stand
//! still, so their pixels moved with the camera alone, found from the depth
//! (reprojected by the previous frame's unjittered view and projection). A
//! `--gltf` character's skinned body moves and writes no motion of its own
//! here (an engine's meshes would): under TAA it trails.
//! Without the hair's motion vectors its pixels are reprojected so too, as if
//! the hair stood still with the head: simulated hair then smears and ghosts
//! as it swings.

use std::sync::Mutex;

use ash::vk;
use glam::{Mat4, Vec2};
use gpu_allocator::vulkan::Allocator;
use gpu_allocator::MemoryLocation;
use vkhair::render::Camera;
use vkhair::{ash, gpu_allocator};

use crate::host::{allocate, graphics_pipeline, transition, BoxError, Memory, PipelineDesc};
use crate::swapchain::range;

/// What the host's velocity image holds where the hair wrote no motion
/// (larger than any motion in pixels the half floats carry here).
pub const NO_MOTION: f32 = 30000.0;
/// The history's format (linear light).
const HISTORY: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// The velocity image's format.
pub const VELOCITY: vk::Format = vk::Format::R16G16_SFLOAT;
/// How much of the current frame a resolved pixel takes.
const BLEND: f32 = 0.1;

const VERT: &str = r#"#version 460
void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"#;

const FRAG: &str = r#"#version 460
layout(set = 0, binding = 0) uniform sampler2D current;
layout(set = 0, binding = 1) uniform sampler2D history;
layout(set = 0, binding = 2) uniform sampler2D velocity;
layout(set = 0, binding = 3) uniform sampler2D depth;
layout(push_constant) uniform Push {
    mat4 reproject; // unjittered NDC of this frame → clip of the previous frame
    vec2 jitter;    // this frame's, pixels
    float blend;    // the share of the current frame
    uint valid;     // 0: no history yet
} pc;
layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_history;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = textureSize(current, 0) - 1;
    vec2 size = vec2(last + 1);
    vec3 c = texelFetch(current, p, 0).rgb;
    vec3 lo = c;
    vec3 hi = c;
    for (int dy = -1; dy <= 1; dy++) {
        for (int dx = -1; dx <= 1; dx++) {
            vec3 n = texelFetch(current, clamp(p + ivec2(dx, dy), ivec2(0), last), 0).rgb;
            lo = min(lo, n);
            hi = max(hi, n);
        }
    }
    vec2 v = texelFetch(velocity, p, 0).xy;
    if (v.x >= 29000.0) {
        // The host's still geometry: where the camera saw this point before.
        vec2 ndc = (gl_FragCoord.xy - pc.jitter) / size * 2.0 - 1.0;
        vec4 before = pc.reproject * vec4(ndc, texelFetch(depth, p, 0).r, 1.0);
        v = (ndc - before.xy / before.w) * 0.5 * size;
    }
    vec2 uv = (gl_FragCoord.xy - v) / size;
    bool inside = all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)));
    vec3 h = clamp(texture(history, uv).rgb, lo, hi);
    vec3 result = pc.valid != 0u && inside ? mix(h, c, pc.blend) : c;
    out_color = vec4(result, 1.0);
    out_history = vec4(result, 1.0);
}
"#;

/// An image and its view.
pub type ImageAndView = (vk::Image, vk::ImageView);

/// An image, its view and memory.
struct Target {
    image: vk::Image,
    view: vk::ImageView,
    memory: Memory,
}

/// The images of one extent.
struct Images {
    extent: vk::Extent2D,
    /// The depth view the sets read (a new swapchain brings a new one).
    depth_view: vk::ImageView,
    scene: Target,
    velocity: Target,
    history: [Target; 2],
}

/// The TAA pass: its pipeline, samplers and sets, and the images of the
/// current extent.
pub struct Taa {
    device: ash::Device,
    set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    /// Set `i` reads history `1 − i` (written by the frame before).
    sets: [vk::DescriptorSet; 2],
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    linear: vk::Sampler,
    nearest: vk::Sampler,
    scene_format: vk::Format,
    images: Option<Images>,
    /// Whether TAA runs (key J).
    pub on: bool,
    /// Whether vkhair writes the hair's motion vectors (key V).
    pub motion_vectors: bool,
    /// Frames resolved since the history was last started afresh.
    frames: u64,
    /// The previous frame's unjittered view and projection.
    previous: Mat4,
}

impl Taa {
    /// The pass for a swapchain of `format`.
    pub fn new(device: &ash::Device, format: vk::Format, on: bool, motion_vectors: bool) -> Result<Taa, BoxError> {
        let sampler = |filter| {
            vk::SamplerCreateInfo::default()
                .mag_filter(filter)
                .min_filter(filter)
                .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        };
        let bindings: Vec<_> = (0..4)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::FRAGMENT)
            })
            .collect();
        let sizes = [vk::DescriptorPoolSize { ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER, descriptor_count: 8 }];
        let push = [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::FRAGMENT, offset: 0, size: 80 }];
        // SAFETY: valid create infos; everything is destroyed in `destroy`.
        let (linear, nearest, set_layout, pool, layout) = unsafe {
            let linear = device.create_sampler(&sampler(vk::Filter::LINEAR), None)?;
            let nearest = device.create_sampler(&sampler(vk::Filter::NEAREST), None)?;
            let set_layout = device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )?;
            let pool = device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default().max_sets(2).pool_sizes(&sizes),
                None,
            )?;
            let layouts = [set_layout];
            let layout = device.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts).push_constant_ranges(&push),
                None,
            )?;
            (linear, nearest, set_layout, pool, layout)
        };
        let set_layouts = [set_layout, set_layout];
        // SAFETY: the pool holds two sets of this layout.
        let sets = unsafe {
            device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&set_layouts),
            )?
        };
        let pipeline = pipeline(device, layout, format)?;
        Ok(Taa {
            device: device.clone(),
            set_layout,
            pool,
            sets: [sets[0], sets[1]],
            layout,
            pipeline,
            linear,
            nearest,
            scene_format: format,
            images: None,
            on,
            motion_vectors,
            frames: 0,
            previous: Mat4::IDENTITY,
        })
    }

    /// Starts the history afresh (a toggle, a resize, a reset).
    pub fn restart(&mut self) {
        self.frames = 0;
    }

    /// This frame's jitter, pixels: Halton(2, 3), eight offsets within ±0.5.
    pub fn jitter(&self) -> Vec2 {
        let halton = |mut i: u64, base: u64| {
            let (mut f, mut r) = (1.0f32, 0.0f32);
            while i > 0 {
                f /= base as f32;
                r += f * (i % base) as f32;
                i /= base;
            }
            r
        };
        let i = self.frames % 8 + 1;
        Vec2::new(halton(i, 2), halton(i, 3)) - 0.5
    }

    /// The scene image and the velocity image for a frame of `extent` (made
    /// for a new extent or swapchain; the device is idle then), as (image,
    /// view) pairs.
    pub fn images(
        &mut self,
        allocator: &Mutex<Allocator>,
        extent: vk::Extent2D,
        depth_view: vk::ImageView,
    ) -> Result<(ImageAndView, ImageAndView), BoxError> {
        let fits = self.images.as_ref().is_some_and(|i| i.extent == extent && i.depth_view == depth_view);
        if !fits {
            self.free_images(allocator);
            let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
            let scene = self.target(allocator, extent, self.scene_format, usage, "viewer TAA scene")?;
            let velocity = self.target(allocator, extent, VELOCITY, usage, "viewer TAA velocity")?;
            let history = [
                self.target(allocator, extent, HISTORY, usage, "viewer TAA history 0")?,
                self.target(allocator, extent, HISTORY, usage, "viewer TAA history 1")?,
            ];
            let images = Images { extent, depth_view, scene, velocity, history };
            for (i, &set) in self.sets.iter().enumerate() {
                let read = |view, sampler| {
                    [vk::DescriptorImageInfo {
                        sampler,
                        image_view: view,
                        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    }]
                };
                let infos = [
                    read(images.scene.view, self.nearest),
                    read(images.history[1 - i].view, self.linear),
                    read(images.velocity.view, self.nearest),
                    [vk::DescriptorImageInfo {
                        sampler: self.nearest,
                        image_view: depth_view,
                        image_layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
                    }],
                ];
                let writes: Vec<_> = infos
                    .iter()
                    .enumerate()
                    .map(|(b, info)| {
                        vk::WriteDescriptorSet::default()
                            .dst_set(set)
                            .dst_binding(b as u32)
                            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                            .image_info(info)
                    })
                    .collect();
                // SAFETY: the sets are not in use (the device is idle on a new extent).
                unsafe { self.device.update_descriptor_sets(&writes, &[]) };
            }
            self.images = Some(images);
            self.frames = 0;
        }
        let i = self.images.as_ref().ok_or("no TAA images")?;
        Ok(((i.scene.image, i.scene.view), (i.velocity.image, i.velocity.view)))
    }

    fn target(
        &self,
        allocator: &Mutex<Allocator>,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        name: &str,
    ) -> Result<Target, BoxError> {
        let d = &self.device;
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .usage(usage);
        // SAFETY: valid create info; destroyed in `free_images`.
        let image = unsafe { d.create_image(&info, None) }?;
        // SAFETY: the image is alive.
        let requirements = unsafe { d.get_image_memory_requirements(image) };
        let memory = allocate(allocator, name, requirements, MemoryLocation::GpuOnly, false)?;
        // SAFETY: memory allocated for this image.
        unsafe { d.bind_image_memory(image, memory.memory(), memory.offset()) }?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(range(vk::ImageAspectFlags::COLOR));
        // SAFETY: valid create info; destroyed in `free_images`.
        let view = unsafe { d.create_image_view(&view_info, None) }?;
        Ok(Target { image, view, memory: Memory(Some(memory)) })
    }

    /// Records the resolve of the frame seen by `camera` (jittered by
    /// `jitter`) into `output` (the swapchain image and view, in any layout;
    /// left in `COLOR_ATTACHMENT_OPTIMAL`). The scene and velocity images hold
    /// the frame in `COLOR_ATTACHMENT_OPTIMAL`, `depth` its depth in
    /// `DEPTH_ATTACHMENT_OPTIMAL`; all three are left read-only for the
    /// shader (the next frame starts them afresh).
    ///
    /// # Safety
    /// `cmd` is recording outside rendering; the images are this frame's.
    pub unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        output: (vk::Image, vk::ImageView),
        depth: vk::Image,
        camera: &Camera,
        jitter: Vec2,
    ) -> Result<(), BoxError> {
        let d = &self.device;
        let images = self.images.as_ref().ok_or("TAA resolve before its images")?;
        let slot = (self.frames % 2) as usize;
        let written = (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE);
        let sampled = (vk::PipelineStageFlags2::FRAGMENT_SHADER, vk::AccessFlags2::SHADER_SAMPLED_READ);
        let attachment = (
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE | vk::AccessFlags2::COLOR_ATTACHMENT_READ,
        );
        let color = range(vk::ImageAspectFlags::COLOR);
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let barriers = [
            transition(
                (images.scene.image, color),
                written,
                sampled,
                (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, read_only),
            ),
            transition(
                (images.velocity.image, color),
                written,
                sampled,
                (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, read_only),
            ),
            transition(
                (depth, range(vk::ImageAspectFlags::DEPTH)),
                written,
                sampled,
                (vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL, vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL),
            ),
            // The history the previous frame wrote (a first frame reads none
            // of it), and the one it read, written now.
            transition(
                (images.history[1 - slot].image, color),
                written,
                sampled,
                (
                    if self.frames == 0 {
                        vk::ImageLayout::UNDEFINED
                    } else {
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
                    },
                    read_only,
                ),
            ),
            transition(
                (images.history[slot].image, color),
                (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                attachment,
                (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
            ),
            transition(
                (output.0, color),
                (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                attachment,
                (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
            ),
        ];
        let now = camera.projection * camera.view;
        let mut push = [0u32; 20];
        let reproject = (self.previous * now.inverse()).to_cols_array();
        for (p, v) in push.iter_mut().zip(reproject.iter().chain(&[jitter.x, jitter.y, BLEND])) {
            *p = v.to_bits();
        }
        push[19] = u32::from(self.frames > 0);
        let attachments = [output.1, images.history[slot].view].map(|view| {
            vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::DONT_CARE)
                .store_op(vk::AttachmentStoreOp::STORE)
        });
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: images.extent };
        let rendering = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&attachments);
        let viewport = crate::host::full_viewport(images.extent);
        // SAFETY: guaranteed by the caller; every object is alive.
        unsafe {
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&barriers));
            d.cmd_begin_rendering(cmd, &rendering);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.sets[slot]], &[]);
            d.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::cast_slice(&push));
            d.cmd_draw(cmd, 3, 1, 0, 0);
            d.cmd_end_rendering(cmd);
        }
        self.previous = now;
        self.frames += 1;
        Ok(())
    }

    fn free_images(&mut self, allocator: &Mutex<Allocator>) {
        if let Some(images) = self.images.take() {
            let Images { scene, velocity, history: [h0, h1], .. } = images;
            for mut t in [scene, velocity, h0, h1] {
                // SAFETY: the device is idle whenever the images are replaced or freed.
                unsafe {
                    self.device.destroy_image_view(t.view, None);
                    self.device.destroy_image(t.image, None);
                }
                t.memory.free(allocator);
            }
        }
    }

    /// Destroys everything (the device is idle).
    pub fn destroy(&mut self, allocator: &Mutex<Allocator>) {
        self.free_images(allocator);
        // SAFETY: the device is idle; nothing uses these any more.
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
            self.device.destroy_descriptor_pool(self.pool, None);
            self.device.destroy_descriptor_set_layout(self.set_layout, None);
            self.device.destroy_sampler(self.linear, None);
            self.device.destroy_sampler(self.nearest, None);
        }
    }
}

/// The resolve's pipeline: one triangle, into the swapchain's format and the history's.
fn pipeline(device: &ash::Device, layout: vk::PipelineLayout, format: vk::Format) -> Result<vk::Pipeline, BoxError> {
    let desc = PipelineDesc {
        vert: VERT,
        frag: FRAG,
        names: ("taa.vert", "taa.frag"),
        vertex_input: vk::PipelineVertexInputStateCreateInfo::default(),
        cull: vk::CullModeFlags::NONE,
        colors: &[format, HISTORY],
        depth: None,
        viewport: None,
    };
    graphics_pipeline(device, layout, &desc)
}
