//! `vkhair bench`: every GPU figure beside its CPU reference, its recorded work
//! and the time the bytes it moves would take at the memory bandwidth of real
//! GPUs, on the thesis scene, Sintel and a large generated groom; then scaling
//! curves with their fitted exponents (`scaling.csv`, `scaling.png`).
//!
//! Each figure is the median and p95 of `--samples` samples; GPU and CPU
//! reference samples alternate step by step in one process. Two GPU figures
//! are taken of every sample: the sum of the stage's timestamp scopes, and the
//! wall time of a submission holding just that step or frame (record, submit,
//! wait) less the median wall time of an empty submission. On a GPU the
//! timestamps are the figure. On a CPU device (lavapipe) they are not: the
//! driver writes a timestamp when it reaches the command, not when the work
//! before it has finished (a 32-point step read 0.05 ms in timestamps against
//! 9.7 ms of wall time), so there the wall-clock figure is the one reported,
//! and a stage measured alone is the difference of two steps' wall times.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use vkhair::groom::grow::{grow, GrowParams};
use vkhair::groom::{scenes, Groom};
use vkhair::sim::{motion, Collider, SimParams, VolumeMode, VolumeParams};
use vkhair::{ContextOptions, GpuContext, RecordedWork};

use crate::args::sim::SimArgs;
use crate::chart::plot_file;
use crate::destinations::{self, Kind, Output};
use crate::output::Error;
use crate::say;
use crate::say_err;
use measure::{measure_sim, Samples, SimCase, SimFigures};
use modes::{default_exact, frame_ms, render_rows, write_modes, OFF};

mod frames;
mod measure;
mod modes;
mod peer;
mod scaling;
mod truth;

/// Peak memory bandwidth of a few GPUs, bytes per second (vendors' figures): the
/// physical bound of a stage that moves its bytes once.
pub const PEAK_BANDWIDTH: &[(&str, f64)] = &[
    ("H100 SXM", 3.35e12),
    ("H200", 4.8e12),
    ("A100 80GB SXM", 2.039e12),
    ("RTX 4090", 1.008e12),
    ("RX 7900 XTX", 0.96e12),
];

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Samples per figure (the report gives their median and p95).
    #[arg(long, default_value_t = 20)]
    samples: usize,
    /// Seconds the samples of one simulation figure may take: past them it
    /// stops sampling, keeping at least 5 (a large groom's CPU reference takes
    /// seconds a step).
    #[arg(long, default_value_t = 10.0)]
    figure_seconds: f64,
    /// Samples per point of the scaling curves.
    #[arg(long, default_value_t = 5)]
    scaling_samples: usize,
    /// Folder holding Sintel's sintel_hair.tfx and sintel_bust.obj (its rows are
    /// skipped, with the reason printed, when absent).
    #[arg(long, default_value = "../shared/data/sintel")]
    sintel: PathBuf,
    /// Key hairs of the large generated groom (32 points each).
    #[arg(long, default_value_t = 20_000)]
    large: usize,
    /// Small scenes and short scaling ranges (a smoke run): frames of 160×120
    /// (the resolution curve's 1080p point aside) and drawn hairs at a tenth
    /// of a scalp's density.
    #[arg(long)]
    quick: bool,
    /// Folder for scaling.csv and scaling.png.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Write every figure as JSON to this file.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Refuse to run on a CPU implementation of Vulkan (lavapipe): for
    /// tools/gpu-bench.sh on a machine with a GPU.
    #[arg(long)]
    require_gpu: bool,
    /// Simulation knobs for every row (each row sets its own volume mode and grid).
    #[command(flatten)]
    sim: SimArgs,
}

/// What every measurement of a run shares.
struct Bench<'a> {
    ctx: &'a GpuContext,
    args: &'a BenchArgs,
    clock: Clocking,
}

