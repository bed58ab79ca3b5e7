//! `vkhair`: the command-line program of the vkhair crate.

mod plot_cmd;
mod render_cmd;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use glam::Vec3;
use vkhair::ash::vk;
use vkhair::config::Config;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::grow::{grow, GrowParams, Scalp};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::tfx::TfxFile;
use vkhair::groom::{scenes, Groom};
use vkhair::sim::{
    motion, CpuHairSim, HairSim, Preconditioner, RigidTransform, SimParams, SimStage, SimState, SolverMode, VolumeMode,
    VolumeParams,
};
use vkhair::{list_devices, ContextOptions, GpuContext, GpuProfiler};

#[derive(Parser)]
#[command(name = "vkhair", version, about = "Real-time strand hair on Vulkan: devices, grooms, growth")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List Vulkan devices, what vkhair can use of each, and which one it would choose.
    Devices,
    /// Print counts, lengths, bounds and point statistics of a .hair or .tfx file.
    Inspect {
        /// The groom file (.hair or .tfx).
        file: PathBuf,
    },
    /// Grow strands on a scalp and write them as a .hair file.
    Grow(GrowArgs),
    /// Simulate a groom on the GPU with the shaking-head motion; print per-stage GPU times.
    Simulate(SimulateArgs),
    /// Simulate and render a head of hair headless: PNG frames, a contact sheet and a
    /// per-pass GPU timing table.
    Render(render_cmd::RenderArgs),
    /// Print the default parameters as commented TOML, a starting point for --config.
    Config,
    /// Chart the render benchmark's CSV (cargo bench --bench render) as a PNG.
    Plot(plot_cmd::PlotArgs),
    /// Resample and/or pick key hairs from a .hair or .tfx file; write a .hair file.
    Convert {
        /// Input groom (.hair or .tfx).
        input: PathBuf,
        /// Resample every strand to this many points by arc length.
        #[arg(long)]
        points: Option<usize>,
        /// Keep this many strands, spread evenly (key hairs).
        #[arg(long)]
        key_hairs: Option<usize>,
        /// Output .hair file.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// Groom file (.hair or .tfx); default: the `thesis` scene with its colliders.
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

#[derive(Clone, Copy, ValueEnum)]
enum ScalpKind {
    /// The `thesis` reference scene (1750 × 6 on a head sphere); other options ignored.
    Thesis,
    /// A sphere cap around +Y, face (+Z) left free.
    Sphere,
    /// An ellipsoid cap around +Y, face (+Z) left free.
    Ellipsoid,
    /// Upward-facing triangles in the top part of an OBJ mesh (--obj).
    Obj,
}

#[derive(clap::Args)]
struct GrowArgs {
    /// Scalp shape.
    #[arg(long, value_enum, default_value = "thesis")]
    scalp: ScalpKind,
    /// OBJ mesh for --scalp obj.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Sphere radius / ellipsoid semi-axes "x,y,z" (scalp units).
    #[arg(long, default_value = "0.1")]
    radius: String,
    /// Centre of the sphere/ellipsoid "x,y,z".
    #[arg(long, default_value = "0,0,0")]
    center: String,
    /// Roots within this angle of +Y, degrees (sphere/ellipsoid).
    #[arg(long, default_value_t = 110.0)]
    max_angle: f32,
    /// OBJ: only triangles above this fraction of the mesh height.
    #[arg(long, default_value_t = 0.8)]
    min_height: f32,
    /// OBJ: only triangles whose normal·up is at least this.
    #[arg(long, default_value_t = 0.2)]
    min_up_dot: f32,
    /// Number of strands.
    #[arg(long, default_value_t = 1000)]
    strands: usize,
    /// Points per strand.
    #[arg(long, default_value_t = 16)]
    points: usize,
    /// Strand length (scalp units); default 0.3, or 35 % of the mesh height for OBJ.
    #[arg(long)]
    length: Option<f32>,
    /// Bend toward gravity, radians over the strand.
    #[arg(long, default_value_t = 2.5)]
    droop: f32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output .hair file.
    #[arg(long)]
    out: PathBuf,
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Devices => devices(),
        Command::Inspect { file } => inspect(&file),
        Command::Grow(args) => grow_cmd(&args),
        Command::Simulate(args) => simulate(&args),
        Command::Render(args) => render_cmd::render(&args),
        Command::Config => Config::default().to_commented_toml().map(|text| print!("{text}")).map_err(Into::into),
        Command::Plot(args) => plot_cmd::plot(&args),
        Command::Convert { input, points, key_hairs, out } => convert(&input, points, key_hairs, &out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("vkhair: {e}");
            ExitCode::FAILURE
        }
    }
}

type CliResult = Result<(), Box<dyn std::error::Error>>;

fn devices() -> CliResult {
    let reports = list_devices(&ContextOptions::default())?;
    if reports.is_empty() {
        println!("no Vulkan devices (install mesa-vulkan-drivers for lavapipe)");
    }
    for r in &reports {
        let i = &r.info;
        let kind = match i.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        };
        println!(
            "{} {} ({kind}, Vulkan {}.{}.{}, {})",
            if r.chosen { "*" } else { " " },
            i.name,
            vk::api_version_major(i.api_version),
            vk::api_version_minor(i.api_version),
            vk::api_version_patch(i.api_version),
            i.driver
        );
        match &r.usable {
            Ok(()) => println!("    usable: yes"),
            Err(why) => println!("    usable: no — {why}"),
        }
        println!(
            "    timestamps: {} valid bits, {} ns/tick; shared memory {} KiB; workgroup ≤ {}; tessellation ≤ {}",
            i.timestamp_valid_bits,
            i.timestamp_period,
            i.max_compute_shared_memory / 1024,
            i.max_compute_invocations,
            i.max_tessellation_level
        );
        println!("    async compute queue: {}", if r.async_compute { "yes" } else { "no (single queue path)" });
        if !r.optional_extensions.is_empty() {
            println!("    optional extensions: {}", r.optional_extensions.join(", "));
        }
    }
    println!("(* = chosen; force a device with {}=<name substring>)", vkhair::DEVICE_ENV);
    Ok(())
}

