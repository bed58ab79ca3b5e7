//! GPU tests of the Vulkan core. Each opens a headless context with
//! `VK_LAYER_KHRONOS_validation` and synchronization validation, and fails on
//! any warning or error message, including objects alive at device destruction.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::barrier::{self, AccessKind};
use super::buffer::{Buffer, BufferDesc};
use super::device::Device;
use super::image::{Image, ImageDesc};
use super::pipeline::{Blend, ComputePipeline, GraphicsDesc, GraphicsPipeline};
use super::reflect::{compare, gpu_struct, reflect, GpuStruct};
use super::shaders;
use crate::gpu_types::{self, LayoutProbe, ScaleAddPush};
use crate::{ContextOptions, GpuContext, GpuProfiler, ValidationLog};

/// A validated headless context that checks its log when dropped.
pub(crate) struct TestGpu {
    ctx: Option<GpuContext>,
    log: ValidationLog,
}

impl TestGpu {
    pub(crate) fn new() -> Self {
        let log = ValidationLog::new();
        let ctx = GpuContext::headless(&ContextOptions::validated(&log))
            .expect("headless context with validation (install mesa-vulkan-drivers and vulkan-validationlayers)");
        TestGpu { ctx: Some(ctx), log }
    }

    pub(crate) fn ctx(&self) -> &GpuContext {
        self.ctx.as_ref().expect("context lives until drop")
    }

    pub(crate) fn device(&self) -> &Arc<Device> {
        &self.ctx().device
    }

    /// Drops the context and returns everything validation said, without failing.
    pub(crate) fn finish_with_messages(mut self) -> Vec<crate::ValidationMessage> {
        drop(self.ctx.take());
        self.log.take()
    }
}

impl Drop for TestGpu {
    fn drop(&mut self) {
        drop(self.ctx.take());
        if !std::thread::panicking() {
            self.log.assert_clean();
        }
    }
}

fn storage(device: &Arc<Device>, name: &str, size: u64) -> Buffer {
    Buffer::storage(device, name, size).expect("buffer")
}

#[test]
fn upload_readback_round_trip() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let buffer = storage(d, "round trip", 4096);
    let bytes: Vec<u8> = (0..1000u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect();
    d.upload(&buffer, 100, &bytes).expect("upload");
    assert_eq!(d.readback(&buffer, 100, 1000).expect("readback"), bytes);
    // Partial reads see the same bytes at the same places.
    assert_eq!(d.readback(&buffer, 600, 10).expect("readback"), bytes[500..510]);
    assert!(matches!(d.upload(&buffer, 4000, &bytes), Err(crate::Error::OutOfBounds { .. })));
    assert!(matches!(d.readback(&buffer, u64::MAX, 2), Err(crate::Error::OutOfBounds { .. })));
}

#[test]
fn scale_add_matches_cpu() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let pipeline = ComputePipeline::new(d, &shaders::CORE_SCALE_ADD_COMP, 1).expect("pipeline");
    // The shader declares local_size_x = 64.
    assert_eq!(pipeline.workgroup_size(), [64, 1, 1]);
    let n = 1000usize; // not a multiple of 64: the tail must be bounds-checked
    let src: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin() * 100.0).collect();
    let sentinel = -12345.0f32;
    let src_buf = storage(d, "src", 4 * n as u64);
    let dst_buf = storage(d, "dst", 4 * (n as u64 + 64));
    d.upload_pod(&src_buf, &src).expect("upload");
    d.upload_pod(&dst_buf, &vec![sentinel; n + 64]).expect("upload");
    let set = pipeline.buffer_set(0, &[(0, &src_buf), (1, &dst_buf)]).expect("set");
    let push = ScaleAddPush { count: n as u32, scale: 1.5, bias: -2.25, pad0: 0 };
    d.submit_once("scale_add", |cmd| {
        // SAFETY: recording command buffer of this device.
        unsafe {
            pipeline.bind(cmd, &[set]);
            pipeline.push(cmd, &push);
            pipeline.dispatch_threads(cmd, [n as u32, 1, 1]);
        }
    })
    .expect("submit");
    let out: Vec<f32> = d.readback_pod(&dst_buf, n + 64).expect("readback");
    for i in 0..n {
        let expected = 1.5 * src[i] - 2.25;
        // Tolerance: the GPU may fuse the multiply-add (one rounding instead of two).
        assert!((out[i] - expected).abs() <= 1e-5 * expected.abs().max(1.0), "element {i}: {} vs {expected}", out[i]);
    }
    assert!(out[n..].iter().all(|&v| v == sentinel), "writes past count");
}

