//! Motion vectors of opaque frames ([`crate::render::Transparency::Off`]):
//! the walk of `motion.rs` picking, per pixel, the nearest ribbon that covers
//! its centre — the one the opaque draw shaded there — with the words the
//! transparency pass would otherwise give it (the target's size and depth
//! convention, the per-pixel picks), per drawn extent.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;

use super::motion::{self, MotionPipelines, MOTION_NONE};
use super::shading::ShadingResources;
use super::{DrawFrame, TargetKey};
use crate::error::Result;
use crate::gpu_types::OitCounters;
use crate::render::graph::{FrameGraph, Use};
use crate::render::pass::RenderPass;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;

/// The words of one drawn extent and the pipelines bound to them.
struct Words {
    extent: vk::Extent2D,
    /// The walk's `OitCounters` (only the size and the depth convention are read).
    counters: Buffer,
    /// Per drawn pixel the pick (velocity, depth).
    keys: Buffer,
    /// By target, velocity format and the host's depth format.
    pipelines: HashMap<(TargetKey, vk::Format, vk::Format), MotionPipelines>,
}

/// The opaque frames' motion words: the current extent's, and earlier ones
/// kept until the frames that used them completed.
pub(super) struct OpaqueMotion {
    device: Arc<Device>,
    current: Option<Words>,
    retired: Vec<(u64, Words)>,
}

impl OpaqueMotion {
    pub(super) fn new(device: &Arc<Device>) -> Self {
        OpaqueMotion { device: device.clone(), current: None, retired: Vec::new() }
    }

    /// Drops every pipeline (the draw's inputs changed); the caller made sure
    /// no pending work uses them.
    pub(super) fn forget(&mut self) {
        if let Some(words) = &mut self.current {
            words.pipelines.clear();
        }
    }

    /// Frees words whose last frame is `frames_in_flight` frames before `frame`.
    pub(super) fn collect_retired(&mut self, frame: u64, frames_in_flight: u32) {
        let keep = u64::from(frames_in_flight);
        self.retired.retain(|(last, _)| last.saturating_add(keep) > frame);
    }

    /// Sets of words waiting for their frames to complete.
    pub(super) fn retired_count(&self) -> usize {
        self.retired.len()
    }

    /// Records `frame`'s motion vectors after its opaque draw (nothing for a
    /// frame without them) in the [`RenderPass::Motion`] scope.
    ///
    /// # Safety
    /// As for `DrawPass::record`, after the frame's opaque draw.
    pub(super) unsafe fn record(
        &mut self,
        frame: &DrawFrame<'_>,
        graph: &mut FrameGraph,
        shading: &ShadingResources,
    ) -> Result<()> {
        let Some(motion) = &frame.motion else {
            return Ok(());
        };
        let d = self.device.clone();
        let extent = frame.target.extent;
        if let Some(old) = self.current.take_if(|w| w.extent != extent) {
            // Frames up to the previous one may still be using them.
            self.retired.push((frame.frame.saturating_sub(1), old));
        }
        let words = match &mut self.current {
            Some(words) => words,
            None => {
                let counters = Buffer::new(
                    &d,
                    &crate::vk::buffer::BufferDesc {
                        name: "vkhair opaque motion words",
                        size: std::mem::size_of::<OitCounters>() as u64,
                        usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                        location: gpu_allocator::MemoryLocation::GpuOnly,
                    },
                )?;
                let keys = motion::MotionBuffers::keys_buffer(&d, extent)?;
                self.current.insert(Words { extent, counters, keys, pipelines: HashMap::new() })
            }
        };
        let host_depth = motion.host_depth.map(|(_, format)| (format, motion.reverse_z));
        let key = (frame.target.key, motion.format, host_depth.map_or(vk::Format::UNDEFINED, |d| d.0));
        if !words.pipelines.contains_key(&key) {
            let (shading_buffers, images) = shading.bindings(&frame.inputs);
            let mut buffers = shading_buffers.to_vec();
            buffers.extend([
                (9, &words.counters),
                (motion::PREVIOUS_BINDING, motion.previous),
                // Opaque frames match no depth: never read (the picks, so that
                // no other buffer seems read by the walk and the write).
                (motion::DEPTH_BINDING, &words.keys),
                (motion::KEYS_BINDING, &words.keys),
                (motion::BLOCK_BINDING, motion.uniforms),
            ]);
            words.pipelines.insert(key, MotionPipelines::new(&d, &buffers, &images, motion.format, host_depth)?);
        }
        let walk = &words.pipelines[&key];
        let counters = OitCounters {
            width: extent.width,
            height: extent.height,
            reverse_z: u32::from(frame.target.key.reverse_z),
            ..OitCounters::default()
        };
        let fills = [
            Use::buffer(&words.counters, &[AccessKind::AnyTransferWrite]),
            Use::buffer(&words.keys, &[AccessKind::AnyTransferWrite]),
        ];
        let (reads, picks) = ([frame.inputs.hairs.0, frame.inputs.hairs.1, &words.counters], [&words.keys]);
        // SAFETY: guaranteed by the caller.
        unsafe {
            let scope = RenderPass::Motion.open(&d, frame.cmd, frame.timing);
            graph.record(&d, frame.cmd, &fills);
            d.raw.cmd_update_buffer(frame.cmd, words.counters.raw(), 0, bytemuck::bytes_of(&counters));
            d.raw.cmd_fill_buffer(frame.cmd, words.keys.raw(), 0, vk::WHOLE_SIZE, MOTION_NONE);
            walk.record(&d, frame.cmd, graph, motion, (frame.segments, (&reads, &picks)));
            scope.close(&d, frame.cmd, frame.timing);
        }
        Ok(())
    }
}