impl Bench<'_> {
    /// How long the samples of one simulation figure may take.
    fn budget(&self) -> std::time::Duration {
        std::time::Duration::from_secs_f64(self.args.figure_seconds)
    }

    /// The simulation parameters of a row ([`row_params`]).
    fn params(&self, mode: VolumeMode, grid: u32) -> SimParams {
        row_params(&self.args.sim, mode, grid)
    }
}

/// The simulation parameters of a row: vkhair's defaults, the simulation
/// flags `sim`, then the row's volume `mode` on a `grid`³ grid.
fn row_params(sim: &SimArgs, mode: VolumeMode, grid: u32) -> SimParams {
    let mut params = flag_params(sim);
    params.volume = VolumeParams { mode, resolution: [grid; 3], ..params.volume };
    params
}

/// vkhair's defaults with the simulation flags `sim` (as the frames' rows
/// take them).
fn flag_params(sim: &SimArgs) -> SimParams {
    let mut params = SimParams::default();
    sim.apply(&mut params);
    params
}

/// One stage's figures on one scene.
struct Row {
    scene: String,
    stage: String,
    /// "step" or "frame".
    per: &'static str,
    /// The GPU figure (see the module docs), ms.
    gpu: Samples,
    /// The sum of the timestamp scopes, ms.
    timestamps: Samples,
    cpu: Option<Samples>,
    work: RecordedWork,
    /// A render frame's error against the exact reference, 8-bit sRGB steps.
    error: Option<f64>,
}

impl Row {
    fn ratio(&self) -> f64 {
        self.cpu.as_ref().map_or(f64::NAN, |c| self.gpu.median() / c.median())
    }

    fn new(scene: &str, stage: &str, per: &'static str, gpu: Samples, timestamps: Samples, work: RecordedWork) -> Row {
        Row { scene: scene.into(), stage: stage.into(), per, gpu, timestamps, cpu: None, work, error: None }
    }

    fn bytes(&self) -> u64 {
        self.work.bytes_read + self.work.bytes_written
    }

    fn json(&self) -> Value {
        let bound: serde_json::Map<String, Value> = PEAK_BANDWIDTH
            .iter()
            .map(|(name, bw)| (name.to_string(), json!(finite(self.bytes() as f64 / bw * 1e3))))
            .collect();
        let per = self.per;
        let mut v = json!({
            "scene": self.scene,
            "stage": self.stage,
            "per": per,
            format!("gpu_ms_per_{per}"): finite(self.gpu.median()),
            format!("gpu_ms_per_{per}_p95"): finite(self.gpu.p95()),
            format!("gpu_timestamp_ms_per_{per}"): finite(self.timestamps.median()),
            format!("dispatches_per_{per}"): self.work.dispatches,
            format!("barriers_per_{per}"): self.work.barriers,
            format!("bytes_read_per_{per}"): self.work.bytes_read,
            format!("bytes_written_per_{per}"): self.work.bytes_written,
            "bandwidth_bound_ms": bound,
            "samples": self.gpu.0.len(),
        });
        if let Some(cpu) = &self.cpu {
            v[format!("cpu_ms_per_{per}")] = finite(cpu.median());
            v[format!("cpu_ms_per_{per}_p95")] = finite(cpu.p95());
            v["ratio_gpu_to_cpu"] = finite(self.ratio());
        }
        if let Some(e) = self.error {
            v["error_vs_reference_srgb_steps"] = finite(e);
        }
        v
    }
}

