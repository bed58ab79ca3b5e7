//! Deep opacity maps (Yuksel & Keyser 2008, `glsl/render/shadow*`): two passes
//! over the interpolated hairs per shadow-casting light, into its atlas tile.
//!
//! 1. **Shadow depth** ([`RenderPass::ShadowDepth`]): the hairs as lines seen
//!    from the light; the depth test keeps the nearest light-space depth z0
//!    (meters along the light's axis) in an R32 float atlas.
//! 2. **Shadow opacity** ([`RenderPass::ShadowOpacity`]): the same lines again,
//!    additive and without a depth test: a fragment at depth d adds the strand
//!    opacity to the layer d − z0 falls in and to every layer behind it, z0 goes
//!    to alpha (MAX blending).
//!
//! Directional lights get an orthographic map fitted to the hair's bounding
//! sphere; spot lights a perspective map from their position aimed at it.

use std::sync::Arc;

use ash::vk;
use glam::{Vec3, Vec4};

use super::atlas::{ShadowAtlas, DEPTH_FORMAT, Z0_FORMAT};
use super::compute_maps::ComputeMaps;
use super::{Bounds, ShadowParams, SHADOW_ATLAS_FORMAT};
use crate::codes::shadow_kind;
use crate::error::{Error, Result};
use crate::gpu_types::{GpuLight, GpuShadowMap, GpuShadowParams};
use crate::profiler::{PassScope, Timing};
use crate::render::graph::{FrameGraph, Use};
use crate::render::pass::RenderPass;
use crate::render::Raster;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::pipeline::{Blend, GraphicsDesc, GraphicsPipeline};
use crate::vk::rendering;
use crate::vk::shaders::{ShaderSource, RENDER_SHADOW_DEPTH_FRAG, RENDER_SHADOW_OPACITY_FRAG, RENDER_SHADOW_VERT};

/// The two passes' pipelines over one atlas, and the compute rasteriser's
/// (`compute_maps.rs`), made on its first frame.
pub(super) struct OpacityMaps {
    device: Arc<Device>,
    pub(super) atlas: ShadowAtlas,
    depth_pass: (GraphicsPipeline, vk::DescriptorSet),
    opacity_pass: (GraphicsPipeline, vk::DescriptorSet),
    compute: Option<ComputeMaps>,
}

impl OpacityMaps {
    /// The atlas for `params` (a 1 × 1 atlas without casters) and the passes
    /// reading the frame's `uniforms` and hairs from `hair_positions`.
    pub(super) fn new(
        device: &Arc<Device>,
        params: &ShadowParams,
        uniforms: &Buffer,
        hair_positions: &Buffer,
    ) -> Result<Self> {
        if !device.info.rgba32f_blend {
            return Err(Error::MissingRequirement("blending into R32G32B32A32_SFLOAT attachments".into()));
        }
        let atlas = ShadowAtlas::new(device, params)?;
        let pipeline = |name, fragment: &ShaderSource, color_format, depth_format, blend| {
            GraphicsPipeline::new(
                device,
                &GraphicsDesc {
                    name,
                    stages: &[&RENDER_SHADOW_VERT, fragment],
                    topology: vk::PrimitiveTopology::LINE_LIST,
                    patch_control_points: 0,
                    color_formats: &[color_format],
                    depth_format,
                    samples: vk::SampleCountFlags::TYPE_1,
                    depth_test: depth_format != vk::Format::UNDEFINED,
                    depth_write: depth_format != vk::Format::UNDEFINED,
                    reverse_z: false,
                    blend,
                    rasterizer_discard: false,
                },
                1,
            )
        };
        let depth_pipeline =
            pipeline("vkhair shadow depth", &RENDER_SHADOW_DEPTH_FRAG, Z0_FORMAT, DEPTH_FORMAT, Blend::None)?;
        let depth_set = depth_pipeline.resource_set(0, &[(0, uniforms), (1, hair_positions)], &[])?;
        let opacity_pipeline = pipeline(
            "vkhair shadow opacity",
            &RENDER_SHADOW_OPACITY_FRAG,
            SHADOW_ATLAS_FORMAT,
            vk::Format::UNDEFINED,
            Blend::AddColorMaxAlpha,
        )?;
        let (z0_view, sampler) = atlas.z0_sampled();
        let opacity_set =
            opacity_pipeline.resource_set(0, &[(0, uniforms), (1, hair_positions)], &[(2, z0_view, sampler)])?;
        Ok(OpacityMaps {
            device: device.clone(),
            atlas,
            depth_pass: (depth_pipeline, depth_set),
            opacity_pass: (opacity_pipeline, opacity_set),
            compute: None,
        })
    }

