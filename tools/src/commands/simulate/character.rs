//! `simulate --gltf`: key hairs grown on an animated character's head, their
//! roots bound to the character's mesh and riding it as the tool skins it
//! every step into a GPU buffer the simulation reads (`HairSim::bind_scalp_source`,
//! the way a host hands over its skinning pass's output), the body near the
//! head one mesh collider following the bones (`HairSim::set_skinned_mesh`),
//! the bones' capsules the body colliders every step, and two measures of how well the hair stays on and
//! out of the character: the roots' distance from the scalp points they were
//! grown on, skinned by the animation (`root_error_max_m`), and the share of
//! free points inside the skinned body near the head (`inside_fraction_max`),
//! both every 10 steps.

use glam::Vec3;
use vkhair::ash::vk;
use vkhair::groom::binding::TriangleGrid;
use vkhair::groom::mesh::TriMesh;
use vkhair::groom::sdf::MeshSdf;
use vkhair::headless::HostBuffer;
use vkhair::sim::scalp::Scalp;
use vkhair::sim::{HairSim, SimState};
use vkhair::{ContextOptions, GpuContext, GpuProfiler};

use super::check::{tip_drift, write_final};
use super::{announce, apply_simulated, run_summary, simulate_params, SimulateArgs, TRACK};
use crate::output::{progress, CliResult};
use crate::profile::{host_now_ns, percentile, Profile};
use crate::say;
use crate::scene::CharacterScene;

/// How far a grown root may lie from the scalp it was grown on, meters.
const ROOT_TOLERANCE: f32 = 1e-3;
/// The body counted for `inside_fraction_max`: triangles within this of the
/// head joint at each check, meters.
const NEAR_HEAD: f32 = 0.6;
/// Points this close to the body's surface are judged by its nearest triangle, meters.
const SURFACE: f32 = 0.03;
/// Grid points along the longest axis of the body's field at each check.
const BODY_FIELD_RESOLUTION: u32 = 64;

