//! A crowd against one groom of the same hair: 16 thesis heads in a 4 × 4
//! grid (each its own member of a [`Crowd`], swaying on its own, with the
//! thesis colliders) against one [`HairSim`] of the same key hairs placed
//! where the members stand (their colliders as body colliders), both drawn by
//! one renderer at 1920 × 1080 with a shadow-casting light, in the same run:
//! GPU time per frame (the step, smoothing, interpolation, shadows and draw,
//! from timestamp queries), their ratio, and the dispatches a step records
//! for crowds of 1, 4 and 16 members. Written to
//! `target/vkhair-bench/crowd.csv`.
//!
//! `cargo bench --features bench --bench crowd` (add `-- quick` for 960 × 540).

use glam::Vec3;
use vkhair::crowd::{Crowd, Member, MemberPose};
use vkhair::groom::scenes;
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::{Camera, Light, LodParams, RenderParams, Renderer, ShadowParams};
use vkhair::sim::{motion, Collider, HairSim, KeyHairs, RigidTransform, SimParams};
use vkhair::{ContextOptions, GpuContext, GpuProfiler, Groom};

/// Frames measured after one warm-up frame.
const FRAMES: u32 = 3;
const SIDE: usize = 4;
const SPACING: f32 = 0.6;

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let (w, h) = if quick { (960, 540) } else { (1920, 1080) };
    let ctx = GpuContext::headless(&ContextOptions::default()).expect("context");
    let thesis = scenes::thesis().expect("thesis");
    let members = SIDE * SIDE;
    println!("{} — {members} thesis heads ({} key hairs each) at {w}×{h}", ctx.info().name, thesis.strand_count());
    for count in [1, 4, 16] {
        println!("  a step of {count:>2} members records {} dispatches", step_dispatches(&ctx, &thesis, count));
    }
    let crowd_members: Vec<Member> = (0..members)
        .map(|_| Member { colliders: motion::thesis_colliders(), ..Member::rigid(thesis.clone()) })
        .collect();
    let mut crowd = Crowd::new(&ctx, &crowd_members, &poses(0), &SimParams::default()).expect("crowd");
    // The same key hairs in one groom, the colliders in the world.
    let placed: Vec<Groom> = poses(0).iter().map(|p| thesis.rigidly_moved(&p.head.matrix()).expect("placed")).collect();
    let positions: Vec<Vec3> = placed.iter().flat_map(|g| g.positions().iter().copied()).collect();
    let counts = vec![thesis.strand(0).len() as u32; thesis.strand_count() * members];
    let merged = Groom::new(positions, &counts).expect("merged");
    let identity = RigidTransform::default();
    let mut one = HairSim::new(&ctx, &merged, &SimParams::default(), &identity).expect("one groom");
    let colliders: Vec<Collider> = poses(0).iter().flat_map(|p| world_colliders(&p.head)).collect();
    one.set_body_colliders(&colliders).expect("colliders");

    let camera =
        Camera::look_at(Vec3::new(0.0, 1.9, 3.2), Vec3::new(0.0, 1.45, 0.0), 0.75, w as f32 / h as f32, 0.05, 20.0)
            .expect("camera");
    let target = Offscreen::new(&ctx, w, h).expect("target");
    let mut profiler = GpuProfiler::new(&ctx, 1, 32).expect("profiler");
    let mut frame = 0u64;
    let bounds = crowd.bounds();
    let mut crowd_renderer = renderer(&ctx, crowd.key_hairs());
    fn bounded(sim: &HairSim, (centre, radius): (Vec3, f32)) -> KeyHairs<'_> {
        sim.key_hairs().with_bounds(centre, radius).expect("bounds")
    }
    let mut one_renderer = renderer(&ctx, bounded(&one, bounds));
    let mut crowd_ms = 0.0;
    let mut one_ms = 0.0;
    for k in 0..=FRAMES {
        let f = frame;
        let c = measure(&ctx, &mut profiler, &mut frame, |cmd, p| {
            crowd.set_poses(&poses(k as usize + 1)).expect("poses");
            // SAFETY: a recording command buffer of the context's device; run_commands waits.
            unsafe { crowd.record_step(cmd, Some(p)).expect("crowd step") };
            record_frame(cmd, p, crowd.key_hairs(), &mut crowd_renderer, &target, &camera, f);
        });
        let f = frame;
        let o = measure(&ctx, &mut profiler, &mut frame, |cmd, p| {
            // SAFETY: as above.
            unsafe { one.record_step(cmd, &identity, Some(p)).expect("step") };
            record_frame(cmd, p, bounded(&one, bounds), &mut one_renderer, &target, &camera, f);
        });
        if k > 0 {
            crowd_ms += c / f64::from(FRAMES);
            one_ms += o / f64::from(FRAMES);
        }
    }
    let (hairs, per_hair) = crowd_renderer.hair_counts();
    println!("  drawn: {hairs} hairs of {per_hair} vertices");
    println!(
        "  GPU ms per frame: crowd of {members} {crowd_ms:.2}, one groom {one_ms:.2}; ratio {:.3}",
        crowd_ms / one_ms
    );
    let csv = format!(
        "width,height,members,hairs,crowd_ms,one_groom_ms,ratio\n{w},{h},{members},{hairs},{crowd_ms:.4},{one_ms:.4},{:.4}\n",
        crowd_ms / one_ms
    );
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/vkhair-bench");
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("crowd.csv"), csv).is_ok() {
        println!("written to {}", dir.join("crowd.csv").display());
    }
}

