//! The egui overlay, drawn by `egui-ash-renderer` into the same command buffer
//! as vkhair, after it: live per-pass GPU timings, a frame-time graph, and
//! sliders for the main parameters, applied at run time.

use std::collections::VecDeque;

use ash::vk;
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use vkhair::ash;

use crate::device::HostGpu;
use crate::hair::{Hair, FRAMES_IN_FLIGHT};
use crate::host::BoxError;

/// Frame times kept for the graph.
const GRAPH_FRAMES: usize = 120;

/// Shadow map sides offered.
const SHADOW_SIDES: [u32; 5] = [128, 256, 512, 1024, 2048];

/// What the overlay's controls changed this frame.
#[derive(Default)]
pub struct Changes {
    /// Simulation, render or material parameters: `Hair::apply`.
    pub params: bool,
    /// The shadow maps' resolution: `Hair::apply_shadows` (waits for the device).
    pub shadows: bool,
}

/// A tessellated overlay frame, ready to record.
pub struct Painted {
    primitives: Vec<egui::ClippedPrimitive>,
    pixels_per_point: f32,
    /// Textures egui no longer needs, freed once this frame's work completed.
    pub free: Vec<egui::TextureId>,
}

pub struct Overlay {
    ctx: egui::Context,
    state: egui_winit::State,
    renderer: Renderer<egui_ash_renderer::allocator::GpuAllocator>,
    frame_times: VecDeque<f32>,
}

impl Overlay {
    pub fn new(window: &winit::window::Window, gpu: &HostGpu, format: vk::Format) -> Result<Overlay, BoxError> {
        let ctx = egui::Context::default();
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let srgb = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB);
        let mode = RenderMode::DynamicRendering(DynamicRendering {
            color_attachment_format: format,
            depth_attachment_format: None,
            stencil_attachment_format: None,
        });
        let options = Options {
            in_flight_frames: FRAMES_IN_FLIGHT as usize,
            enable_depth_test: false,
            enable_depth_write: false,
            srgb_framebuffer: srgb,
        };
        let renderer = Renderer::with_gpu_allocator(gpu.allocator().clone(), gpu.device.clone(), mode, options)?;
        Ok(Overlay { ctx, state, renderer, frame_times: VecDeque::with_capacity(GRAPH_FRAMES) })
    }

    /// Passes a window event to egui; true when egui used it (the camera
    /// should not).
    pub fn on_event(&mut self, window: &winit::window::Window, event: &winit::event::WindowEvent) -> bool {
        self.state.on_window_event(window, event).consumed
    }

    /// Whether the pointer is over the overlay (drags there are egui's).
    pub fn wants_pointer(&self) -> bool {
        self.ctx.egui_wants_pointer_input()
    }

    /// Runs the UI for this frame and uploads the textures it needs (this
    /// submits to `gpu.queue` through `pool` and waits for it).
    pub fn paint(
        &mut self,
        window: &winit::window::Window,
        gpu: &HostGpu,
        pool: vk::CommandPool,
        hair: &mut Hair,
        frame_ms: f32,
        changes: &mut Changes,
    ) -> Result<Painted, BoxError> {
        if self.frame_times.len() == GRAPH_FRAMES {
            self.frame_times.pop_front();
        }
        self.frame_times.push_back(frame_ms);
        let input = self.state.take_egui_input(window);
        let times = &self.frame_times;
        let mut output = self.ctx.run_ui(input, |ui| {
            egui::Window::new("vkhair").default_pos([8.0, 8.0]).default_width(230.0).resizable(false).show(
                ui.ctx(),
                |ui| {
                    panel(ui, hair, times, changes);
                },
            );
        });
        self.state.handle_platform_output(window, output.platform_output);
        let primitives = self.ctx.tessellate(output.shapes, output.pixels_per_point);
        let mut delta = std::mem::take(&mut output.textures_delta);
        for (id, deltas) in &delta.set {
            for delta in deltas {
                self.renderer.set_texture(gpu.queue, pool, *id, delta)?;
            }
        }
        let free = delta.free.drain().collect();
        delta.clear();
        Ok(Painted { primitives, pixels_per_point: output.pixels_per_point, free })
    }

    /// Records the overlay inside the caller's rendering of the swapchain image.
    /// Binds egui's pipeline, vertex and index buffers and sets viewport and scissor.
    pub fn record(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D, painted: &Painted) -> Result<(), BoxError> {
        self.renderer.cmd_draw(cmd, extent, painted.pixels_per_point, &painted.primitives)?;
        Ok(())
    }

    /// Frees textures of a frame whose work completed.
    pub fn free(&mut self, ids: &[egui::TextureId]) -> Result<(), BoxError> {
        for id in ids {
            self.renderer.free_texture(*id)?;
        }
        Ok(())
    }
}