pub fn simulate_character(a: &SimulateArgs, ch: CharacterScene) -> CliResult {
    let config = simulate_params(a)?;
    let params = config.sim.clone();
    let (crate::args::input::Scaled { groom, .. }, _, _) = crate::scene::character_groom(&ch, &a.input)?;
    let time = |step: usize| step as f32 * params.dt;
    // Roots bound to the character's triangles in the bind pose (world).
    let bound = ch.bind_roots(&groom, ROOT_TOLERANCE)?;
    let ctx = GpuContext::headless(&ContextOptions::default())?;
    let mut sim = HairSim::new(&ctx, &groom, &params, &ch.head_at(0.0))?;
    // The roots ride the skinned mesh: the tool skins the character every step
    // and writes the vertices into a GPU buffer, as a host's skinning pass
    // would; the simulation reads them from there.
    let scalp = Scalp { skin: Vec::new(), ..ch.scalp()? };
    let vertices = ch.character.positions.len();
    let skinned_buffer = HostBuffer::new(&ctx, "vkhair tool skinned character", vertices as u64 * 16)?;
    let write_skinned = |time: f32| -> Result<Vec<Vec3>, vkhair::Error> {
        let skinned = ch.character.skin(&ch.pose(time));
        let packed: Vec<u8> =
            skinned.iter().flat_map(|v| v.extend(1.0).to_array()).flat_map(f32::to_ne_bytes).collect();
        skinned_buffer.write(0, &packed)?;
        Ok(skinned)
    };
    write_skinned(0.0)?;
    let source = skinned_buffer.scalp_source(16, vk::Format::R32G32B32A32_SFLOAT, vertices as u32);
    // SAFETY: the buffer is the context's, with storage usage, and outlives
    // `sim` (declared before it drops); each write completes before the step
    // reading it is submitted.
    unsafe { sim.bind_scalp_source(&scalp, &source)? };
    // The body near the head as one field that follows the character's bones.
    let (body, body_skin) = ch.body_region()?;
    sim.set_skinned_mesh(&body, &body_skin, &ch.scalp_bones(0.0), &config.mesh_collider)?;
    apply_simulated(&mut sim, a.sim.simulated_count(groom.strand_count())?, groom.strand_count())?;
    let mut profiler = GpuProfiler::new(&ctx, 1, 1024)?;
    let (strands, points) = sim.size();
    let label = a.input.gltf.as_ref().map_or_else(String::new, |p| p.display().to_string());
    announce(a, &label, &ctx, &sim, &params);
    let bar = progress(a.steps, "steps");
    let mut profile = Profile::new("step");
    let (mut root_error, mut inside) = (0.0f32, 0.0f64);
    for step in 0..a.steps {
        sim.set_body_colliders(&ch.colliders_at(time(step + 1)))?;
        sim.set_mesh_bones(&ch.scalp_bones(time(step + 1)))?;
        let skinned = write_skinned(time(step + 1))?;
        let started = host_now_ns();
        if let Some(report) = sim.run(1, |_| ch.head_at(time(step + 1)), Some(&mut profiler))? {
            profile.add(&report, TRACK, 1);
        }
        profile.add_cpu_span(&format!("step {step}: record, submit, wait"), started, host_now_ns());
        if (step + 1) % 10 == 0 || step + 1 == a.steps {
            let state = sim.read_state()?;
            let pose = ch.pose(time(step + 1));
            root_error = root_error.max(ch.root_error(&state, &bound, &skinned));
            let head = ch.character.joint_transform(&pose, ch.head).transform_point3(Vec3::ZERO);
            inside = inside.max(share_inside_body(&state, &ch.character.triangles, &skinned, head)?);
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    profile.print_table();
    let state = sim.read_state()?;
    let last_head = ch.head_at(time(a.steps));
    let drift = tip_drift(&state, &last_head);
    if let (Some(p50), Some(p95)) = (percentile(&drift, 50), percentile(&drift, 95)) {
        say!(
            "tip drift from rest (in the head's frame): p50 {:.2} % p95 {:.2} % of strand length",
            100.0 * p50,
            100.0 * p95
        );
    }
    say!("roots from their skinned scalp points: at most {root_error:.2e} m (checked every 10 steps)");
    say!(
        "points inside the body within {NEAR_HEAD} m of the head: at most {:.3} % (checked every 10 steps)",
        100.0 * inside
    );
    if let Some(out) = &a.out {
        write_final(out, &state, &last_head, 1.0)?;
        say!("wrote {}: {strands} strands × {points} points", out.display());
    }
    a.profile_out.write(&profile, || {
        let mut run = run_summary(a, &ctx, &label, &sim, &params);
        run["root_error_max_m"] = root_error.into();
        run["inside_fraction_max"] = inside.into();
        run
    })?;

    Ok(())
}

/// The share of free points inside the skinned body's triangles near `head`:
/// within `SURFACE` of the surface by the side of the nearest triangle (its
/// outward normal), deeper by the sign of the body's distance field (the sign
/// by the field's ray-parity vote, so the body cut at `NEAR_HEAD` still has an
/// inside; its cells are too coarse to judge points near the skin).
fn share_inside_body(
    state: &SimState,
    triangles: &[[u32; 3]],
    skinned: &[Vec3],
    head: Vec3,
) -> Result<f64, vkhair::Error> {
    let near: Vec<[u32; 3]> = triangles
        .iter()
        .copied()
        .filter(|t| t.iter().any(|&v| skinned[v as usize].distance(head) < NEAR_HEAD))
        .collect();
    let body = TriMesh::new(skinned.to_vec(), near)?;
    let field = MeshSdf::build(&body, BODY_FIELD_RESOLUTION, 0.05)?;
    let grid = TriangleGrid::new(&body, SURFACE)?;
    let free: Vec<Vec3> = state.positions.iter().filter(|p| p.w > 0.0).map(|p| p.truncate()).collect();
    let is_inside = |p: Vec3| match grid.nearest(p) {
        Some(n) => (p - n.point).dot(body.scaled_normal(n.binding.triangle as usize)) < 0.0,
        None => field.sample(p) < 0.0,
    };
    let inside = free.iter().filter(|p| is_inside(**p)).count();
    Ok(inside as f64 / free.len().max(1) as f64)
}