/// Member `m`'s head at step `step`: its place in the grid, swaying by the
/// reference motion, each member at its own phase.
fn head(m: usize, step: usize) -> RigidTransform {
    let (row, col) = ((m / SIDE) as f32, (m % SIDE) as f32);
    let sway = motion::reference_motion((step + 7 * m) as f32 / 60.0);
    let place = Vec3::new((col - 1.5) * SPACING, 0.0, -(row - 1.5) * SPACING);
    RigidTransform { rotation: sway.rotation, translation: sway.translation + place }
}

fn poses(step: usize) -> Vec<MemberPose> {
    (0..SIDE * SIDE).map(|m| MemberPose::rigid(head(m, step))).collect()
}

fn world_colliders(head: &RigidTransform) -> Vec<Collider> {
    motion::thesis_colliders().iter().map(|c| c.moved(&head.matrix())).collect()
}

/// Dispatches one step of a crowd of `count` thesis heads records.
fn step_dispatches(ctx: &GpuContext, thesis: &Groom, count: usize) -> u64 {
    let members = vec![Member::rigid(thesis.clone()); count];
    let poses = |s: usize| -> Vec<MemberPose> { (0..count).map(|m| MemberPose::rigid(head(m, s))).collect() };
    let mut crowd = Crowd::new(ctx, &members, &poses(0), &SimParams::default()).expect("crowd");
    crowd.run(1, poses).expect("warm-up");
    let before = ctx.recorded_work();
    crowd.run(1, |s| poses(s + 1)).expect("step");
    (ctx.recorded_work() - before).dispatches
}

fn renderer(ctx: &GpuContext, hairs: KeyHairs<'_>) -> Renderer {
    // Half the default hairs per key hair: 16 heads' interpolated hairs at
    // the default fill 150 MB, past lavapipe's 128 MiB storage range.
    // Without a level of detail: every head at that detail, however far.
    let params = RenderParams {
        hairs_per_key: RenderParams::default().hairs_per_key / 2,
        lod: LodParams { enabled: false, ..LodParams::default() },
        ..RenderParams::default()
    };
    let mut r = Renderer::new(ctx, hairs, &params).expect("renderer");
    r.set_lights(&[
        Light::Directional { direction: Vec3::new(0.4, -0.6, -1.0), color: Vec3::splat(0.9) },
        Light::Directional { direction: Vec3::new(-0.8, -0.2, -0.3), color: Vec3::splat(0.3) },
    ])
    .expect("lights");
    r.set_shadows(hairs, &ShadowParams { casters: vec![0.into()], resolution: 1024, ..Default::default() })
        .expect("shadows");
    r
}

/// GPU milliseconds of everything `record` times in one frame.
fn measure(
    ctx: &GpuContext,
    profiler: &mut GpuProfiler,
    frame: &mut u64,
    mut record: impl FnMut(vkhair::ash::vk::CommandBuffer, &mut GpuProfiler),
) -> f64 {
    ctx.run_commands("bench frame", |cmd| {
        // SAFETY: a recording command buffer of the context's device.
        let _ = unsafe { profiler.begin_frame(cmd, *frame) };
        record(cmd, profiler);
    })
    .expect("submit");
    *frame += 1;
    let report = profiler.drain().pop().expect("timestamps");
    report.total_nanoseconds() / 1e6
}

fn record_frame(
    cmd: vkhair::ash::vk::CommandBuffer,
    profiler: &mut GpuProfiler,
    hairs: KeyHairs<'_>,
    renderer: &mut Renderer,
    target: &Offscreen,
    camera: &Camera,
    frame: u64,
) {
    // SAFETY: a recording command buffer of the context's device; the step
    // before it is ordered by the renderer's barriers.
    unsafe {
        renderer.record_prepare(cmd, hairs, Some(camera), Some(&mut *profiler)).expect("prepare");
        renderer.record_shadows(cmd, hairs, Some(&mut *profiler)).expect("shadows");
        target.record_clear(cmd, Vec3::ZERO);
        renderer.record_draw(cmd, frame, &target.target(), camera, Some(profiler)).expect("draw");
    }
}
