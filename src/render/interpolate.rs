//! Pass 2 — single-strand interpolation (`glsl/render/interpolate.*`): a draw
//! with no vertex buffer, one patch per key segment and instance; the control
//! stage's line count is the number of hairs the instance grows from each key
//! hair (instance n grows `LINES_PER_INSTANCE` hairs from n × that on,
//! `codes::interpolate`), its segment count the smoothing level. Each vertex is the smoothed key vertex plus an offset in
//! the key hair's frame: a stable random clump coordinate (uniform in the unit
//! disk, fixed per hair) × clump width × mix(root width, tip width) along the
//! strand. The frame is built on the GPU from the smoothed tangent and the key
//! hair's rest-plane normal turned with the head, so it does not flip.
//!
//! In [`InterpolationMode::Barycentric`] the patches are triangles of key-hair
//! roots instead ([`super::scalp`]), each hair blending three key hairs with
//! stable random weights.
//!
//! With [`Followers`] (a dense authored groom) a third evaluation stage draws
//! them instead: one patch per follower segment, each point the blend of its
//! guides plus its rest offset in their frames (see [`super::followers`]).
//!
//! Each mode's vertex is one function (`glsl/include/grow_*.glsl`) that either
//! the evaluation stage above or a compute dispatch (`interpolate.comp`, one
//! invocation per vertex) calls: [`Interpolator`] picks which.

use std::sync::Arc;

use ash::vk;
use glam::{Vec3, Vec4};

use super::followers::Followers;
use super::graph::{FrameGraph, Use};
use super::pass::{self, RenderPass};
use super::smooth::SmoothPass;
use super::{InterpolationMode, Interpolator};
use crate::codes;
use crate::error::{Error, Result};
use crate::gpu_types::InterpolatePush;
use crate::profiler::Timing;
use crate::sim::SimState;
use crate::vk::barrier::AccessKind;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::pipeline::{ComputePipeline, GraphicsPipeline};
use crate::vk::shaders::{
    ShaderSource, RENDER_INTERPOLATE_BARY_TESE, RENDER_INTERPOLATE_COMP, RENDER_INTERPOLATE_COMP_BARY,
    RENDER_INTERPOLATE_COMP_FOLLOW, RENDER_INTERPOLATE_FOLLOW_TESE, RENDER_INTERPOLATE_TESC, RENDER_INTERPOLATE_TESE,
    RENDER_INTERPOLATE_VERT,
};

/// Per key hair, its rest-plane normal ([`super::reference::rest_plane_normals`]).
fn reference_vectors(rest: &SimState) -> Vec<Vec4> {
    super::strand_frames::rest_plane_normals(rest).into_iter().map(|n| n.extend(0.0)).collect()
}

/// Rejects `mode` when it cannot grow hairs from key hairs whose roots form
/// `triangles` scalp triangles.
pub(super) fn check_mode(mode: InterpolationMode, triangles: u32) -> Result<()> {
    if mode == InterpolationMode::Barycentric && triangles == 0 {
        return Err(Error::unsupported(
            "barycentric interpolation",
            "it needs at least 3 key hairs whose roots form a triangle",
        ));
    }
    Ok(())
}

/// What `mode` grows hairs from: the `strands` key hairs, or the `triangles`
/// scalp triangles between their roots.
pub(super) fn units(mode: InterpolationMode, strands: u32, triangles: u32) -> u32 {
    match mode {
        InterpolationMode::SingleStrand => strands,
        InterpolationMode::Barycentric => triangles,
    }
}

/// Mean area of `triangles` of key-hair roots of `rest`, m² (0 for none).
fn mean_area(rest: &SimState, triangles: &[[u32; 3]]) -> f32 {
    let roots = rest.rest_roots();
    let sum: f32 = triangles.iter().map(|t| super::scalp::triangle_area(&roots, t)).sum();
    sum / triangles.len().max(1) as f32
}