fn load(path: &Path) -> Result<(Groom, String), vkhair::Error> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
    if ext == "tfx" {
        let f = TfxFile::open(path)?;
        Ok((f.groom, format!("TressFX {} (.tfx)", f.version)))
    } else {
        let f = HairFile::open(path)?;
        let info = f.info_str();
        Ok((
            f.groom,
            format!("cyHair (.hair){}", if info.is_empty() { String::new() } else { format!(", info \"{info}\"") }),
        ))
    }
}

fn inspect(path: &Path) -> CliResult {
    let (groom, kind) = load(path)?;
    let s = groom.stats();
    println!("{}: {kind}", path.display());
    println!("strands            {}", s.strands);
    println!("points             {}", s.points);
    println!(
        "points per strand  min {}  mean {:.2}  max {}",
        s.points_per_strand.0, s.points_per_strand.1, s.points_per_strand.2
    );
    println!(
        "strand length      min {:.4}  mean {:.4}  max {:.4}",
        s.strand_length.0, s.strand_length.1, s.strand_length.2
    );
    println!("segment length     min {:.5}  max {:.5}", s.segment_length.0, s.segment_length.1);
    println!("bounds             {:.4} .. {:.4}  (size {:.4})", s.bounds.0, s.bounds.1, s.bounds.1 - s.bounds.0);
    println!(
        "attributes         thickness {}  transparency {}  colors {}",
        yes(s.has_thickness),
        yes(s.has_transparency),
        yes(s.has_colors)
    );
    Ok(())
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn parse_vec3(name: &str, s: &str) -> Result<Vec3, String> {
    let parts: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("--{name} {s:?}: {e}"))?;
    match parts.as_slice() {
        [v] => Ok(Vec3::splat(*v)),
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("--{name} {s:?}: give one value or three separated by commas")),
    }
}

fn grow_cmd(a: &GrowArgs) -> CliResult {
    let groom = match a.scalp {
        ScalpKind::Thesis => scenes::thesis()?,
        kind => {
            let mut length = a.length.unwrap_or(0.3);
            let scalp = match kind {
                ScalpKind::Obj => {
                    let path = a.obj.as_ref().ok_or("--scalp obj needs --obj FILE.obj")?;
                    let mesh = TriMesh::load_obj(path)?;
                    let (lo, hi) = mesh.bounds();
                    if a.length.is_none() {
                        length = 0.35 * (hi.y - lo.y);
                    }
                    Scalp::Mesh { mesh, up: Vec3::Y, min_height: a.min_height, min_up_dot: a.min_up_dot }
                }
                _ => {
                    let radii = parse_vec3("radius", &a.radius)?;
                    let center = parse_vec3("center", &a.center)?;
                    let mut scalp = Scalp::sphere_cap(center, radii.x, a.max_angle.to_radians());
                    if let Scalp::Ellipsoid { radii: r, .. } = &mut scalp {
                        *r = radii;
                    }
                    scalp
                }
            };
            let params = GrowParams {
                strands: a.strands,
                points_per_strand: a.points,
                length,
                droop: a.droop,
                seed: a.seed,
                ..GrowParams::default()
            };
            grow(&scalp, &params)?
        }
    };
    let s = groom.stats();
    HairFile::new(groom, "grown by vkhair").save(&a.out)?;
    println!(
        "wrote {}: {} strands, {} points, mean length {:.4}",
        a.out.display(),
        s.strands,
        s.points,
        s.strand_length.1
    );
    Ok(())
}

fn convert(input: &Path, points: Option<usize>, key_hairs: Option<usize>, out: &Path) -> CliResult {
    let (mut groom, _) = load(input)?;
    if let Some(n) = key_hairs {
        groom = groom.select_evenly(n)?;
    }
    if let Some(n) = points {
        groom = groom.resampled(n)?;
    }
    let s = groom.stats();
    HairFile::new(groom, &format!("from {}", input.file_name().and_then(|n| n.to_str()).unwrap_or("input")))
        .save(out)?;
    println!("wrote {}: {} strands, {} points", out.display(), s.strands, s.points);
    Ok(())
}

/// The simulation parameters: the tool's defaults (FLIP at 32³), then the
/// `--config` file, then the flags given. Checked before any GPU work.
fn simulate_params(a: &SimulateArgs) -> Result<SimParams, vkhair::Error> {
    let base = Config {
        sim: SimParams { volume: VolumeParams::flip([32, 32, 32]), ..SimParams::default() },
        ..Config::default()
    };
    let config = match &a.config {
        Some(path) => base.load_over(path)?,
        None => base,
    };
    let mut params = config.sim;
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
    params.validate()?;
    Ok(params)
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

fn simulate(a: &SimulateArgs) -> CliResult {
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
    let params = simulate_params(a)?;
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
    let chunk = 100;
    let mut done = 0;
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
