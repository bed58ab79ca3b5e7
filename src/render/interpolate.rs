//! Pass 2 — single-strand interpolation (`glsl/render/interpolate.*`): a draw
//! with no vertex buffer, one patch per key segment; the control stage's line
//! count is the number of hairs grown from each key hair, its segment count the
//! smoothing level. Each vertex is the smoothed key vertex plus an offset in
//! the key hair's frame: a stable random clump coordinate (uniform in the unit
//! disk, fixed per hair) × clump width × mix(root width, tip width) along the
//! strand. The frame is built on the GPU from the smoothed tangent and the key
//! hair's rest-plane normal turned with the head, so it does not flip.

use std::sync::Arc;

use ash::vk;
use glam::{Vec3, Vec4};

use crate::error::Result;
use crate::gpu_types::InterpolatePush;
use crate::sim::SimState;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::GraphicsPipeline;
use crate::vk::shaders::{ShaderSource, RENDER_INTERPOLATE_TESC, RENDER_INTERPOLATE_VERT};

/// Per key hair, the normal of the plane its rest shape lies in (head frame):
/// root tangent × (tip − root), or any perpendicular of the root tangent for a
/// straight hair.
pub(super) fn reference_vectors(rest: &SimState) -> Vec<Vec4> {
    (0..rest.strands)
        .map(|s| {
            let base = s * rest.points;
            let root = rest.rest[base].truncate();
            let t0 = (rest.rest[base + 1].truncate() - root).normalize_or(Vec3::NEG_Y);
            let tip = rest.rest[base + rest.points - 1].truncate();
            let n = t0.cross(tip - root).try_normalize().unwrap_or_else(|| t0.any_orthonormal_vector());
            n.extend(0.0)
        })
        .collect()
}

pub(super) struct InterpolatePass {
    pipeline: GraphicsPipeline,
    set: vk::DescriptorSet,
}

impl InterpolatePass {
    /// `evaluation` is the single-strand or the barycentric evaluation stage; the
    /// buffers are bound by number (0–2 smoothed data and key frames, 3–4 output,
    /// 5 scalp triangles) where the stage declares them.
    pub(super) fn new(device: &Arc<Device>, evaluation: &ShaderSource, buffers: &[(u32, &Buffer)]) -> Result<Self> {
        let pipeline = super::capture_pipeline(
            device,
            evaluation.name,
            &[&RENDER_INTERPOLATE_VERT, &RENDER_INTERPOLATE_TESC, evaluation],
            1,
            1,
        )?;
        let set = pipeline.declared_buffer_set(0, buffers)?;
        Ok(InterpolatePass { pipeline, set })
    }

    /// # Safety
    /// `cmd` is recording inside a dynamic rendering instance with viewport and
    /// scissor set, after the smoothing pass's writes were made visible.
    pub(super) unsafe fn record(&self, device: &Device, cmd: vk::CommandBuffer, push: &InterpolatePush) {
        // SAFETY: guaranteed by the caller. `strands` counts key hairs, or scalp
        // triangles in barycentric mode: one patch per key segment of each.
        unsafe {
            self.pipeline.bind(cmd, &[self.set]);
            self.pipeline.push(cmd, push);
            device.raw.cmd_draw(cmd, push.strands * (push.points - 1), 1, 0, 0);
        }
    }
}
