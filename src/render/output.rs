//! Passes 4–5 of [`Renderer`]: the hair drawn into the host's target, opaque
//! ([`super::draw`]) or transparent ([`super::oit`]), directly or through the
//! supersampling images ([`super::resolve`]).

use ash::vk;

use super::draw::{self, DrawInputs, DrawTarget, TargetKey};
use super::oit::{OitPass, OitStats, OitTarget};
use super::resolve::{SUPERSAMPLED_COLOR, SUPERSAMPLED_DEPTH};
use super::{Camera, RenderTarget, Renderer, Transparency};
use crate::error::{Error, Result};
use crate::profiler::GpuProfiler;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::rendering::{self, Load};

/// Passes 4–5: the draw and the resolve.
impl Renderer {
    /// Records the draw pass for the host's frame `frame`: the hairs prepared by
    /// [`Renderer::record_prepare`] into the host's `target`, seen by `camera`. The
    /// color (and depth) image is loaded, drawn into with depth test and write
    /// against what the host drew, and stored. With [`super::RenderParams::supersampling`],
    /// the hair is drawn at twice the size into the renderer's own images and
    /// resolved into `target` (depth tested, not written). When the target's size
    /// changes, the images of the old size are kept until `frame` is
    /// [`super::RenderParams::frames_in_flight`] frames later. Viewport and scissor are
    /// left set to the full target and one of vkhair's pipelines bound; vkhair
    /// binds no vertex or index buffers, so the host's stay bound, and the host
    /// binds its own pipeline and pushes its constants again afterwards
    /// (`tests/viewer.rs` draws after the hair relying on exactly this).
    ///
    /// With [`super::RenderParams::transparency`] on, the hair is composited over
    /// the target's colour instead (see `render/oit.rs`): each fragment depth-tested
    /// against the target's depth, and the depth of the nearest fragment at least
    /// half opaque written where it is nearer (not with supersampling, whose
    /// resolve leaves the host's depth as it was); the target must then be
    /// single-sample.
    ///
    /// # Safety
    /// As for [`Renderer::record_prepare`], which must have been recorded before in
    /// submission order. `target`'s views belong to the context's device, are in the
    /// layouts [`RenderTarget`] names, and are not used by other pending work in a
    /// conflicting way; writes to them recorded earlier on the same queue are ordered
    /// before the draw by the recorded barrier. Frame indices increase by one per host
    /// frame, and the command buffers of frame `frame − frames_in_flight` and earlier
    /// have completed (the usual frames-in-flight wait).
    pub unsafe fn record_draw(
        &mut self,
        cmd: vk::CommandBuffer,
        frame: u64,
        target: &RenderTarget,
        camera: &Camera,
        mut profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        if target.extent.width == 0 || target.extent.height == 0 {
            return Err(Error::param(
                "render target extent",
                format!("{:?}", target.extent),
                "non-zero width and height",
            ));
        }
        if self.last_frame.is_some_and(|last| frame < last) {
            return Err(Error::incompatible(
                "frame",
                format!("{frame} is before the previous frame {:?}", self.last_frame),
            ));
        }
        self.last_frame = Some(frame);
        self.resolve.collect_retired(frame, self.params.frames_in_flight);
        self.oit.collect_retired(frame, self.params.frames_in_flight);
        let finite = camera.view.is_finite() && camera.projection.is_finite() && camera.fov_y.is_finite();
        if !finite {
            return Err(Error::param(
                "camera",
                "a non-finite matrix or field of view",
                "finite view, projection and field of view",
            ));
        }
        let host_key = TargetKey {
            color: target.color_format,
            depth: target.depth_format,
            samples: target.samples,
            primitive: self.params.primitive,
        };
        // The host's earlier attachment writes (its head, its clear) before ours.
        let attachments = barrier::memory(HOST_ATTACHMENT_WRITES, barrier::ATTACHMENTS);
        let host_color = [rendering::color(target.color, Load::Keep)];
        let host_depth = rendering::depth(target.depth, Load::Keep);
        let has_depth = target.depth_format != vk::Format::UNDEFINED;
        let host_rendering = rendering::info(target.extent, &host_color, has_depth.then_some(&host_depth));
        let host = DrawTarget { key: host_key, rendering: &host_rendering, extent: target.extent };
        let counts = self.hair_counts();
        let vertices = self.line_vertices();
        let inputs = DrawInputs {
            hairs: self.interpolate.hairs(),
            shadow_uniforms: self.shadows.uniforms(),
            atlas: self.shadows.atlas(),
            transmittance: self.shadows.transmittance(),
        };
        let marschner = self.material.marschner;
        let mode = self.params.transparency;
        // With supersampling, the hair goes into the renderer's own images first.
        let mut images = match self.params.supersampling {
            true => Some(self.resolve.take(frame, target.extent)?),
            false => None,
        };
        let ss_key = TargetKey {
            color: SUPERSAMPLED_COLOR,
            depth: SUPERSAMPLED_DEPTH,
            samples: vk::SampleCountFlags::TYPE_1,
            primitive: self.params.primitive,
        };
        // Their attachments, the barriers that make them ready, views and extent,
        // then the rendering instance over the attachments.
        let ss = images.as_ref().map(|i| (i.attachments(), i.to_attachments(), i.views(), i.extent()));
        let ss_rendering = ss.as_ref().map(|((color, depth), _, _, big)| rendering::info(*big, color, Some(depth)));
        let host_barrier = [attachments];
        let (drawn, before, oit_target) = match (&ss, &ss_rendering) {
            (Some((_, to_attachments, (color, depth), big)), Some(ss_rendering)) => (
                DrawTarget { key: ss_key, rendering: ss_rendering, extent: *big },
                (&[][..], &to_attachments[..]),
                OitTarget {
                    key: ss_key,
                    extent: *big,
                    color: (*color, Load::color([0.0; 4])),
                    depth: Some((*depth, Load::depth(1.0))),
                    before: (&[], to_attachments),
                },
            ),
            _ => (
                DrawTarget { key: host_key, rendering: &host_rendering, extent: target.extent },
                (&host_barrier[..], &[][..]),
                OitTarget {
                    key: host_key,
                    extent: target.extent,
                    color: (target.color, Load::Keep),
                    depth: has_depth.then_some((target.depth, Load::Keep)),
                    before: (&host_barrier, &[]),
                },
            ),
        };
        let params = draw::draw_params(
            mode != Transparency::Off,
            &self.material,
            &self.lights,
            self.detail.width_scale,
            counts,
            camera,
            drawn.extent,
        );
        // SAFETY: guaranteed by the caller; the supersampling images are this
        // renderer's and earlier resolves that sampled them are ordered by the barriers.
        let result = unsafe {
            let result = match mode {
                Transparency::Off => {
                    self.draw.record(cmd, before, &drawn, &inputs, &params, &marschner, vertices, &mut profiler)
                }
                _ => self.oit.record(
                    cmd,
                    frame,
                    (mode, &self.params.oit),
                    &mut self.draw,
                    &oit_target,
                    &inputs,
                    (&params, &marschner),
                    vertices,
                    &mut profiler,
                ),
            };
            match &mut images {
                Some(images) => {
                    result.and_then(|_| self.resolve.record(cmd, images, &host, attachments, &mut profiler))
                }
                None => result,
            }
        };
        if let Some(images) = images {
            self.resolve.restore(images);
        }
        result
    }

