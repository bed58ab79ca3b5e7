//! Pass 1 — B-spline smoothing (`glsl/render/smooth.*`): key hairs drawn as
//! patches of 4 control points; the control stage sets `level` segments per
//! key segment, the isolines evaluation stage evaluates the uniform cubic
//! B-spline and stores position and tangent (storage writes from the
//! pipeline; rasterization is off). Mirrored phantom points put the curve
//! exactly through root and tip.
//!
//! Storage writes rather than transform feedback: both work on lavapipe, but
//! writes go to any index (each smoothed vertex is stored exactly once, in
//! strand order, with no duplicate patch end points to strip) and need no
//! extension, while `VK_EXT_transform_feedback` is absent on some drivers.

use std::sync::Arc;

use ash::vk;
use glam::Vec4;

use super::graph::{FrameGraph, Use};
use super::pass::{self, RenderPass};
use crate::error::Result;
use crate::gpu_types::SmoothPush;
use crate::profiler::Timing;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::GraphicsPipeline;
use crate::vk::shaders::{RENDER_SMOOTH_TESC, RENDER_SMOOTH_TESE, RENDER_SMOOTH_VERT};

/// The smoothing pass and the smoothed key hairs it stores.
pub(super) struct SmoothPass {
    device: Arc<Device>,
    pipeline: GraphicsPipeline,
    /// One set per half of the simulation's double-buffered positions (each with
    /// the positions before the step that produced it).
    sets: [vk::DescriptorSet; 2],
    /// Smoothed positions, strand after strand.
    positions: Buffer,
    /// Smoothed unit tangents, as `positions`.
    tangents: Buffer,
}

impl SmoothPass {
    /// The pass reading the simulation's two position buffers `keys` and the
    /// positions before the step of each (`before`), with room for `vertices`
    /// smoothed vertices.
    pub(super) fn new(device: &Arc<Device>, keys: [&Buffer; 2], before: [&Buffer; 2], vertices: u64) -> Result<Self> {
        let positions = Buffer::storage(device, "vkhair smoothed positions", vertices * 16)?;
        let tangents = Buffer::storage(device, "vkhair smoothed tangents", vertices * 16)?;
        let pipeline = pass::capture_pipeline(
            device,
            "vkhair smoothing",
            &[&RENDER_SMOOTH_VERT, &RENDER_SMOOTH_TESC, &RENDER_SMOOTH_TESE],
            4,
            2,
        )?;
        let sets = [
            pipeline.buffer_set(0, &[(0, keys[0]), (1, &positions), (2, &tangents), (3, before[0])])?,
            pipeline.buffer_set(0, &[(0, keys[1]), (1, &positions), (2, &tangents), (3, before[1])])?,
        ];
        Ok(SmoothPass { device: device.clone(), pipeline, sets, positions, tangents })
    }

    /// The smoothed positions and tangents (what the interpolation pass reads).
    pub(super) fn outputs(&self) -> (&Buffer, &Buffer) {
        (&self.positions, &self.tangents)
    }

    /// Records the pass in its own capture instance and scope: it reads the
    /// key hairs of `keys` (the simulation's latest half and the positions
    /// before its step) in the vertex stage and writes the smoothed positions
    /// and tangents in the evaluation stage.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass;
    /// `keys` are the buffers of half `half` the pass was made with.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        (half, keys): (usize, [&Buffer; 2]),
        push: &SmoothPush,
        graph: &mut FrameGraph,
        timing: Timing<'_>,
    ) {
        let d = &self.device;
        let vertices = push.strands * (push.points - 1) * 4;
        let uses = [
            Use::buffer(keys[0], &[AccessKind::VertexRead]),
            Use::buffer(keys[1], &[AccessKind::VertexRead]),
            Use::buffer(&self.positions, &[AccessKind::TessellationWrite]),
            Use::buffer(&self.tangents, &[AccessKind::TessellationWrite]),
        ];
        // SAFETY: guaranteed by the caller.
        unsafe {
            pass::record_capture(d, cmd, (RenderPass::Smooth, timing), (graph, &uses), |cmd| {
                self.pipeline.bind(cmd, &[self.sets[half]]);
                self.pipeline.push(cmd, push);
                d.raw.cmd_draw(cmd, vertices, 1, 0, 0);
            });
        }
    }

    /// Reads `n` smoothed positions and tangents back (submits and waits).
    pub(super) fn read(&self, n: usize) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        Ok((self.device.readback_pod(&self.positions, n)?, self.device.readback_pod(&self.tangents, n)?))
    }
}
