//! A windowed host embedding vkhair the way an engine does.
//!
//! The viewer owns everything Vulkan: a `winit` window, an `ash-window`
//! surface, its own instance, device, queue and `gpu-allocator` allocator, a
//! swapchain with two frames in flight (recreated on resize), the head mesh and
//! floor it draws itself, and an egui overlay drawn by `egui-ash-renderer`.
//! vkhair borrows the device through `GpuContext::from_host` and records into
//! the viewer's command buffer every frame: the simulation at a fixed 60 Hz
//! (`FixedStepDriver`), the key hairs drawn between the last two states by the
//! driver's alpha, shadow maps and hair, all timed by `GpuProfiler`.
//!
//! ```text
//! cargo run --release --example viewer
//! cargo run --release --example viewer -- --input sintel_hair.tfx --obj sintel_bust.obj --scale 0.01
//! cargo run --release --example viewer -- --gltf tests/data/mannequiny-0.3.0.glb --animation run
//! cargo run --release --example viewer -- --crowd 16 --gltf tests/data/mannequiny-0.3.0.glb --moving
//! ```
//!
//! With `--crowd N` the viewer is a host with many characters: N members of
//! one `vkhair::crowd::Crowd` (`crowd.rs`), one simulation step and one
//! renderer for all of them, each member's head or skinned body drawn by the
//! host at its place.
//!
//! With `--gltf` the viewer is a host with a skinned character: its own
//! compute pass skins the mesh every frame (`skin.rs`), draws it, and hands
//! the skinned vertices to vkhair, whose key hairs' roots ride them
//! (`HairSim::bind_scalp_source`); the bones' capsules are the body's
//! colliders and M pauses the animation.
//!
//! Mouse: drag to orbit, scroll to zoom. Keys: L level of detail, S shadows,
//! A supersampling, K shading model, T transparency, M head motion, J TAA
//! (`taa.rs`: a jittered camera, vkhair's motion vectors and a resolve), V the
//! hair's motion vectors in the TAA, Space pause, N one step while paused, R
//! reset, Esc quit. `--frames N
//! --screenshot FILE.png` renders N frames through the swapchain, saves the last
//! presented image and exits; `--validation` turns on the Khronos layer with
//! synchronization validation and makes any message an error.

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

#[path = "../embed_minimal/host.rs"]
#[allow(dead_code)]
mod host;

mod crowd;
mod device;
mod frame;
mod hair;
mod overlay;
mod record;
mod scene;
mod skin;
mod swapchain;
mod taa;

use frame::Running;
use host::BoxError;

/// Command line.
#[derive(Parser, Debug, Clone)]
#[command(name = "viewer", about = "vkhair in a window: a host with a swapchain, an egui overlay and vkhair beside it")]
pub struct Args {
    /// Groom file (.hair or .tfx) instead of the thesis scene.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Character mesh (OBJ, the groom's units) the strands collide with and the viewer draws.
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// Skinned, animated glTF character (.glb or .gltf, meters): key hairs
    /// grown on its head ride its mesh as the viewer skins it on the GPU every
    /// frame, its bones' capsules keep them off the body. Instead of --input.
    #[arg(long, conflicts_with_all = ["input", "obj"])]
    pub gltf: Option<PathBuf>,
    /// A crowd of this many characters (1..=64) in one vkhair simulation and
    /// renderer, on a grid: thesis heads swaying each at its own phase and,
    /// with --gltf, the character at every other place.
    #[arg(long, conflicts_with_all = ["input", "obj"], value_parser = clap::value_parser!(u32).range(1..=64))]
    pub crowd: Option<u32>,
    /// The --gltf animation, by name or index [default: the first].
    #[arg(long, requires = "gltf")]
    pub animation: Option<String>,
    /// The --gltf joint the hair grows on, by name [default: found by weights].
    #[arg(long, requires = "gltf")]
    pub head_joint: Option<String>,
    /// Multiply groom and mesh positions by this (0.01: centimetres to meters; > 0).
    #[arg(long, default_value_t = 1.0, value_parser = positive)]
    pub scale: f32,
    /// TOML parameters over vkhair's defaults (see presets/).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Window width, pixels (16..=8192).
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub width: u32,
    /// Window height, pixels (16..=8192).
    #[arg(long, default_value_t = 720, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub height: u32,
    /// Render this many frames (at least 1), then exit.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// Advance the simulation and animation by this many seconds each frame
    /// instead of the wall clock's time (a repeatable run, e.g. for a capture;
    /// 0.001..=1).
    #[arg(long, value_parser = frame_time)]
    pub frame_time: Option<f64>,
    /// Save the last presented image here (PNG), with --frames.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Ask the window system for a new size (WIDTHxHEIGHT) at frame --resize-frame.
    #[arg(long, value_parser = parse_size)]
    pub resize: Option<(u32, u32)>,
    /// The frame at which --resize is asked for.
    #[arg(long, default_value_t = 30)]
    pub resize_frame: u64,
    /// No egui overlay.
    #[arg(long)]
    pub no_overlay: bool,
    /// Simulate but draw no hair: the host's scene alone, for comparison.
    #[arg(long)]
    pub no_hair: bool,
    /// Start with TAA on (key J): a jittered camera, the hair's motion
    /// vectors, and a resolve that blends each pixel with its history.
    #[arg(long)]
    pub taa: bool,
    /// Start with the hair's motion vectors left out of the TAA (key V): its
    /// pixels reprojected as if the hair stood still with the head.
    #[arg(long)]
    pub no_motion_vectors: bool,
    /// Start with the head moving (key M).
    #[arg(long)]
    pub moving: bool,
    /// The Khronos validation layer with synchronization validation; any message
    /// fails the run (exit status 2).
    #[arg(long)]
    pub validation: bool,
}

