//! Recording of the volume stage's kernels.

use std::sync::Arc;

use ash::vk;

use super::buffers::{self, Kernel, KernelPipeline, VolumeBuffers, GROUP, INDIRECT_STRIDE};
use super::grid::GridLayout;
use super::params::{Preconditioner, PressureSolver, VolumeMode, VolumeParams};
use super::VolumeStats;
use crate::codes::vol_status;
use crate::error::Result;
use crate::gpu_types::{
    CoarsestPass, CyclePass, GpuVolumeParams, LevelPass, PcgScalars, ReducePass, SmoothingPass, VolumePush,
    WorkgroupSolvePass,
};
use crate::profiler::{PassScope, Timing};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;

use crate::limits::VOL_COARSEST_SWEEPS;

/// Most passes over loop back edges one share of the solve in one workgroup may
/// make in its iteration loop, the loops inside it included: lavapipe (gallivm's
/// loop limiter) leaves a loop after 65,535 passes, silently.
const WORKGROUP_LOOP_BUDGET: u32 = 60_000;

/// Iterations one dispatch of the solve in one workgroup may do on `grid`: the
/// passes of its iteration loop over the cell loops inside it (each invocation
/// takes every `GROUP`th cell), the coarsest level's sweeps, the tree reductions
/// and the level lookups stay within [`WORKGROUP_LOOP_BUDGET`]. None where one
/// iteration would not (grids above about 1.9 million cells): the solve is then
/// dispatched per kernel and iteration.
pub(crate) fn workgroup_share(grid: &GridLayout, preconditioner: Preconditioner) -> Option<u32> {
    let share = WORKGROUP_LOOP_BUDGET / workgroup_trips(grid, preconditioner);
    (share > 0).then_some(share)
}

/// Loop trips of one invocation through one iteration of the solve in one
/// workgroup (`pcg_workgroup.comp`).
fn workgroup_trips(grid: &GridLayout, preconditioner: Preconditioner) -> u32 {
    let per = |cells: u32| cells.div_ceil(GROUP);
    let levels = &grid.levels;
    // Matrix product, update, r·z and the new direction; three reductions.
    let trips = 4 * per(levels[0].cells()) + 3 * GROUP.ilog2();
    match preconditioner {
        Preconditioner::Multigrid => trips + cycle_trips(grid, 0),
        _ => trips + per(levels[0].cells()),
    }
}

/// Loop trips of one invocation through a workgroup's V-cycle from level
/// `from` down (`mg_workgroup.glsl`): per level two sweeps down, two up and
/// the restriction over its cells, each invocation taking every `GROUP`th,
/// and the level lookups; the coarsest level's sweeps.
fn cycle_trips(grid: &GridLayout, from: usize) -> u32 {
    let per = |cells: u32| cells.div_ceil(GROUP);
    let levels = &grid.levels;
    let n = levels.len() as u32;
    let down: u32 = levels[from..].windows(2).map(|pair| 4 * per(pair[0].cells()) + per(pair[1].cells()) + 8 * n).sum();
    down + VOL_COARSEST_SWEEPS
}

/// Most cells of a level the dispatched solve's V-cycle leaves to its
/// one-workgroup coarse cycle (16³: 16 cells an invocation of a workgroup of
/// 256 a sweep).
pub(crate) const CYCLE_CELLS: u32 = 4096;

/// The level the dispatched solve's one-workgroup coarse cycle starts at: the
/// first below the finest with at most [`CYCLE_CELLS`] cells, when it and the
/// coarsest are two levels or more (else none: the per-level passes and the
/// coarsest's own).
pub(crate) fn cycle_start(grid: &GridLayout) -> Option<usize> {
    let levels = &grid.levels;
    let first = (1..levels.len()).find(|&l| levels[l].cells() <= CYCLE_CELLS)?;
    (first + 1 < levels.len()).then_some(first)
}

