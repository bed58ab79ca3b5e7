//! One frame of the viewer, and everything that lives as long as the window:
//! the host's frames in flight (command buffers, fences, semaphores), vkhair
//! on the host's device, the host's scene, the overlay and the orbit camera.
//!
//! Per frame, into one command buffer: vkhair's simulation steps, geometry and
//! shadow maps; the host's floor and head (clearing the swapchain image and
//! depth); vkhair's hair into them; the overlay; then present.

use std::sync::{Arc, Mutex};

use ash::vk;
use glam::Vec3;
use vkhair::config::Config;
use vkhair::render::Camera;
use vkhair::sim::SimParams;
use vkhair::{ash, GpuContext, HostDevice, HostQueue};
use winit::window::Window;

use crate::device::HostGpu;
use crate::hair::{Hair, Scene, FRAMES_IN_FLIGHT};
use crate::host::{BoxError, Memory};
use crate::overlay::{Changes, Overlay, Painted};
use crate::scene::HostScene;
use crate::skin::GpuSkin;
use crate::swapchain::Swapchain;
use crate::taa::Taa;
use crate::Args;

/// Vertical field of view, radians.
const FOV_Y: f32 = 0.698_131_7;

/// The camera orbiting the scene's centre.
pub struct Orbit {
    center: Vec3,
    radius: f32,
    yaw: f32,
    pitch: f32,
    distance: f32,
}

impl Orbit {
    pub fn drag(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * 0.01;
        self.pitch = (self.pitch + dy * 0.01).clamp(-1.4, 1.4);
    }

    pub fn zoom(&mut self, lines: f32) {
        self.distance = (self.distance * 0.9f32.powf(lines)).clamp(0.3 * self.radius, 20.0 * self.radius);
    }

    pub(crate) fn camera(&self, extent: vk::Extent2D) -> Result<Camera, BoxError> {
        let dir = Vec3::new(self.yaw.sin() * self.pitch.cos(), self.pitch.sin(), self.yaw.cos() * self.pitch.cos());
        let eye = self.center + dir * self.distance;
        let near = (self.distance - 2.0 * self.radius).max(0.01 * self.distance);
        let aspect = extent.width as f32 / extent.height.max(1) as f32;
        Ok(Camera::look_at(eye, self.center, FOV_Y, aspect, near, self.distance + 3.0 * self.radius)?)
    }
}

/// What the window shows while it is open.
pub struct Running {
    // vkhair first: dropped (in `shut_down`) before the host's device.
    pub(crate) hair: Option<Hair>,
    pub(crate) ctx: Option<GpuContext>,
    /// A `--gltf` character's skinning pass (destroyed after vkhair).
    pub(crate) skin: Option<GpuSkin>,
    pub(crate) overlay: Option<Overlay>,
    pub(crate) scene: HostScene,
    /// The TAA resolve (keys J and V).
    pub(crate) taa: Taa,
    pub(crate) swapchain: Swapchain,
    pub(crate) pool: vk::CommandPool,
    pub(crate) cmds: Vec<vk::CommandBuffer>,
    pub(crate) fences: Vec<vk::Fence>,
    pub(crate) acquired: Vec<vk::Semaphore>,
    /// Overlay textures to free once each slot's frame completed.
    pub(crate) free: Vec<Vec<egui::TextureId>>,
    pub(crate) readback: Option<(vk::Buffer, Memory, vk::Extent2D)>,
    pub(crate) frame: u64,
    /// `--no-hair`.
    pub(crate) no_hair: bool,
    pub resized: bool,
    pub orbit: Orbit,
    pub(crate) messages: Arc<Mutex<Vec<String>>>,
    pub(crate) gpu: HostGpu,
}

