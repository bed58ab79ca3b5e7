//! `vkhair simulate`: run the simulation headless, report per-stage GPU time,
//! tip drift and (with --obj) how many points ended inside the mesh collider.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use glam::Vec3;
use vkhair::config::Config;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::sdf::MeshSdf;
use vkhair::groom::{scenes, Groom};
use vkhair::sim::{
    motion, CpuHairSim, HairSim, MeshCollider, Preconditioner, RigidTransform, SimParams, SimStage, SimState,
    SolverMode, VolumeMode, VolumeParams,
};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

use crate::{load, CliResult};

#[derive(clap::Args)]
pub struct SimulateArgs {
    /// Groom file (.hair or .tfx); default: the `thesis` scene with its colliders.
    /// It is held in its authored style unless --config says otherwise (see
    /// `SimParams::styled`).
    #[arg(long)]
    input: Option<PathBuf>,
    /// Multiply input positions by this (e.g. 0.01 for Blender units to meters).
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
    /// Resample input strands to this many points (at most 64).
    #[arg(long, default_value_t = 16)]
    points: usize,
    /// Simulation steps (1/60 s each).
    #[arg(long, default_value_t = 120)]
    steps: usize,
    /// Parameter file (TOML, see `vkhair config`); the flags below win over it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Constraint iterations [default: 20].
    #[arg(long)]
    iterations: Option<u32>,
    /// Use the DFTL solver instead of PBD iterations.
    #[arg(long)]
    dftl: bool,
    /// Also run the CPU reference and report the largest position difference.
    #[arg(long)]
    check: bool,
    /// Volume stage (hair-hair interaction): FLIP on a MAC grid, density friction,
    /// or off [default: flip].
    #[arg(long, value_enum)]
    volume: Option<VolumeArg>,
    /// Volume grid cells per axis [default: 32].
    #[arg(long)]
    grid: Option<u32>,
    /// Use the Jacobi preconditioner instead of multigrid for the pressure solve.
    #[arg(long)]
    jacobi: bool,
    /// Iteration cap of the pressure solve [default: 40].
    #[arg(long)]
    max_iterations: Option<u32>,
    /// Head motion: still, the shake (0.6 rad at 1 Hz) or a violent shake
    /// (1 rad at 2 Hz), about the neck.
    #[arg(long, value_enum, default_value = "shake")]
    motion: MotionArg,
    /// Character mesh (OBJ, same units and frame as the groom, scaled by --scale):
    /// the strands collide with its signed distance field.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Do not collide with the --obj mesh (its field still measures how many
    /// points end up inside it).
    #[arg(long)]
    no_mesh_collider: bool,
    /// Write the simulated strands after the last step as a .hair file: in the
    /// input's frame (the head's motion undone) and units (--scale undone), one
    /// strand per input strand with --points points each.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum MotionArg {
    Still,
    Shake,
    Violent,
}

#[derive(Clone, Copy, ValueEnum)]
enum VolumeArg {
    Off,
    Flip,
    Friction,
}

/// The simulation parameters: the tool's defaults (FLIP at 32³; an `--input`
/// groom held in its authored style, [`SimParams::styled`]), then the `--config`
/// file, then the flags given. Checked before any GPU work.
fn simulate_params(a: &SimulateArgs) -> Result<Config, vkhair::Error> {
    let sim = if a.input.is_some() { SimParams::styled() } else { SimParams::default() };
    let base = Config { sim: SimParams { volume: VolumeParams::flip([32, 32, 32]), ..sim }, ..Config::default() };
    let config = match &a.config {
        Some(path) => base.load_over(path)?,
        None => base,
    };
    let mut config = config;
    let params = &mut config.sim;
    if let Some(iterations) = a.iterations {
        params.iterations = iterations;
    }
    if a.dftl {
        params.solver = SolverMode::Dftl;
    }
    if let Some(volume) = a.volume {
        params.volume.mode = match volume {
            VolumeArg::Off => VolumeMode::Off,
            VolumeArg::Flip => VolumeMode::Flip,
            VolumeArg::Friction => VolumeMode::Friction,
        };
    }
    if let Some(grid) = a.grid {
        params.volume.resolution = [grid; 3];
    }
    if a.jacobi {
        params.volume.preconditioner = Preconditioner::Jacobi;
    }
    if let Some(cap) = a.max_iterations {
        params.volume.max_iterations = cap;
    }
    config.validate()?;
    Ok(config)
}

