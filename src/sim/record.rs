//! Recording a step ([`HairSim::record_step`]): the uploads of the
//! sub-steps' parameters and colliders, the step kernel's dispatch and, with
//! the volume stage on, its kernels after each sub-step.

use ash::vk;
use glam::Vec4;

use super::planner::SubstepInputs;
use super::{state, step, volume, HairSim, SimStage};
use crate::error::Result;
use crate::gpu_types::{ColliderShape, GpuCollider, GpuVolumeParams, SimPush, SimStepParams, StepRange};
use crate::profiler::{GpuProfiler, PassScope, Timing};
use crate::sim::RigidTransform;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;

// vkCmdUpdateBuffer takes at most 64 KiB: the sub-steps' parameter blocks
// and the colliders each fit one update.
const _: () = assert!(super::MAX_SUBSTEPS as usize * std::mem::size_of::<SimStepParams>() <= 65_536);
const _: () = assert!(super::MAX_COLLIDERS * std::mem::size_of::<GpuCollider>() <= 65_536);

/// Recording.
impl HairSim {
    /// Records one step that ends with the head at `head` into `cmd`, with a debug
    /// label and (when a profiler is given) a timestamp scope per stage: with the
    /// volume stage off one dispatch and two barriers (uploads of the sub-steps'
    /// parameters, then the dispatch); with it on, per sub-step the step dispatch
    /// followed by the volume stage's kernels. With a level of detail
    /// ([`HairSim::set_simulated_hairs`]) each step dispatch is followed by a
    /// barrier and the followers' dispatch. A step that starts with a teleport or
    /// reset ([`HairSim::teleport`], [`HairSim::reset`], a head moving a root
    /// farther than [`crate::sim::SimParams::teleport_distance`]) records the move's dispatch
    /// and two barriers after the uploads, before the step (debug label [`MOVE_LABEL`](crate::sim::MOVE_LABEL), no timestamp scope).
    /// Leaves the step pipeline, the followers' or the volume stage's last kernel
    /// bound.
    ///
    /// # Safety
    /// `cmd` is a command buffer of the context's device in the recording state,
    /// outside a render pass, for a queue of the graphics family (or the context's
    /// compute queue, as [`crate::schedule::FrameScheduler`] uses it). The buffers of this
    /// simulation must not be in use by other pending work that conflicts with it
    /// (the recorded barriers order it after everything earlier in submission order).
    /// With a profiler, its `begin_frame` was called for the frame being recorded.
    pub unsafe fn record_step(
        &mut self,
        cmd: vk::CommandBuffer,
        head: &RigidTransform,
        profiler: Option<&mut GpuProfiler>,
    ) -> Result<()> {
        let timing = Timing::of(profiler.as_deref());
        let planned = self.planner.next(head)?;
        let inputs = planned.substeps;
        // The kernel specialised to the switches of these sub-steps: prepared by
        // `new`, `set_params` and `set_mesh_collider`, so found here.
        let features = inputs.iter().fold(0, |f, sub| f | sub.params.flags);
        self.pipeline.prepare_variant(features)?;
        // The followers' and the move's kernels, compiled when first needed.
        if self.has_followers() {
            self.follow.prepare()?;
        }
        if planned.start.is_some() || !self.partial_moves.is_empty() {
            self.mover.prepare()?;
        }
        let scalp = self.take_scalp_upload();
        let mut partial = std::mem::take(&mut self.partial_moves);
        if planned.start.as_ref().is_some_and(|start| start.reset) {
            // A reset places every key hair on its scalp already.
            partial.clear();
        }
        let corners = self.moved_corners(&partial, scalp.as_deref());
        // SAFETY (whole body): guaranteed by the caller; all buffers belong to this
        // device, and update sizes are multiples of 4 below 64 KiB (by construction).
        unsafe {
            self.record_uploads(cmd, &inputs, scalp.as_deref(), &corners);
            if let Some(start) = &planned.start {
                let points = self.planner.strands * self.planner.points;
                self.mover.record(cmd, self.current, start, 0..points);
            }
            let points = self.planner.points as usize;
            for mv in &partial {
                let range = (mv.strands.start * points) as u32..(mv.strands.end * points) as u32;
                let rigid = super::teleport::Move { transform: mv.transform, reset: false };
                self.mover.record(cmd, self.current, &rigid, range);
            }
            self.pending_rest.clear();
            self.pending_guides = false;
            let Some(volume) = &self.volume else {
                self.record_dispatch(cmd, self.current, [0, inputs.len() as u32], features, timing);
                self.current = 1 - self.current;
                return Ok(());
            };
            let between = barrier::memory(&[AccessKind::ComputeWrite], barrier::COMPUTE_READ_WRITE);
            let mut current = self.current;
            for (k, sub) in inputs.iter().enumerate() {
                if k > 0 {
                    self.device.cmd_barrier(cmd, &[entry_barrier()], &[], &[]);
                    self.record_volume_uploads(cmd, volume, sub);
                    self.device.cmd_barrier(cmd, &[uploaded_barrier()], &[], &[]);
                }
                self.record_dispatch(cmd, current, [k as u32, 1], features, timing);
                self.device.cmd_barrier(cmd, &[between], &[], &[]);
                let labels = SimStage::VOLUME.map(SimStage::label);
                // The barrier above made the step's writes visible.
                volume.record(cmd, 1 - current, labels, timing);
                current = 1 - current;
            }
            self.current = current;
        }
        Ok(())
    }

