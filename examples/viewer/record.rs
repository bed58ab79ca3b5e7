//! The viewer's command buffer for one frame, the screenshot, and teardown.

use ash::vk;
use gpu_allocator::MemoryLocation;
use vkhair::render::RenderTarget;
use vkhair::{ash, gpu_allocator};

use crate::frame::Running;
use crate::host::{allocate, cleared, transition, BoxError, Memory};
use crate::overlay::Painted;
use crate::skin::GpuSkin;
use crate::swapchain::{range, DEPTH};

impl Running {
    /// Records frame slot `slot` into swapchain image `image`; with `capture`,
    /// also copies the image into the readback buffer.
    pub(crate) fn record(
        &mut self,
        slot: usize,
        image: usize,
        dt: f64,
        painted: Option<&Painted>,
        capture: bool,
    ) -> Result<(), BoxError> {
        let d = self.gpu.device.clone();
        let cmd = self.cmds[slot];
        let extent = self.swapchain.extent;
        let taa = self.taa.on;
        let jitter = self.taa.jitter();
        let camera = match taa {
            // The frame's sub-pixel offset: vkhair and the host's meshes draw with it.
            true => self.orbit.camera(extent)?.with_jitter(jitter)?,
            false => self.orbit.camera(extent)?,
        };
        let output = (self.swapchain.images[image], self.swapchain.views[image]);
        // With TAA the scene goes into images of the TAA's, resolved into the swapchain image.
        let (scene_color, velocity) = match taa {
            true => {
                let (scene, velocity) = self.taa.images(self.gpu.allocator(), extent, self.swapchain.depth_view)?;
                (scene, Some(velocity))
            }
            false => (output, None),
        };
        let color = (scene_color.0, range(vk::ImageAspectFlags::COLOR));
        let depth = (self.swapchain.depth, range(vk::ImageAspectFlags::DEPTH));
        let color_view = scene_color.1;
        if capture {
            self.ensure_readback(extent)?;
        }
        let frame = self.frame;
        let hair = self.hair.as_mut().expect("vkhair lives until shut_down");
        // SAFETY: the slot's previous submission completed (its fence was waited on);
        // every handle is alive; vkhair records outside rendering, as it requires.
        unsafe {
            d.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(cmd, &begin)?;
            // 1. vkhair: simulation steps due, geometry between the last two states, shadows.
            hair.record_simulation(cmd, frame, dt, &camera, self.skin.as_mut())?;
            // 2. The host: clear, floor and head.
            let attachment =
                (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::COLOR_ATTACHMENT_WRITE);
            let tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
            let depth_rw =
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE;
            let to_attachment = [
                transition(
                    color,
                    (vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT, vk::AccessFlags2::NONE),
                    attachment,
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                ),
                // The depth image is shared by the frames in flight: after the previous
                // frame's depth tests and vkhair's depth writes.
                transition(
                    depth,
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE),
                    (tests, depth_rw),
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL),
                ),
            ];
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
            let clear_color = vk::ClearValue { color: vk::ClearColorValue { float32: [0.02, 0.025, 0.035, 1.0] } };
            let clear_depth = vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 } };
            let colors = [cleared(color_view, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, clear_color)];
            let depth_attachment =
                cleared(self.swapchain.depth_view, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL, clear_depth);
            let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
            let rendering = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .color_attachments(&colors)
                .depth_attachment(&depth_attachment);
            let view_projection = camera.jittered_projection((extent.width, extent.height)) * camera.view;
            d.cmd_begin_rendering(cmd, &rendering);
            match hair.crowd_drawn() {
                Some((heads, bodies)) => {
                    let body = self.skin.as_ref().map(|s| (s.drawn(), bodies.as_slice()));
                    self.scene.record_crowd(cmd, extent, view_projection, &heads, body);
                }
                None => self.scene.record_head(cmd, extent, view_projection, self.skin.as_ref().map(GpuSkin::drawn)),
            }
            d.cmd_end_rendering(cmd);
            // The velocity image: no motion where the hair writes none (the
            // resolve then reprojects the pixel by its depth).
            if let Some((velocity_image, velocity_view)) = velocity {
                let to_attachment = [transition(
                    (velocity_image, range(vk::ImageAspectFlags::COLOR)),
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::NONE),
                    attachment,
                    (vk::ImageLayout::UNDEFINED, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                )];
                d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_attachment));
                let none = vk::ClearValue {
                    color: vk::ClearColorValue { float32: [crate::taa::NO_MOTION, crate::taa::NO_MOTION, 0.0, 0.0] },
                };
                let colors = [cleared(velocity_view, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, none)];
                let rendering =
                    vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&colors);
                d.cmd_begin_rendering(cmd, &rendering);
                d.cmd_end_rendering(cmd);
            }
            // 3. vkhair: the hair over them, depth-tested against the head and floor.
            let target = RenderTarget {
                color: color_view,
                color_format: self.swapchain.format,
                depth: self.swapchain.depth_view,
                depth_format: DEPTH,
                depth_image: self.swapchain.depth,
                velocity: match (velocity, self.taa.motion_vectors) {
                    (Some((_, view)), true) => view,
                    _ => vk::ImageView::null(),
                },
                velocity_format: match (velocity, self.taa.motion_vectors) {
                    (Some(_), true) => crate::taa::VELOCITY,
                    _ => vk::Format::UNDEFINED,
                },
                extent,
                samples: vk::SampleCountFlags::TYPE_1,
            };
            if !self.no_hair {
                hair.record_draw(cmd, frame, &target, &camera)?;
            }
            // 4. The host again: the floor, depth-tested against the hair's depth,
            // with only its pipeline and push constants set again (see
            // `HostScene::record_floor` for the state it relies on vkhair leaving).
            let written = (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE);
            let after_hair = [
                transition(
                    color,
                    written,
                    (
                        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                        vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
                    ),
                    (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                ),
                transition(
                    depth,
                    written,
                    (tests, depth_rw),
                    (vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL),
                ),
            ];
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&after_hair));
            let load = |view, layout| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(view)
                    .image_layout(layout)
                    .load_op(vk::AttachmentLoadOp::LOAD)
                    .store_op(vk::AttachmentStoreOp::STORE)
            };
            let colors = [load(color_view, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
            let depth_attachment = load(self.swapchain.depth_view, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
            let rendering = vk::RenderingInfo::default()
                .render_area(area)
                .layer_count(1)
                .color_attachments(&colors)
                .depth_attachment(&depth_attachment);
            d.cmd_begin_rendering(cmd, &rendering);
            self.scene.record_floor(cmd, view_projection);
            d.cmd_end_rendering(cmd);
            // 5. With TAA: the resolve into the swapchain image.
            let color = (output.0, range(vk::ImageAspectFlags::COLOR));
            let color_view = output.1;
            if taa {
                self.taa.record(cmd, output, self.swapchain.depth, &camera, jitter)?;
            }
            // 6. The overlay over everything (its own pipeline, viewport and scissor).
            if let (Some(overlay), Some(painted)) = (self.overlay.as_mut(), painted) {
                let after_hair = [transition(
                    color,
                    (vk::PipelineStageFlags2::ALL_COMMANDS, vk::AccessFlags2::MEMORY_WRITE),
                    (
                        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                        vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
                    ),
                    (vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL),
                )];
                d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&after_hair));
                let colors = [vk::RenderingAttachmentInfo::default()
                    .image_view(color_view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::LOAD)
                    .store_op(vk::AttachmentStoreOp::STORE)];
                let rendering =
                    vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&colors);
                d.cmd_begin_rendering(cmd, &rendering);
                overlay.record(cmd, extent, painted)?;
                d.cmd_end_rendering(cmd);
            }
            // 7. Present (and the screenshot's copy first).
            let mut layout = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
            if let (true, Some((buffer, _, _))) = (capture, &self.readback) {
                let to_copy = [transition(
                    color,
                    written,
                    (vk::PipelineStageFlags2::COPY, vk::AccessFlags2::TRANSFER_READ),
                    (layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
                )];
                d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_copy));
                let region = vk::BufferImageCopy::default()
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 });
                d.cmd_copy_image_to_buffer(cmd, color.0, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, *buffer, &[region]);
                let to_host = [vk::MemoryBarrier2::default()
                    .src_stage_mask(vk::PipelineStageFlags2::COPY)
                    .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                    .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                    .dst_access_mask(vk::AccessFlags2::HOST_READ)];
                d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&to_host));
                layout = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
            }
            let to_present = [transition(
                color,
                written,
                (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE),
                (layout, vk::ImageLayout::PRESENT_SRC_KHR),
            )];
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_present));
            d.end_command_buffer(cmd)?;
        }
        Ok(())
    }

    /// A host-visible buffer for one image of `extent`.
    fn ensure_readback(&mut self, extent: vk::Extent2D) -> Result<(), BoxError> {
        if self.readback.as_ref().is_some_and(|(_, _, e)| *e == extent) {
            return Ok(());
        }
        self.free_readback();
        let d = &self.gpu.device;
        let size = u64::from(extent.width) * u64::from(extent.height) * 4;
        let info = vk::BufferCreateInfo::default().size(size).usage(vk::BufferUsageFlags::TRANSFER_DST);
        // SAFETY: valid create info; destroyed in `free_readback`.
        let buffer = unsafe { d.create_buffer(&info, None) }?;
        // SAFETY: the buffer is alive.
        let requirements = unsafe { d.get_buffer_memory_requirements(buffer) };
        let memory = allocate(self.gpu.allocator(), "viewer screenshot", requirements, MemoryLocation::GpuToCpu, true)?;
        // SAFETY: memory allocated for this buffer.
        unsafe { d.bind_buffer_memory(buffer, memory.memory(), memory.offset()) }?;
        self.readback = Some((buffer, Memory(Some(memory)), extent));
        Ok(())
    }

    fn free_readback(&mut self) {
        if let Some((buffer, mut memory, _)) = self.readback.take() {
            // SAFETY: the device is idle whenever the readback is replaced or freed.
            unsafe { self.gpu.device.destroy_buffer(buffer, None) };
            memory.free(self.gpu.allocator());
        }
    }

    /// Writes the captured image (the device is idle) as an RGBA PNG.
    pub(crate) fn write_screenshot(&self, path: &std::path::Path) -> Result<(), BoxError> {
        let (_, memory, extent) = self.readback.as_ref().ok_or("no image was captured")?;
        let allocation = memory.0.as_ref().ok_or("the screenshot memory was freed")?;
        let bytes = (extent.width * extent.height * 4) as usize;
        let mut pixels = allocation.mapped_slice().ok_or("the screenshot memory is not mapped")?[..bytes].to_vec();
        let bgra = matches!(self.swapchain.format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM);
        for p in pixels.chunks_exact_mut(4) {
            if bgra {
                p.swap(0, 2);
            }
            p[3] = 255;
        }
        // Written beside and renamed: a failed write leaves no torn file.
        let partial = path.with_extension("png.partial");
        let write = || -> Result<(), BoxError> {
            let file = std::io::BufWriter::new(std::fs::File::create(&partial)?);
            let mut encoder = png::Encoder::new(file, extent.width, extent.height);
            encoder.set_color(png::ColorType::Rgba);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header()?;
            writer.write_image_data(&pixels)?;
            writer.finish()?;
            std::fs::rename(&partial, path)?;
            Ok(())
        };
        write().map_err(|e| {
            let _ = std::fs::remove_file(&partial);
            format!("{}: {e}", path.display()).into()
        })
    }

    /// Waits for the device, destroys vkhair's objects and then the host's, and
    /// returns the validation messages of the whole run (teardown included).
    pub fn shut_down(mut self) -> Vec<String> {
        let d = self.gpu.device.clone();
        // SAFETY: waiting before destroying; the handles below are this run's.
        unsafe {
            let _ = d.device_wait_idle();
        }
        drop(self.overlay.take());
        drop(self.hair.take());
        drop(self.ctx.take());
        if let Some(skin) = &mut self.skin {
            skin.destroy(self.gpu.allocator());
        }
        self.free_readback();
        self.taa.destroy(self.gpu.allocator());
        self.scene.destroy(self.gpu.allocator());
        self.swapchain.destroy(d.clone(), self.gpu.allocator());
        // SAFETY: the device is idle; nothing uses these any more.
        unsafe {
            for (&fence, &semaphore) in self.fences.iter().zip(&self.acquired) {
                d.destroy_fence(fence, None);
                d.destroy_semaphore(semaphore, None);
            }
            d.destroy_command_pool(self.pool, None);
        }
        let messages = self.messages.clone();
        drop(self);
        messages.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}
