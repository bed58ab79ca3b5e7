//! Pass 4 with transparency ([`crate::render::Transparency::Exact`] and
//! [`crate::render::Transparency::Fast`], `glsl/render/oit_*`): the hair as
//! transparent strands composited over the target. What both modes share
//! lives here; what differs, in `exact.rs` and `fast.rs`.
//!
//! 1. **Build** (in the [`RenderPass::Draw`] scope): every vertex of the hairs
//!    shaded once (`shade_points.comp`, a dispatch); then the ribbons of the draw
//!    pass's vertex stage (`ribbon.vert`'s coverage variant), with their true
//!    width, the shaded colour of their ends and a coverage per fragment,
//!    depth-tested against the target's depth (not written). Every surviving
//!    fragment takes its colour and coverage and is either pushed onto its pixel's list
//!    (exact; beyond the pool, counted and added to the weighted sums instead)
//!    or added to the weighted sums (fast). Both keep the nearest depth of a
//!    fragment at least half opaque.
//!    A second dispatch (`hair_rect.comp`) finds the rectangle of pixels the
//!    ribbons can reach.
//! 2. **Composite** ([`RenderPass::Composite`]): over that rectangle (two
//!    triangles, `hair_rect.vert`), blends each pixel's hair over the target as
//!    premultiplied colour, then writes that nearest half-opaque depth into the
//!    target's depth where it is nearer, so later host passes see the hair.
//!    After the compute rasteriser the exact mode's lists are resolved by a
//!    compute dispatch first (`oit_resolve.comp`, one invocation a pixel of the
//!    rectangle, into four half floats a pixel), so the lists are walked by
//!    every unit of the GPU and the fragment stage only blends
//!    (`oit_resolved.frag`); after the hardware build the fragment stage
//!    walks them (`oit_resolve.frag`).
//!
//! The pass owns the lists, the accumulation images and their pipelines for the
//! current extent and mode; when either changes, the old ones are retired and
//! freed once the frames that used them are `frames_in_flight` behind.

mod pipelines;
mod stats;

pub use stats::OitStats;

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::exact::{self, Lists, OitPool};
use super::fast::{self, WeightedSums};
use super::motion::{MotionBuffers, MotionPipelines};
use super::raster::{DepthSource, RasterBuffers};
use super::ribbons::RibbonIndices;
use super::shading::ShadingResources;
use super::tiles::{self, BinPipelines, TileBins};
use super::{DrawFrame, DrawMethod, TargetKey};
use crate::codes::sentinel::OIT_END;
use crate::error::{Error, Result};
use crate::gpu_types::OitCounters;
use crate::profiler::PassScope;
use crate::render::graph::{FrameGraph, Use};
use crate::render::pass::RenderPass;
use crate::render::OitParams;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::debug::LabelColor;
use crate::vk::device::{Device, DeviceInfo};
use crate::vk::image::Sampler;
use crate::vk::pipeline::{ComputePipeline, GraphicsPipeline};
use crate::vk::rendering;

/// Bytes per pixel of the compute resolve's output (four half floats).
const RESOLVED_BYTES_PER_PIXEL: u64 = 8;
/// Its binding (`OitResolved` in `oit_resolve.comp` and `oit_resolved.frag`).
const RESOLVED_BINDING: u32 = 28;

/// How the build makes fragments.
enum Build {
    /// The ribbons through the hardware raster pipeline (`ribbon.vert`'s
    /// coverage variant and the mode's fragment stage).
    Ribbons(GraphicsPipeline, vk::DescriptorSet),
    /// The compute rasteriser (`strand_raster.comp`, `raster.rs`).
    Compute(ComputePipeline, vk::DescriptorSet),
    /// The tiled rasteriser's bins (`tiles.rs`; its fine pass is the resolve).
    Tiles(Box<BinPipelines>),
}

/// The pipelines of one target and their descriptor sets.
struct Pipelines {
    points: (ComputePipeline, vk::DescriptorSet),
    rect: (ComputePipeline, vk::DescriptorSet),
    build: Build,
    /// The compute resolve before the composite (the compute rasteriser's exact mode).
    resolve: Option<(ComputePipeline, vk::DescriptorSet)>,
    composite: (GraphicsPipeline, vk::DescriptorSet),
    depth: Option<(GraphicsPipeline, vk::DescriptorSet)>,
    /// The motion vectors' walk and write (targets with a velocity image).
    motion: Option<MotionPipelines>,
}

