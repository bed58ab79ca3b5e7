//! Cuts and teleports ([`HairSim::teleport`](super::HairSim::teleport),
//! [`HairSim::reset`](super::HairSim::reset), [`SimParams::teleport_distance`](super::SimParams::teleport_distance)):
//! the whole state moved rigidly with the head, or put back to the rest pose,
//! before a step, so that a camera cut or a respawn does not fling the hair
//! across the jump.
//!
//! A pending move is applied at the start of the next step: the GPU records one
//! dispatch of `glsl/sim/move.comp` over every point of the half the step reads
//! (simulated and following key hairs alike), then the step, which starts from
//! the new head (no interpolation across the jump). The CPU reference applies
//! the same operations ([`super::reference::move_state`]).

use std::ops::Range;
use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3};

use super::body::RigidTransform;
use super::state::GpuState;
use crate::error::Result;
use crate::gpu_types::{MovePush, StateMove};
use crate::profiler::{PassScope, Timing};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::SIM_MOVE_COMP;

/// Debug label of the move's dispatch.
pub const MOVE_LABEL: &str = "vkhair sim: teleport or reset";

/// A rigid move of some key hairs only (a crowd member's teleport), applied
/// after the whole state's move at the start of the next step.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PartialMove {
    /// The key hairs moved.
    pub strands: Range<usize>,
    /// New head · old head⁻¹.
    pub transform: Mat4,
}

/// A move asked for and not yet applied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PendingMove {
    /// The head the next step starts from.
    pub to: RigidTransform,
    /// Whether the hair goes back to its rest pose (else it moves rigidly).
    pub reset: bool,
}

/// What the kernel or the CPU reference applies to the state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Move {
    /// Teleport: new head · old head⁻¹. Reset: the new head.
    pub transform: Mat4,
    pub reset: bool,
}

impl Move {
    /// The move from the head `from` for `pending`.
    pub(crate) fn between(from: &RigidTransform, pending: &PendingMove) -> Move {
        let to = pending.to.matrix();
        let transform = if pending.reset { to } else { to * from.matrix().inverse() };
        Move { transform, reset: pending.reset }
    }
}

/// The largest distance any of `roots` (head frame) moves when the head goes
/// from `from` to `to`, meters.
pub(crate) fn root_displacement(roots: &[Vec3], from: &RigidTransform, to: &RigidTransform) -> f32 {
    let (a, b) = (from.matrix(), to.matrix());
    roots.iter().map(|r| a.transform_point3(*r).distance(b.transform_point3(*r))).fold(0.0, f32::max)
}

/// The move kernel with its sets for both halves of the double buffer.
pub(crate) struct MoveKernel {
    device: Arc<Device>,
    pub(crate) pipeline: ComputePipeline,
    pub(crate) sets: [vk::DescriptorSet; 2],
}

impl MoveKernel {
    pub(crate) fn new(device: &Arc<Device>, gpu: &GpuState) -> Result<Self> {
        // Compiled on the first move (`prepare`): most simulations never teleport.
        let pipeline = ComputePipeline::deferred(device, &SIM_MOVE_COMP, 2, false)?;
        let set = |parity: usize| pipeline.declared_buffer_set(0, &gpu.move_bindings(parity));
        let sets = [set(0)?, set(1)?];
        Ok(MoveKernel { device: device.clone(), pipeline, sets })
    }

    /// Compiles the kernel unless it is (before recording a move).
    pub(crate) fn prepare(&mut self) -> Result<()> {
        self.pipeline.prepare()
    }

    /// Records `mv` over the points `points` of half `parity`, with a barrier
    /// before (earlier reads and writes of the state) and after (the step's
    /// reads). Leaves the move pipeline bound.
    ///
    /// # Safety
    /// `cmd` is recording on this device outside a render pass, after the step's
    /// uploads (the rest positions) in submission order.
    pub(crate) unsafe fn record(&self, cmd: vk::CommandBuffer, parity: usize, mv: &Move, points: Range<u32>) {
        let (first, count) = (points.start, points.len() as u32);
        let push =
            MovePush::from(&StateMove { transform: mv.transform, reset: u32::from(mv.reset), points: count, first });
        let before = barrier::memory(&[AccessKind::AnyWrite], barrier::COMPUTE_READ_WRITE);
        let after = barrier::memory(&[AccessKind::ComputeWrite], barrier::COMPUTE_READ_WRITE);
        let threads = self.pipeline.grid_stride_threads(count);
        let d = &self.device;
        // SAFETY: guaranteed by the caller; the sets hold this simulation's buffers.
        unsafe {
            d.cmd_barrier(cmd, &[before], &[], &[]);
            PassScope::record(d, cmd, Timing::default(), MOVE_LABEL, LabelColor::Compute, || {
                self.pipeline.bind(cmd, &[self.sets[parity]]);
                self.pipeline.push(cmd, &push);
                self.pipeline.dispatch_threads(cmd, [threads, 1, 1]);
            });
            d.cmd_barrier(cmd, &[after], &[], &[]);
        }
    }
}