/// The --obj mesh scaled like the groom.
fn load_mesh(obj: Option<&Path>, scale: f32) -> Result<Option<TriMesh>, vkhair::Error> {
    match obj {
        Some(path) => {
            let m = TriMesh::load_obj(path)?;
            TriMesh::new(m.positions.iter().map(|p| *p * scale).collect(), m.triangles).map(Some)
        }
        None => Ok(None),
    }
}

/// Share of free particles inside `field` (head frame), with the head at `head`.
fn share_inside(state: &SimState, field: &MeshSdf, head: &RigidTransform) -> f64 {
    let back = head.matrix().inverse();
    let free: Vec<Vec3> = state.positions.iter().filter(|p| p.w > 0.0).map(|p| p.truncate()).collect();
    let inside = free.iter().filter(|p| field.sample(back.transform_point3(**p)) < 0.0).count();
    inside as f64 / free.len().max(1) as f64
}

/// Per strand, the tip's distance from the rest shape carried by `head`, as a
/// fraction of the strand's rest length, sorted.
fn tip_drift(state: &SimState, head: &RigidTransform) -> Vec<f32> {
    let m = head.matrix();
    let mut drift: Vec<f32> = (0..state.strands)
        .map(|s| {
            let tip = s * state.points + state.points - 1;
            let moved = m.transform_point3(state.rest[tip].truncate());
            (state.positions[tip].truncate() - moved).length() / state.rest_strand_length(s).max(f32::MIN_POSITIVE)
        })
        .collect();
    drift.sort_by(f32::total_cmp);
    drift
}

fn percentile(sorted: &[f32], percent: usize) -> Option<f32> {
    (!sorted.is_empty()).then(|| sorted[(sorted.len() - 1) * percent / 100])
}

/// The simulated strands in the input's frame and units, as a .hair file.
fn write_final(path: &Path, state: &SimState, head: &RigidTransform, scale: f32) -> CliResult {
    let back = head.matrix().inverse();
    let positions: Vec<Vec3> = state.positions.iter().map(|p| back.transform_point3(p.truncate()) / scale).collect();
    let counts = vec![state.points as u32; state.strands];
    let groom = Groom::new(positions, &counts)?;
    HairFile::new(groom, "vkhair simulate: strands after the last step").save(path)?;
    Ok(())
}

