//! Pass 1 — B-spline smoothing (`glsl/render/smooth.*`): key hairs drawn as
//! patches of 4 control points; the control stage sets `level` segments per
//! key segment, the isolines evaluation stage evaluates the uniform cubic
//! B-spline and stores position and tangent (storage writes from the
//! pipeline; rasterization is off).
//!
//! Storage writes rather than transform feedback: both work on lavapipe, but
//! writes go to any index (each smoothed vertex is stored exactly once, in
//! strand order, with no duplicate patch end points to strip) and need no
//! extension, while `VK_EXT_transform_feedback` is absent on some drivers.

use std::sync::Arc;

use ash::vk;

use crate::error::Result;
use crate::gpu_types::SmoothPush;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::GraphicsPipeline;
use crate::vk::shaders::{RENDER_SMOOTH_TESC, RENDER_SMOOTH_TESE, RENDER_SMOOTH_VERT};

pub(super) struct SmoothPass {
    pipeline: GraphicsPipeline,
    /// One set per half of the simulation's double-buffered positions.
    sets: [vk::DescriptorSet; 2],
}

impl SmoothPass {
    pub(super) fn new(device: &Arc<Device>, keys: [&Buffer; 2], positions: &Buffer, tangents: &Buffer) -> Result<Self> {
        let pipeline = super::capture_pipeline(
            device,
            "vkhair smoothing",
            &[&RENDER_SMOOTH_VERT, &RENDER_SMOOTH_TESC, &RENDER_SMOOTH_TESE],
            4,
            2,
        )?;
        let sets = [
            pipeline.buffer_set(0, &[(0, keys[0]), (1, positions), (2, tangents)])?,
            pipeline.buffer_set(0, &[(0, keys[1]), (1, positions), (2, tangents)])?,
        ];
        Ok(SmoothPass { pipeline, sets })
    }

    /// Records the draw (inside an attachment-less rendering instance).
    ///
    /// # Safety
    /// `cmd` is recording inside a dynamic rendering instance with viewport and
    /// scissor set; `half` names the simulation half holding the latest state.
    pub(super) unsafe fn record(&self, device: &Device, cmd: vk::CommandBuffer, half: usize, push: &SmoothPush) {
        let vertices = push.strands * (push.points - 1) * 4;
        // SAFETY: guaranteed by the caller.
        unsafe {
            self.pipeline.bind(cmd, &[self.sets[half]]);
            self.pipeline.push(cmd, push);
            device.raw.cmd_draw(cmd, vertices, 1, 0, 0);
        }
    }
}