/// `scale_add` over `src` (already on the device) with `push`, binding the
/// pipeline itself (`None`) or the variant for a constant; the results.
fn scale_add_with(
    d: &Arc<Device>,
    pipeline: &ComputePipeline,
    src: &Buffer,
    push: &ScaleAddPush,
    constant: Option<u32>,
) -> Vec<f32> {
    let n = push.count as usize;
    let dst = storage(d, "dst", 4 * n as u64);
    let set = pipeline.buffer_set(0, &[(0, src), (1, &dst)]).expect("set");
    d.submit_once("scale_add variant", |cmd| {
        // SAFETY: recording command buffer of this device; what is bound is compiled.
        unsafe {
            match constant {
                None => pipeline.bind(cmd, &[set]),
                Some(c) => pipeline.bind_variant(cmd, c, &[set]),
            }
            pipeline.push(cmd, push);
            pipeline.dispatch_threads(cmd, [n as u32, 1, 1]);
        }
    })
    .expect("submit");
    d.readback_pod::<f32>(&dst, n).expect("readback")
}

#[test]
fn a_variant_sets_specialisation_constant_0() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let mut pipeline = ComputePipeline::new(d, &shaders::CORE_SCALE_ADD_COMP, 3).expect("pipeline");
    pipeline.prepare_variant(3).expect("variant");
    // Preparing it again keeps the one there is.
    pipeline.prepare_variant(3).expect("variant again");
    let n = 100usize;
    let src: Vec<f32> = (0..n).map(|i| i as f32 * 0.5).collect();
    let src_buf = storage(d, "src", 4 * n as u64);
    d.upload_pod(&src_buf, &src).expect("upload");
    let push = ScaleAddPush { count: n as u32, scale: 2.0, bias: 0.25, pad0: 0 };
    // Constant 0 (BIAS_TIMES) at its default 1, at 3 (the variant), and at 7,
    // never prepared: that binds the default pipeline.
    let results: Vec<Vec<f32>> =
        [None, Some(3), Some(7)].map(|c| scale_add_with(d, &pipeline, &src_buf, &push, c)).into();
    // Exact: the inputs and results are small multiples of powers of two.
    for (i, x) in src.iter().enumerate() {
        assert_eq!(results[0][i], 2.0 * x + 0.25, "default, element {i}");
        assert_eq!(results[1][i], 2.0 * x + 0.75, "variant 3, element {i}");
        assert_eq!(results[2][i], 2.0 * x + 0.25, "unprepared variant 7 falls back, element {i}");
    }
}

#[test]
fn a_deferred_pipeline_compiles_only_what_is_prepared() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let mut pipeline =
        ComputePipeline::deferred(d, &shaders::CORE_SCALE_ADD_COMP, 2, false).expect("deferred pipeline");
    assert!(!pipeline.is_prepared(), "nothing is compiled at creation");
    pipeline.prepare_variant(3).expect("variant");
    assert!(!pipeline.is_prepared(), "a variant compiles only itself");
    let n = 64usize;
    let src: Vec<f32> = (0..n).map(|i| i as f32).collect();
    let src_buf = storage(d, "src", 4 * n as u64);
    d.upload_pod(&src_buf, &src).expect("upload");
    let push = ScaleAddPush { count: n as u32, scale: 1.0, bias: 0.5, pad0: 0 };
    let variant = scale_add_with(d, &pipeline, &src_buf, &push, Some(3));
    pipeline.prepare().expect("prepare");
    assert!(pipeline.is_prepared());
    let default = scale_add_with(d, &pipeline, &src_buf, &push, None);
    // Exact: small integers plus multiples of a half.
    for (i, x) in src.iter().enumerate() {
        assert_eq!(variant[i], x + 1.5, "variant 3, element {i}");
        assert_eq!(default[i], x + 0.5, "default, element {i}");
    }
}