pub fn simulate(a: &SimulateArgs) -> CliResult {
    let (groom, colliders, label, pivot) = match &a.input {
        None => (scenes::thesis()?, motion::thesis_colliders(), "thesis scene".to_owned(), motion::NECK_PIVOT),
        Some(path) => {
            let (groom, _) = load(path)?;
            let scaled: Vec<Vec3> = groom.positions().iter().map(|p| *p * a.scale).collect();
            let counts: Vec<u32> = (0..groom.strand_count()).map(|i| groom.strand_len(i) as u32).collect();
            let groom = Groom::new(scaled, &counts)?.resampled(a.points)?;
            // Turn about the centre of the roots' lowest level: roughly the neck.
            let (lo, hi) = groom.bounds();
            let pivot = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
            (groom, Vec::new(), path.display().to_string(), pivot)
        }
    };
    let config = simulate_params(a)?;
    let params = config.sim.clone();
    let mesh = load_mesh(a.obj.as_deref(), a.scale)?;
    let colliding = mesh.is_some() && !a.no_mesh_collider;
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let head = |i: usize| {
        let t = (i + 1) as f32 * params.dt;
        match a.motion {
            MotionArg::Still => RigidTransform::default(),
            MotionArg::Shake => motion::shaking_head_about(t, 0.6, 1.0, pivot),
            MotionArg::Violent => motion::shaking_head_about(t, 1.0, 2.0, pivot),
        }
    };
    let mut sim = HairSim::new(&ctx, &groom, &params, &RigidTransform::default())?;
    sim.set_colliders(&colliders)?;
    let field = match &mesh {
        Some(m) => {
            let collider = MeshCollider::new(&ctx, m, &config.mesh_collider)?;
            let [nx, ny, nz] = collider.dims();
            println!(
                "mesh collider{}: {} triangles, {nx}×{ny}×{nz} field of {:.1} mm cells",
                if colliding { "" } else { " (off: only measuring)" },
                m.triangles.len(),
                collider.cell() * 1e3
            );
            let field = collider.read_field()?;
            if colliding {
                sim.set_mesh_collider(Some(collider))?;
            }
            Some(field)
        }
        None => None,
    };
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024)?;
    let (strands, points) = sim.size();
    println!(
        "{label}: {strands} key hairs × {points} points on {}, {} steps of {:.4} s",
        ctx.info().name,
        a.steps,
        params.dt
    );
    println!(
        "parameters: {} iterations, {:?} solver, volume {:?} at {:?}{}",
        params.iterations,
        params.solver,
        params.volume.mode,
        params.volume.resolution,
        a.config.as_ref().map(|c| format!(" (from {} and the flags)", c.display())).unwrap_or_default()
    );
    let mut totals = vec![0.0f64; SimStage::ALL.len()];
    // With a mesh collider, the share of points inside it is checked every 10 steps.
    let chunk = if field.is_some() { 10 } else { 100 };
    let mut done = 0;
    let mut worst_inside = 0.0f64;
    while done < a.steps {
        let n = chunk.min(a.steps - done);
        let start = done;
        if let Some(report) = sim.run(n, |i| head(start + i), Some(&mut profiler))? {
            for (name, ns) in report.totals_by_name() {
                if let Some(k) = SimStage::ALL.iter().position(|s| s.label() == name) {
                    totals[k] += ns;
                }
            }
        }
        done += n;
        if let Some(field) = &field {
            worst_inside = worst_inside.max(share_inside(&sim.read_state()?, field, &head(done - 1)));
        }
    }
    let sum: f64 = totals.iter().sum();
    println!("{:<28} {:>12} {:>8}", "stage", "ms/step", "share");
    for (stage, ns) in SimStage::ALL.iter().zip(&totals) {
        println!("{:<28} {:>12.3} {:>7.1}%", stage.label(), ns / 1e6 / a.steps as f64, 100.0 * ns / sum.max(1.0));
    }
    println!("{:<28} {:>12.3}", "total", sum / 1e6 / a.steps as f64);
    let state = sim.read_state()?;
    println!("kinetic energy {:.4} J/kg per particle", state.kinetic_energy() / state.positions.len() as f64);
    let last_head = head(a.steps.saturating_sub(1));
    let drift = tip_drift(&state, &last_head);
    if let (Some(p50), Some(p95)) = (percentile(&drift, 50), percentile(&drift, 95)) {
        println!("tip drift from rest: p50 {:.2} % p95 {:.2} % of strand length", 100.0 * p50, 100.0 * p95);
    }
    if let Some(field) = &field {
        println!(
            "points inside the mesh collider: {:.3} % after the last step, at most {:.3} % (checked every {chunk} steps)",
            100.0 * share_inside(&state, field, &last_head),
            100.0 * worst_inside
        );
    }
    if let Some(out) = &a.out {
        write_final(out, &state, &last_head, a.scale)?;
        println!("wrote {}: {strands} strands × {points} points", out.display());
    }
    if let (Some(grid), Some(stats)) = (sim.volume_grid(), sim.volume_stats()?) {
        println!(
            "volume grid {}×{}×{} cells of {:.1} mm; last pressure solve: {} iterations, residual {:.1e}{}",
            grid.dims[0],
            grid.dims[1],
            grid.dims[2],
            grid.cell_size * 1e3,
            stats.iterations,
            stats.relative_residual,
            if stats.converged { "" } else { " (not converged)" }
        );
    }
    if a.check {
        let mut cpu = CpuHairSim::new(&groom, &params, &RigidTransform::default())?;
        cpu.set_colliders(&colliders)?;
        if let (Some(m), true) = (&mesh, colliding) {
            let p = &config.mesh_collider;
            cpu.set_mesh_collider(Some(MeshSdf::build(m, p.resolution, p.margin)?));
        }
        for i in 0..a.steps {
            cpu.step(&head(i))?;
        }
        let max =
            state.positions.iter().zip(&cpu.state().positions).map(|(g, c)| (*g - *c).length()).fold(0.0f32, f32::max);
        println!("largest GPU − CPU reference position difference: {max:e} m");
        if params.volume.mode == VolumeMode::Flip {
            println!(
                "  (FLIP: the GPU and the reference solve the pressure with different preconditioners, each to a \
                 relative residual of {:e}; step by step they agree to micrometres, and like any chaotic system the \
                 trajectories then drift apart — compare with --volume friction or off, which match bit for bit)",
                params.volume.tolerance
            );
        }
    }
    Ok(())
}