/// The overlay's window: status, frame times, passes, sliders.
fn panel(ui: &mut egui::Ui, hair: &mut Hair, times: &VecDeque<f32>, changes: &mut Changes) {
    ui.label(hair.status());
    let last = times.back().copied().unwrap_or(0.0);
    let worst = times.iter().copied().fold(0.0f32, f32::max);
    ui.label(format!(
        "frame {last:.1} ms ({:.0} fps), worst of {} {worst:.1} ms",
        1000.0 / last.max(1e-3),
        times.len()
    ));
    let (rect, _) = ui.allocate_exact_size(egui::vec2(220.0, 40.0), egui::Sense::hover());
    ui.painter().rect_filled(rect, 2.0, egui::Color32::from_gray(24));
    let scale = worst.max(1.0);
    let points: Vec<egui::Pos2> = times
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let x = rect.left() + rect.width() * i as f32 / (GRAPH_FRAMES - 1) as f32;
            egui::pos2(x, rect.bottom() - rect.height() * (t / scale))
        })
        .collect();
    ui.painter().add(egui::Shape::line(points, egui::Stroke::new(1.5, egui::Color32::from_rgb(120, 200, 120))));
    ui.separator();
    egui::CollapsingHeader::new("GPU passes (ms)").default_open(true).show(ui, |ui| {
        egui::Grid::new("passes").striped(true).num_columns(2).show(ui, |ui| match &hair.report {
            Some(report) => {
                // Top-level passes in the order they ran, repeated ones (steps) summed.
                let mut rows: Vec<(&str, f64)> = Vec::new();
                for p in report.passes.iter().filter(|p| p.depth == 0) {
                    match rows.iter_mut().find(|(n, _)| *n == p.name) {
                        Some(row) => row.1 += p.nanoseconds,
                        None => rows.push((&p.name, p.nanoseconds)),
                    }
                }
                for (name, ns) in rows {
                    ui.label(name.trim_start_matches("vkhair "));
                    ui.label(format!("{:.2}", ns * 1e-6));
                    ui.end_row();
                }
                ui.label("total");
                ui.label(format!("{:.2}", report.total_nanoseconds() * 1e-6));
                ui.end_row();
            }
            None => {
                ui.label("(waiting for timestamps)");
                ui.end_row();
            }
        });
    });
    ui.separator();
    let sim = &mut hair.config.sim;
    changes.params |=
        ui.add(egui::Slider::new(&mut sim.global_shape_stiffness, 0.0..=1.0).text("shape stiffness")).changed();
    let mut wind = sim.wind.x;
    if ui.add(egui::Slider::new(&mut wind, 0.0..=20.0).text("wind (m/s²)")).changed() {
        sim.wind.x = wind;
        sim.wind_enabled = wind > 0.0;
        changes.params = true;
    }
    let lod = &mut hair.config.render.lod;
    changes.params |=
        ui.add(egui::Slider::new(&mut lod.full_detail_distance, 0.1..=10.0).text("LOD distance (m)")).changed();
    let before = hair.shadows.resolution;
    egui::ComboBox::from_label("shadow resolution").selected_text(before.to_string()).show_ui(ui, |ui| {
        for side in SHADOW_SIDES {
            ui.selectable_value(&mut hair.shadows.resolution, side, side.to_string());
        }
    });
    changes.shadows |= hair.shadows.resolution != before;
    ui.small("L LOD · S shadows · A SSAA · K shading · T transparency\nM motion · Space pause · N step · R reset");
}
