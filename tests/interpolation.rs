//! Drawing between the last two simulation states (`KeyHairs::blended`) by the
//! fixed-step driver's alpha, under validation: both states bit for bit at 0
//! and 1, the CPU blend between, and no judder when frames outpace steps.

use glam::{Quat, Vec3, Vec4};
use vkhair::headless::Submit;
use vkhair::render::reference::{blend_key_points, smooth_strand};
use vkhair::render::{RenderParams, Renderer};
use vkhair::sim::{FixedStepDriver, HairSim, RigidTransform, SimParams};
use vkhair::Groom;

use crate::common;

use common::Gpu;

/// The head at step `k`: turning and moving sideways, so every step moves the hair.
fn head(k: usize) -> RigidTransform {
    let t = k as f32 / 60.0;
    RigidTransform { rotation: Quat::from_rotation_y(1.5 * t), translation: Vec3::new(0.3 * t, 0.0, 0.0) }
}

fn groom() -> Groom {
    common::grown_groom(40, 8, 7)
}

/// A simulation of `groom()` after `steps` steps of `head`.
fn sim_after(gpu: &Gpu, steps: usize) -> HairSim {
    let mut sim = HairSim::new(gpu.ctx(), &groom(), &SimParams::default(), &RigidTransform::default()).expect("sim");
    sim.run(steps, |k| head(k + 1), None).expect("steps");
    sim
}

fn renderer(gpu: &Gpu, sim: &HairSim) -> Renderer {
    Renderer::new(gpu.ctx(), sim, &RenderParams { smoothing_level: 3, ..RenderParams::default() }).expect("renderer")
}

/// The smoothed key hairs a renderer draws of `sim` at `alpha`.
fn smoothed(renderer: &mut Renderer, sim: &HairSim, alpha: f32) -> Vec<Vec4> {
    let hairs = sim.key_hairs().blended(alpha).expect("alpha");
    renderer.prepare_now(hairs, None).expect("prepare");
    renderer.read_smoothed().expect("smoothed").0
}