    /// Records the uploads of a step between the entry and the uploaded barrier:
    /// the sub-steps' parameters and colliders, pending rest data, a scalp's
    /// vertices skinned from bone matrices, and with the volume stage its
    /// uploads for the first sub-step.
    ///
    /// # Safety
    /// As [`HairSim::record_step`].
    unsafe fn record_uploads(
        &self,
        cmd: vk::CommandBuffer,
        inputs: &[SubstepInputs],
        scalp: Option<&[Vec4]>,
        corners: &[(usize, Vec<Vec4>)],
    ) {
        let d = &self.device;
        // Every sub-step of set 0, then of set 1, … (see `StepRange::stride`).
        let sets = inputs.first().map_or(0, |sub| sub.sets.len());
        let params: Vec<SimStepParams> = (0..=sets)
            .flat_map(|s| inputs.iter().map(move |sub| if s == 0 { &sub.params } else { &sub.sets[s - 1] }))
            .map(SimStepParams::from)
            .collect();
        // SAFETY: guaranteed by the caller; sizes are multiples of 4, each update
        // below 64 KiB (the parameter blocks in chunks; at most MAX_COLLIDERS
        // colliders of 32 bytes); the parameters' buffer holds every set's
        // MAX_SUBSTEPS blocks (`HairSim::set_parameter_sets`).
        unsafe {
            d.cmd_barrier(cmd, &[entry_barrier()], &[], &[]);
            update_chunked(d, cmd, self.gpu.params.raw(), 0, bytemuck::cast_slice(&params));
            for (k, sub) in inputs.iter().enumerate().filter(|(_, sub)| !sub.colliders.is_empty()) {
                let offset = state::collider_offset(k);
                let colliders = gpu_colliders(&sub.colliders);
                d.raw.cmd_update_buffer(cmd, self.gpu.colliders.raw(), offset, bytemuck::cast_slice(&colliders));
            }
            // At most SIM_MESH_MAX_BONES bones of 96 bytes a sub-step.
            for (k, sub) in inputs.iter().enumerate().filter(|(_, sub)| !sub.bones.is_empty()) {
                let offset = state::bone_offset(k);
                d.raw.cmd_update_buffer(cmd, self.gpu.mesh_bones.raw(), offset, bytemuck::cast_slice(&sub.bones));
            }
            if self.pending_guides {
                let guides = bytemuck::cast_slice(&self.lod.guides);
                update_chunked(d, cmd, self.gpu.guides.raw(), 0, guides);
            }
            for range in &self.pending_rest {
                let rest = bytemuck::cast_slice(&self.shape.rest[range.clone()]);
                let lengths = bytemuck::cast_slice(&self.shape.rest_lengths[range.clone()]);
                update_chunked(d, cmd, self.gpu.rest.raw(), range.start as u64 * 16, rest);
                update_chunked(d, cmd, self.gpu.rest_lengths.raw(), range.start as u64 * 4, lengths);
            }
            if let Some(vertices) = scalp {
                update_chunked(d, cmd, self.gpu.scalp_vertices.raw(), 0, bytemuck::cast_slice(vertices));
            }
            // Teleported key hairs start the step from this step's scalp.
            for (first, run) in corners {
                let at = *first as u64 * 48;
                update_chunked(d, cmd, self.gpu.scalp_previous.raw(), at, bytemuck::cast_slice(run));
            }
            if let (Some(volume), Some(first)) = (&self.volume, inputs.first()) {
                self.record_volume_uploads(cmd, volume, first);
            }
            d.cmd_barrier(cmd, &[uploaded_barrier()], &[], &[]);
        }
    }