/// How a kernel is dispatched.
#[derive(Clone, Copy)]
enum Launch {
    /// Enough workgroups for this many invocations.
    Threads(u32),
    /// From indirect entry k (per multigrid level; the last is a single workgroup).
    Indirect(usize),
    /// One workgroup whose invocations go round their loops this many times.
    Workgroup(u32),
    /// From the single-workgroup indirect entry, looping this many times.
    IndirectWorkgroup(u32),
}

/// The volume stage's GPU side: grid, buffers and kernels, recorded per sub-step.
pub(crate) struct VolumeStage {
    device: Arc<Device>,
    pub grid: GridLayout,
    pub buffers: VolumeBuffers,
    kernels: Vec<KernelPipeline>,
    /// The parameters, the solver resolved for this device (never `Auto`).
    pub params: VolumeParams,
}

impl VolumeStage {
    /// Creates the stage for `grid`; `particles` lists the (positions, velocities)
    /// buffer pairs it may run on (one descriptor-set variant each).
    pub(crate) fn new(
        device: &Arc<Device>,
        grid: GridLayout,
        params: &VolumeParams,
        colliders: &Buffer,
        mesh_field: &Buffer,
        particles: &[(&Buffer, &Buffer)],
    ) -> Result<Self> {
        params.validate()?;
        let buffers = VolumeBuffers::new(device, &grid)?;
        let kernels = buffers::kernels(device, &buffers, colliders, mesh_field, particles)?;
        let mut stage = VolumeStage { device: device.clone(), grid, buffers, kernels, params: params.clone() };
        stage.set_params(params)?;
        Ok(stage)
    }

    /// Takes `params` for the grid this stage has, the solver resolved by the
    /// device's type (`Auto` never recorded), and compiles the kernels a step
    /// then records.
    pub(crate) fn set_params(&mut self, params: &VolumeParams) -> Result<()> {
        self.params = VolumeParams { solver: params.solver.on_device(self.device.info.device_type), ..params.clone() };
        for kernel in self.kernels_recorded() {
            self.kernels[kernel as usize].pipeline.prepare()?;
        }
        Ok(())
    }

    /// The kernels [`VolumeStage::record`] binds with the current parameters
    /// (its branches, in the same terms).
    fn kernels_recorded(&self) -> Vec<Kernel> {
        let mut kernels = vec![Kernel::Scatter, Kernel::Cells, Kernel::G2p];
        if self.params.mode != VolumeMode::Flip {
            return kernels;
        }
        let multigrid = self.params.preconditioner == Preconditioner::Multigrid;
        kernels.extend([Kernel::Mark, Kernel::MgStencil, Kernel::Gradient]);
        if multigrid {
            kernels.push(Kernel::MgCoarsen);
        }
        if self.workgroup_solve().is_some() {
            kernels.push(Kernel::PcgWorkgroup);
            return kernels;
        }
        kernels.extend([Kernel::PcgInit, Kernel::PcgReduce, Kernel::PcgDirection, Kernel::PcgApply, Kernel::PcgUpdate]);
        if multigrid {
            let coarse = if cycle_start(&self.grid).is_some() { Kernel::MgCycle } else { Kernel::MgCoarsest };
            kernels.extend([Kernel::MgSmooth, Kernel::MgRestrict, coarse]);
        }
        kernels
    }

    /// The iterations a dispatch of the one-workgroup solve does, when the
    /// pressure is solved that way (the solver asks for it and the grid fits).
    fn workgroup_solve(&self) -> Option<u32> {
        let share = workgroup_share(&self.grid, self.params.preconditioner);
        share.filter(|_| self.params.solver == PressureSolver::Workgroup)
    }

    fn kernel(&self, kernel: Kernel) -> &KernelPipeline {
        &self.kernels[kernel as usize]
    }

