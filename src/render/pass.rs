//! What the render passes share: their names and timestamp slots, and the
//! attachment-less "capture" instance the geometry passes store from.
//!
//! ## The pass convention
//!
//! Every pass is a plain struct in its own file ([`super::smooth`],
//! [`super::interpolate`], [`super::shadow`], [`super::draw`], [`super::resolve`])
//! that
//!
//! - makes its pipelines, descriptor sets and the buffers and images it writes
//!   in `new`, and owns them (a later pass borrows what it reads through an
//!   accessor of the pass that wrote it);
//! - records itself in `unsafe fn record(…)`, inside its own [`PassScope`] named
//!   by its [`RenderPass`], declaring before each step every resource the step
//!   reads or writes ([`super::graph::Use`]) to the entry point's
//!   [`super::graph::FrameGraph`], which records the barriers those uses need
//!   after the earlier passes' declared uses: no pass places a barrier for
//!   its neighbour, nor between its own steps (every barrier under `render/`
//!   is one the graph derived);
//! - states in its `# Safety` section what must have been recorded before.
//!
//! There is no `Pass` trait: the passes take different inputs each frame
//! (a simulation half, a camera, the host's target), and a trait would force
//! them through one grab-bag argument. [`super::Renderer`] lists the passes in
//! frame order and hands each what it needs.

use std::sync::Arc;

use ash::vk;

use super::graph::{FrameGraph, Use};
use crate::error::Result;
use crate::profiler::{PassScope, Timing};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering;
use crate::vk::shaders::ShaderSource;

/// The passes of a frame, in recording order: their debug labels and
/// timestamp scopes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RenderPass {
    /// Pass 1: B-spline smoothing of the key hairs.
    Smooth,
    /// Pass 2: strand interpolation.
    Interpolate,
    /// Pass 3a: shadows, the depth where the hair starts, per light.
    ShadowDepth,
    /// Pass 3b: shadows, opacity accumulated into three layers, per light.
    ShadowOpacity,
    /// Pass 3c: density-volume shadows, transmittance toward the light at every cell.
    ShadowVolume,
    /// Pass 4: drawing and shading (with transparency: storing the shaded fragments).
    Draw,
    /// Pass 4b (with transparency): sorting and blending each pixel's fragments
    /// into the target.
    Composite,
    /// Pass 4c (a target with a velocity image): the hair's motion vectors.
    Motion,
    /// Pass 5: supersampling resolve.
    Resolve,
}

impl RenderPass {
    /// Every pass, in recording order.
    pub const ALL: [RenderPass; 9] = [
        RenderPass::Smooth,
        RenderPass::Interpolate,
        RenderPass::ShadowDepth,
        RenderPass::ShadowOpacity,
        RenderPass::ShadowVolume,
        RenderPass::Draw,
        RenderPass::Composite,
        RenderPass::Motion,
        RenderPass::Resolve,
    ];

    /// The debug label and timestamp scope name of the pass.
    pub fn label(self) -> &'static str {
        match self {
            RenderPass::Smooth => "vkhair render: smooth",
            RenderPass::Interpolate => "vkhair render: interpolate",
            RenderPass::ShadowDepth => "vkhair render: shadow depth",
            RenderPass::ShadowOpacity => "vkhair render: shadow opacity",
            RenderPass::ShadowVolume => "vkhair render: shadow volume",
            RenderPass::Draw => "vkhair render: draw",
            RenderPass::Composite => "vkhair render: composite",
            RenderPass::Motion => "vkhair render: motion vectors",
            RenderPass::Resolve => "vkhair render: resolve",
        }
    }

    /// What the pass's commands are (its label colour).
    pub(crate) fn kind(self) -> LabelColor {
        match self {
            RenderPass::ShadowVolume | RenderPass::Motion => LabelColor::Compute,
            _ => LabelColor::Graphics,
        }
    }

    /// Opens the pass's scope.
    ///
    /// # Safety
    /// As for [`PassScope::open`].
    pub(crate) unsafe fn open(self, device: &Device, cmd: vk::CommandBuffer, timing: Timing<'_>) -> PassScope {
        // SAFETY: guaranteed by the caller.
        unsafe { PassScope::open(device, cmd, timing, self.label(), self.kind()) }
    }
}

/// A pipeline of tessellation stages that only store (rasterization off), for the
/// geometry passes.
pub(super) fn capture_pipeline(
    device: &Arc<Device>,
    name: &str,
    stages: &[&ShaderSource],
    patch_control_points: u32,
    max_sets: u32,
) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        device,
        &GraphicsDesc {
            name,
            stages,
            topology: vk::PrimitiveTopology::PATCH_LIST,
            patch_control_points,
            color_formats: &[],
            depth_format: vk::Format::UNDEFINED,
            samples: vk::SampleCountFlags::TYPE_1,
            depth_test: false,
            depth_write: false,
            reverse_z: false,
            blend: Blend::None,
            rasterizer_discard: true,
        },
        max_sets,
    )
}

/// Records one storing pass: its scope, the barriers `graph` derives for
/// `uses` (what the pass reads and writes), and an attachment-less rendering
/// instance around `record`. Later passes declare what they read of its output.
///
/// # Safety
/// `cmd` is a recording command buffer of `device`, outside a render pass;
/// `record` records draws of capture pipelines only, touching no resource that
/// `uses` leaves out.
pub(super) unsafe fn record_capture(
    device: &Device,
    cmd: vk::CommandBuffer,
    (pass, timing): (RenderPass, Timing<'_>),
    (graph, uses): (&mut FrameGraph, &[Use]),
    record: impl FnOnce(vk::CommandBuffer),
) {
    let extent = vk::Extent2D { width: 1, height: 1 };
    let rendering = rendering::info(extent, &[], None);
    // SAFETY: guaranteed by the caller; every object belongs to this device.
    unsafe {
        let scope = pass.open(device, cmd, timing);
        graph.record(device, cmd, uses);
        device.raw.cmd_begin_rendering(cmd, &rendering);
        device.cmd_set_full_viewport(cmd, extent);
        record(cmd);
        device.raw.cmd_end_rendering(cmd);
        scope.close(device, cmd, timing);
    }
}
