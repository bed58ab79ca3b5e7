//! The simulation knobs every command that simulates takes (`render`,
//! `simulate`, `bench`), and the head motion they simulate.

use clap::ValueEnum;
use glam::Vec3;
use vkhair::ash::vk;
use vkhair::sim::{motion, Preconditioner, PressureSolver, RigidTransform, SimParams, SolverMode, VolumeMode};

/// Flags over the simulation parameters: each given one wins over the command's
/// defaults and the `--config` file.
#[derive(clap::Args, Clone, Debug)]
pub struct SimArgs {
    /// Constraint iterations per sub-step [default: 20].
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Sub-steps per 1/60 s step [default: 1].
    #[arg(long)]
    pub substeps: Option<u32>,
    /// Use the DFTL solver instead of PBD iterations.
    #[arg(long)]
    pub dftl: bool,
    /// Volume stage (hair-hair interaction): FLIP on a MAC grid, density friction,
    /// or off [default: `simulate` flip, `render` and `bench` off].
    #[arg(long, value_enum)]
    pub volume: Option<VolumeMode>,
    /// Volume grid cells per axis [default: 32].
    #[arg(long)]
    pub grid: Option<u32>,
    /// Use the Jacobi preconditioner instead of multigrid for the pressure solve.
    #[arg(long)]
    pub jacobi: bool,
    /// Iteration cap of the pressure solve [default: 40].
    #[arg(long)]
    pub max_iterations: Option<u32>,
    /// How the GPU records the pressure solve: the whole solve in one workgroup
    /// (one dispatch) or a dispatch per kernel and iteration over the device;
    /// auto picks workgroup on a CPU device, dispatched on a GPU [default: auto].
    #[arg(long, value_enum)]
    pub pressure: Option<PressureSolver>,
    /// Head motion about the neck: still, the shake (0.6 rad at 1 Hz) or violent
    /// (for soak runs: 1.2 rad at 3 Hz with a nod and jolts of the whole head).
    #[arg(long, value_enum, default_value = "shake")]
    pub motion: MotionArg,
    /// Simulate only this share of the key hairs (0 < share ≤ 1; at least one):
    /// the first of a spatially progressive order of the roots; the others
    /// follow the simulated hair nearest them (simulation level of detail).
    #[arg(long)]
    pub simulated: Option<f32>,
}

impl SimArgs {
    /// The line every command that simulates prints: the knobs these flags set,
    /// as they are after the defaults, the `--config` file and the flags, the
    /// pressure solver as recorded on a device of `device_type`.
    pub fn describe(&self, p: &SimParams, device_type: vk::PhysicalDeviceType) -> String {
        let solver = p.volume.solver.on_device(device_type);
        let solver = match p.volume.solver {
            PressureSolver::Auto if device_type == vk::PhysicalDeviceType::CPU => {
                format!("{solver:?}: auto, a CPU device")
            }
            PressureSolver::Auto => format!("{solver:?}: auto, a GPU"),
            _ => format!("{solver:?}"),
        };
        format!(
            "parameters: {} iterations, {:?} solver, volume {:?} at {:?}, {} sub-step{}, {:?} pressure solve ({}) capped at {} iterations, motion {:?}",
            p.iterations,
            p.solver,
            p.volume.mode,
            p.volume.resolution,
            p.substeps,
            if p.substeps == 1 { "" } else { "s" },
            p.volume.preconditioner,
            solver,
            p.volume.max_iterations,
            self.motion,
        )
    }

    /// The key hairs `--simulated` leaves simulated of `strands` (none: all),
    /// checked before any GPU work.
    pub fn simulated_count(&self, strands: usize) -> Result<Option<usize>, crate::output::Error> {
        let Some(share) = self.simulated else {
            return Ok(None);
        };
        if !(share.is_finite() && share > 0.0 && share <= 1.0) {
            return Err(
                format!("--simulated must be a share of the key hairs above 0 and at most 1 (got {share})").into()
            );
        }
        Ok(Some(((share * strands as f32).ceil() as usize).clamp(1, strands.max(1))))
    }

    /// Applies the flags given to `params` (validated later, with the rest).
    pub fn apply(&self, params: &mut SimParams) {
        if let Some(iterations) = self.iterations {
            params.iterations = iterations;
        }
        if let Some(substeps) = self.substeps {
            params.substeps = substeps;
        }
        if self.dftl {
            params.solver = SolverMode::Dftl;
        }
        if let Some(mode) = self.volume {
            params.volume.mode = mode;
        }
        if let Some(grid) = self.grid {
            params.volume.resolution = [grid; 3];
        }
        if self.jacobi {
            params.volume.preconditioner = Preconditioner::Jacobi;
        }
        if let Some(cap) = self.max_iterations {
            params.volume.max_iterations = cap;
        }
        if let Some(solver) = self.pressure {
            params.volume.solver = solver;
        }
    }
}

/// `--motion`: how the head moves (about the neck `pivot`).
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MotionArg {
    /// The head stays still (does the groom hold its style?).
    Still,
    /// 0.6 rad at 1 Hz, with a nod.
    Shake,
    /// For soak runs: 1.2 rad at 3 Hz with a nod, and the whole head jolted by a
    /// tenth of the groom's size.
    Violent,
}

impl MotionArg {
    /// The head at `time` seconds, for a groom of bounding-box size `size`.
    pub fn head(self, time: f32, pivot: Vec3, size: f32) -> RigidTransform {
        match self {
            MotionArg::Still => RigidTransform::default(),
            MotionArg::Shake => motion::shaking_head_about(time, 0.6, 1.0, pivot),
            MotionArg::Violent => motion::violent_about(time, pivot, 0.1 * size),
        }
    }
}
