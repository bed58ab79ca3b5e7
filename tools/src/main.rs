//! `vkhair`: the command-line program of the vkhair crate.

mod bench_cmd;
mod bench_measure;
mod groom_input;
mod output;
mod plot_cmd;
mod profile;
mod render_cmd;
mod sim_check;
mod simulate_cmd;

use std::path::{Path, PathBuf};

use groom_input::load;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use glam::Vec3;
use vkhair::ash::vk;
use vkhair::config::Config;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::grow::{grow, GrowParams, Scalp};
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;
use vkhair::{list_devices, ContextOptions};

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
        /// Refuse a file with defects instead of repairing it (see `render --strict`).
        #[arg(long)]
        strict: bool,
    },
    /// Grow strands on a scalp and write them as a .hair file.
    Grow(GrowArgs),
    /// Simulate a groom on the GPU with the shaking-head motion; print per-stage GPU times.
    Simulate(simulate_cmd::SimulateArgs),
    /// Simulate and render a head of hair headless: PNG frames, a contact sheet and a
    /// per-pass GPU timing table.
    Render(render_cmd::RenderArgs),
    /// Measure every stage on the GPU beside its CPU reference (thesis, Sintel, a
    /// large groom), with recorded work, bandwidth bounds and scaling curves.
    Bench(bench_cmd::BenchArgs),
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
        /// Refuse a file with defects instead of repairing it (see `render --strict`).
        #[arg(long)]
        strict: bool,
    },
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
    output::restore_sigpipe();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Devices => devices(),
        Command::Inspect { file, strict } => inspect(&file, strict),
        Command::Grow(args) => grow_cmd(&args),
        Command::Simulate(args) => simulate_cmd::simulate(&args),
        Command::Render(args) => render_cmd::render(&args),
        Command::Config => Config::default()
            .to_commented_toml()
            .map(|text| say!("{}", text.trim_end_matches('\n')))
            .map_err(Into::into),
        Command::Plot(args) => plot_cmd::plot(&args),
        Command::Bench(args) => bench_cmd::bench(&args),
        Command::Convert { input, points, key_hairs, out, strict } => convert(&input, points, key_hairs, &out, strict),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("vkhair: {e}");
            ExitCode::FAILURE
        }
    }
}

type CliResult = Result<(), output::Error>;

fn devices() -> CliResult {
    let reports = list_devices(&ContextOptions::default())?;
    if reports.is_empty() {
        say!("no Vulkan devices (install mesa-vulkan-drivers for lavapipe)");
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
        say!(
            "{} {} ({kind}, Vulkan {}.{}.{}, {})",
            if r.chosen { "*" } else { " " },
            i.name,
            vk::api_version_major(i.api_version),
            vk::api_version_minor(i.api_version),
            vk::api_version_patch(i.api_version),
            i.driver
        );
        match &r.usable {
            Ok(()) => say!("    usable: yes"),
            Err(why) => say!("    usable: no — {why}"),
        }
        say!(
            "    timestamps: {} valid bits, {} ns/tick; shared memory {} KiB; workgroup ≤ {}; tessellation ≤ {}",
            i.timestamp_valid_bits,
            i.timestamp_period,
            i.max_compute_shared_memory / 1024,
            i.max_compute_invocations,
            i.max_tessellation_level
        );
        say!("    async compute queue: {}", if r.async_compute { "yes" } else { "no (single queue path)" });
        say!(
            "    subgroup arithmetic: {}",
            if i.subgroup_reductions { "yes" } else { "no (reductions through shared memory)" }
        );
        if !r.optional_extensions.is_empty() {
            say!("    optional extensions: {}", r.optional_extensions.join(", "));
        }
    }
    say!("(* = chosen; force a device with {}=<name substring>)", vkhair::DEVICE_ENV);
    Ok(())
}

fn inspect(path: &Path, strict: bool) -> CliResult {
    let (groom, kind) = load(path, strict)?;
    let s = groom.stats();
    say!("{}: {kind}", path.display());
    say!("strands            {}", s.strands);
    say!("points             {}", s.points);
    say!(
        "points per strand  min {}  mean {:.2}  max {}",
        s.points_per_strand.0,
        s.points_per_strand.1,
        s.points_per_strand.2
    );
    say!(
        "strand length      min {:.4}  mean {:.4}  max {:.4}",
        s.strand_length.0,
        s.strand_length.1,
        s.strand_length.2
    );
    say!("segment length     min {:.5}  max {:.5}", s.segment_length.0, s.segment_length.1);
    say!("bounds             {:.4} .. {:.4}  (size {:.4})", s.bounds.0, s.bounds.1, s.bounds.1 - s.bounds.0);
    say!(
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
    say!("wrote {}: {} strands, {} points, mean length {:.4}", a.out.display(), s.strands, s.points, s.strand_length.1);
    Ok(())
}

fn convert(input: &Path, points: Option<usize>, key_hairs: Option<usize>, out: &Path, strict: bool) -> CliResult {
    let (mut groom, _) = load(input, strict)?;
    if let Some(n) = key_hairs {
        groom = groom.select_evenly(n)?;
    }
    if let Some(n) = points {
        groom = groom.resampled(n)?;
    }
    let s = groom.stats();
    HairFile::new(groom, &format!("from {}", input.file_name().and_then(|n| n.to_str()).unwrap_or("input")))
        .save(out)?;
    say!("wrote {}: {} strands, {} points", out.display(), s.strands, s.points);
    Ok(())
}