#[test]
fn layout_probe_round_trips_every_member() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let pipeline = ComputePipeline::new(d, &shaders::CORE_LAYOUT_PROBE_COMP, 1).expect("pipeline");
    let mut transform = glam::Mat4::from_scale_rotation_translation(
        glam::Vec3::new(2.0, 3.0, 4.0),
        glam::Quat::from_rotation_z(0.5),
        glam::Vec3::new(1.0, -1.0, 0.5),
    )
    .to_cols_array_2d();
    transform[3][3] = 1.0;
    let input = LayoutProbe {
        position: [0.25, -0.5, 2.0],
        radius: 0.125,
        transform,
        ids: [7, 11],
        weights: [3.5, -1.0],
        color: [0.1, 0.2, 0.3, 0.4],
    };
    let count = 40u32;
    let input_buf = storage(d, "probe input", std::mem::size_of::<LayoutProbe>() as u64);
    let out_buf = storage(d, "probe output", std::mem::size_of::<LayoutProbe>() as u64 * count as u64);
    d.upload_pod(&input_buf, &[input]).expect("upload");
    let set = pipeline.buffer_set(0, &[(0, &input_buf), (1, &out_buf)]).expect("set");
    d.submit_once("layout probe", |cmd| {
        // SAFETY: recording command buffer of this device.
        unsafe {
            pipeline.bind(cmd, &[set]);
            pipeline.push(cmd, &count);
            pipeline.dispatch_threads(cmd, [count, 1, 1]);
        }
    })
    .expect("submit");
    let out: Vec<LayoutProbe> = d.readback_pod(&out_buf, count as usize).expect("readback");
    let m = glam::Mat4::from_cols_array_2d(&input.transform);
    for (i, p) in out.iter().enumerate() {
        let expected = m.transform_point3(glam::Vec3::from(input.position)) + glam::Vec3::splat(i as f32);
        assert!((glam::Vec3::from(p.position) - expected).length() < 1e-4, "probe {i}: {:?} vs {expected}", p.position);
        assert_eq!(p.radius, input.radius);
        assert_eq!(p.transform, input.transform);
        assert_eq!(p.ids, [7 + i as u32, 11 + i as u32]);
        assert_eq!(p.weights, [3.5, 3.5 + 0.125]);
        assert_eq!(p.color, input.color);
    }
}

#[test]
fn every_shader_struct_matches_its_rust_twin() {
    let names = [
        ScaleAddPush::GLSL_NAME,
        LayoutProbe::GLSL_NAME,
        gpu_types::SimStepParams::GLSL_NAME,
        gpu_types::GpuCollider::GLSL_NAME,
        gpu_types::SmoothPush::GLSL_NAME,
        gpu_types::InterpolatePush::GLSL_NAME,
        gpu_types::GpuLight::GLSL_NAME,
        gpu_types::DrawParams::GLSL_NAME,
        gpu_types::OitCounters::GLSL_NAME,
        gpu_types::GpuMotion::GLSL_NAME,
        gpu_types::TileCounters::GLSL_NAME,
        gpu_types::MarschnerPush::GLSL_NAME,
        gpu_types::GpuVolumeParams::GLSL_NAME,
        gpu_types::VolumePush::GLSL_NAME,
        gpu_types::PcgScalars::GLSL_NAME,
        gpu_types::GpuShadowMap::GLSL_NAME,
        gpu_types::GpuShadowParams::GLSL_NAME,
    ];
    let mut found = vec![0usize; names.len()];
    for shader in shaders::ALL {
        let r = reflect(shader).expect("reflect");
        let problems = gpu_types::check_all(&r);
        assert!(problems.is_empty(), "{}: {problems:?}", shader.name);
        for (count, name) in found.iter_mut().zip(names) {
            *count += r.structs_named(name).count();
        }
    }
    // Every Rust twin is used by at least one shader, so it was really compared.
    for (count, name) in found.iter().zip(names) {
        assert!(*count > 0, "no shader uses {name}");
    }
}