fn bits(v: &[Vec4]) -> Vec<u32> {
    v.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn alpha_zero_and_one_draw_the_two_states_and_between_them_the_cpu_blend() {
    let gpu = Gpu::new();
    let (sim, previous) = (sim_after(&gpu, 5), sim_after(&gpu, 4));
    let (mut r, mut r_previous) = (renderer(&gpu, &sim), renderer(&gpu, &previous));
    // 0: the state one step earlier, to the bit (the simulation is deterministic).
    assert_eq!(bits(&smoothed(&mut r, &sim, 0.0)), bits(&smoothed(&mut r_previous, &previous, 1.0)));
    // 1: the latest state, as drawn without blending.
    let latest = smoothed(&mut r, &sim, 1.0);
    r.prepare_now(&sim, None).expect("prepare");
    assert_eq!(bits(&latest), bits(&r.read_smoothed().expect("smoothed").0));
    // Between: the CPU blend of the two states read back, smoothed on the CPU.
    let (before, after) = (previous.read_state().expect("state"), sim.read_state().expect("state"));
    let points = groom().point_count() / groom().strand_count();
    let per_strand = r.smoothed_vertices_per_strand() as usize;
    let mut moved = 0.0f32;
    for alpha in [0.25, 0.6] {
        let gpu_smoothed = smoothed(&mut r, &sim, alpha);
        let blended = blend_key_points(&before.positions, &after.positions, alpha);
        let mut worst = 0.0f32;
        for (s, keys) in blended.chunks_exact(points).enumerate() {
            for (k, (p, _)) in smooth_strand(keys, 3).iter().enumerate() {
                worst = worst.max((gpu_smoothed[s * per_strand + k].truncate() - *p).length());
            }
        }
        println!("alpha {alpha}: largest difference from the CPU blend {worst:e} m");
        assert!(worst < 2e-6, "alpha {alpha}: {worst} m from the CPU blend");
        moved = moved.max(gpu_smoothed.iter().zip(&latest).map(|(a, b)| (*a - *b).length()).fold(0.0, f32::max));
    }
    assert!(moved > 1e-3, "the step moved the hair by only {moved} m: the blend is not tested");
    for bad in [-0.1, 1.5, f32::NAN] {
        assert!(sim.key_hairs().blended(bad).is_err(), "alpha {bad} accepted");
    }
}

/// Frames at 240 Hz over a 60 Hz simulation: each frame's drawn hairs move by at
/// most a quarter of the step's displacement (plus 2 %), vertex by vertex; drawn
/// unblended, the frame of a step jumps by the whole step.
#[test]
fn frames_at_four_times_the_step_rate_move_a_quarter_step_each() {
    let gpu = Gpu::new();
    let mut sim = HairSim::new(gpu.ctx(), &groom(), &SimParams::default(), &RigidTransform::default()).expect("sim");
    let mut r = renderer(&gpu, &sim);
    let mut driver = FixedStepDriver::new(1.0 / 60.0, 4).expect("driver");
    let mut step = 0;
    // Per frame: drawn at alpha, unblended, and the latest step's displacement per vertex.
    let mut frames: Vec<(Vec<Vec4>, Vec<Vec4>, Vec<f32>)> = Vec::new();
    for _ in 0..24 {
        let plan = driver.advance(1.0 / 240.0);
        sim.run(
            plan.steps as usize,
            |_| {
                step += 1;
                head(step)
            },
            None,
        )
        .expect("steps");
        let (before, latest) = (smoothed(&mut r, &sim, 0.0), smoothed(&mut r, &sim, 1.0));
        let displacement = before.iter().zip(&latest).map(|(a, b)| (*a - *b).length()).collect();
        frames.push((smoothed(&mut r, &sim, plan.alpha), latest, displacement));
    }
    assert!(step >= 5, "only {step} steps ran");
    let (mut worst_blended, mut worst_unblended) = (0.0f32, 0.0f32);
    for pair in frames.windows(2) {
        let ((drawn_a, latest_a, step_a), (drawn_b, latest_b, step_b)) = (&pair[0], &pair[1]);
        for v in 0..drawn_a.len() {
            let step_moved = step_a[v].max(step_b[v]);
            if step_moved < 1e-5 {
                continue;
            }
            worst_blended = worst_blended.max((drawn_b[v] - drawn_a[v]).length() / step_moved);
            worst_unblended = worst_unblended.max((latest_b[v] - latest_a[v]).length() / step_moved);
        }
    }
    println!("largest move per frame over the step's: blended {worst_blended:.3}, unblended {worst_unblended:.3}");
    assert!(worst_blended <= 0.25 * 1.02, "a frame moved {worst_blended} of a step: judder");
    assert!(
        worst_unblended > 0.9,
        "unblended frames should jump a whole step ({worst_unblended}): the test sees nothing"
    );
}

/// Through the frame scheduler, in SINGLE QUEUE and SECOND DEVICE (both
/// hand-offs) with each pipelining: alpha 0 and 1 of the shown state are the
/// simulation's states after `shown − 1` and `shown` steps, to the bit.
#[test]
fn the_scheduler_hands_off_both_states_in_every_mode() {
    use vkhair::schedule::{FrameScheduler, HandOff, Pipelining, ScheduleMode, SchedulerOptions};
    let render = Gpu::new();
    let sim_gpu = Gpu::new();
    let mut options = Vec::new();
    for pipelining in [Pipelining::Latency, Pipelining::Throughput] {
        options.push(SchedulerOptions { mode: Some(ScheduleMode::SingleQueue), pipelining, ..Default::default() });
        for hand_off in [HandOff::ExternalMemory, HandOff::HostStaging] {
            options.push(SchedulerOptions {
                mode: Some(ScheduleMode::SecondDevice),
                sim_device: Some(sim_gpu.ctx().clone()),
                hand_off: Some(hand_off),
                pipelining,
                ..Default::default()
            });
        }
    }
    let reference: Vec<(Vec<u32>, HairSim)> = (0..=4)
        .map(|n| {
            let sim = sim_after(&render, n);
            (bits(&smoothed(&mut renderer(&render, &sim), &sim, 1.0)), sim)
        })
        .collect();
    for o in options {
        let what = format!("{:?} {:?} {:?}", o.mode, o.hand_off, o.pipelining);
        let mut s =
            FrameScheduler::new(render.ctx(), &groom(), &SimParams::default(), &RigidTransform::default(), &[], &o)
                .expect("scheduler");
        for frame in 0..4 {
            let heads = [head(frame + 1)];
            // SAFETY: a recording command buffer of the rendering device, waited for.
            render.ctx().run_frame("frame", |cmd| unsafe { s.record_frame(cmd, &heads, None) }).expect("frame");
        }
        let shown = s.shown_steps() as usize;
        assert!(shown >= 3, "{what}: shows the state after {shown} steps");
        let mut r =
            Renderer::new(render.ctx(), s.key_hairs(), &RenderParams { smoothing_level: 3, ..Default::default() })
                .expect("renderer");
        for (alpha, steps) in [(0.0, shown - 1), (1.0, shown)] {
            r.prepare_now(s.key_hairs().blended(alpha).expect("alpha"), None).expect("prepare");
            let drawn = bits(&r.read_smoothed().expect("smoothed").0);
            assert!(drawn == reference[steps].0, "{what}: alpha {alpha} is not the state after {steps} steps");
        }
        println!("{what}: alpha 0 and 1 are the states after {} and {shown} steps", shown - 1);
    }
}
