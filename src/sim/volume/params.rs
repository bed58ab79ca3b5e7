//! Parameters of the volume stage.

use crate::error::{Error, Result};

/// Most cells a volume grid may have (2²²: 4,194,304, e.g. 161³ or 256 × 128 × 128).
pub const MAX_VOLUME_CELLS: u64 = 1 << 22;

/// What the volume stage does with the grid (with the `clap` feature, a
/// command-line value: `off`, `flip`, `friction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum VolumeMode {
    /// No volume stage: key hairs do not interact (the cheapest).
    #[default]
    Off,
    /// FLIP/PIC hair-hair interaction through a pressure projection on the MAC grid
    /// (McAdams et al. 2009): hair keeps its volume and moves coherently.
    Flip,
    /// The cheaper density-based alternative from the same grid: velocity smoothing
    /// toward the cells' mean velocity ("friction") and a push away from cells denser
    /// than a threshold ("repulsion"). No pressure solve.
    Friction,
}

/// Preconditioner of the conjugate-gradient pressure solve on the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preconditioner {
    /// The diagonal of the matrix: cheap per iteration, many iterations.
    Jacobi,
    /// One multigrid V-cycle (damped Jacobi smoothing, cell-doubling levels down to at
    /// most 256 cells): a few more kernels per iteration, far fewer iterations.
    #[default]
    Multigrid,
}

/// How the GPU records the pressure solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum PressureSolver {
    /// The solve in one workgroup on a CPU implementation of Vulkan (a workgroup
    /// there is a CPU thread, and a dispatch costs more than a share of the
    /// grid), dispatched over the device on a GPU (one workgroup is one of its
    /// compute units: measured on an H100, the 64³ pressure solve of 100,000 ×
    /// 32 particles took 68.6 ms in one workgroup and 4.8 ms dispatched).
    #[default]
    Auto,
    /// The whole solve (every iteration, its preconditioner and its sums) in one
    /// workgroup, stopping at the tolerance or the cap: one dispatch up to 32³
    /// cells, a few on larger grids (shares of the iterations: CPU drivers cut
    /// long shader loops), dispatched per kernel and iteration above about 1.9
    /// million cells. Few dispatches and barriers, but one workgroup's worth of
    /// the device.
    Workgroup,
    /// A dispatch per kernel and iteration over the whole device, every iteration up
    /// to the cap recorded (those after convergence dispatch zero workgroups):
    /// per iteration 4 passes per multigrid level above those of at most 16³
    /// (one pass of a single workgroup for all of those) and 5 more.
    Dispatched,
}

impl PressureSolver {
    /// The way the solve is recorded on a device of `device_type`:
    /// [`Auto`](Self::Auto) resolved ([`Workgroup`](Self::Workgroup) on
    /// `vk::PhysicalDeviceType::CPU`, else [`Dispatched`](Self::Dispatched)),
    /// the others as they are.
    pub fn on_device(self, device_type: ash::vk::PhysicalDeviceType) -> PressureSolver {
        match self {
            PressureSolver::Auto if device_type == ash::vk::PhysicalDeviceType::CPU => PressureSolver::Workgroup,
            PressureSolver::Auto => PressureSolver::Dispatched,
            chosen => chosen,
        }
    }
}

/// Parameters of the volume stage (hair-hair interaction on a grid).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumeParams {
    /// What the stage does. Default: [`VolumeMode::Off`].
    pub mode: VolumeMode,
    /// Cells along the grid's x, y and z axes (each 4..=256, at most
    /// [`MAX_VOLUME_CELLS`] in all). Cells are cubes, sized so that the hair's reach
    /// (root box plus the longest strand on every side, plus one cell) fits along every
    /// axis. Default: 32 × 32 × 32.
    pub resolution: [u32; 3],
    /// FLIP share α of the grid-to-particle update (0 = pure PIC, 1 = pure FLIP).
    /// Default: 0.95.
    pub flip_ratio: f32,
    /// Preconditioner of the GPU pressure solve. Default: [`Preconditioner::Multigrid`].
    pub preconditioner: Preconditioner,
    /// How the GPU records the pressure solve. Default: [`PressureSolver::Auto`]
    /// (by the device's type).
    pub solver: PressureSolver,
    /// Tolerance of the pressure solve: it stops when max |residual| ≤ tolerance ×
    /// max |initial divergence| (0 < tolerance < 1). Default: 1e-5.
    pub tolerance: f32,
    /// Iteration cap of the pressure solve (1..=1000). With
    /// [`PressureSolver::Dispatched`] every iteration up to the cap is recorded and
    /// the ones after convergence dispatch zero workgroups. Default: 40.
    pub max_iterations: u32,
    /// Friction mode: share of a particle's velocity replaced by the cells' mean
    /// velocity per sub-step (0..=1). Default: 0.1.
    pub friction: f32,
    /// Friction mode: acceleration pushing particles down the density gradient where
    /// the density exceeds `repulsion_threshold`, m/s² (0..=1e6; 0 switches it off).
    /// Default: 2.
    pub repulsion: f32,
    /// Friction mode: density (summed trilinear particle weights per cell) above which
    /// repulsion acts (0 < threshold ≤ 1e6). Default: 8.
    pub repulsion_threshold: f32,
}

impl Default for VolumeParams {
    fn default() -> Self {
        VolumeParams {
            mode: VolumeMode::Off,
            resolution: [32, 32, 32],
            flip_ratio: 0.95,
            preconditioner: Preconditioner::Multigrid,
            solver: PressureSolver::Auto,
            tolerance: 1e-5,
            max_iterations: 40,
            friction: 0.1,
            repulsion: 2.0,
            repulsion_threshold: 8.0,
        }
    }
}

impl VolumeParams {
    /// FLIP with the given grid resolution and the other fields at their defaults.
    pub fn flip(resolution: [u32; 3]) -> Self {
        VolumeParams { mode: VolumeMode::Flip, resolution, ..VolumeParams::default() }
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        for (axis, &n) in ["x", "y", "z"].iter().zip(&self.resolution) {
            if !(4..=256).contains(&n) {
                return Err(Error::param("volume resolution", format!("{n} cells along {axis}"), "4..=256 per axis"));
            }
        }
        let cells: u64 = self.resolution.iter().map(|&n| u64::from(n)).product();
        if cells > MAX_VOLUME_CELLS {
            return Err(Error::param(
                "volume resolution",
                format!("{cells} cells"),
                format!("at most {MAX_VOLUME_CELLS}"),
            ));
        }
        let unit = |name: &'static str, v: f32| {
            if v.is_finite() && (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(Error::param(name, v, "0..=1"))
            }
        };
        unit("volume flip_ratio", self.flip_ratio)?;
        unit("volume friction", self.friction)?;
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(Error::param("volume tolerance", self.tolerance, "(0, 1)"));
        }
        if !(1..=1000).contains(&self.max_iterations) {
            return Err(Error::param("volume max_iterations", self.max_iterations, "1..=1000"));
        }
        if !(self.repulsion.is_finite() && self.repulsion >= 0.0 && self.repulsion <= 1e6) {
            return Err(Error::param("volume repulsion", self.repulsion, "0..=1e6 m/s²"));
        }
        if !(self.repulsion_threshold.is_finite() && self.repulsion_threshold > 0.0 && self.repulsion_threshold <= 1e6)
        {
            return Err(Error::param("volume repulsion_threshold", self.repulsion_threshold, "(0, 1e6]"));
        }
        Ok(())
    }
}