/// A JSON number, or null for NaN/Inf (JSON has no such numbers).
fn finite(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// How the GPU figures are taken on this device (see the module docs).
#[derive(Clone, Copy)]
struct Clocking {
    /// Whether the wall clock stands for the GPU (a CPU device).
    wall: bool,
    /// Median wall time of an empty submission, ms.
    empty_ms: f64,
}

impl Clocking {
    fn new(ctx: &GpuContext) -> Result<Clocking, Error> {
        use vkhair::headless::Submit;
        let mut empty = Samples::default();
        for _ in 0..20 {
            let started = std::time::Instant::now();
            ctx.run_commands("vkhair bench empty submission", |_| {})?;
            empty.0.push(started.elapsed().as_secs_f64() * 1e3);
        }
        let wall = ctx.info().device_type == vkhair::ash::vk::PhysicalDeviceType::CPU;
        Ok(Clocking { wall, empty_ms: empty.median() })
    }

    /// The GPU figure of samples with these timestamps and wall times.
    fn figure(&self, timestamps: &Samples, wall: &Samples) -> Samples {
        match self.wall {
            true => Samples(wall.0.iter().map(|w| (w - self.empty_ms).max(0.0)).collect()),
            false => timestamps.clone(),
        }
    }

    fn describe(&self) -> String {
        match self.wall {
            true => format!(
                "a CPU device: GPU figures are wall time less an empty submission ({:.3} ms), timestamps shown beside",
                self.empty_ms
            ),
            false => "GPU figures from timestamp queries".to_owned(),
        }
    }
}

/// The row of a simulation configuration and, with the volume stage, the row of
/// the volume stage alone: its own scopes on a GPU; on a CPU device, the step
/// less the step without the volume stage (`without`).
fn sim_rows(scene: &str, stage: &str, f: &SimFigures, clock: Clocking, without: Option<&SimFigures>) -> Vec<Row> {
    let gpu = clock.figure(&f.gpu, &f.gpu_wall);
    let mut row = Row::new(scene, stage, "step", gpu.clone(), f.gpu.clone(), f.work);
    row.cpu = (!f.cpu.0.is_empty()).then(|| f.cpu.clone());
    let mut rows = vec![row];
    if let Some(off) = without {
        let alone = volume_alone(f, off, clock);
        let stage = format!("{stage}: volume stage alone");
        let mut row = Row::new(scene, &stage, "step", alone, f.volume_gpu.clone(), f.work - off.work);
        row.cpu = (!f.volume_cpu.0.is_empty()).then(|| f.volume_cpu.clone());
        rows.push(row);
    }
    rows
}

/// The GPU figure of the volume stage alone: its scopes on a GPU, on a CPU
/// device the step less the median step without it (`off`).
fn volume_alone(f: &SimFigures, off: &SimFigures, clock: Clocking) -> Samples {
    match clock.wall {
        true => {
            let base = clock.figure(&off.gpu, &off.gpu_wall).median();
            Samples(clock.figure(&f.gpu, &f.gpu_wall).0.iter().map(|g| (g - base).max(0.0)).collect())
        }
        false => f.volume_gpu.clone(),
    }
}

/// A scene of the bench: its groom, colliders and how `render` draws it.
struct Scene {
    name: String,
    groom: Groom,
    colliders: Vec<Collider>,
    render_args: Option<Vec<String>>,
}

fn grown(strands: usize, points: usize) -> Result<Groom, Error> {
    let p = GrowParams { strands, points_per_strand: points, length: 0.35, seed: 3, ..GrowParams::default() };
    Ok(grow(&scenes::thesis_scalp(), &p)?)
}

/// The drawn hairs' density (per cm² of scalp) of a `--quick` run's frames:
/// a tenth of the default, 9,661 hairs over the thesis' scalp.
pub const QUICK_DENSITY: &str = "15";

/// The scene flags a frame of `a` adds to its own: `--quick`'s density.
pub fn quick_args(a: &BenchArgs) -> &'static [&'static str] {
    if a.quick {
        &["--density", QUICK_DENSITY]
    } else {
        &[]
    }
}