fn positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("expected a finite number above 0, got {s:?}")),
    }
}

fn frame_time(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.001..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("expected seconds within 0.001..=1, got {s:?}")),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let parse = |v: &str| v.parse::<u32>().ok().filter(|v| (16..=8192).contains(v));
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!("each side must be 16..=8192 pixels (got {s:?})")),
    }
}

/// The application: the window, then everything drawn into it.
struct App {
    args: Args,
    window: Option<Window>,
    running: Option<Running>,
    /// The first error, which ends the run.
    error: Option<BoxError>,
    /// Validation messages of the finished run.
    messages: Vec<String>,
    last_frame: Instant,
    cursor: (f64, f64),
    dragging: bool,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: BoxError) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }

    fn shut_down(&mut self) {
        if let Some(running) = self.running.take() {
            self.messages = running.shut_down();
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("vkhair viewer")
            .with_inner_size(winit::dpi::PhysicalSize::new(self.args.width, self.args.height));
        let made = event_loop
            .create_window(attributes)
            .map_err(BoxError::from)
            .and_then(|window| Running::new(&self.args, &window).map(|r| (window, r)));
        match made {
            Ok((window, running)) => {
                self.window = Some(window);
                self.running = Some(running);
                self.last_frame = Instant::now();
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let (Some(window), Some(running)) = (self.window.as_ref(), self.running.as_mut()) else {
            return;
        };
        if running.overlay_event(window, &event) {
            return;
        }
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(_) => {
                running.resized = true;
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed && !event.repeat => {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => {
                        event_loop.exit();
                        Ok(())
                    }
                    Key::Named(NamedKey::Space) => running.key(" "),
                    Key::Character(c) => running.key(&c.to_lowercase()),
                    _ => Ok(()),
                }
            }
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                self.dragging = state == ElementState::Pressed && !running.overlay_wants_pointer();
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                if self.dragging {
                    running.orbit.drag((position.x - self.cursor.0) as f32, (position.y - self.cursor.1) as f32);
                }
                self.cursor = (position.x, position.y);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                running.orbit.zoom(lines);
                Ok(())
            }
            WindowEvent::RedrawRequested => {
                let now = Instant::now();
                let dt = self.args.frame_time.unwrap_or(now.duration_since(self.last_frame).as_secs_f64());
                self.last_frame = now;
                running.draw(window, dt, &self.args).map(|done| {
                    if done {
                        event_loop.exit();
                    }
                })
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(window) = &self.window {
            window.request_redraw();
        }
    }

    fn exiting(&mut self, _: &ActiveEventLoop) {
        self.shut_down();
    }
}

fn main() -> std::process::ExitCode {
    let mut args = Args::parse();
    args.validation |= std::env::var("VKHAIR_VALIDATION").is_ok_and(|v| v == "1");
    if args.screenshot.is_some() && args.frames.is_none() {
        eprintln!("viewer: --screenshot needs --frames (the frame whose image is saved)");
        return std::process::ExitCode::from(1);
    }
    let mut app = App {
        args,
        window: None,
        running: None,
        error: None,
        messages: Vec::new(),
        last_frame: Instant::now(),
        cursor: (0.0, 0.0),
        dragging: false,
    };
    let result = EventLoop::new().map_err(BoxError::from).and_then(|event_loop| {
        event_loop.set_control_flow(ControlFlow::Poll);
        event_loop.run_app(&mut app).map_err(BoxError::from)
    });
    app.shut_down();
    for m in &app.messages {
        eprintln!("validation: {m}");
    }
    if let Some(e) = app.error.or(result.err()) {
        eprintln!("viewer: {e}");
        return std::process::ExitCode::from(1);
    }
    if !app.messages.is_empty() {
        eprintln!("viewer: {} validation messages", app.messages.len());
        return std::process::ExitCode::from(2);
    }
    std::process::ExitCode::SUCCESS
}