    /// Records the transfers that start a sub-step: the uniform block, the indirect
    /// dispatch sizes, and zero counts and sums for the scatter. The caller orders
    /// them after earlier use and before the kernels (TRANSFER_WRITE → COMPUTE_SHADER
    /// and DRAW_INDIRECT).
    ///
    /// # Safety
    /// `cmd` is recording, outside a render pass, on this device.
    pub(crate) unsafe fn record_uploads(&self, cmd: vk::CommandBuffer, gpu: &GpuVolumeParams) {
        let d = &self.device.raw;
        let mut indirect: Vec<[u32; 4]> =
            self.grid.levels.iter().map(|l| [l.cells().div_ceil(GROUP), 1, 1, 0]).collect();
        indirect.push([1, 1, 1, 0]);
        // SAFETY: guaranteed by the caller; sizes are multiples of 4 below 64 KiB and the
        // buffers have TRANSFER_DST usage.
        unsafe {
            d.cmd_update_buffer(cmd, self.buffers.params.raw(), 0, bytemuck::bytes_of(gpu));
            d.cmd_update_buffer(cmd, self.buffers.indirect.raw(), 0, bytemuck::cast_slice(&indirect));
            d.cmd_fill_buffer(cmd, self.buffers.counts.raw(), 0, vk::WHOLE_SIZE, 0);
            d.cmd_fill_buffer(cmd, self.buffers.accum.raw(), 0, vk::WHOLE_SIZE, 0);
        }
    }

    /// The barrier between two kernels: compute writes before compute reads and
    /// writes, and — after the one kernel that writes the indirect dispatches
    /// (`indirect`: `PcgReduce`) — before indirect-dispatch reads. Waiting for
    /// the indirect stage after every kernel halved the dispatched pressure
    /// solve's time on an H100 (thesis FLIP 32³: 3.47 → 1.73 ms a step; 100k
    /// guides, 64³: 4.53 → 2.39 ms), whose 40 recorded iterations are mostly
    /// zero-sized dispatches once converged; an indirect read needs no wait
    /// on the kernels since the last reduction, which the earlier barriers
    /// already ordered.
    unsafe fn barrier(&self, cmd: vk::CommandBuffer, indirect: bool) {
        let to: &[AccessKind] = if indirect {
            &[AccessKind::ComputeRead, AccessKind::ComputeWrite, AccessKind::IndirectRead]
        } else {
            &[AccessKind::ComputeRead, AccessKind::ComputeWrite]
        };
        let b = barrier::memory(&[AccessKind::ComputeWrite], to);
        // SAFETY: guaranteed by the caller.
        unsafe { self.device.cmd_barrier(cmd, &[b], &[], &[]) };
    }

    /// Binds, pushes and dispatches one kernel, then records the barrier after it.
    unsafe fn run(&self, cmd: vk::CommandBuffer, kernel: Kernel, variant: usize, push: VolumePush, launch: Launch) {
        let k = self.kernel(kernel);
        // SAFETY: guaranteed by the caller; the indirect buffer is written only by
        // record_uploads and pcg_reduce, both ordered before this by barriers.
        unsafe {
            k.pipeline.bind(cmd, &[k.sets[variant]]);
            k.pipeline.push(cmd, &push);
            match launch {
                Launch::Threads(n) => k.pipeline.dispatch_threads(cmd, [n, 1, 1]),
                Launch::Workgroup(trips) => k.pipeline.dispatch_groups(cmd, [1, 1, 1], trips),
                Launch::Indirect(entry) => {
                    // The most it launches: the count record_uploads set.
                    let most = self.grid.levels.get(entry).map_or(1, |l| l.cells().div_ceil(GROUP));
                    let offset = entry as u64 * INDIRECT_STRIDE;
                    k.pipeline.dispatch_indirect_at_most(cmd, self.buffers.indirect.raw(), offset, [most, 1, 1], 1)
                }
                Launch::IndirectWorkgroup(trips) => {
                    let offset = self.grid.levels.len() as u64 * INDIRECT_STRIDE;
                    k.pipeline.dispatch_indirect_at_most(cmd, self.buffers.indirect.raw(), offset, [1, 1, 1], trips)
                }
            }
            self.barrier(cmd, kernel == Kernel::PcgReduce);
        }
    }