impl Running {
    pub fn new(args: &Args, window: &Window) -> Result<Running, BoxError> {
        let scene_data = Scene::load(args)?;
        // An --input groom, or one grown on a character, is held in its style
        // (as `vkhair render` does).
        let styled = args.input.is_some() || args.gltf.is_some();
        let sim = if styled { SimParams::styled() } else { SimParams::default() };
        let base = Config { sim, ..Config::default() };
        let config = match &args.config {
            Some(path) => base.load_over(path)?,
            None => base,
        };
        let gpu = HostGpu::new(window, args.validation)?;
        let messages = gpu.messages.clone();
        // SAFETY: the handles are valid, belong together, were created with vkhair's
        // requirements and outlive the context and everything made from it (dropped
        // first in `shut_down`); the viewer never uses the queue while vkhair submits.
        let ctx = unsafe {
            GpuContext::from_host(HostDevice {
                entry: gpu.entry.clone(),
                instance: gpu.instance.clone(),
                physical_device: gpu.physical,
                device: gpu.device.clone(),
                graphics_queue: HostQueue { family: gpu.family, queue: gpu.queue },
                compute_queue: None,
                allocator: Some(gpu.allocator().clone()),
                debug_utils: true,
                compute_full_subgroups: false,
                buffer_int64_atomics: false,
                enabled_extensions: Vec::new(),
            })
        }?;
        // A character's skinning pass is the host's: vkhair reads the skinned
        // vertices it writes.
        let skin = match &scene_data.rig {
            Some(rig) => Some(GpuSkin::new(&gpu.device, gpu.allocator(), &rig.character)?),
            None => None,
        };
        let mut hair = Hair::new(&ctx, &scene_data, config, skin.as_ref())?;
        hair.moving |= args.moving;
        let size = window.inner_size();
        let swapchain = Swapchain::new(&gpu, (size.width.max(1), size.height.max(1)))?;
        let floor_y = scene_data.floor_y;
        // A crowd is framed on the grid its members stand in.
        let (center, radius) = match hair.crowd_framing() {
            // Its hair, and the floor below it (the characters' bodies).
            Some((_, c, r)) => {
                let lo = (c - Vec3::splat(r)).min(Vec3::new(c.x, floor_y, c.z));
                vkhair::groom::bounding_sphere((lo, c + Vec3::splat(r)))
            }
            None => (scene_data.center, scene_data.radius),
        };
        let scene = HostScene::new(
            &gpu.device,
            gpu.allocator(),
            swapchain.format,
            &scene_data.head,
            (center, floor_y, 3.0 * radius),
        )?;
        let taa = Taa::new(&gpu.device, swapchain.format, args.taa, !args.no_motion_vectors)?;
        let d = &gpu.device;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(gpu.family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid create infos; everything is destroyed in `shut_down`.
        let (pool, cmds, fences, acquired) = unsafe {
            let pool = d.create_command_pool(&pool_info, None)?;
            let alloc =
                vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(FRAMES_IN_FLIGHT);
            let cmds = d.allocate_command_buffers(&alloc)?;
            let mut fences = Vec::new();
            let mut acquired = Vec::new();
            for _ in 0..FRAMES_IN_FLIGHT {
                fences
                    .push(d.create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None)?);
                acquired.push(d.create_semaphore(&vk::SemaphoreCreateInfo::default(), None)?);
            }
            (pool, cmds, fences, acquired)
        };
        let overlay = if args.no_overlay { None } else { Some(Overlay::new(window, &gpu, swapchain.format)?) };
        let half_fov = 0.5 * FOV_Y;
        // A crowd is seen from above one corner, its rows apart.
        let (yaw, pitch, near) = if hair.crowd_framing().is_some() { (-0.35, 0.35, 0.55) } else { (0.0, 0.1, 1.0) };
        let orbit = Orbit { center, radius, yaw, pitch, distance: near * radius / half_fov.sin() };
        Ok(Running {
            hair: Some(hair),
            ctx: Some(ctx),
            skin,
            overlay,
            scene,
            taa,
            swapchain,
            pool,
            cmds,
            fences,
            acquired,
            free: vec![Vec::new(); FRAMES_IN_FLIGHT as usize],
            readback: None,
            frame: 0,
            no_hair: args.no_hair,
            resized: false,
            orbit,
            messages,
            gpu,
        })
    }

    fn hair(&mut self) -> &mut Hair {
        self.hair.as_mut().expect("vkhair lives until shut_down")
    }