/// No shader declares two resources at one binding: GLSL accepts it and the
/// two would alias one descriptor (a header's buffer landing on another
/// header's binding, as the motion depths once did on the tiled rasteriser's
/// per-tile counts).
#[test]
fn no_shader_declares_two_resources_at_one_binding() {
    let mut checked = 0;
    for shader in shaders::ALL {
        let r = reflect(shader).expect("reflect");
        let mut seen = std::collections::HashMap::new();
        for b in &r.bindings {
            if let Some(other) = seen.insert((b.set, b.binding), &b.name) {
                panic!("{}: {} and {other} both at set {} binding {}", shader.name, b.name, b.set, b.binding);
            }
        }
        checked += r.bindings.len();
    }
    assert!(checked > 100, "only {checked} bindings reflected");
}

/// Deliberately wrong twins: the comparison must reject them.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeWithoutRadius {
    position: [f32; 3],
    transform: [[f32; 4]; 4],
    ids: [u32; 2],
    weights: [f32; 2],
    color: [f32; 4],
    _pad0: f32,
}
gpu_struct!(ProbeWithoutRadius => "LayoutProbe" { position, transform, ids, weights, color, _pad0 });

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PushSwapped {
    count: u32,
    bias: f32,
    scale: f32,
    pad0: u32,
}
gpu_struct!(PushSwapped => "ScaleAddPush" { count, bias, scale, pad0 });

#[test]
fn layout_comparison_rejects_mismatches() {
    let probe = reflect(&shaders::CORE_LAYOUT_PROBE_COMP).expect("reflect");
    let layouts: Vec<_> = probe.structs_named("LayoutProbe").collect();
    assert!(!layouts.is_empty());
    for l in &layouts {
        assert!(compare::<LayoutProbe>(l).is_ok());
        let err = compare::<ProbeWithoutRadius>(l).expect_err("missing member must be reported");
        assert!(err.contains("offset"), "{err}");
    }
    let push = reflect(&shaders::CORE_SCALE_ADD_COMP).expect("reflect");
    let layout = push.structs_named("ScaleAddPush").next().expect("push struct");
    let err = compare::<PushSwapped>(layout).expect_err("swapped members must be reported");
    assert!(err.contains("bias") && err.contains("scale"), "{err}");
}

