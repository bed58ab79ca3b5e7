//! `vkhair simulate`: run the simulation headless, report per-stage GPU time,
//! tip drift and (with --obj) how many points ended inside the mesh collider.

use std::path::{Path, PathBuf};

use glam::Vec3;
use vkhair::config::Config;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::scenes;
use vkhair::groom::sdf::MeshSdf;
use vkhair::sim::{motion, HairSim, MeshCollider, RigidTransform, SimParams, VolumeMode, VolumeParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

use crate::args::input::InputArgs;
use crate::args::sim::SimArgs;
use crate::destinations::{self, Kind, Output};
use crate::output::{progress, CliResult};
use crate::profile::{host_now_ns, percentile, Profile, ProfileArgs};
use crate::say;

mod character;
mod check;
mod dispatches;
mod drawn;

use check::{share_inside, tip_drift, write_final, Reference, StepCheck};

#[derive(clap::Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Simulation steps (1/60 s each, 1..=10,000,000).
    #[arg(long, default_value_t = 120)]
    steps: usize,
    /// Parameter file (TOML, see `vkhair config`); the flags below win over it.
    #[arg(long)]
    config: Option<PathBuf>,
    #[command(flatten)]
    sim: SimArgs,
    /// Also run the CPU reference: every 10 steps it takes one step from the GPU's
    /// state and must land within a stated tolerance of the GPU's step; without
    /// FLIP the whole run is compared too. Exits non-zero beyond the tolerance.
    #[arg(long)]
    check: bool,
    /// Write the simulated strands after the last step as a .hair file: in the
    /// input's frame (the head's motion undone) and units (--scale undone), one
    /// strand per input strand with --points points each.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write the strands as the renderer draws them after the last step as a
    /// .hair file (world, meters, full detail): a dense groom's followers
    /// evaluated from their guides, in the input's strand order, at their
    /// follower points (before the tessellation smooths them); else the hairs
    /// grown from the key hairs.
    #[arg(long)]
    drawn_out: Option<PathBuf>,
    /// Print the compute dispatches of the last steps (up to 10), per kernel
    /// and step: how many, the workgroups they launch (the most, for those
    /// whose count the GPU reads from a buffer), invocations per workgroup
    /// and the most loop trips of one invocation — the counts that predict
    /// their cost on a GPU.
    #[arg(long)]
    dispatches: bool,
    #[command(flatten)]
    profile_out: ProfileArgs,
}

