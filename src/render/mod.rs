//! Rendering a full head of hair from the simulated key hairs.
//!
//! The passes, in recording order ([`RenderPass`] names their debug labels
//! and timestamp scopes):
//!
//! 1. **Smooth** ([`smooth`]): key hairs straight from the simulation's GPU
//!    buffers, as patches of 4 control points, tessellated as isolines into
//!    uniform cubic B-splines (mirrored phantom points put the curve exactly
//!    through root and tip); positions and tangents stored for the next passes.
//!
//! Later passes (strand interpolation, drawing, shading, anti-aliasing, level of
//! detail) build on the smoothed strands.

pub mod reference;
pub mod smooth;

use std::sync::Arc;

use ash::vk;
use glam::Vec4;
use gpu_allocator::MemoryLocation;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu_types::SmoothPush;
use crate::profiler::GpuProfiler;
use crate::sim::HairSim;
use crate::vk::barrier::{self, Access};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use smooth::SmoothPass;

/// Most smoothed segments per key segment (the tessellation level limit vkhair uses).
pub const MAX_SMOOTHING_LEVEL: u32 = 64;

/// The passes of a frame, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RenderPass {
    /// Pass 1: B-spline smoothing of the key hairs.
    Smooth,
}

impl RenderPass {
    /// The debug label and timestamp scope name of the pass.
    pub fn label(self) -> &'static str {
        match self {
            RenderPass::Smooth => "vkhair render: smooth",
        }
    }
}

/// Rendering parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderParams {
    /// Smoothed segments per key segment (1..=64). Default: 4 (a 6-point key hair
    /// becomes 20 segments, as in the thesis scene).
    pub smoothing_level: u32,
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams { smoothing_level: 4 }
    }
}

impl RenderParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SMOOTHING_LEVEL).contains(&self.smoothing_level) {
            return Err(Error::param(
                "smoothing_level",
                format!("{} is outside 1..={MAX_SMOOTHING_LEVEL}", self.smoothing_level),
            ));
        }
        Ok(())
    }
}

/// Renders hair from a [`HairSim`]'s key hairs into the host's images.
pub struct Renderer {
    device: Arc<Device>,
    params: RenderParams,
    strands: u32,
    points: u32,
    /// Smoothing level the buffers were sized for.
    capacity_level: u32,
    smoothed_positions: Buffer,
    smoothed_tangents: Buffer,
    smooth: SmoothPass,
}