#[test]
fn reflection_reads_interfaces() {
    let r = reflect(&shaders::CORE_SCALE_ADD_COMP).expect("reflect");
    assert_eq!(r.stage, vk::ShaderStageFlags::COMPUTE);
    assert_eq!(r.workgroup_size, Some([64, 1, 1]));
    assert_eq!(r.push_constant_size, 16);
    let b: Vec<_> = r.bindings.iter().map(|b| (b.set, b.binding, b.ty, b.count)).collect();
    assert_eq!(b, [(0, 0, vk::DescriptorType::STORAGE_BUFFER, 1), (0, 1, vk::DescriptorType::STORAGE_BUFFER, 1)]);
    let v = reflect(&shaders::CORE_TRIANGLE_VERT).expect("reflect");
    assert_eq!(v.stage, vk::ShaderStageFlags::VERTEX);
    assert_eq!(v.workgroup_size, None);
    assert_eq!(v.push_constant_size, 32);
    assert!(v.bindings.is_empty());
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TrianglePush {
    color: [f32; 4],
    offset: [f32; 2],
    scale: [f32; 2],
}

#[test]
fn graphics_pipeline_draws_with_dynamic_rendering() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let format = vk::Format::R8G8B8A8_UNORM;
    let extent = vk::Extent2D { width: 64, height: 48 };
    let target = Image::new(
        d,
        &ImageDesc {
            name: "triangle target",
            extent,
            format,
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            samples: vk::SampleCountFlags::TYPE_1,
            aspect: vk::ImageAspectFlags::COLOR,
        },
    )
    .expect("image");
    let pipeline = GraphicsPipeline::new(
        d,
        &GraphicsDesc {
            name: "triangle",
            stages: &[&shaders::CORE_TRIANGLE_VERT, &shaders::CORE_TRIANGLE_FRAG],
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            patch_control_points: 0,
            color_formats: &[format],
            depth_format: vk::Format::UNDEFINED,
            samples: vk::SampleCountFlags::TYPE_1,
            depth_test: false,
            depth_write: false,
            reverse_z: false,
            blend: Blend::None,
            rasterizer_discard: false,
        },
        0,
    )
    .expect("pipeline");
    let push = TrianglePush { color: [1.0, 0.0, 0.5, 1.0], offset: [0.0, 0.0], scale: [1.6, 1.6] };
    d.submit_once("triangle", |cmd| {
        let attachment = vk::RenderingAttachmentInfo::default()
            .image_view(target.view())
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: [0.0, 0.0, 0.0, 1.0] } });
        let attachments = [attachment];
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
            .layer_count(1)
            .color_attachments(&attachments);
        // SAFETY: recording command buffer; all objects belong to this device.
        unsafe {
            d.cmd_barrier(
                cmd,
                &[],
                &[],
                &[barrier::image(
                    &target,
                    barrier::NOTHING,
                    barrier::COLOR_ATTACHMENT,
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                )],
            );
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.raw.cmd_set_viewport(
                cmd,
                0,
                &[vk::Viewport { x: 0.0, y: 0.0, width: 64.0, height: 48.0, min_depth: 0.0, max_depth: 1.0 }],
            );
            d.raw.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
            pipeline.bind(cmd, &[]);
            pipeline.push(cmd, &push);
            d.raw.cmd_draw(cmd, 3, 1, 0, 0);
            d.raw.cmd_end_rendering(cmd);
        }
    })
    .expect("draw");
    let pixels = d.readback_image(&target, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, 4).expect("readback");
    let at = |x: usize, y: usize| &pixels[(y * 64 + x) * 4..(y * 64 + x) * 4 + 4];
    assert_eq!(at(32, 24), [255, 0, 128, 255], "centre is inside the triangle");
    assert_eq!(at(1, 1), [0, 0, 0, 255], "corner keeps the clear color");
    assert_eq!(at(62, 1), [0, 0, 0, 255], "corner keeps the clear color");
    let covered = pixels.chunks_exact(4).filter(|p| p[0] == 255).count();
    // Triangle area in NDC: 0.5 · 1.6 · 1.6 = 1.28 of 4 → 32 % of 3072 pixels.
    let expected = 0.32 * 3072.0;
    assert!((covered as f64 - expected).abs() < 0.05 * expected, "covered {covered} vs {expected}");
}