/// The simulation parameters: the tool's defaults (FLIP at 32³; an `--input`
/// groom held in its authored style, [`SimParams::styled`]), then the `--config`
/// file, then the flags given. Checked before any GPU work.
fn simulate_params(a: &SimulateArgs) -> Result<Config, vkhair::Error> {
    let sim = if a.input.input.is_some() { SimParams::styled() } else { SimParams::default() };
    let base = Config { sim: SimParams { volume: VolumeParams::flip([32, 32, 32]), ..sim }, ..Config::default() };
    let mut config = match &a.config {
        Some(path) => base.load_over(path)?,
        None => base,
    };
    a.sim.apply(&mut config.sim);
    config.validate().map_err(crate::args::flag_error)?;
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

/// Says what runs: the groom's `label`, its size, the device, the steps and
/// the parameters (with the file they came from).
fn announce(a: &SimulateArgs, label: &str, ctx: &GpuContext, sim: &HairSim, params: &SimParams) {
    let (strands, points) = sim.size();
    say!(
        "{label}: {strands} key hairs × {points} points on {}, {} steps of {:.4} s",
        ctx.info().name,
        a.steps,
        params.dt
    );
    say!(
        "{}{}",
        a.sim.describe(params, ctx.info().device_type),
        a.config.as_ref().map(|c| format!(" (from {} and the flags)", c.display())).unwrap_or_default()
    );
}

/// The `run` object of the `--json` summary.
fn run_summary(
    a: &SimulateArgs,
    ctx: &GpuContext,
    label: &str,
    sim: &HairSim,
    params: &SimParams,
) -> serde_json::Value {
    let (strands, points) = sim.size();
    serde_json::json!({
        "command": "simulate",
        "device": ctx.info().name,
        "groom": label,
        "key_hairs": strands,
        "points_per_key_hair": points,
        "steps": a.steps,
        "dt_s": params.dt,
        "iterations": params.iterations,
        "volume": format!("{:?}", params.volume.mode),
    })
}

/// Simulates only `count` of the `strands` key hairs (`--simulated`), if given.
fn apply_simulated(sim: &mut HairSim, count: Option<usize>, strands: usize) -> CliResult {
    if let Some(count) = count {
        sim.set_simulated_hairs(count)?;
        say!("simulated: {count} of {strands} key hairs (the others follow them)");
    }
    Ok(())
}

/// The most steps `--steps` takes: a soak run's length, not the edge of
/// `usize` (2⁶⁴ − 1 was taken and ran until killed).
const MAX_STEPS: usize = 10_000_000;

/// The profile's track: `simulate` records on the graphics queue.
const TRACK: &str = "graphics queue";

/// Options that mean something only with others, and values out of range: an
/// error saying what the option needs, before any file is read or GPU work done.
fn check_options(a: &SimulateArgs) -> Result<(), String> {
    if a.steps == 0 {
        return Err("--steps must be at least 1".into());
    }
    if a.steps > MAX_STEPS {
        return Err(format!("--steps must be at most {MAX_STEPS} (46 hours of simulated time; got {})", a.steps));
    }
    a.input.check()?;
    if a.input.gltf.is_some() && a.check {
        return Err("--check compares the thesis scene or an --input groom with the CPU reference, not --gltf".into());
    }
    Ok(())
}

pub fn simulate(a: &SimulateArgs) -> CliResult {
    check_options(a)?;
    let mut inputs = a.input.files();
    inputs.extend(a.config.as_deref());
    let mut outputs: Vec<Output> =
        a.out.as_deref().map(|path| Output { flag: "--out", path, kind: Kind::File(&["hair"]) }).into_iter().collect();
    outputs.extend(a.drawn_out.as_deref().map(|path| Output {
        flag: "--drawn-out",
        path,
        kind: Kind::File(&["hair"]),
    }));
    outputs.extend(a.profile_out.outputs());
    let _made = destinations::check(&inputs, &outputs)?;
    if let Some(ch) = crate::scene::load_character(&a.input)? {
        return character::simulate_character(a, ch);
    }
    let scale = a.input.scale();
    let mut dense = None;
    let (groom, colliders, label, pivot) = match &a.input.input {
        None => (scenes::thesis()?, motion::thesis_colliders(), "thesis scene".to_owned(), motion::NECK_PIVOT),
        Some(path) => {
            let (scaled, followers) = a.input.groom_and_guides(path)?;
            let groom = scaled.groom;
            // Turn about the centre of the roots' lowest level: roughly the neck.
            let (lo, hi) = followers.as_ref().map_or(&groom, |d| &d.groom).bounds();
            let pivot = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
            if let Some(d) = &followers {
                say!(
                    "guides: {} of {} strands ({}); every strand drawn follows them",
                    d.guides.len(),
                    d.groom.strand_count(),
                    d.chosen_by
                );
            }
            dense = followers;
            (groom, Vec::new(), path.display().to_string(), pivot)
        }
    };
    let config = simulate_params(a)?;
    let params = config.sim.clone();
    let simulated = a.sim.simulated_count(groom.strand_count())?;
    let mesh = load_mesh(a.input.obj.as_deref(), scale)?;
    let colliding = a.input.colliding();
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let (lo, hi) = groom.bounds();
    let size = (hi - lo).max_element();
    let head = |i: usize| a.sim.motion.head((i + 1) as f32 * params.dt, pivot, size);
    let mut sim = HairSim::new(&ctx, &groom, &params, &RigidTransform::default())?;
    sim.set_colliders(&colliders)?;
    apply_simulated(&mut sim, simulated, groom.strand_count())?;
    let field = match &mesh {
        Some(m) => {
            let collider = MeshCollider::new(&ctx, m, &config.mesh_collider)?;
            let [nx, ny, nz] = collider.dims();
            say!(
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
    announce(a, &label, &ctx, &sim, &params);
    say!(
        "style: global shape {:.2} over {:.2} of the strand, local shape {:.2}, rest-shape spring {}, sag-free {}",
        params.global_shape_stiffness,
        params.global_shape_range,
        params.local_shape_stiffness,
        if params.spring_enabled { "on" } else { "off" },
        if params.sag_free { "on" } else { "off" }
    );
    let reference = Reference {
        simulated,
        params: &params,
        colliders: &colliders,
        mesh: match (&mesh, colliding) {
            (Some(m), true) => Some(MeshSdf::build(m, config.mesh_collider.resolution, config.mesh_collider.margin)?),
            _ => None,
        },
    };
    let mut steps_checked = StepCheck::default();
    let bar = progress(a.steps, "steps");
    let mut profile = Profile::new("step");
    // Every 10 steps: the share of points inside the mesh collider, and with
    // --check one step of the CPU reference from the GPU's state.
    let chunk = 10;
    let (mut done, mut worst_inside) = (0, 0.0f64);
    let mut logged_steps = 0;
    while done < a.steps {
        let n = chunk.min(a.steps - done);
        let start = done;
        if a.dispatches && done + n >= a.steps {
            ctx.start_dispatch_log();
            logged_steps = n;
        }
        if a.check {
            // One step of the GPU against the same step of the reference.
            let state = sim.read_state()?;
            let started = host_now_ns();
            if let Some(report) = sim.run(1, |_| head(start), Some(&mut profiler))? {
                profile.add(&report, TRACK, 1);
            }
            profile.add_cpu_span(&format!("step {start}: record, submit, wait"), started, host_now_ns());
            let previous = if start == 0 { RigidTransform::default() } else { head(start - 1) };
            let cpu = reference.step(state, &previous, &head(start))?;
            steps_checked.add(sim.read_state()?.step_difference(&cpu, params.dt));
        }
        let first = start + usize::from(a.check);
        if first < start + n {
            let started = host_now_ns();
            if let Some(report) = sim.run(start + n - first, |i| head(first + i), Some(&mut profiler))? {
                profile.add(&report, TRACK, start + n - first);
            }
            profile.add_cpu_span(
                &format!("steps {first}..{}: record, submit, wait", start + n),
                started,
                host_now_ns(),
            );
        }
        done += n;
        if let Some(field) = &field {
            worst_inside = worst_inside.max(share_inside(&sim.read_state()?, field, &head(done - 1)));
        }
        bar.inc(n as u64);
    }
    bar.finish_and_clear();
    profile.print_table();
    if a.dispatches {
        dispatches::print(&ctx.take_dispatch_log(), logged_steps);
    }
    let state = sim.read_state()?;
    say!("kinetic energy {:.4} J/kg per particle", state.kinetic_energy() / state.positions.len() as f64);
    let last_head = head(a.steps - 1);
    let drift = tip_drift(&state, &last_head);
    if let (Some(p50), Some(p95)) = (percentile(&drift, 50), percentile(&drift, 95)) {
        say!("tip drift from rest: p50 {:.2} % p95 {:.2} % of strand length", 100.0 * p50, 100.0 * p95);
    }
    if let Some(field) = &field {
        say!(
            "points inside the mesh collider: {:.3} % after the last step, at most {:.3} % (checked every {chunk} steps)",
            100.0 * share_inside(&state, field, &last_head),
            100.0 * worst_inside
        );
    }
    if let Some(out) = &a.out {
        write_final(out, &state, &last_head, scale)?;
        say!("wrote {}: {strands} strands × {points} points", out.display());
    }
    if let Some(out) = &a.drawn_out {
        drawn::write_drawn(out, &ctx, &sim, &groom, dense.as_ref(), &config)?;
    }
    if let (Some(grid), Some(stats)) = (sim.volume_grid(), sim.volume_stats()?) {
        let solve = match params.volume.mode {
            VolumeMode::Flip => format!(
                "; last pressure solve: {} iterations, residual {:.1e}{}",
                stats.iterations,
                stats.relative_residual,
                if stats.converged { "" } else { " (not converged)" }
            ),
            _ => " (density friction: no pressure solve)".to_owned(),
        };
        say!(
            "volume grid {}×{}×{} cells of {:.1} mm{solve}",
            grid.dims[0],
            grid.dims[1],
            grid.dims[2],
            grid.cell_size * 1e3,
        );
    }
    a.profile_out.write(&profile, || run_summary(a, &ctx, &label, &sim, &params))?;
    if a.check {
        let whole_run = if params.volume.mode == VolumeMode::Flip {
            None
        } else {
            let mut cpu = reference.start(&groom)?;
            for i in 0..a.steps {
                cpu.step(&head(i))?;
            }
            Some(state.step_difference(cpu.state(), params.dt))
        };
        steps_checked.verdict(whole_run, &ctx.info().name)?;
    }
    Ok(())
}