    /// Records the maps of `uniforms` drawn by `raster`: see
    /// [`OpacityMaps::record`] and `ComputeMaps::record`, which leave the atlas
    /// alike. The compute passes are made on the first compute frame, reading
    /// `inputs` (the uniform buffer and the hair positions this was made with).
    ///
    /// # Safety
    /// As [`OpacityMaps::record`].
    pub(super) unsafe fn record_with(
        &mut self,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        uniforms: &GpuShadowParams,
        vertices: u32,
        (raster, inputs): (Raster, (&Buffer, &Buffer)),
        timing: Timing<'_>,
    ) -> Result<()> {
        if raster != Raster::Compute {
            // SAFETY: guaranteed by the caller.
            unsafe { self.record(cmd, graph, uniforms, vertices, inputs, timing) };
            return Ok(());
        }
        if self.compute.is_none() {
            self.compute = Some(ComputeMaps::new(&self.device, &self.atlas, inputs.0, inputs.1)?);
        }
        if let Some(compute) = &self.compute {
            // SAFETY: guaranteed by the caller; the passes were made for this atlas.
            unsafe { compute.record(cmd, graph, uniforms, &self.atlas, inputs, timing) };
        }
        Ok(())
    }

    /// Records both passes for the maps of `uniforms` over `vertices` line
    /// vertices, each in its scope, declaring to `graph` what they read
    /// (`inputs`: the uniform buffer and the hair positions the passes were
    /// made with) and the atlas images they draw.
    ///
    /// # Safety
    /// `cmd` is recording outside a render pass on this device; every earlier
    /// command on the resources since `graph` was made was declared to it.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        uniforms: &GpuShadowParams,
        vertices: u32,
        (uniform_buffer, hairs): (&Buffer, &Buffer),
        timing: Timing<'_>,
    ) {
        let d = &self.device;
        let maps = uniforms.map_count();
        let inputs = [
            Use::buffer(hairs, &[AccessKind::VertexRead]),
            Use::buffer(uniform_buffer, &[AccessKind::VertexUniformRead, AccessKind::FragmentUniformRead]),
        ];
        let extent = self.atlas.extent();
        let (z0_attachment, depth_attachment) = self.atlas.depth_pass_attachments();
        let depth_rendering = rendering::info(extent, &z0_attachment, Some(&depth_attachment));
        let atlas_attachment = self.atlas.opacity_pass_attachment();
        let opacity_rendering = rendering::info(extent, &atlas_attachment, None);
        // Each map is its own nested scope: the profile lists every light's map.
        let light_of = |map: usize| (0..8).find(|&i| uniforms.light_map[i / 4][i % 4] == map as u32).unwrap_or(map);
        let draw_tiles = |cmd: vk::CommandBuffer,
                          pass: &(GraphicsPipeline, vk::DescriptorSet),
                          stage: RenderPass,
                          timing: Timing<'_>| {
            // SAFETY: inside the rendering instance recorded below.
            unsafe {
                pass.0.bind(cmd, &[pass.1]);
                for (k, map) in uniforms.maps.iter().enumerate().take(maps) {
                    if map.is_density_volume() {
                        continue; // density volume: no map
                    }
                    let label = format!("{}, light {}", stage.label(), light_of(k));
                    let scope = PassScope::open(d, cmd, timing, &label, LabelColor::Graphics);
                    let [x, y, w, h] = map.tile;
                    let viewport = vk::Viewport { x, y, width: w, height: h, min_depth: 0.0, max_depth: 1.0 };
                    let scissor = vk::Rect2D {
                        offset: vk::Offset2D { x: x as i32, y: y as i32 },
                        extent: vk::Extent2D { width: w as u32, height: h as u32 },
                    };
                    d.raw.cmd_set_viewport(cmd, 0, &[viewport]);
                    d.raw.cmd_set_scissor(cmd, 0, &[scissor]);
                    pass.0.push(cmd, &(k as u32));
                    d.raw.cmd_draw(cmd, vertices, 1, 0, 0);
                    scope.close(d, cmd, timing);
                }
            }
        };
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            let scope = RenderPass::ShadowDepth.open(d, cmd, timing);
            graph.record(d, cmd, &[&inputs[..], &self.atlas.depth_pass_uses()].concat());
            d.raw.cmd_begin_rendering(cmd, &depth_rendering);
            draw_tiles(cmd, &self.depth_pass, RenderPass::ShadowDepth, timing);
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, timing);
            let scope = RenderPass::ShadowOpacity.open(d, cmd, timing);
            graph.record(d, cmd, &[&inputs[..], &self.atlas.opacity_pass_uses()].concat());
            d.raw.cmd_begin_rendering(cmd, &opacity_rendering);
            draw_tiles(cmd, &self.opacity_pass, RenderPass::ShadowOpacity, timing);
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, timing);
        }
    }
}