#[test]
fn synchronization_validation_reports_a_missing_barrier() {
    let gpu = TestGpu::new();
    {
        let d = gpu.device();
        let pipeline = ComputePipeline::new(d, &shaders::CORE_SCALE_ADD_COMP, 1).expect("pipeline");
        let src = storage(d, "hazard src", 256);
        let dst = storage(d, "hazard dst", 256);
        let set = pipeline.buffer_set(0, &[(0, &src), (1, &dst)]).expect("set");
        let push = ScaleAddPush { count: 64, scale: 1.0, bias: 0.0, pad0: 0 };
        d.submit_once("hazard", |cmd| {
            // SAFETY: recording command buffer. The missing barrier between the fill
            // (transfer write) and the dispatch (storage read) is the point of the test.
            unsafe {
                d.raw.cmd_fill_buffer(cmd, src.raw(), 0, vk::WHOLE_SIZE, 0);
                pipeline.bind(cmd, &[set]);
                pipeline.push(cmd, &push);
                pipeline.dispatch_threads(cmd, [64, 1, 1]);
            }
        })
        .expect("submit");
    }
    let messages = gpu.finish_with_messages();
    assert!(
        messages
            .iter()
            .any(|m| m.id.contains("SYNC-HAZARD-READ-AFTER-WRITE") || m.id.contains("SYNC-HAZARD-READ_AFTER_WRITE")),
        "expected a read-after-write hazard, got {messages:#?}"
    );
}

#[test]
fn leaked_objects_are_reported_at_device_destruction() {
    let gpu = TestGpu::new();
    {
        let d = gpu.device();
        let info = vk::BufferCreateInfo::default().size(64).usage(vk::BufferUsageFlags::STORAGE_BUFFER);
        // SAFETY: valid create info; the buffer is leaked on purpose.
        let leaked = unsafe { d.raw.create_buffer(&info, None) }.expect("buffer");
        d.set_name(leaked, "deliberately leaked");
    }
    let messages = gpu.finish_with_messages();
    assert!(
        messages.iter().any(|m| m.severity == crate::Severity::Error && m.text.contains("VkBuffer")),
        "expected a leak report, got {messages:#?}"
    );
}

#[test]
fn repeated_create_and_destroy_is_clean() {
    for round in 0..3 {
        let gpu = TestGpu::new();
        let d = gpu.device();
        let buffers: Vec<Buffer> =
            (0..8).map(|i| storage(d, &format!("round {round} buffer {i}"), 1024 * (i + 1))).collect();
        let _image = Image::new(
            d,
            &ImageDesc {
                name: "round image",
                extent: vk::Extent2D { width: 32, height: 32 },
                format: vk::Format::R32_SFLOAT,
                usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::COLOR_ATTACHMENT,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )
        .expect("image");
        let pipeline = ComputePipeline::new(d, &shaders::CORE_SCALE_ADD_COMP, 4).expect("pipeline");
        let _set = pipeline.buffer_set(0, &[(0, &buffers[0]), (1, &buffers[1])]).expect("set");
        let _profiler = GpuProfiler::new(gpu.ctx(), 3, 16).expect("profiler");
        // Everything drops here, then the device; TestGpu fails on any report.
    }
}

#[test]
fn zero_sized_resources_are_rejected() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let err = Buffer::new(
        d,
        &BufferDesc {
            name: "empty",
            size: 0,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
        },
    );
    assert!(matches!(err, Err(crate::Error::InvalidParameter { .. })));
}