/// The interpolation pass: its two pipelines, the key frames and scalp
/// triangles it reads, and the hairs it stores.
pub(super) struct InterpolatePass {
    device: Arc<Device>,
    single_strand: Pipeline,
    barycentric: Pipeline,
    /// Per key hair, its rest-plane normal (head frame).
    reference: Buffer,
    /// Scalp triangles between key-hair roots (barycentric mode).
    _triangle_buffer: Buffer,
    triangles: u32,
    /// Mean area of the scalp triangles at rest, m² (0 without triangles).
    mean_triangle_area: f32,
    /// Interpolated positions, hair after hair.
    positions: Buffer,
    /// Interpolated (tangent, t along the hair), as `positions`.
    tangents: Buffer,
    /// The followers' pipeline and binding buffers, when drawing followers.
    follow: Option<Follow>,
    /// Per drawn follower its own albedo and width factor at the root and the
    /// tip (two vec4); two zero vec4 never read without followers.
    looks: Buffer,
    /// Whether the hairs have their own albedo.
    own_colors: bool,
}

/// The followers' evaluation stage and what it reads.
struct Follow {
    pipeline: Pipeline,
    _bindings: Buffer,
    _offsets: Buffer,
}

/// One mode's two ways to grow its hairs: the tessellation stages and the
/// compute dispatch, each with its descriptor set.
struct Pipeline {
    pipeline: GraphicsPipeline,
    set: vk::DescriptorSet,
    compute: ComputePipeline,
    compute_set: vk::DescriptorSet,
}

/// Workgroups of one row of the compute dispatch: within
/// `maxComputeWorkGroupCount`'s least x (65,535) on every device.
const DISPATCH_ROW: u32 = 32_768;

/// The workgroup counts (x, y) of a dispatch of `groups` workgroups in rows of
/// at most [`DISPATCH_ROW`] (`interpolate.comp` numbers workgroup (x, y) as
/// y · x-count + x; invocations past the vertices do nothing).
fn dispatch_grid(groups: u32) -> (u32, u32) {
    let x = groups.clamp(1, DISPATCH_ROW);
    (x, groups.div_ceil(x).max(1))
}