    /// The volume stage's uploads for sub-step `sub`: its parameters and the
    /// colliders it sees.
    ///
    /// # Safety
    /// As [`HairSim::record_step`], between an entry and an uploaded barrier.
    unsafe fn record_volume_uploads(&self, cmd: vk::CommandBuffer, volume: &volume::VolumeStage, sub: &SubstepInputs) {
        let colliders = self.planner.collider_count();
        // SAFETY: guaranteed by the caller; at most MAX_COLLIDERS colliders of 32 bytes.
        unsafe {
            if !sub.colliders.is_empty() {
                let gpu = gpu_colliders(&sub.colliders);
                self.device.raw.cmd_update_buffer(cmd, self.gpu.volume_colliders.raw(), 0, bytemuck::cast_slice(&gpu));
            }
            let params = GpuVolumeParams::from(&sub.volume_params(&volume.grid, &volume.params, colliders));
            volume.record_uploads(cmd, &params);
        }
    }

    /// Whether key hairs are left out of the step, following their guides
    /// (a level of detail: [`HairSim::set_simulated_hairs`]).
    fn has_followers(&self) -> bool {
        (self.lod.simulated as u32) < self.planner.strands
    }

    /// Records the step kernel for sub-steps `range` = [first, count], reading
    /// half `parity` of the double buffer, in a timestamp scope, with the
    /// kernel's variant for the switches `features`.
    ///
    /// # Safety
    /// As [`HairSim::record_step`], after the uploads' barrier.
    unsafe fn record_dispatch(
        &self,
        cmd: vk::CommandBuffer,
        parity: usize,
        range: [u32; 2],
        features: u32,
        timing: Timing<'_>,
    ) {
        let (strands, groups) = (self.planner.strands, self.planner.packing().hairs_per_group);
        let simulated = self.lod.simulated as u32;
        let stride = self.planner.params.substeps;
        let push = SimPush::from(&StepRange { first: range[0], count: range[1], simulated, stride });
        // SAFETY: guaranteed by the caller.
        unsafe {
            PassScope::record(&self.device, cmd, timing, SimStage::Step.label(), LabelColor::Compute, || {
                self.pipeline.bind_variant(cmd, features, &[self.sets[parity]]);
                self.pipeline.push(cmd, &push);
                self.pipeline.dispatch_threads(cmd, [step::threads(simulated, groups), 1, 1]);
            });
            if self.has_followers() {
                // The followers read the guides the step wrote.
                let stepped = barrier::memory(&[AccessKind::ComputeWrite], barrier::COMPUTE_READ_WRITE);
                self.device.cmd_barrier(cmd, &[stepped], &[], &[]);
                PassScope::record(&self.device, cmd, timing, SimStage::Follow.label(), LabelColor::Compute, || {
                    self.follow.bind(cmd, &[self.follow_sets[parity]]);
                    self.follow.push(cmd, &push);
                    self.follow.dispatch_threads(cmd, [strands - simulated, 1, 1]);
                });
            }
        }
    }
}

/// The colliders of a sub-step as the GPU buffers hold them.
fn gpu_colliders(colliders: &[ColliderShape]) -> Vec<GpuCollider> {
    colliders.iter().map(GpuCollider::from).collect()
}

/// Earlier work (a previous step's reads and writes) before a step's uploads.
fn entry_barrier() -> vk::MemoryBarrier2<'static> {
    barrier::memory(
        &[AccessKind::AnyWrite],
        &[AccessKind::TransferWrite, AccessKind::ComputeRead, AccessKind::ComputeWrite, AccessKind::ComputeUniformRead],
    )
}

/// A step's uploads before the kernels that read them.
fn uploaded_barrier() -> vk::MemoryBarrier2<'static> {
    barrier::memory(
        &[AccessKind::TransferWrite],
        &[AccessKind::ComputeUniformRead, AccessKind::ComputeRead, AccessKind::ComputeWrite, AccessKind::IndirectRead],
    )
}

/// `vkCmdUpdateBuffer` in chunks of at most 64 KiB.
///
/// # Safety
/// `cmd` is recording; `buffer` has TRANSFER_DST usage and room for the data;
/// `offset` and the data length are multiples of 4.
unsafe fn update_chunked(d: &Device, cmd: vk::CommandBuffer, buffer: vk::Buffer, offset: u64, data: &[u8]) {
    for (k, chunk) in data.chunks(65536).enumerate() {
        // SAFETY: guaranteed by the caller.
        unsafe { d.raw.cmd_update_buffer(cmd, buffer, offset + k as u64 * 65536, chunk) };
    }
}