fn bench_scenes(a: &BenchArgs) -> Result<(Vec<Scene>, Vec<String>), Error> {
    let size = |full: (u32, u32)| {
        let (w, h) = if a.quick { (160, 120) } else { full };
        let mut args = vec!["--width".to_owned(), w.to_string(), "--height".into(), h.to_string()];
        args.extend(quick_args(a).iter().map(|s| s.to_string()));
        args
    };
    let mut skipped = Vec::new();
    let mut list = vec![Scene {
        name: "thesis 1750×6".into(),
        groom: scenes::thesis()?,
        colliders: motion::thesis_colliders(),
        render_args: Some(size((800, 600))),
    }];
    let (hair, bust) = (a.sintel.join("sintel_hair.tfx"), a.sintel.join("sintel_bust.obj"));
    if hair.is_file() && bust.is_file() {
        let groom = crate::args::input::load_scaled(&hair, false, 0.01, 32)?.groom;
        let mut args = size((1280, 720));
        for s in ["--input", &hair.display().to_string(), "--obj", &bust.display().to_string(), "--scale", "0.01"] {
            args.push(s.to_owned());
        }
        let name = format!("Sintel {}×32", groom.strand_count());
        list.push(Scene { name, groom, colliders: Vec::new(), render_args: Some(args) });
    } else {
        let why = format!("Sintel: {} or {} is missing", hair.display(), bust.display());
        say!("skipped {why}");
        skipped.push(why);
    }
    let large = if a.quick { a.large.min(500) } else { a.large };
    list.push(Scene {
        name: format!("generated {large}×32"),
        groom: grown(large, 32)?,
        colliders: motion::thesis_colliders(),
        render_args: None,
    });
    Ok((list, skipped))
}

fn print_rows(rows: &[Row]) {
    say!(
        "{:<22} {:<36} {:>9} {:>9} {:>9} {:>9} {:>7} {:>5} {:>5} {:>9} {:>9} {:>6}",
        "scene",
        "stage (ms per step or frame)",
        "GPU med",
        "GPU p95",
        "stamps",
        "CPU ref",
        "GPU/CPU",
        "disp",
        "barr",
        "MB moved",
        "H100 ms",
        "err"
    );
    for r in rows {
        let cpu = r.cpu.as_ref().map_or(f64::NAN, Samples::median);
        say!(
            "{:<22} {:<36} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>7.2} {:>5} {:>5} {:>9.2} {:>9.4} {:>6}",
            r.scene,
            r.stage,
            r.gpu.median(),
            r.gpu.p95(),
            r.timestamps.median(),
            cpu,
            r.ratio(),
            r.work.dispatches,
            r.work.barriers,
            r.bytes() as f64 / 1e6,
            r.bytes() as f64 / PEAK_BANDWIDTH[0].1 * 1e3,
            r.error.map_or(String::new(), |e| format!("{e:.1}"))
        );
    }
}

/// Writes `csv` whole as `out/name` (creating `out`); returns its path.
fn write_csv(out: &Path, name: &str, csv: &str) -> Result<PathBuf, Error> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let path = out.join(name);
    vkhair::files::write_atomic(&path, csv.as_bytes())?;
    Ok(path)
}