    /// Records steps 1–6 on particle variant `variant`, after a barrier that made the
    /// particle buffers and the uploads visible. `labels` name the four timestamp
    /// scopes (scatter, transfer, pressure, update).
    ///
    /// # Safety
    /// `cmd` is recording on this device outside a render pass; the profiler, when
    /// given, had `begin_frame` called for this frame.
    pub(crate) unsafe fn record(&self, cmd: vk::CommandBuffer, variant: usize, labels: [&str; 4], timing: Timing<'_>) {
        let scoped = |label: &str, body: &dyn Fn()| {
            // SAFETY: guaranteed by the caller.
            unsafe { PassScope::record(&self.device, cmd, timing, label, LabelColor::Compute, body) }
        };
        let none = VolumePush::default();
        // SAFETY (all closures): guaranteed by the caller.
        scoped(labels[0], &|| unsafe {
            self.run(cmd, Kernel::Scatter, variant, none, Launch::Threads(self.grid.particles));
        });
        let flip = self.params.mode == VolumeMode::Flip;
        scoped(labels[1], &|| unsafe {
            let [nx, ny, nz] = self.grid.dims;
            let extended = (nx + 1) * (ny + 1) * (nz + 1);
            self.run(cmd, Kernel::Cells, variant, none, Launch::Threads(extended));
            // Faces and the labels they complete serve the pressure solve only.
            if flip {
                self.run(cmd, Kernel::Mark, variant, none, Launch::Threads(self.grid.cells()));
            }
        });
        if flip {
            scoped(labels[2], &|| unsafe { self.record_pressure(cmd, variant) });
        }
        scoped(labels[3], &|| unsafe {
            self.run(cmd, Kernel::G2p, variant, none, Launch::Threads(self.grid.particles));
        });
    }

    /// Multigrid level `level` and the next coarser one (zero past the coarsest).
    fn level_pass(&self, level: usize) -> LevelPass {
        let l = self.grid.levels[level];
        let coarse = self.grid.levels.get(level + 1);
        LevelPass {
            dims: l.dims,
            first: l.offset,
            coarse_dims: coarse.map_or([0; 3], |c| c.dims),
            coarse_first: coarse.map_or(0, |c| c.offset),
        }
    }

    /// A smoothing pass on `level` in `mode`, with the partials when `partials`.
    fn smoothing_push(&self, level: usize, mode: u32, partials: bool) -> VolumePush {
        let l = self.level_pass(level);
        VolumePush::from(&SmoothingPass {
            dims: l.dims,
            first: l.first,
            coarse_dims: l.coarse_dims,
            coarse_first: l.coarse_first,
            mode,
            partials: u32::from(partials),
        })
    }

    /// Step 5: the pressure solve (in one workgroup, or a dispatch per kernel and
    /// iteration) and the gradient subtraction.
    unsafe fn record_pressure(&self, cmd: vk::CommandBuffer, variant: usize) {
        let levels = self.grid.levels.len();
        let single = Launch::Indirect(levels);
        let cells = Launch::Indirect(0);
        let multigrid = self.params.preconditioner == Preconditioner::Multigrid;
        let partials = self.grid.cells().div_ceil(GROUP);
        let reduce = |mode: u32| VolumePush::from(&ReducePass { mode, partials, dispatches: levels as u32 + 1 });
        let none = VolumePush::default();
        // SAFETY: guaranteed by the caller.
        unsafe {
            if multigrid {
                for level in 0..levels - 1 {
                    let push = VolumePush::from(&self.level_pass(level));
                    self.run(cmd, Kernel::MgCoarsen, variant, push, Launch::Indirect(level + 1));
                }
            }
            let words = if multigrid { self.grid.level_cells() } else { self.grid.cells() };
            self.run(cmd, Kernel::MgStencil, variant, none, Launch::Threads(words));
            if let Some(share) = self.workgroup_solve() {
                for k in 0..self.params.max_iterations.div_ceil(share) {
                    let push = VolumePush::from(&WorkgroupSolvePass { start: u32::from(k == 0), iterations: share });
                    let trips = share.saturating_mul(workgroup_trips(&self.grid, self.params.preconditioner));
                    self.run(cmd, Kernel::PcgWorkgroup, variant, push, Launch::Workgroup(trips));
                }
                self.run(cmd, Kernel::Gradient, variant, none, Launch::Threads(self.grid.faces[2]));
                return;
            }
            self.run(cmd, Kernel::PcgInit, variant, none, cells);
            if multigrid {
                self.record_vcycle(cmd, variant);
            }
            self.run(cmd, Kernel::PcgReduce, variant, reduce(0), single);
            self.run(cmd, Kernel::PcgDirection, variant, none, cells);
            for _ in 0..self.params.max_iterations {
                self.run(cmd, Kernel::PcgApply, variant, none, cells);
                self.run(cmd, Kernel::PcgReduce, variant, reduce(1), single);
                self.run(cmd, Kernel::PcgUpdate, variant, none, cells);
                if multigrid {
                    self.record_vcycle(cmd, variant);
                }
                self.run(cmd, Kernel::PcgReduce, variant, reduce(2), single);
                self.run(cmd, Kernel::PcgDirection, variant, none, cells);
            }
            self.run(cmd, Kernel::Gradient, variant, none, Launch::Threads(self.grid.faces[2]));
        }
    }