impl InterpolatePass {
    /// The pass growing hairs from `smooth`'s output for the key hairs of `rest`
    /// (or the scalp `triangles` between their roots), with room for
    /// `hair_vertices` vertices; with `followers`, their pipeline too.
    pub(super) fn new(
        device: &Arc<Device>,
        rest: &SimState,
        triangles: &[[u32; 3]],
        smooth: &SmoothPass,
        hair_vertices: u64,
        followers: Option<&Followers>,
    ) -> Result<Self> {
        let storage = |name: &str, size: u64| Buffer::storage(device, name, size);
        let positions = storage("vkhair hair positions", hair_vertices * 16)?;
        let tangents = storage("vkhair hair tangents", hair_vertices * 16)?;
        let reference_data = reference_vectors(rest);
        let reference = storage("vkhair key frames", reference_data.len() as u64 * 16)?;
        device.upload_pod(&reference, &reference_data)?;
        let triangle_data: Vec<[u32; 4]> = triangles.iter().map(|t| [t[0], t[1], t[2], 0]).collect();
        let triangle_buffer = storage("vkhair scalp triangles", (triangle_data.len().max(1) * 16) as u64)?;
        device.upload_pod(&triangle_buffer, &triangle_data)?;
        let (smoothed_positions, smoothed_tangents) = smooth.outputs();
        let bindings = [
            (0, smoothed_positions),
            (1, smoothed_tangents),
            (2, &reference),
            (3, &positions),
            (4, &tangents),
            (5, &triangle_buffer),
        ];
        let pipeline = |evaluation: &ShaderSource, grow: &ShaderSource| -> Result<Pipeline> {
            let pipeline = pass::capture_pipeline(
                device,
                evaluation.name,
                &[&RENDER_INTERPOLATE_VERT, &RENDER_INTERPOLATE_TESC, evaluation],
                1,
                1,
            )?;
            // Each evaluation stage declares the bindings it uses.
            let set = pipeline.declared_buffer_set(0, &bindings)?;
            let compute = ComputePipeline::new(device, grow, 1)?;
            let compute_set = compute.declared_buffer_set(0, &bindings)?;
            Ok(Pipeline { pipeline, set, compute, compute_set })
        };
        let colors = followers.and_then(Followers::colors);
        let widths = followers.and_then(Followers::width_factors);
        // Every follower's entry: its colours (zero without) and width factors
        // (1 without); the follower stage writes the factors into the hairs.
        let look_data: Vec<Vec4> = match followers {
            Some(f) => (0..f.count())
                .flat_map(|i| {
                    let [root, tip] = colors.map_or([Vec3::ZERO; 2], |c| c[i]);
                    let [wr, wt] = widths.map_or([1.0; 2], |w| w[i]);
                    [root.extend(wr), tip.extend(wt)]
                })
                .collect(),
            None => vec![Vec4::ZERO; 2],
        };
        let looks = storage("vkhair hair colours", (look_data.len() * 16) as u64)?;
        device.upload_pod(&looks, &look_data)?;
        let follow = match followers {
            None => None,
            Some(f) => {
                let b = storage("vkhair follower bindings", std::mem::size_of_val(f.gpu_bindings()) as u64)?;
                device.upload_pod(&b, f.gpu_bindings())?;
                let o = storage("vkhair follower offsets", std::mem::size_of_val(f.gpu_offsets()) as u64)?;
                device.upload_pod(&o, f.gpu_offsets())?;
                let pipeline = pass::capture_pipeline(
                    device,
                    RENDER_INTERPOLATE_FOLLOW_TESE.name,
                    &[&RENDER_INTERPOLATE_VERT, &RENDER_INTERPOLATE_TESC, &RENDER_INTERPOLATE_FOLLOW_TESE],
                    1,
                    1,
                )?;
                let all = [
                    (0, smoothed_positions),
                    (1, smoothed_tangents),
                    (2, &reference),
                    (3, &positions),
                    (4, &tangents),
                    (6, &b),
                    (7, &o),
                    (8, &looks),
                ];
                let set = pipeline.declared_buffer_set(0, &all)?;
                let compute = ComputePipeline::new(device, &RENDER_INTERPOLATE_COMP_FOLLOW, 1)?;
                let compute_set = compute.declared_buffer_set(0, &all)?;
                Some(Follow { pipeline: Pipeline { pipeline, set, compute, compute_set }, _bindings: b, _offsets: o })
            }
        };
        Ok(InterpolatePass {
            device: device.clone(),
            follow,
            own_colors: colors.is_some(),
            looks,
            single_strand: pipeline(&RENDER_INTERPOLATE_TESE, &RENDER_INTERPOLATE_COMP)?,
            barycentric: pipeline(&RENDER_INTERPOLATE_BARY_TESE, &RENDER_INTERPOLATE_COMP_BARY)?,
            reference,
            _triangle_buffer: triangle_buffer,
            triangles: triangles.len() as u32,
            mean_triangle_area: mean_area(rest, triangles),
            positions,
            tangents,
        })
    }

    /// Scalp triangles between key-hair roots.
    pub(super) fn triangles(&self) -> u32 {
        self.triangles
    }

    /// Mean area of the scalp triangles at rest, m² (0 without triangles).
    pub(super) fn mean_triangle_area(&self) -> f32 {
        self.mean_triangle_area
    }

    /// Rejects `mode` when it cannot grow hairs from these key hairs.
    pub(super) fn check_mode(&self, mode: InterpolationMode) -> Result<()> {
        check_mode(mode, self.triangles)
    }

    /// Key hairs (of `strands`), or scalp triangles: what `mode` grows hairs from.
    pub(super) fn units(&self, mode: InterpolationMode, strands: u32) -> u32 {
        units(mode, strands, self.triangles)
    }

    /// Per drawn hair its own albedo and width factor at the root and the
    /// tip, and whether the hairs have their own albedo (their width factors
    /// are in the hair positions' w).
    pub(super) fn looks(&self) -> (&Buffer, bool) {
        (&self.looks, self.own_colors)
    }