pub fn bench(a: &BenchArgs) -> Result<(), Error> {
    if a.samples == 0 {
        return Err("--samples must be at least 1 (the report's figures are medians of 20 by default)".into());
    }
    if !(a.figure_seconds.is_finite() && a.figure_seconds > 0.0 && a.figure_seconds <= 1e6) {
        return Err(format!("--figure-seconds must be a number of seconds above 0 (got {})", a.figure_seconds).into());
    }
    // A bad --simulated share, and the simulation flags with the volume stage
    // on (every row's modes), are refused before any GPU work.
    a.sim.simulated_count(1)?;
    row_params(&a.sim, VolumeMode::Flip, 32).validate().map_err(crate::args::flag_error)?;
    // The frames' rows take the flags as they are (`--grid` included).
    flag_params(&a.sim).validate().map_err(crate::args::flag_error)?;
    if a.large == 0 {
        return Err("--large must be at least 1 (key hairs of the large generated groom)".into());
    }
    if a.scaling_samples == 0 {
        return Err("--scaling-samples must be at least 1 (each point of a curve is a median of 5 by default)".into());
    }
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let info = ctx.info();
    if a.require_gpu && info.device_type == vkhair::ash::vk::PhysicalDeviceType::CPU {
        return Err(format!(
            "--require-gpu: the device chosen is {}, a CPU implementation; no GPU was found (see `vkhair devices`; VKHAIR_DEVICE picks one)",
            info.name
        )
        .into());
    }
    // After the device is known: the check makes the --out folder, which a
    // refused run must not leave behind.
    let mut outputs = vec![Output { flag: "--out", path: &a.out, kind: Kind::Folder }];
    outputs.extend(a.json.as_deref().map(|path| Output { flag: "--json", path, kind: Kind::File(&["json"]) }));
    let _made = destinations::check(&[], &outputs)?;
    say!("{} ({}): {} samples per figure, GPU and CPU reference interleaved", info.name, info.driver, a.samples);
    let clock = Clocking::new(&ctx)?;
    say!("{}", clock.describe());
    let b = Bench { ctx: &ctx, args: a, clock };
    let base = b.params(VolumeMode::Off, 32);
    say!("{} (each row sets its own volume stage)", a.sim.describe(&base, info.device_type));
    let (scenes, skipped) = bench_scenes(a)?;
    let mut rows = Vec::new();
    let mut modes = Vec::new();
    let mut truth = None;
    for s in &scenes {
        say!(
            "{}: {} key hairs × {} points",
            s.name,
            s.groom.strand_count(),
            s.groom.point_count() / s.groom.strand_count().max(1)
        );
        let simulated = a.sim.simulated_count(s.groom.strand_count())?;
        let case = |mode: VolumeMode| SimCase {
            groom: &s.groom,
            colliders: &s.colliders,
            params: b.params(mode, 32),
            cpu: true,
            motion: a.sim.motion,
            simulated,
        };
        let off = measure_sim(&ctx, &case(VolumeMode::Off), a.samples, b.budget())?;
        rows.extend(sim_rows(&s.name, "sim, volume off", &off, clock, None));
        let f = measure_sim(&ctx, &case(VolumeMode::Friction), a.samples, b.budget())?;
        rows.extend(sim_rows(&s.name, "sim, density friction 32³", &f, clock, Some(&off)));
        let f = measure_sim(&ctx, &case(VolumeMode::Flip), a.samples, b.budget())?;
        rows.extend(sim_rows(&s.name, "sim, FLIP 32³", &f, clock, Some(&off)));
        if s.name.starts_with("Sintel") {
            rows.extend(peer::rows(&b, &s.name, &s.groom)?);
        }
        if let Some(args) = &s.render_args {
            render_rows(&b, &s.name, args, &mut rows, &mut modes)?;
            if s.name.starts_with("Sintel") {
                if a.quick {
                    say!(
                        "{}: no ground-truth comparison in a --quick run (a full head of strands takes seconds)",
                        s.name
                    );
                } else {
                    let t = truth::against_full_head(&b, args)?;
                    say!(
                        "{}: the default frame ({} strands) against a full head ({} strands, one hair each): mean {:.1}, \
                         p95 {:.1} 8-bit sRGB steps over {} hair pixels",
                        s.name,
                        t.default_strands,
                        t.truth_strands,
                        t.error.mean,
                        t.error.p95,
                        t.error.pixels
                    );
                    truth = Some(t);
                }
            }
        }
    }
    print_rows(&rows);
    say!("err: a frame drawn once more unlit against render::reference::composite_strands, mean absolute error over hair pixels in 8-bit sRGB steps");
    if !modes.is_empty() {
        let csv = write_modes(&a.out, &modes)?;
        chart(&csv);
    }
    let curves = scaling::scaling(&b)?;
    for c in &curves {
        let (g, cpu) = c.exponents();
        say!("scaling, {}: time ∝ {}^{g:.2} on the GPU, ^{cpu:.2} on the CPU reference", c.axis, c.unit);
    }
    let csv = scaling::write_scaling(&a.out, &curves)?;
    chart(&csv);
    if let Some(path) = &a.json {
        let find = |stage: &str| rows.iter().find(|r| r.scene == scenes[0].name && r.stage == stage);
        let (off, flip) = (find("sim, volume off"), find("sim, FLIP 32³: volume stage alone"));
        let sintel_row = |stage: &str| rows.iter().find(|r| r.scene.starts_with("Sintel") && r.stage == stage);
        let median = |r: Option<&Row>, cpu: bool| {
            finite(r.map_or(f64::NAN, |r| {
                if cpu {
                    r.cpu.as_ref().map_or(f64::NAN, Samples::median)
                } else {
                    r.gpu.median()
                }
            }))
        };
        // The render frame in the off and the default exact mode: the thesis
        // (the first scene) at 800×600 and Sintel at 1280×720, where measured.
        let thesis = scenes.first().map(|s| s.name.as_str());
        let sintel = scenes.iter().find(|s| s.name.starts_with("Sintel")).map(|s| s.name.as_str());
        let frame = |scene: Option<&str>, mode: &str| finite(frame_ms(&modes, scene, mode));
        let summary = json!({
            "command": "bench",
            "device": info.name,
            "driver": info.driver,
            "samples": a.samples,
            "gpu_figures": clock.describe(),
            "scene": scenes[0].name,
            "iterations": base.iterations,
            "substeps": base.substeps,
            "solver": format!("{:?}", base.solver),
            "gpu_ms_per_step": median(off, false),
            "cpu_ms_per_step": median(off, true),
            "dispatches_per_step": off.map(|r| r.work.dispatches),
            "barriers_per_step": off.map(|r| r.work.barriers),
            "flip_dispatches_per_step": flip.map(|r| r.work.dispatches),
            "sintel_step_ms_4it": median(sintel_row(peer::STYLED_4), false),
            "sintel_step_ms_20it": median(sintel_row(peer::STYLED_20), false),
            "peer_work_step_ms_4it": median(sintel_row(peer::PEER_WORK_4), false),
            "volume_gpu_ms_per_step": median(flip, false),
            "volume_cpu_ms_per_step": median(flip, true),
            "frame_ms_off": frame(thesis, OFF),
            "frame_ms_exact": frame(thesis, &default_exact()),
            "sintel_frame_ms_off": frame(sintel, OFF),
            "sintel_frame_ms_exact": frame(sintel, &default_exact()),
            "sintel_truth": truth.as_ref().map(|t| json!({
                "mean_error": finite(t.error.mean),
                "p95_error": finite(t.error.p95),
                "hair_pixels": t.error.pixels,
                "default_strands": t.default_strands,
                "truth_strands": t.truth_strands,
            })),
            "bandwidth_bytes_per_s": PEAK_BANDWIDTH.iter().map(|(n, b)| json!({"device": n, "bytes_per_s": b})).collect::<Vec<_>>(),
            "stages": rows.iter().map(Row::json).collect::<Vec<_>>(),
            "scaling": curves.iter().map(|c| {
                let (g, cpu) = c.exponents();
                json!({
                    "axis": c.axis,
                    "unit": c.unit,
                    "gpu_exponent": finite(g),
                    "cpu_exponent": finite(cpu),
                    "points": c.points.iter().map(|p| json!({"work": p.0, "gpu_ms": finite(p.1), "cpu_ms": finite(p.2)})).collect::<Vec<_>>(),
                })
            }).collect::<Vec<_>>(),
            "skipped": skipped,
        });
        let text = serde_json::to_string_pretty(&summary).map_err(|e| format!("cannot encode the report: {e}"))?;
        vkhair::files::write_atomic(path, text.as_bytes())?;
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// The chart of a table the bench wrote, beside it: a chart that cannot be
/// drawn (no font on the machine) is a warning, since the table and the
/// report hold the figures.
fn chart(csv: &std::path::Path) {
    if let Err(e) = plot_file(csv, &csv.with_extension("png")) {
        say_err!("vkhair: warning: no chart of {}: {e}", csv.display());
    }
}