    /// z = V-cycle(r), then the partials of r·z and max |r|: damped Jacobi pre- and
    /// post-smoothing (2 sweeps each), half the summed residual restricted,
    /// piecewise-constant prolongation, Jacobi sweeps on the coarsest level.
    /// Symmetric, so conjugate gradients may use it. Four passes per level: the
    /// two pre-sweeps are one pass, the prolongation is folded into the first
    /// post-sweep and the partials into the last (see `mg_smooth.comp`). The
    /// levels of at most [`CYCLE_CELLS`] below the finest, when there are two
    /// or more, are one dispatch of a single workgroup (`mg_cycle.comp`, the
    /// same arithmetic a cell), since each dispatch and its barrier cost
    /// microseconds on a GPU that a small level never fills.
    unsafe fn record_vcycle(&self, cmd: vk::CommandBuffer, variant: usize) {
        let levels = self.grid.levels.len();
        let cycle = cycle_start(&self.grid);
        // The levels dispatched a pass each: above the cycle's, or all but
        // the coarsest without it.
        let dispatched = cycle.unwrap_or(levels - 1);
        // SAFETY: guaranteed by the caller.
        unsafe {
            for level in 0..dispatched {
                let at = Launch::Indirect(level);
                self.run(cmd, Kernel::MgSmooth, variant, self.smoothing_push(level, 0, false), at);
                let restrict = VolumePush::from(&self.level_pass(level));
                self.run(cmd, Kernel::MgRestrict, variant, restrict, Launch::Indirect(level + 1));
            }
            match cycle {
                Some(first_level) => {
                    let push = VolumePush::from(&CyclePass { first_level: first_level as u32 });
                    let trips = cycle_trips(&self.grid, first_level);
                    self.run(cmd, Kernel::MgCycle, variant, push, Launch::IndirectWorkgroup(trips));
                }
                None => {
                    let last = self.level_pass(levels - 1);
                    let coarsest = VolumePush::from(&CoarsestPass {
                        dims: last.dims,
                        first: last.first,
                        partials: u32::from(levels == 1),
                    });
                    self.run(cmd, Kernel::MgCoarsest, variant, coarsest, Launch::Indirect(levels));
                }
            }
            for level in (0..dispatched).rev() {
                let at = Launch::Indirect(level);
                self.run(cmd, Kernel::MgSmooth, variant, self.smoothing_push(level, 1, false), at);
                self.run(cmd, Kernel::MgSmooth, variant, self.smoothing_push(level, 2, level == 0), at);
            }
        }
    }

    /// Reads the solver scalars of the latest sub-step (submits and waits).
    pub(crate) fn read_stats(&self) -> Result<VolumeStats> {
        let s: Vec<PcgScalars> = self.device.readback_pod(&self.buffers.scalars, 1)?;
        let s = s[0];
        Ok(VolumeStats {
            iterations: s.iterations,
            converged: s.converged == 1 && s.status == vol_status::OK,
            relative_residual: if s.bmax > 0.0 { s.rmax / s.bmax } else { 0.0 },
            non_finite: s.status == vol_status::NONFINITE,
        })
    }
}