#[test]
fn profiler_reports_passes_frames_in_flight_later() {
    let gpu = TestGpu::new();
    let d = gpu.device();
    let pipeline = ComputePipeline::new(d, &shaders::CORE_SCALE_ADD_COMP, 1).expect("pipeline");
    let n = 1 << 16;
    let src = storage(d, "profiled src", 4 * n);
    let dst = storage(d, "profiled dst", 4 * n);
    let set = pipeline.buffer_set(0, &[(0, &src), (1, &dst)]).expect("set");
    let push = ScaleAddPush { count: n as u32, scale: 2.0, bias: 1.0, pad0: 0 };
    let frames_in_flight = 2;
    let mut profiler = GpuProfiler::new(gpu.ctx(), frames_in_flight, 4).expect("profiler");
    let mut reports = Vec::new();
    for frame in 0..5u64 {
        if frame == 3 {
            profiler.set_enabled(false);
        }
        d.submit_once("profiled frame", |cmd| {
            // SAFETY: recording command buffer; earlier frames completed (submit_once waits).
            unsafe {
                if let Some(r) = profiler.begin_frame(cmd, frame) {
                    reports.push((frame, r));
                }
                let outer = profiler.begin_scope(cmd, "frame");
                for pass in ["first", "second"] {
                    let scope = profiler.begin_scope(cmd, pass);
                    pipeline.bind(cmd, &[set]);
                    pipeline.push(cmd, &push);
                    pipeline.dispatch_threads(cmd, [n as u32, 1, 1]);
                    d.cmd_barrier(
                        cmd,
                        &[barrier::memory(&[AccessKind::ComputeWrite], barrier::COMPUTE_READ_WRITE)],
                        &[],
                        &[],
                    );
                    profiler.end_scope(cmd, scope);
                }
                profiler.end_scope(cmd, outer);
            }
        })
        .expect("submit");
    }
    // Frame f reports frame f − 2: frames 2, 3, 4 report 0, 1, 2 (frames 3 and 4 ran disabled).
    let got: Vec<(u64, u64)> = reports.iter().map(|(f, r)| (*f, r.frame)).collect();
    assert_eq!(got, [(2, 0), (3, 1), (4, 2)]);
    for (_, r) in &reports {
        let names: Vec<_> = r.passes.iter().map(|p| (p.name.as_str(), p.depth)).collect();
        assert_eq!(names, [("frame", 0), ("first", 1), ("second", 1)]);
        assert!(r.passes.iter().all(|p| p.nanoseconds > 0.0), "{r}");
        let inner: f64 = r.passes[1..].iter().map(|p| p.nanoseconds).sum();
        assert!(r.passes[0].nanoseconds >= inner, "outer scope covers inner ones: {r}");
    }
    // Disabled frames wrote no timestamps: nothing more to drain.
    assert!(profiler.drain().is_empty());
    assert_eq!(profiler.latest().map(|r| r.frame), Some(2));
}

#[test]
fn profiler_rejects_bad_parameters() {
    let gpu = TestGpu::new();
    assert!(matches!(GpuProfiler::new(gpu.ctx(), 0, 4), Err(crate::Error::InvalidParameter { .. })));
    assert!(matches!(GpuProfiler::new(gpu.ctx(), 2, 0), Err(crate::Error::InvalidParameter { .. })));
    assert!(matches!(GpuProfiler::new(gpu.ctx(), 17, 4), Err(crate::Error::InvalidParameter { .. })));
}

/// The workgroup sizes the shaders were compiled with are the constants of
/// `src/limits.rs` that build.rs injects, and every injected constant is used by
/// some shader (none is left stale on one side only).
#[test]
fn shaders_are_built_with_the_shared_constants() {
    use crate::limits;
    let expected = |name: &str| -> Option<u32> {
        let sim = ["sim/step.comp"];
        let item = ["render/shadow_volume.comp", "core/scale_add.comp", "core/shadow_probe.comp"];
        if sim.contains(&name) {
            Some(limits::SIM_WORKGROUP)
        } else if item.contains(&name) || name.starts_with("sim/sdf/") {
            Some(limits::ITEM_GROUP)
        } else if name.starts_with("sim/volume/") {
            Some(limits::VOL_GROUP)
        } else {
            None
        }
    };
    let mut checked = 0;
    for shader in shaders::ALL {
        let Some(size) = expected(shader.name) else { continue };
        let reflection = reflect(shader).expect("reflect");
        assert_eq!(reflection.workgroup_size, Some([size, 1, 1]), "{}", shader.name);
        checked += 1;
    }
    assert_eq!(
        checked, 32,
        "1 simulation, 8 per-item (5 of them the mesh collider's) and 23 volume kernels (17, 5 shared-memory \
         variants and the scatter's 64-bit one)"
    );
    let sources: String = glsl_sources().into_iter().map(|(_, text)| text).collect();
    for (name, _) in limits::SHADER_CONSTANTS {
        assert!(sources.contains(name), "{name} is injected but no shader uses it");
    }
}

