//! The volume stage: hair-hair interaction on a staggered MAC grid (FLIP after
//! Zhu & Bridson 2005, as McAdams et al. 2009 apply it to hair), or the cheaper
//! density-based friction and repulsion from the same grid.
//!
//! It runs after the integrate stage of every sub-step, on the positions and
//! velocities just written, and corrects the velocities in place (positions are
//! left alone: the next sub-step's prediction carries the correction). Steps:
//!
//! 1. **Scatter** (`scatter.comp`), one invocation per particle: its grid
//!    position and velocity along the grid axes (kept for the update), a count
//!    for its cell, and its trilinear weight w and weighted velocity v·w added
//!    to the 8 cell centres and the 8 faces of each axis within a cell of it.
//!    The sums are fixed point (trunc(x · 2³²) in two 32-bit words, carried
//!    with 32-bit atomics; `glsl/include/volume_fixed.glsl`): integer sums,
//!    the same bits whatever order the particles add in, so the stage stays
//!    bitwise deterministic without sorting. The cost follows the particle
//!    count, not the densest cell (no invocation loops over a cell's
//!    particles). Particles outside the grid add nothing and keep their
//!    velocity (they are *rejected*, not clamped).
//! 2. **Cells** (`cells.comp`), one invocation per cell of a grid one larger
//!    along every axis: density (summed weight) and mean velocity per cell;
//!    labels solid (centre inside a collider), fluid (holds a particle) or
//!    air; per u/v/w face Σ w·v / Σ w, or the colliders' velocity next to a
//!    solid cell.
//! 3. **Mark** (`mark.comp`): an air cell whose six faces all carry particle
//!    weight becomes fluid: key-hair particles are sparse, and the gaps
//!    between them must not be free surface.
//! 4. **Pressure** (FLIP only, `pcg_*`, `mg_*`): the Poisson system over fluid
//!    cells (air p = 0, solid faces Neumann with their velocity), solved by
//!    preconditioned conjugate gradients entirely on the GPU, with dot products
//!    summed in a fixed order, until max |r| ≤ tolerance · max |b| or the
//!    iteration cap. The preconditioner is Jacobi or one
//!    multigrid V-cycle. The matrix is read as one stencil word per cell and
//!    level (`mg_stencil.comp`, once per solve). Two ways to record it
//!    ([`PressureSolver`]): by default the whole solve runs in one workgroup
//!    (`pcg_workgroup.comp`: phases over the cells between workgroup barriers,
//!    one dispatch, or a few shares of the iterations on large grids, since
//!    lavapipe leaves any shader loop after 65,535 passes); or dispatched per
//!    kernel and iteration over the whole device (dot products reduced per
//!    workgroup with subgroup operations, then in one workgroup; every iteration
//!    up to the cap recorded, a reduction kernel setting the indirect dispatches
//!    of the remaining ones to zero once converged), where a V-cycle is four passes
//!    per level (the two pre-sweeps in one, the prolongation folded into the
//!    first post-sweep, the next dot product into the last) down to the levels
//!    of at most 16³, which are one pass of a single workgroup (`mg_cycle.comp`;
//!    else the coarsest level's own), and an iteration that plus 5 (10 passes at
//!    32³, 14 at 64³). Then the pressure difference is subtracted on faces between a
//!    fluid cell and a non-solid one (`gradient.comp`).
//! 5. **Update** (`g2p.comp`): FLIP/PIC blend ṽ = α(v + Lerp(x, v − v*)) +
//!    (1 − α)Lerp(x, v), or friction and repulsion from the cells.
//!
//! [`SimStage::VolumeScatter`](super::SimStage) and the three stages after it name
//! the debug labels and timestamp scopes (steps 1, 2–3, 4, 5). The cells'
//! (mean velocity, density) stay in a GPU buffer for the renderer
//! ([`HairSim::density_buffer`](super::HairSim::density_buffer)).
//! `reference.rs` is the CPU oracle, with modified incomplete Cholesky (MIC(0))
//! as its preconditioner.

mod buffers;
pub(crate) mod grid;
mod params;
mod record;
pub(crate) mod reference;
#[cfg(test)]
mod tests;

pub use grid::VolumeGrid;
pub use params::{Preconditioner, PressureSolver, VolumeMode, VolumeParams, MAX_VOLUME_CELLS};
pub(crate) use record::VolumeStage;

/// What the latest pressure solve did (read back from the GPU).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeStats {
    /// Conjugate-gradient iterations of the latest sub-step.
    pub iterations: u32,
    /// Whether the residual reached the tolerance (false: the cap stopped it, or it
    /// broke down).
    pub converged: bool,
    /// max |r| / max |b| at the end (0 when there was nothing to solve).
    pub relative_residual: f32,
    /// Whether the solve met non-finite numbers (the projection was then skipped).
    pub non_finite: bool,
}