    /// The interpolated hairs: positions and (tangent, t).
    pub(super) fn hairs(&self) -> (&Buffer, &Buffer) {
        (&self.positions, &self.tangents)
    }

    /// Records the pass in its own scope, through the tessellation stages (a
    /// capture instance) or a compute dispatch as `interpolator` says
    /// ([`Interpolator::Auto`] is taken as [`Interpolator::Compute`]),
    /// declaring to `graph` that it reads `smoothed` (the smoothing pass's
    /// output) and writes the hairs.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device outside a render pass,
    /// after the smoothing pass. `push.strands` counts key hairs, or scalp
    /// triangles in barycentric mode, or (with `push.hairs` 1 and
    /// `push.points` the follower points) the followers drawn when the pass
    /// was created with followers.
    pub(super) unsafe fn record(
        &self,
        cmd: vk::CommandBuffer,
        mode: InterpolationMode,
        interpolator: Interpolator,
        push: &InterpolatePush,
        (graph, smoothed): (&mut FrameGraph, (&Buffer, &Buffer)),
        timing: Timing<'_>,
    ) {
        let d = &self.device;
        let (read, write) = match interpolator {
            Interpolator::Tessellation => (AccessKind::TessellationRead, AccessKind::TessellationWrite),
            _ => (AccessKind::ComputeRead, AccessKind::ComputeWrite),
        };
        let uses = [
            Use::buffer(smoothed.0, &[read]),
            Use::buffer(smoothed.1, &[read]),
            Use::buffer(&self.positions, &[write]),
            Use::buffer(&self.tangents, &[write]),
        ];
        let p = match (&self.follow, mode) {
            (Some(f), _) => &f.pipeline,
            (None, InterpolationMode::SingleStrand) => &self.single_strand,
            (None, InterpolationMode::Barycentric) => &self.barycentric,
        };
        if interpolator != Interpolator::Tessellation {
            // Every grown vertex: the units' hairs' smoothed vertices (their
            // points, with followers).
            let per_hair = if self.follow.is_some() { push.points } else { push.stride };
            // Within the hairs' buffer (at most maxStorageBufferRange / 16
            // vertices, checked when the renderer was made): far below 2^32.
            let vertices = u64::from(push.strands) * u64::from(push.hairs) * u64::from(per_hair);
            let vertices = u32::try_from(vertices).unwrap_or(u32::MAX);
            let (x, y) = dispatch_grid(vertices.div_ceil(p.compute.workgroup_size()[0]));
            // SAFETY: guaranteed by the caller; the dispatch covers every vertex
            // (interpolate.comp returns past the last).
            unsafe {
                let scope = RenderPass::Interpolate.open(d, cmd, timing);
                graph.record(d, cmd, &uses);
                p.compute.bind(cmd, &[p.compute_set]);
                p.compute.push(cmd, push);
                p.compute.dispatch_groups(cmd, [x, y, 1], 1);
                scope.close(d, cmd, timing);
            }
            return;
        }
        // SAFETY: guaranteed by the caller: one patch per key segment of each
        // unit (per follower segment, one line each, with followers).
        unsafe {
            pass::record_capture(d, cmd, (RenderPass::Interpolate, timing), (graph, &uses), |cmd| {
                p.pipeline.bind(cmd, &[p.set]);
                p.pipeline.push(cmd, push);
                let instances = push.hairs.div_ceil(codes::interpolate::LINES_PER_INSTANCE);
                d.raw.cmd_draw(cmd, push.strands * (push.points - 1), instances, 0, 0);
            });
        }
    }

    /// Reads `n` hair vertices back: positions and (tangent, t) (submits and waits).
    pub(super) fn read(&self, n: usize) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        Ok((self.device.readback_pod(&self.positions, n)?, self.device.readback_pod(&self.tangents, n)?))
    }

    /// Reads the `n` key hairs' reference vectors back (submits and waits).
    pub(super) fn read_reference(&self, n: usize) -> Result<Vec<Vec4>> {
        self.device.readback_pod(&self.reference, n)
    }
}