/// build.rs refuses a shader that declares an injected constant itself: the
/// check finds `#define` and `const` declarations (not uses), and no shader of
/// the crate has one.
#[test]
fn shaders_may_not_redeclare_the_injected_constants() {
    use crate::codes::SHADER_CODES;
    use crate::limits::{redeclared_constants, SHADER_CONSTANTS};
    let bad = "#define VOL_GROUP 128u\nconst uint MAX_LIGHTS = 4u;\nlayout(local_size_x = VOL_GROUP) in;\n\
               // #define SIM_WORKGROUP 1\nuint n = ITEM_GROUP;\nconst uint SIM_GRAVITY = 1u;\n";
    assert_eq!(redeclared_constants(bad, SHADER_CONSTANTS), vec![(1, "VOL_GROUP"), (2, "MAX_LIGHTS")]);
    assert_eq!(redeclared_constants(bad, SHADER_CODES), vec![(6, "SIM_GRAVITY")]);
    for (path, source) in glsl_sources() {
        for table in [SHADER_CONSTANTS, SHADER_CODES] {
            assert!(redeclared_constants(&source, table).is_empty(), "{} redeclares a constant", path.display());
        }
    }
}

/// Every file under `glsl/` with its text.
fn glsl_sources() -> Vec<(std::path::PathBuf, String)> {
    let mut out = Vec::new();
    let mut dirs = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("glsl folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else {
                let text = std::fs::read_to_string(&path).expect("shader source");
                out.push((path, text));
            }
        }
    }
    out
}

/// A host including `glsl/include/shadow.glsl` in its own shaders must define
/// MAX_SHADOW_MAPS, as the README says: without it the header stops compilation
/// with a message naming the macro; with it, the host's shader compiles.
#[test]
fn shadow_header_needs_the_documented_macro() {
    let include = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl/include");
    let source = "#version 460\n#include \"shadow.glsl\"\nlayout(location = 0) out vec4 color;\nvoid main() { color = vec4(1.0); }\n";
    let compile = |define: bool| {
        let compiler = shaderc::Compiler::new().expect("compiler");
        let mut options = shaderc::CompileOptions::new().expect("options");
        options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
        if define {
            options.add_macro_definition("MAX_SHADOW_MAPS", Some(&format!("{}u", crate::render::MAX_SHADOW_MAPS)));
        }
        let include = include.clone();
        options.set_include_callback(move |name, _, _, _| {
            let path = include.join(name);
            let content = std::fs::read_to_string(&path).map_err(|e| e.to_string())?;
            Ok(shaderc::ResolvedInclude { resolved_name: path.to_string_lossy().into_owned(), content })
        });
        compiler.compile_into_spirv(source, shaderc::ShaderKind::Fragment, "host.frag", "main", Some(&options))
    };
    let error = compile(false).err().expect("fails without the macro").to_string();
    assert!(error.contains("MAX_SHADOW_MAPS"), "{error}");
    compile(true).expect("compiles with the macro");
}

/// Reflection tells read-only, write-only and read-write bindings apart (the
/// traffic counters rely on it): the step kernel reads its input half and writes
/// the other; a volume kernel both reads and writes its labels.
#[test]
fn reflection_reads_the_access_of_each_binding() {
    let step = reflect(&shaders::SIM_STEP_COMP).expect("reflect");
    let access = |r: &crate::vk::reflect::Reflection, binding: u32| {
        let b = r.bindings.iter().find(|b| b.binding == binding).expect("binding");
        (b.reads, b.writes)
    };
    assert_eq!(access(&step, 0), (true, false), "parameters");
    assert_eq!(access(&step, 1), (true, false), "positions in");
    assert_eq!(access(&step, 8), (false, true), "positions out");
    let mark = reflect(&shaders::SIM_VOLUME_MARK_COMP).expect("reflect");
    assert_eq!(access(&mark, 16), (true, true), "labels");
    assert_eq!(access(&mark, 0), (true, false), "uniform block");
}
