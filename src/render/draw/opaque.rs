//! Pass 4 with [`Transparency::Off`](crate::render::Transparency::Off)
//! (`glsl/render/ribbon.vert`, `draw.*`): the hairs as camera-facing ribbons
//! placed by the vertex stage, two triangles a segment (or lines), shaded with Kajiya-Kay diffuse and two shifted
//! highlights (or Marschner) for every light, into the target's colour and
//! depth (depth-tested against what the host drew). With a depth image the
//! ribbons are drawn twice in one rendering instance: first depth only (no
//! fragment stage), then shaded with depth writes off and the depth test
//! passing only fragments at the nearest depth, so that hidden layers of hair
//! are not shaded. Pipelines are made on first use for each [`TargetKey`] and
//! set of shading features (the shading stage is specialised to them,
//! [`DrawFrame::features`]).

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::sync::Arc;

use super::ribbons::RibbonIndices;
use super::shading::ShadingResources;
use super::{DrawFrame, TargetKey};
use crate::error::Result;
use crate::render::graph::FrameGraph;
use crate::render::pass::RenderPass;
use crate::render::Primitive;
use crate::vk::device::Device;
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering;
use crate::vk::shaders::{ShaderSource, RENDER_DRAW_FRAG, RENDER_DRAW_VERT, RENDER_RIBBON_VERT};
use ash::vk;

/// The pipelines of one target: the depth pre-pass (targets with a depth image)
/// and the shading draw per set of shading features (only the fragment stage
/// differs), each with its descriptor set.
struct Pipelines {
    depth: Option<(GraphicsPipeline, vk::DescriptorSet)>,
    shade: HashMap<u32, (GraphicsPipeline, vk::DescriptorSet)>,
}

/// The opaque draw's pipelines per target.
pub(super) struct OpaquePipelines {
    device: Arc<Device>,
    pipelines: HashMap<TargetKey, Pipelines>,
}

impl OpaquePipelines {
    pub(super) fn new(device: &Arc<Device>) -> Self {
        OpaquePipelines { device: device.clone(), pipelines: HashMap::new() }
    }

    /// Drops every pipeline and set (their resources changed); the caller made sure
    /// no pending work uses them.
    pub(super) fn forget(&mut self) {
        self.pipelines.clear();
    }

    /// Makes the pipelines and descriptor sets for `frame`'s target and shading
    /// features on first use.
    fn make(&mut self, frame: &DrawFrame<'_>, shading: &ShadingResources) -> Result<()> {
        let key = frame.target.key;
        if self.pipelines.get(&key).is_some_and(|p| p.shade.contains_key(&frame.features)) {
            return Ok(());
        }
        let (buffers, images) = shading.bindings(&frame.inputs);
        let color_formats = [key.color];
        let has_depth = key.depth != vk::Format::UNDEFINED;
        // Ribbons are two triangles a segment placed by the vertex stage; lines
        // one line a segment. Either way the fragment stage reads the same
        // outputs at the same locations.
        let (stages, topology): (&[&ShaderSource], _) = if key.primitive == Primitive::Lines {
            (&[&RENDER_DRAW_VERT, &RENDER_DRAW_FRAG], vk::PrimitiveTopology::LINE_LIST)
        } else {
            (&[&RENDER_RIBBON_VERT, &RENDER_DRAW_FRAG], vk::PrimitiveTopology::TRIANGLE_LIST)
        };
        let desc = |name, stages, depth_write, blend| GraphicsDesc {
            name,
            stages,
            topology,
            patch_control_points: 0,
            color_formats: &color_formats,
            depth_format: key.depth,
            samples: key.samples,
            depth_test: has_depth,
            depth_write,
            reverse_z: key.reverse_z,
            blend,
            rasterizer_discard: false,
        };
        // The geometry is the same in both: only the hair positions (bindings 1
        // and 2) and the uniform block.
        let made = match self.pipelines.entry(key) {
            Entry::Occupied(made) => made.into_mut(),
            Entry::Vacant(slot) => {
                let depth = if has_depth {
                    let geometry = &stages[..stages.len() - 1];
                    let depth_desc = desc("vkhair hair depth", geometry, true, Blend::NoColor);
                    let pipeline = GraphicsPipeline::new(&self.device, &depth_desc, 1)?;
                    let set = pipeline.resource_set(0, &buffers[..3], &[])?;
                    Some((pipeline, set))
                } else {
                    None
                };
                slot.insert(Pipelines { depth, shade: HashMap::new() })
            }
        };
        let shade_desc = desc("vkhair hair draw", stages, false, Blend::None);
        let pipeline = GraphicsPipeline::specialised(&self.device, &shade_desc, 1, Some(frame.features))?;
        let set = pipeline.resource_set(0, &buffers, &images)?;
        made.shade.insert(frame.features, (pipeline, set));
        Ok(())
    }

    /// Records `frame` in the draw's scope: the shading updates, the barriers
    /// `graph` derives for what the draw reads and its target, and one draw of the frame's ribbons or lines (twice with a depth
    /// pre-pass). Leaves the ribbons' index buffer bound.
    ///
    /// # Safety
    /// As for `DrawPass::record`.
    pub(super) unsafe fn record(
        &mut self,
        frame: &DrawFrame<'_>,
        graph: &mut FrameGraph,
        shading: &mut ShadingResources,
        ribbons: &RibbonIndices,
    ) -> Result<()> {
        // Made (or found) before anything is recorded: a failure leaves `cmd` as it was.
        self.make(frame, shading)?;
        let (d, cmd, target) = (&*self.device, frame.cmd, &frame.target);
        let color = target.color_attachment();
        let depth = target.depth_attachment();
        let info = rendering::info(target.extent, &color, depth.as_ref());
        // SAFETY: guaranteed by the caller; all objects belong to this device.
        unsafe {
            let scope = RenderPass::Draw.open(d, cmd, frame.timing);
            shading.record_updates(graph, frame);
            let pipelines = &self.pipelines[&target.key];
            let shade = &pipelines.shade[&frame.features];
            d.raw.cmd_begin_rendering(cmd, &info);
            d.cmd_set_full_viewport(cmd, target.extent);
            // Within one rendering instance, rasterization order puts the depth
            // pre-pass's writes before the shading draw's tests.
            for (pipeline, set) in pipelines.depth.iter().chain([shade]) {
                pipeline.bind(cmd, &[*set]);
                match target.key.primitive {
                    Primitive::Lines => d.raw.cmd_draw(cmd, 2 * frame.segments, 1, 0, 0),
                    Primitive::Ribbons => ribbons.draw(d, cmd, frame.segments),
                }
            }
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, frame.timing);
        }
        Ok(())
    }
}