/// How the drawn strands stand for real hairs, as the opacity maps see them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShadowFootprint {
    /// Real hairs each drawn strand stands for.
    pub hairs: f32,
    /// Spacing of the drawn strands half-way along them, m.
    pub spacing: f32,
}

impl ShadowFootprint {
    /// One drawn strand per hair: the maps as `ShadowParams` set them.
    #[cfg(test)]
    pub(crate) const ONE_HAIR: ShadowFootprint = ShadowFootprint { hairs: 1.0, spacing: 0.0 };

    /// The filter radius of a map whose texels are `texel` m wide: a lookup
    /// reaches the neighbouring drawn strands, whose hairs spread over
    /// (1 − 1/n) × spacing (as the transparent bands), in texels rounded to the
    /// nearest, up to 3; at least `radius`.
    pub(crate) fn filter_radius(&self, radius: u32, texel: f32) -> u32 {
        let spread = crate::render::strand_frames::strand_spread(self.hairs, self.spacing);
        let wanted = if texel > 0.0 { (spread / texel).round() } else { 0.0 };
        radius.max(wanted.clamp(0.0, 3.0) as u32)
    }
}

/// The light's map for hair within `bounds`: matrices fitted to the sphere,
/// layers and filter from `params` (the filter widened for the `footprint`'s
/// spacing), atlas tile `index`; each fragment of a strand standing for
/// `footprint.hairs` hairs adds their opacity, `params.opacity · hairs`.
pub(crate) fn light_map(
    light: &GpuLight,
    light_index: usize,
    bounds: Bounds,
    params: &ShadowParams,
    index: usize,
    footprint: ShadowFootprint,
) -> Result<GpuShadowMap> {
    let Bounds { centre, radius } = bounds;
    let kind = light.kind();
    let direction = light.direction().normalize_or_zero();
    let radius = radius.max(1e-4);
    // World size of a texel at the hair's centre.
    let texel;
    let (view, projection) = match kind {
        0 => {
            let eye = centre - direction * (2.0 * radius);
            let view = glam::camera::rh::view::look_at_mat4(eye, centre, up_for(direction));
            texel = 2.0 * radius / params.resolution as f32;
            (
                view,
                glam::camera::rh::proj::vulkan::orthographic(
                    -radius,
                    radius,
                    -radius,
                    radius,
                    radius * 0.5,
                    radius * 3.5,
                ),
            )
        }
        2 => {
            let eye = light.position();
            let to_centre = centre - eye;
            let distance = to_centre.length();
            let outer = light.cos_outer().clamp(-1.0, 1.0).acos();
            let fit = if distance > radius * 1.01 { (radius / distance).asin() } else { outer };
            let half = fit.min(outer.max(0.05)).clamp(0.01, 1.45);
            let aim = if distance > 1e-6 { to_centre / distance } else { direction };
            let near = (distance - radius).max(radius * 0.01);
            let view = glam::camera::rh::view::look_at_mat4(eye, eye + aim, up_for(aim));
            texel = 2.0 * distance * half.tan() / params.resolution as f32;
            (view, glam::camera::rh::proj::vulkan::perspective(2.0 * half, 1.0, near, distance + radius))
        }
        _ => {
            return Err(Error::unsupported(
                "deep opacity maps of point lights",
                format!(
                    "light {light_index} is a point light; use a directional or spot light, or a density-volume caster"
                ),
            ))
        }
    };
    let row = view.row(2);
    Ok(GpuShadowMap {
        view_proj: (projection * view).to_cols_array_2d(),
        view_z: (-row).to_array(),
        layers: Vec4::new(params.layers[0], params.layers[1], params.layers[2], params.extinction).to_array(),
        tile: params.tile(index),
        params: [
            params.opacity * footprint.hairs,
            footprint.filter_radius(params.pcf_radius, texel) as f32,
            shadow_kind::DEEP_OPACITY as f32,
            0.0,
        ],
    })
}

fn up_for(direction: Vec3) -> Vec3 {
    if direction.y.abs() > 0.95 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}
