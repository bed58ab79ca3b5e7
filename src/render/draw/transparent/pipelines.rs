//! The transparency pass's pipelines, made per target on first use.

use ash::vk;

use super::{Build, Pipelines, TransparentPass, RESOLVED_BINDING};
use crate::error::{Error, Result};
use crate::render::draw::motion::{self, MotionPipelines};
use crate::render::draw::shading::ShadingResources;
use crate::render::draw::tiles::BinPipelines;
use crate::render::draw::{DrawFrame, ModeShaders};
use crate::render::Raster;
use crate::vk::pipeline::{Blend, ComputePipeline, GraphicsDesc, GraphicsPipeline};
use crate::vk::shaders::{
    RENDER_HAIR_RECT_COMP, RENDER_HAIR_RECT_VERT, RENDER_OIT_DEPTH_FRAG, RENDER_RIBBON_VERT_COVERAGE,
    RENDER_SHADE_POINTS_COMP, RENDER_STRAND_RASTER_COMP,
};

use super::super::fast::{ABSORBANCE, WEIGHTED_SUM};

impl TransparentPass {
    /// Makes the pipelines for `frame`'s target on first use, bound to the
    /// shading inputs and the current resources, and the vertex shading's
    /// variant for the frame's shading features.
    pub(super) fn make_pipelines(
        &mut self,
        frame: &DrawFrame<'_>,
        shaders: &ModeShaders,
        shading: &ShadingResources,
    ) -> Result<()> {
        let Some(res) = self.current.as_mut() else {
            return Err(Error::incompatible("transparency", "pipelines requested before the resources"));
        };
        let key = frame.target.key;
        let velocity = frame.velocity_format();
        if let Some(made) = res.pipelines.get_mut(&(key, shaders.key(), velocity)) {
            return made.points.0.prepare_variant(frame.features);
        }
        let d = &self.device;
        let has_depth = key.depth != vk::Format::UNDEFINED;
        let weighted_formats = [WEIGHTED_SUM, ABSORBANCE];
        let target_formats = [key.color];
        let desc = |name, stages, colors, depth_test, depth_write, blend| GraphicsDesc {
            name,
            stages,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            patch_control_points: 0,
            color_formats: colors,
            depth_format: key.depth,
            samples: vk::SampleCountFlags::TYPE_1,
            depth_test,
            depth_write,
            reverse_z: key.reverse_z,
            blend,
            rasterizer_discard: false,
        };
        let mut ours = vec![(9, &self.counters), (12, &res.opaque), (20, &self.colors)];
        if let Some(lists) = &res.lists {
            ours.extend(lists.bindings());
        }
        if let Some(raster) = &res.raster_buffers {
            ours.extend(raster.bindings());
        }
        if let Some(resolved) = &res.resolved {
            ours.push((RESOLVED_BINDING, resolved));
        }
        if let Some(bins) = &res.tiles {
            ours.extend(bins.bindings());
        }
        // The depths motion vectors follow: written by the exact mode's
        // composites where the frame has motion vectors (a placeholder, never
        // written, where it has none); the fast mode's nearest half-opaque ones.
        match (&res.motion, &frame.motion) {
            (Some(words), Some(motion)) => {
                ours.extend(words.bindings(&res.opaque));
                ours.extend([(motion::PREVIOUS_BINDING, motion.previous), (motion::BLOCK_BINDING, motion.uniforms)]);
            }
            _ => ours.push((motion::DEPTH_BINDING, &self.motion_placeholder)),
        }
        let (shading_buffers, shading_images) = shading.bindings(&frame.inputs);
        let mut buffers = shading_buffers.to_vec();
        buffers.extend_from_slice(&ours);

        // The pool's buffer count specialises the list shaders (oit.glsl).
        let pool_buffers = res.lists.as_ref().map(|lists| lists.pool.buffers);
        // Kernels bound only as a variant are compiled only as that variant.
        let mut points = ComputePipeline::deferred(d, &RENDER_SHADE_POINTS_COMP, 1, false)?;
        points.prepare_variant(frame.features)?;
        let points_set = points.declared_resource_set(0, &buffers, &shading_images)?;
        let rect = ComputePipeline::new(d, &RENDER_HAIR_RECT_COMP, 1)?;
        let rect_set = rect.declared_resource_set(0, &buffers, &[])?;
        let build_stages = [&RENDER_RIBBON_VERT_COVERAGE, shaders.build];
        let build = match res.method.raster() {
            Raster::Tiles => Build::Tiles(Box::new(BinPipelines::new(d, &buffers, &shading_images)?)),
            Raster::Compute => {
                // Constant 0: the pool's buffers (oit.glsl), as the hardware build's.
                let mut pipeline = ComputePipeline::deferred(d, &RENDER_STRAND_RASTER_COMP, 1, false)?;
                pipeline.prepare_variant(pool_buffers.unwrap_or(1))?;
                let set = pipeline.declared_resource_set(0, &buffers, &shading_images)?;
                Build::Compute(pipeline, set)
            }
            _ => {
                let pipeline = GraphicsPipeline::specialised(
                    d,
                    &desc(
                        "vkhair hair transparency build",
                        &build_stages,
                        &weighted_formats,
                        has_depth,
                        false,
                        Blend::Additive,
                    ),
                    1,
                    pool_buffers,
                )?;
                let set = pipeline.declared_resource_set(0, &buffers, &shading_images)?;
                Build::Ribbons(pipeline, set)
            }
        };

        let resolve = match (shaders.resolve, &res.resolved) {
            // The tiled rasteriser's fine pass walks the segments: the whole table.
            (Some(shader), Some(_)) if res.tiles.is_some() => {
                let pipeline = ComputePipeline::new(d, shader, 1)?;
                let set = pipeline.declared_resource_set(0, &buffers, &shading_images)?;
                Some((pipeline, set))
            }
            (Some(shader), Some(_)) => {
                // Constant 0: the pool's buffers (oit.glsl).
                let mut pipeline = ComputePipeline::deferred(d, shader, 1, false)?;
                pipeline.prepare_variant(pool_buffers.unwrap_or(1))?;
                let set = pipeline.declared_resource_set(0, &ours, &[])?;
                Some((pipeline, set))
            }
            (None, _) => None,
            (Some(_), None) => {
                return Err(Error::incompatible("transparency", "a compute resolve without its output buffer"));
            }
        };
        let composite_stages = [&RENDER_HAIR_RECT_VERT, shaders.composite];
        let composite = GraphicsPipeline::specialised(
            d,
            &desc(
                "vkhair hair transparency composite",
                &composite_stages,
                &target_formats,
                false,
                false,
                Blend::Premultiplied,
            ),
            1,
            pool_buffers,
        )?;
        let sums: Vec<_> = res
            .sums
            .iter()
            .flat_map(|s| [(0, s.sum.view(), self.nearest.raw), (1, s.absorbance.view(), self.nearest.raw)])
            .collect();
        let composite_set = composite.declared_resource_set(0, &ours, &sums)?;

        let depth = if has_depth {
            let pipeline = GraphicsPipeline::new(
                d,
                &desc(
                    "vkhair hair transparency depth",
                    &[&RENDER_HAIR_RECT_VERT, &RENDER_OIT_DEPTH_FRAG],
                    &target_formats,
                    true,
                    true,
                    Blend::NoColor,
                ),
                1,
            )?;
            let set = pipeline.declared_resource_set(0, &ours, &[])?;
            Some((pipeline, set))
        } else {
            None
        };
        let motion = match &frame.motion {
            Some(_) => Some(MotionPipelines::new(d, &buffers, &shading_images, velocity, None)?),
            None => None,
        };
        res.pipelines.insert(
            (key, shaders.key(), velocity),
            Pipelines {
                points: (points, points_set),
                rect: (rect, rect_set),
                build,
                resolve,
                composite: (composite, composite_set),
                depth,
                motion,
            },
        );
        Ok(())
    }
}