impl Renderer {
    /// Creates the passes and buffers for the key hairs of `sim`.
    pub fn new(ctx: &GpuContext, sim: &HairSim, params: &RenderParams) -> Result<Self> {
        params.validate()?;
        let device = ctx.device.clone();
        if device.info.max_tessellation_level < params.smoothing_level {
            return Err(Error::MissingRequirement(format!(
                "tessellation level {} (device allows {})",
                params.smoothing_level, device.info.max_tessellation_level
            )));
        }
        let (strands, points) = sim.size();
        // Sized for the level asked for at creation: level-of-detail only lowers it.
        let stride = (points as u64 - 1) * u64::from(params.smoothing_level) + 1;
        let size = strands as u64 * stride * 16;
        if size > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::param(
                "smoothing_level",
                format!("{size} bytes of smoothed strands exceed the device's storage range; lower the level"),
            ));
        }
        let storage = |name: &str| {
            Buffer::new(
                &device,
                &BufferDesc {
                    name,
                    size,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )
        };
        let smoothed_positions = storage("vkhair smoothed positions")?;
        let smoothed_tangents = storage("vkhair smoothed tangents")?;
        let (halves, _) = sim.position_halves();
        let smooth = SmoothPass::new(&device, halves, &smoothed_positions, &smoothed_tangents)?;
        Ok(Renderer {
            device,
            params: params.clone(),
            strands: strands as u32,
            points: points as u32,
            capacity_level: params.smoothing_level,
            smoothed_positions,
            smoothed_tangents,
            smooth,
        })
    }

    /// Current parameters.
    pub fn params(&self) -> &RenderParams {
        &self.params
    }

    /// Changes parameters from the next recorded frame on (validated first). The
    /// smoothing level may not exceed the one the renderer was created with.
    pub fn set_params(&mut self, params: &RenderParams) -> Result<()> {
        params.validate()?;
        if params.smoothing_level > self.capacity_level {
            return Err(Error::param(
                "smoothing_level",
                format!("{} exceeds the {} this renderer was created for", params.smoothing_level, self.capacity_level),
            ));
        }
        self.params = params.clone();
        Ok(())
    }

    /// Smoothed vertices per key hair at the current level.
    pub fn smoothed_vertices_per_strand(&self) -> u32 {
        (self.points - 1) * self.params.smoothing_level + 1
    }

    fn smooth_push(&self) -> SmoothPush {
        SmoothPush {
            strands: self.strands,
            points: self.points,
            level: self.params.smoothing_level,
            stride: self.smoothed_vertices_per_strand(),
        }
    }

    /// Records the geometry passes (smoothing) for `sim`'s latest state into `cmd`.
    ///
    /// # Safety
    /// `cmd` is a command buffer of the context's device in the recording state,
    /// outside a render pass, for a queue of the graphics family; `sim` is the
    /// simulation this renderer was created for. Work recorded earlier in submission
    /// order (the simulation step) is ordered before it by the recorded barriers.
    pub unsafe fn record_prepare(
        &mut self,
        cmd: vk::CommandBuffer,
        sim: &HairSim,
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let (_, half) = sim.position_halves();
        let d = &self.device;
        let entry = barrier::memory(
            Access::ANY_WRITE,
            Access {
                stage: vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            },
        );
        let done = barrier::memory(
            Access {
                stage: vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_WRITE,
            },
            Access {
                stage: vk::PipelineStageFlags2::VERTEX_SHADER
                    | vk::PipelineStageFlags2::TESSELLATION_EVALUATION_SHADER
                    | vk::PipelineStageFlags2::GEOMETRY_SHADER
                    | vk::PipelineStageFlags2::FRAGMENT_SHADER
                    | vk::PipelineStageFlags2::COMPUTE_SHADER,
                access: vk::AccessFlags2::SHADER_STORAGE_READ,
            },
        );
        let extent = vk::Extent2D { width: 1, height: 1 };
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
            .layer_count(1);
        let push = self.smooth_push();
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            d.cmd_barrier(cmd, &[entry], &[], &[]);
            let scope = match profiler.as_deref_mut() {
                Some(p) => Some(p.begin_scope(cmd, RenderPass::Smooth.label())),
                None => {
                    d.cmd_begin_label(cmd, RenderPass::Smooth.label(), LabelColor::Graphics);
                    None
                }
            };
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.raw.cmd_set_viewport(
                cmd,
                0,
                &[vk::Viewport { x: 0.0, y: 0.0, width: 1.0, height: 1.0, min_depth: 0.0, max_depth: 1.0 }],
            );
            d.raw.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
            self.smooth.record(d, cmd, half, &push);
            d.raw.cmd_end_rendering(cmd);
            d.cmd_barrier(cmd, &[done], &[], &[]);
            match (profiler, scope) {
                (Some(p), Some(scope)) => p.end_scope(cmd, scope),
                _ => d.cmd_end_label(cmd),
            }
        }
        Ok(())
    }

    /// Records [`Renderer::record_prepare`] in its own submission and waits (headless
    /// use: tests and tools).
    pub fn prepare_now(&mut self, sim: &HairSim) -> Result<()> {
        let device = self.device.clone();
        let mut result = Ok(());
        device.submit_once("vkhair prepare", |cmd| {
            // SAFETY: submit_once hands over a recording command buffer of this device.
            result = unsafe { self.record_prepare(cmd, sim, None) };
        })?;
        result
    }

    /// Reads the smoothed positions and unit tangents back, strand after strand
    /// ([`Renderer::smoothed_vertices_per_strand`] each; this submits and waits).
    pub fn read_smoothed(&self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let n = self.strands as usize * self.smoothed_vertices_per_strand() as usize;
        let positions = self.device.readback_pod(&self.smoothed_positions, n)?;
        let tangents = self.device.readback_pod(&self.smoothed_tangents, n)?;
        Ok((positions, tangents))
    }
}