/// What the pipelines of a target are kept under: the target, the mode's
/// shaders ([`super::ModeShaders::key`]) and the velocity image's format
/// (`UNDEFINED` for none).
type PipelineKey = (TargetKey, &'static str, vk::Format);

/// The buffers and images of one extent and method, and the pipelines bound to them.
struct Resources {
    extent: vk::Extent2D,
    method: DrawMethod,
    /// Per pixel: the nearest half-opaque depth.
    opaque: Buffer,
    /// Exact mode: the lists.
    lists: Option<Lists>,
    /// Weighted sums and absorbance (fast mode; the hardware build's overflow).
    sums: Option<WeightedSums>,
    /// The compute rasterisers' copy of the target's depth (and the
    /// per-segment one's overflow sums).
    raster_buffers: Option<RasterBuffers>,
    /// The tiled rasteriser's bins.
    tiles: Option<TileBins>,
    /// The compute rasteriser's exact mode: per pixel its resolved hair
    /// (`oit_resolve.comp`; four half floats), which the composite blends.
    resolved: Option<Buffer>,
    /// The motion vectors' per-pixel words, made by the first frame that
    /// writes motion vectors.
    motion: Option<MotionBuffers>,
    /// By target, composite shader (the exact mode's depends on K) and velocity format.
    pipelines: HashMap<PipelineKey, Pipelines>,
}

impl Resources {
    /// The exact mode's pool (fast mode: none).
    fn pool(&self) -> Option<OitPool> {
        self.lists.as_ref().map(|l| l.pool)
    }

    /// The tiled rasteriser's entries: those it holds.
    fn tile_capacity(&self) -> Option<u64> {
        self.tiles.as_ref().map(TileBins::capacity)
    }
}

/// The transparency pass: the per-frame counters, the resources of the current
/// extent and mode, and those of earlier ones still used by frames in flight.
pub(super) struct TransparentPass {
    device: Arc<Device>,
    /// [`OitCounters`], host-visible so the host reads what a frame stored.
    counters: Buffer,
    /// Per hair vertex its shaded colour (`shade_points.comp`), one vec4 for
    /// each vertex the renderer can draw.
    colors: Buffer,
    nearest: Sampler,
    /// Bound where the exact mode's composites would write the depths motion
    /// vectors follow, in frames that write none (never written then).
    motion_placeholder: Buffer,
    current: Option<Resources>,
    retired: Vec<(u64, Resources)>,
    /// Tile entries an earlier frame asked for beyond its bins' capacity: the
    /// next bins hold at least this many.
    tile_demand: u64,
    /// Frames in flight (`collect_retired`'s): frame N − this one has completed
    /// when frame N is recorded. None before the first.
    frames_in_flight: Option<u32>,
}

impl TransparentPass {
    /// The pass for a renderer drawing at most `hair_vertices` hair vertices.
    pub(super) fn new(device: &Arc<Device>, hair_vertices: u64) -> Result<Self> {
        let counters = Buffer::new(
            device,
            &BufferDesc {
                name: "vkhair transparency counters",
                size: std::mem::size_of::<OitCounters>() as u64,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        Ok(TransparentPass {
            device: device.clone(),
            counters,
            colors: Buffer::storage(device, "vkhair hair vertex colors", hair_vertices.max(1) * 16)?,
            nearest: Sampler::nearest(device, "vkhair transparency sums")?,
            motion_placeholder: Buffer::storage(device, "vkhair motion depth placeholder", 16)?,
            current: None,
            retired: Vec::new(),
            tile_demand: 0,
            frames_in_flight: None,
        })
    }

    /// Bytes of GPU memory `method` needs at `extent` on a device with `info`'s limits.
    pub(super) fn memory_bytes(
        &self,
        info: &DeviceInfo,
        method: DrawMethod,
        params: &OitParams,
        extent: vk::Extent2D,
    ) -> u64 {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        // All: the counters, the vertex colours, a depth word per pixel and
        // the overflow: the weighted sums, or the compute rasterisers' buffers.
        let overflow = match method.compute() {
            true => RasterBuffers::memory_bytes(extent, method.lists()),
            false => fast::BYTES_PER_PIXEL * pixels,
        };
        let shared = std::mem::size_of::<OitCounters>() as u64 + self.colors.size() + 4 * pixels + overflow;
        // The compute rasterisers' exact mode resolves into a buffer first.
        let resolved = RESOLVED_BYTES_PER_PIXEL * pixels;
        match method {
            DrawMethod::Opaque => 0,
            DrawMethod::Weighted => shared,
            DrawMethod::Tiles => {
                shared + resolved + TileBins::memory_bytes(extent, self.tile_capacity(info, params, extent))
            }
            DrawMethod::ComputeLists => shared + resolved + Lists::memory_bytes(&OitPool::plan(info, params, extent)),
            DrawMethod::HardwareLists => shared + Lists::memory_bytes(&OitPool::plan(info, params, extent)),
        }
    }

    /// Entries of the tiled rasteriser's bins with `params` on a device with
    /// `info`'s limits: per hair vertex the renderer can draw, or what an
    /// earlier frame asked for.
    fn tile_capacity(&self, info: &DeviceInfo, params: &OitParams, extent: vk::Extent2D) -> u64 {
        tiles::capacity(info, params, (self.colors.size() / 16, extent), self.tile_demand)
    }

    /// Drops every pipeline and set (the draw's inputs changed); the caller made
    /// sure no pending work uses them.
    pub(super) fn forget(&mut self) {
        if let Some(current) = &mut self.current {
            current.pipelines.clear();
        }
    }

    /// Frees retired resources whose last frame is `frames_in_flight` frames before `frame`.
    pub(super) fn collect_retired(&mut self, frame: u64, frames_in_flight: u32) {
        self.frames_in_flight = Some(frames_in_flight);
        let keep = u64::from(frames_in_flight);
        self.retired.retain(|(last, _)| last.saturating_add(keep) > frame);
    }

    /// Sets of resources waiting for their frames to complete.
    pub(super) fn retired_count(&self) -> usize {
        self.retired.len()
    }
}

/// Resources: made for an extent and method, kept while they stay.
impl TransparentPass {
    /// Makes the resources for `method` at `extent` the current ones (retiring others).
    fn prepare(&mut self, frame: u64, method: DrawMethod, params: &OitParams, extent: vk::Extent2D) -> Result<()> {
        let tiled = method == DrawMethod::Tiles;
        let pool = method.lists().then(|| OitPool::plan(&self.device.info, params, extent));
        // The bins grow to what a completed frame asked for: the one
        // `frames_in_flight` before this one (its own copy in the bins).
        let done = self.frames_in_flight.and_then(|f| frame.checked_sub(u64::from(f)));
        let bins_now = self.current.as_ref().and_then(|r| r.tiles.as_ref());
        if let (Some(done), Some(bins)) = (done, bins_now) {
            if let Some(asked) = bins.entries_asked_by(done).filter(|&asked| asked > bins.capacity()) {
                self.tile_demand = self.tile_demand.max(asked + asked / 4);
            }
        }
        if tiled {
            tiles::check_device(&self.device.info)?;
        }
        let bins = tiled.then(|| self.tile_capacity(&self.device.info, params, extent));
        let fits =
            |r: &Resources| r.extent == extent && r.method == method && r.pool() == pool && r.tile_capacity() == bins;
        if let Some(old) = self.current.take_if(|r| !fits(r)) {
            // Frames up to the previous one may still be using them.
            self.retired.push((frame.saturating_sub(1), old));
        }
        if self.current.is_some() {
            return Ok(());
        }
        let d = &self.device;
        // The per-pixel words (list heads, nearest opaque depth) are one buffer each.
        let pixel_words = 4 * u64::from(extent.width) * u64::from(extent.height);
        if pixel_words > u64::from(d.info.max_storage_buffer_range) {
            return Err(Error::incompatible(
                "render target",
                format!(
                    "transparent hair drawn at {}×{} needs {pixel_words} bytes of per-pixel words, more than this device's storage buffer range ({} bytes): draw smaller or without supersampling",
                    extent.width, extent.height, d.info.max_storage_buffer_range
                ),
            ));
        }
        let lists = match pool {
            Some(pool) => Some(Lists::new(d, pool)?),
            None => None,
        };
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        let compute = method.compute();
        self.current = Some(Resources {
            extent,
            method,
            opaque: Buffer::storage(d, "vkhair transparency opaque depth", 4 * pixels)?,
            lists,
            sums: if compute { None } else { Some(WeightedSums::new(d, extent)?) },
            raster_buffers: if compute { Some(RasterBuffers::new(d, extent, !tiled)?) } else { None },
            tiles: match bins {
                Some(capacity) => Some(TileBins::new(d, extent, capacity)?),
                None => None,
            },
            resolved: match compute {
                true => {
                    Some(Buffer::storage(d, "vkhair transparency resolved pixels", RESOLVED_BYTES_PER_PIXEL * pixels)?)
                }
                false => None,
            },
            motion: None,
            pipelines: HashMap::new(),
        });
        Ok(())
    }

    /// Makes the current resources' motion words, where `frame` writes motion
    /// vectors and they have none yet.
    fn prepare_motion(&mut self, frame: &DrawFrame<'_>) -> Result<()> {
        let Some(res) = self.current.as_mut().filter(|r| r.motion.is_none() && frame.motion.is_some()) else {
            return Ok(());
        };
        res.motion = Some(MotionBuffers::new(&self.device, res.extent, res.method.exact())?);
        Ok(())
    }
}

/// Recording.
impl TransparentPass {
    /// Records `frame` by `method` (a transparent one): the build in the
    /// draw's scope and the composite in its own.
    ///
    /// # Safety
    /// As for `DrawPass::record`.
    pub(super) unsafe fn record(
        &mut self,
        frame: &DrawFrame<'_>,
        graph: &mut FrameGraph,
        (method, params): (DrawMethod, &OitParams),
        shading: &mut ShadingResources,
        ribbons: &RibbonIndices,
    ) -> Result<()> {
        let target = &frame.target;
        if target.key.samples != vk::SampleCountFlags::TYPE_1 {
            return Err(Error::incompatible(
                "render target",
                "transparent hair needs a single-sample target (use supersampling for more samples)",
            ));
        }
        let compute = method.compute();
        // Checked, made (or found) before anything is recorded: a failure leaves `cmd` as it was.
        let depth_source = if compute { DepthSource::of(target)? } else { DepthSource::None };
        self.prepare(frame.frame, method, params, target.extent)?;
        self.prepare_motion(frame)?;
        let shaders = match method.exact() {
            true => exact::shaders(params.sorted_fragments, method.raster()),
            _ => fast::SHADERS,
        };
        self.make_pipelines(frame, &shaders, shading)?;
        let Some(res) = self.current.as_ref() else {
            return Err(Error::incompatible("transparency", "no resources after preparing them"));
        };
        let Some(pipelines) = res.pipelines.get(&(target.key, shaders.key(), frame.velocity_format())) else {
            return Err(Error::incompatible("transparency", "no pipelines after making them"));
        };
        let (d, cmd, timing) = (&*self.device, frame.cmd, frame.timing);
        let pool = res.pool();
        // The plan keeps both below the end-of-list marker.
        let capacity = pool.map_or(0, |p| p.capacity as u32);
        let counters = OitCounters {
            used: 0,
            capacity,
            width: target.extent.width,
            sorted: params.sorted_fragments,
            pool_nodes: pool.map_or(1, |p| p.nodes_per_buffer as u32),
            height: target.extent.height,
            hair_x0: u32::MAX,
            hair_y0: u32::MAX,
            hair_x1: 0,
            hair_y1: 0,
            scene_depth: depth_source.code(),
            reverse_z: u32::from(target.key.reverse_z),
            motion_threshold: match &frame.motion {
                Some(motion) if method.exact() => motion.threshold,
                _ => 0.0,
            },
        };
        // The steps' uses of the pass's own buffers: the build's stage reads
        // and writes them all (fragment or compute), the compute resolve and
        // the composite after it.
        use AccessKind::*;
        let (build_rw, build_read): (&[AccessKind], AccessKind) = match compute {
            true => (&[ComputeRead, ComputeWrite], ComputeRead),
            false => (&[FragmentRead, FragmentWrite], VertexRead),
        };
        // Every per-pixel buffer but the bins, which the tiled build declares itself.
        let mut pixels: Vec<&Buffer> = vec![&res.opaque];
        pixels.extend(res.lists.iter().flat_map(Lists::buffers));
        pixels.extend(res.raster_buffers.iter().flat_map(RasterBuffers::buffers));
        pixels.extend(&res.resolved);
        pixels.extend(res.motion.iter().flat_map(MotionBuffers::buffers));
        let mut cleared: Vec<&Buffer> = vec![&res.opaque];
        cleared.extend(res.lists.as_ref().map(Lists::cleared));
        cleared.extend(res.tiles.iter().flat_map(TileBins::cleared));
        cleared.extend(res.raster_buffers.iter().flat_map(RasterBuffers::cleared));
        if frame.motion.is_some() {
            cleared.extend(res.motion.iter().flat_map(MotionBuffers::buffers));
        }
        let sums_attached = res.sums.as_ref().map_or(Vec::new(), |s| s.attachment_uses().to_vec());
        let sums_sampled = res.sums.as_ref().map_or(Vec::new(), |s| s.sampled_uses().to_vec());
        let counters_update = [Use::buffer(&self.counters, &[AnyTransferWrite])];
        let shade =
            [Use::buffer(&self.colors, &[ComputeWrite]), Use::buffer(&self.counters, &[ComputeRead, ComputeWrite])];
        let clear = Use::buffers(cleared, &[AnyTransferWrite]);
        let build = [
            vec![Use::buffer(&self.colors, &[build_read]), Use::buffer(&self.counters, build_rw)],
            Use::buffers(pixels.iter().copied(), build_rw),
            sums_attached,
        ]
        .concat();
        // (The tiled rasteriser's fine pass reads the hairs and their colours too.)
        let resolve = [
            vec![
                Use::buffer(&self.counters, &[ComputeRead, ComputeWrite]),
                Use::buffer(&self.colors, &[ComputeRead]),
                Use::buffer(frame.inputs.hairs.0, &[ComputeRead]),
                Use::buffer(frame.inputs.hairs.1, &[ComputeRead]),
            ],
            Use::buffers(pixels.iter().copied(), &[ComputeRead, ComputeWrite]),
            Use::buffers(res.tiles.iter().flat_map(TileBins::buffers), &[ComputeRead, ComputeWrite]),
        ]
        .concat();
        let composite = [
            vec![Use::buffer(&self.counters, &[VertexRead, FragmentRead])],
            Use::buffers(pixels.iter().copied(), &[FragmentRead, FragmentWrite]),
            sums_sampled,
            target.uses.clone(),
        ]
        .concat();
        let (hairs, per_hair) = (frame.params.counts[0], frame.params.counts[1]);
        let depth_first = target.depth_attachment();
        let depth_again = target.depth_kept();
        let color = target.color_attachment();
        // The composite is the compute path's first use of the attachments.
        let composite_depth = if compute { depth_first.as_ref() } else { depth_again.as_ref() };
        let composite_rendering = rendering::info(target.extent, &color, composite_depth);
        // SAFETY: guaranteed by the caller; every object belongs to this device.
        unsafe {
            let scope = RenderPass::Draw.open(d, cmd, timing);
            // What the pass reads of the earlier passes, and the target it
            // tests against (the build) and blends into (the composite).
            shading.record_updates(graph, frame);
            graph.record(d, cmd, &counters_update);
            d.raw.cmd_update_buffer(cmd, self.counters.raw(), 0, bytemuck::bytes_of(&counters));
            graph.record(d, cmd, &shade);
            let shading_label = format!("{}, vertex shading", RenderPass::Draw.label());
            let inner = PassScope::open(d, cmd, timing, &shading_label, LabelColor::Compute);
            pipelines.points.0.bind_variant(cmd, frame.features, &[pipelines.points.1]);
            // At most 65,535 workgroups (every device's limit); the shader loops over the rest.
            let threads = pipelines.points.0.grid_stride_threads(hairs.saturating_mul(per_hair));
            pipelines.points.0.dispatch_threads(cmd, [threads, 1, 1]);
            // The rectangle the ribbons reach: a dispatch of its own (folded into the
            // shading above, lavapipe's resident memory grew by ~0.4 MB a frame).
            pipelines.rect.0.bind(cmd, &[pipelines.rect.1]);
            pipelines.rect.0.dispatch_threads(cmd, [threads, 1, 1]);
            inner.close(d, cmd, timing);
            graph.record(d, cmd, &clear);
            if let Some(lists) = &res.lists {
                lists.record_clear(d, cmd);
            }
            d.raw.cmd_fill_buffer(cmd, res.opaque.raw(), 0, vk::WHOLE_SIZE, OIT_END);
            if let Some(bins) = &res.tiles {
                bins.record_clear(d, cmd);
            }
            if let (Some(words), Some(_)) = (&res.motion, &frame.motion) {
                words.record_clear(d, cmd);
            }
            if let Some(buffers) = &res.raster_buffers {
                buffers.record_inputs(d, cmd, graph, depth_source, target.extent);
            }
            let build_label = format!("{}, build", RenderPass::Draw.label());
            let inner = PassScope::open(d, cmd, timing, &build_label, LabelColor::Graphics);
            // The tiled build declares its first dispatch's uses with the bins.
            if res.tiles.is_none() {
                graph.record(d, cmd, &build);
            }
            match &pipelines.build {
                Build::Ribbons(pipeline, set) => {
                    let sums = res.sums.as_ref().map(WeightedSums::attachments);
                    let sums = sums.as_ref().map_or(&[][..], |s| &s[..]);
                    let build_rendering = rendering::info(target.extent, sums, depth_first.as_ref());
                    d.raw.cmd_begin_rendering(cmd, &build_rendering);
                    d.cmd_set_full_viewport(cmd, target.extent);
                    pipeline.bind(cmd, &[*set]);
                    ribbons.draw(d, cmd, frame.segments);
                    d.raw.cmd_end_rendering(cmd);
                }
                Build::Compute(pipeline, set) => {
                    pipeline.bind_variant(cmd, pool.map_or(1, |p| p.buffers), &[*set]);
                    pipeline.dispatch_threads(cmd, [pipeline.grid_stride_threads(frame.segments), 1, 1]);
                }
                Build::Tiles(passes) => {
                    if let Some(bins) = &res.tiles {
                        passes.record(d, cmd, (graph, bins, &build), frame.segments);
                        bins.record_readback(d, cmd, graph, frame.frame);
                    }
                }
            }
            inner.close(d, cmd, timing);
            scope.close(d, cmd, timing);

            let scope = RenderPass::Composite.open(d, cmd, timing);
            if let Some((pipeline, set)) = &pipelines.resolve {
                let what = if res.tiles.is_some() { "tiles drawn and resolved" } else { "resolve in compute" };
                let resolve_label = format!("{}, {what}", RenderPass::Composite.label());
                let inner = PassScope::open(d, cmd, timing, &resolve_label, LabelColor::Compute);
                graph.record(d, cmd, &resolve);
                match &res.tiles {
                    // One workgroup a tile: its size is the tile's.
                    Some(bins) => {
                        pipeline.bind(cmd, &[*set]);
                        let [x, y] = bins.grid();
                        pipeline.dispatch_groups(cmd, [x, y, 1], 1);
                    }
                    None => {
                        pipeline.bind_variant(cmd, pool.map_or(1, |p| p.buffers), &[*set]);
                        pipeline.dispatch_threads(cmd, [target.extent.width, target.extent.height, 1]);
                    }
                }
                inner.close(d, cmd, timing);
            }
            // (The build's depth tests before the composite's writes: the target's uses.)
            graph.record(d, cmd, &composite);
            d.raw.cmd_begin_rendering(cmd, &composite_rendering);
            d.cmd_set_full_viewport(cmd, target.extent);
            for (pipeline, set) in [&pipelines.composite].into_iter().chain(&pipelines.depth) {
                pipeline.bind(cmd, &[*set]);
                d.raw.cmd_draw(cmd, 6, 1, 0, 0);
            }
            d.raw.cmd_end_rendering(cmd);
            scope.close(d, cmd, timing);
            if let (Some(motion), Some(walk)) = (&frame.motion, &pipelines.motion) {
                let scope = RenderPass::Motion.open(d, cmd, timing);
                let hairs = frame.inputs.hairs;
                let reads = [&[hairs.0, hairs.1, &self.counters][..], &pixels].concat();
                let picks: Vec<&Buffer> = res.motion.iter().flat_map(MotionBuffers::buffers).collect();
                walk.record(d, cmd, graph, motion, (frame.segments, (&reads, &picks)));
                scope.close(d, cmd, timing);
            }
            graph.record(d, cmd, &[Use::buffer(&self.counters, &[HostRead])]);
        }
        Ok(())
    }
}