    pub fn overlay_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.overlay.as_mut().is_some_and(|o| o.on_event(window, event))
    }

    pub fn overlay_wants_pointer(&self) -> bool {
        self.overlay.as_ref().is_some_and(Overlay::wants_pointer)
    }

    /// A key press (lower-case character, " " for Space).
    pub fn key(&mut self, key: &str) -> Result<(), BoxError> {
        let idle = |r: &Running| -> Result<(), BoxError> {
            // SAFETY: the device is alive; waiting has no other effect.
            unsafe { r.gpu.device.device_wait_idle() }?;
            Ok(())
        };
        match key {
            "l" => self.hair().toggle_lod()?,
            "a" => self.hair().toggle_supersampling()?,
            "k" => self.hair().next_shading()?,
            "t" => self.hair().next_transparency()?,
            "m" => self.hair().moving = !self.hair().moving,
            " " => self.hair().paused = !self.hair().paused,
            "n" => self.hair().pending_steps += 1,
            "s" => {
                idle(self)?;
                let hair = self.hair();
                hair.shadows_on = !hair.shadows_on;
                hair.apply_shadows()?;
            }
            "r" => {
                idle(self)?;
                self.hair().reset()?;
                self.taa.restart();
            }
            "j" => {
                self.taa.on = !self.taa.on;
                self.taa.restart();
                // The hair's motion starts again from the next frame that writes it.
                self.hair().renderer.reset_motion();
            }
            "v" => {
                self.taa.motion_vectors = !self.taa.motion_vectors;
                self.taa.restart();
                self.hair().renderer.reset_motion();
            }
            _ => return Ok(()),
        }
        let taa = match (self.taa.on, self.taa.motion_vectors) {
            (false, _) => "off",
            (true, true) => "on, the hair's motion vectors",
            (true, false) => "on, without the hair's motion vectors",
        };
        println!("viewer: {} · TAA {taa}", self.hair().status());
        Ok(())
    }

    fn recreate(&mut self, window: &Window) -> Result<bool, BoxError> {
        let size = window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(false); // minimised: nothing to draw into
        }
        // SAFETY: waiting for the device before its swapchain is replaced.
        unsafe { self.gpu.device.device_wait_idle() }?;
        let mut old = std::mem::replace(&mut self.swapchain, Swapchain::new(&self.gpu, (size.width, size.height))?);
        old.destroy(self.gpu.device.clone(), self.gpu.allocator());
        self.resized = false;
        Ok(true)
    }

    /// Draws one frame `dt` seconds after the previous; true when `--frames`
    /// were drawn (the screenshot, if asked for, is written).
    pub fn draw(&mut self, window: &Window, dt: f64, args: &Args) -> Result<bool, BoxError> {
        if self.resized && !self.recreate(window)? {
            return Ok(false);
        }
        if args.resize.is_some() && self.frame == args.resize_frame {
            if let Some((w, h)) = args.resize {
                let _ = window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
            }
        }
        let slot = (self.frame % u64::from(FRAMES_IN_FLIGHT)) as usize;
        let d = self.gpu.device.clone();
        // SAFETY: the fence belongs to this device.
        unsafe { d.wait_for_fences(&[self.fences[slot]], true, u64::MAX) }?;
        let done = std::mem::take(&mut self.free[slot]);
        if let Some(o) = &mut self.overlay {
            o.free(&done)?;
        }
        // SAFETY: live swapchain and semaphore; the semaphore's previous wait completed (fence above).
        let acquired = unsafe {
            self.swapchain.loader.acquire_next_image(
                self.swapchain.handle,
                u64::MAX,
                self.acquired[slot],
                vk::Fence::null(),
            )
        };
        let image = match acquired {
            Ok((image, _)) => image as usize,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.resized = true;
                return Ok(false);
            }
            Err(e) => return Err(e.into()),
        };
        let last = args.frames.is_some_and(|n| self.frame + 1 >= n);
        let painted = self.paint(window, dt)?;
        self.record(slot, image, dt, painted.as_ref(), last && args.screenshot.is_some())?;
        if let Some(p) = painted {
            self.free[slot] = p.free;
        }
        let cmd = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmds[slot])];
        let wait = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.acquired[slot])
            .stage_mask(vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)];
        let signal = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.swapchain.finished[image])
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let submit = vk::SubmitInfo2::default()
            .command_buffer_infos(&cmd)
            .wait_semaphore_infos(&wait)
            .signal_semaphore_infos(&signal);
        let swapchains = [self.swapchain.handle];
        let indices = [image as u32];
        let finished = [self.swapchain.finished[image]];
        let present =
            vk::PresentInfoKHR::default().wait_semaphores(&finished).swapchains(&swapchains).image_indices(&indices);
        // SAFETY: the fence was waited on above; the command buffer is recorded.
        let presented = unsafe {
            d.reset_fences(&[self.fences[slot]])?;
            d.queue_submit2(self.gpu.queue, &[submit], self.fences[slot])?;
            self.swapchain.loader.queue_present(self.gpu.queue, &present)
        };
        match presented {
            Ok(false) => {}
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.resized = true,
            Err(e) => return Err(e.into()),
        }
        self.frame += 1;
        if last {
            // SAFETY: waiting for the last frame before reading its image back.
            unsafe { d.device_wait_idle() }?;
            if let Some(path) = &args.screenshot {
                self.write_screenshot(path)?;
            }
            let frames = self.frame;
            if let Some((time, error)) = self.hair().root_error()? {
                println!("viewer: roots within {error:.2e} m of the skinned mesh at {time:.3} s of the animation");
            }
            if let Some(report) = self.hair().report.as_ref() {
                println!("viewer: {frames} frames; GPU passes of frame {}:\n{report}", report.frame);
            }
        }
        Ok(last)
    }

    /// Runs the overlay's UI and applies what it changed.
    fn paint(&mut self, window: &Window, dt: f64) -> Result<Option<Painted>, BoxError> {
        let Some(overlay) = self.overlay.as_mut() else { return Ok(None) };
        let hair = self.hair.as_mut().expect("vkhair lives until shut_down");
        let mut changes = Changes::default();
        let painted = overlay.paint(window, &self.gpu, self.pool, hair, (dt * 1000.0) as f32, &mut changes)?;
        if changes.params {
            hair.apply()?;
        }
        if changes.shadows {
            // SAFETY: new shadow maps replace images pending frames may use.
            unsafe { self.gpu.device.device_wait_idle() }?;
            hair.apply_shadows()?;
        }
        Ok(Some(painted))
    }
}