    /// Sets of size-dependent images waiting for their frames to complete
    /// (supersampling images and transparency lists).
    pub fn retired_image_sets(&self) -> usize {
        self.resolve.retired_count() + self.oit.retired_count()
    }

    /// What the latest frame drawn with [`Transparency::Exact`] stored: fragments
    /// offered, stored, and overflowed because the pool was full (those are
    /// composited unsorted behind the stored ones). Read from
    /// host-visible memory: valid once that frame's commands completed and before
    /// the next frame's are submitted. `None` unless the latest frame drawn with
    /// transparency was an exact-mode frame.
    pub fn transparency_stats(&self) -> Option<OitStats> {
        self.oit.stats()
    }

    /// GPU memory the transparency mode of the current parameters needs for a
    /// target of `extent` (the supersampled extent where supersampling is on), bytes.
    pub fn transparency_memory(&self, extent: vk::Extent2D) -> u64 {
        let scale = if self.params.supersampling { 2 } else { 1 };
        let drawn = vk::Extent2D { width: extent.width * scale, height: extent.height * scale };
        OitPass::memory_bytes(self.params.transparency, &self.params.oit, drawn)
    }
}
/// Writes a host may have made to its attachments before the draw.
const HOST_ATTACHMENT_WRITES: &[AccessKind] =
    &[AccessKind::ColorAttachmentWrite, AccessKind::DepthAttachmentWrite, AccessKind::AnyTransferWrite];
