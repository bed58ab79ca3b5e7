//! Motion vectors for a host's TAA or upscaler: each hair pixel's motion since
//! the previous frame, against the CPU reference (`reference::hair_motion`),
//! for a head moving rigidly, a camera moving, and simulated hair; the jitter
//! excluded; in every transparent mode and rasteriser.

use ash::vk;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::reference::{hair_motion, hair_motions_at, MotionPick, MotionScene};
use vkhair::render::{
    Camera, HairMaterial, LodParams, MotionDirection, MotionParams, MotionUnits, Raster, RenderParams, Renderer,
    Transparency,
};
use vkhair::sim::{HairSim, RigidTransform, SimParams};

use crate::common::{self, Gpu, HostFrame};

const W: u32 = 96;
const H: u32 = 72;
/// What the host's velocity image holds where no hair is.
const CLEAR: Vec2 = Vec2::new(-1000.0, -1000.0);
/// How far a motion vector may be from the reference's, pixels (the goal).
const TOLERANCE: f32 = 0.05;

fn params(transparency: Transparency, raster: Raster, supersampling: bool) -> RenderParams {
    RenderParams {
        transparency,
        raster,
        supersampling,
        hairs_per_key: 2,
        lod: LodParams { full_detail_distance: 100.0, ..LodParams::default() },
        ..RenderParams::default()
    }
}

/// Wide opaque strands (a few pixels across at this size), one hair each.
fn material() -> HairMaterial {
    HairMaterial {
        root_width: 0.008,
        tip_width: 0.008,
        opacity: 1.0,
        represented_hairs: 1.0,
        ..HairMaterial::default()
    }
}

struct Scene {
    sim: HairSim,
    renderer: Renderer,
    offscreen: Offscreen,
}

fn scene(gpu: &Gpu, params: &RenderParams, gravity: bool) -> Scene {
    let groom = common::grown_groom(120, 6, 11);
    let sim_params = SimParams { gravity_enabled: gravity, ..SimParams::default() };
    let sim = HairSim::new(gpu.ctx(), &groom, &sim_params, &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::new(gpu.ctx(), &sim, params).expect("renderer");
    renderer.set_material(&material()).expect("material");
    let mut offscreen = Offscreen::new(gpu.ctx(), W, H).expect("offscreen");
    offscreen.add_velocity(vk::Format::R16G16_SFLOAT, CLEAR).expect("velocity image");
    Scene { sim, renderer, offscreen }
}

/// The hair's positions (w its width factor) and t along it, hair by hair.
fn drawn(renderer: &Renderer) -> (Vec<Vec<Vec4>>, Vec<Vec<f32>>) {
    let (positions, tangents) = renderer.read_hairs().expect("hairs");
    let per_hair = renderer.hair_counts().1 as usize;
    let hairs = positions.chunks_exact(per_hair).map(<[Vec4]>::to_vec).collect();
    let along = tangents.chunks_exact(per_hair).map(|t| t.iter().map(|v| v.w).collect()).collect();
    (hairs, along)
}

/// Draws a frame seen by `camera`; its velocity image, and the hairs drawn.
fn frame(gpu: &Gpu, s: &mut Scene, camera: &Camera) -> (Vec<Vec2>, Vec<Vec<Vec4>>, Vec<Vec<f32>>) {
    let host = HostFrame { clear: Vec3::ZERO, before: None, after: None };
    common::record_frame(gpu, (&s.sim, &mut s.renderer), &s.offscreen, camera, &host);
    let velocity = s.offscreen.read_velocity().expect("velocity");
    let (hairs, along) = drawn(&s.renderer);
    (velocity, hairs, along)
}

/// How the GPU's motion vectors compare with the reference's.
#[derive(Debug)]
struct Agreement {
    /// Pixels where both have a motion vector.
    both: usize,
    /// Of those, farther apart than the tolerance.
    off: usize,
    /// The largest difference and the mean, pixels.
    worst: f32,
    mean: f32,
    /// Pixels where only one of the two has a motion vector.
    one_only: usize,
    /// GPU motion vectors farther than the tolerance from every hair fragment's
    /// motion at their pixel.
    no_hair: usize,
    /// The mean length of the reference's motion vectors, pixels.
    mean_motion: f32,
}

fn agreement(gpu: &[Vec2], (reference, candidates): &Reference) -> Agreement {
    let mut a = Agreement { both: 0, off: 0, worst: 0.0, mean: 0.0, one_only: 0, no_hair: 0, mean_motion: 0.0 };
    for ((g, r), c) in gpu.iter().zip(reference).zip(candidates) {
        if *g != CLEAR && !c.iter().any(|c| c.distance(*g) <= TOLERANCE) {
            a.no_hair += 1;
        }
        match (*g != CLEAR, r) {
            (true, Some(r)) => {
                let d = g.distance(*r);
                a.both += 1;
                a.off += usize::from(d > TOLERANCE);
                a.worst = a.worst.max(d);
                a.mean += d;
                a.mean_motion += r.length();
            }
            (false, None) => {}
            _ => a.one_only += 1,
        }
    }
    a.mean /= a.both.max(1) as f32;
    a.mean_motion /= a.both.max(1) as f32;
    a
}

/// Per pixel the reference's motion vector, and every hair fragment's motion.
type Reference = (Vec<Option<Vec2>>, Vec<Vec<Vec2>>);

/// The reference of a frame drawn by `camera` after one drawn by `before_camera`.
fn reference(
    params: &RenderParams,
    (now, along): (&[Vec<Vec4>], &[Vec<f32>]),
    before: &[Vec<Vec4>],
    camera: &Camera,
    before_camera: &Camera,
) -> Reference {
    let m = material();
    let scene = MotionScene {
        now,
        before,
        along,
        drawn: camera.jittered_projection((W, H)) * camera.view,
        now_view_proj: camera.projection * camera.view,
        before_view_proj: before_camera.projection * before_camera.view,
        pixel: 2.0 * (0.5 * camera.fov_y).tan() / H as f32,
        extent: (W, H),
        samples: if params.supersampling { 2 } else { 1 },
        widths: (m.root_width, m.tip_width),
        opacity: m.opacity,
        pick: match params.transparency {
            Transparency::Off => MotionPick::NearestRibbon(m.least_pixel_width),
            Transparency::Fast => MotionPick::NearestAtLeast(0.5),
            _ => MotionPick::Accumulated(params.motion.threshold),
        },
    };
    (hair_motion(&scene), hair_motions_at(&scene))
}

/// Checks `a` for `params`: the compute rasterisers make the reference's
/// fragments, so their motion vectors are the reference's; the hardware
/// raster pipeline covers a pixel a little differently (its ribbons' edges and
/// depths), so where hairs of different motion cross, its composite may
/// pick another of the pixel's hairs — never a motion no hair there has.
fn check(what: &str, params: &RenderParams, a: &Agreement) {
    println!("{what}: {a:?}");
    assert!(a.both > 300, "{what}: only {} hair pixels with motion vectors", a.both);
    assert!(a.mean_motion > 0.5, "{what}: the hair hardly moved ({} px)", a.mean_motion);
    let share = |n: usize| n as f32 / a.both as f32;
    let walked = match params.transparency {
        Transparency::Exact => params.raster != Raster::Hardware,
        Transparency::Off => true,
        Transparency::Fast => false,
    };
    // Measured: walked 0–1 pixel in 5,000 off; the hardware's 2–6 % off, a
    // mean of 0.01–0.11 px. The opaque mode's write is tested against the
    // target's depth, where its draw wrote the nearest ribbon: a pixel whose
    // drawn ribbon the walk does not count as covering it (their edges
    // differ a little) keeps no motion rather than a hair's behind (1–2 %).
    let one_only = match params.transparency {
        Transparency::Off if !params.supersampling => 0.03,
        _ if walked => 0.02,
        _ => 0.04,
    };
    let (off, mean) = if walked { (0.01, 0.01) } else { (0.08, 0.15) };
    assert!(share(a.off) <= off && a.mean <= mean, "{what}: {} of {} pixels past {TOLERANCE} px", a.off, a.both);
    assert!(share(a.one_only) <= one_only, "{what}: {} pixels have a motion vector on one side only", a.one_only);
    assert!(share(a.no_hair) <= 0.005, "{what}: {} motion vectors are no hair's at their pixel", a.no_hair);
}

fn cases() -> Vec<RenderParams> {
    vec![
        params(Transparency::Exact, Raster::Compute, false),
        params(Transparency::Exact, Raster::Tiles, false),
        params(Transparency::Exact, Raster::Hardware, false),
        params(Transparency::Exact, Raster::Compute, true),
        params(Transparency::Fast, Raster::Hardware, false),
        params(Transparency::Off, Raster::Hardware, false),
        params(Transparency::Off, Raster::Hardware, true),
    ]
}

/// A head moving rigidly (turning and sliding) seen by a still camera: every
/// hair pixel moves as the reference's point of the moved hair.
#[test]
fn a_rigidly_moving_head_under_a_still_camera_has_the_references_motion() {
    let gpu = Gpu::new();
    let camera = common::front_camera(0.6, (W, H));
    let to = RigidTransform { rotation: Quat::from_rotation_y(0.06), translation: Vec3::new(0.012, -0.006, 0.01) };
    for params in cases() {
        let mut s = scene(&gpu, &params, false);
        frame(&gpu, &mut s, &camera);
        s.sim.teleport(&to).expect("teleport");
        s.sim.run(1, |_| to, None).expect("step");
        let (velocity, now, along) = frame(&gpu, &mut s, &camera);
        // Where the hair was: the head's move undone (the move is rigid: no gravity).
        let undo = to.matrix().inverse();
        let before: Vec<Vec<Vec4>> =
            now.iter().map(|h| h.iter().map(|p| undo.transform_point3(p.truncate()).extend(p.w)).collect()).collect();
        let r = reference(&params, (&now, &along), &before, &camera, &camera);
        let what = format!("rigid head, {:?} {:?} ss {}", params.transparency, params.raster, params.supersampling);
        check(&what, &params, &agreement(&velocity, &r));
    }
}

/// A still head seen by a camera moving sideways and turning: the motion is
/// the camera's alone.
#[test]
fn a_still_head_under_a_moving_camera_has_the_references_motion() {
    let gpu = Gpu::new();
    let before_camera = common::front_camera(0.6, (W, H));
    let eye = Mat4::from_translation(Vec3::new(-0.015, 0.008, 0.0)) * Mat4::from_rotation_y(0.02);
    let camera = Camera { view: before_camera.view * eye.inverse(), ..before_camera };
    for params in cases() {
        let mut s = scene(&gpu, &params, false);
        frame(&gpu, &mut s, &before_camera);
        let (velocity, now, along) = frame(&gpu, &mut s, &camera);
        let r = reference(&params, (&now, &along), &now, &camera, &before_camera);
        let what = format!("moving camera, {:?} {:?} ss {}", params.transparency, params.raster, params.supersampling);
        check(&what, &params, &agreement(&velocity, &r));
    }
}

/// Simulated hair swinging after the head moved: each pixel's hair moves from
/// where the previous frame drew the same point of the same hair.
#[test]
fn simulated_hair_has_the_references_motion() {
    let gpu = Gpu::new();
    let camera = common::front_camera(0.6, (W, H));
    let head = |i: usize| RigidTransform {
        rotation: Quat::IDENTITY,
        translation: Vec3::new(0.004 * i.min(6) as f32, 0.0, 0.0),
    };
    for params in
        [params(Transparency::Exact, Raster::Compute, false), params(Transparency::Exact, Raster::Hardware, false)]
    {
        let mut s = scene(&gpu, &params, true);
        s.sim.run(6, head, None).expect("steps");
        let (_, before, _) = frame(&gpu, &mut s, &camera);
        s.sim.run(3, |i| head(i + 6), None).expect("steps");
        let (velocity, now, along) = frame(&gpu, &mut s, &camera);
        let moved = now.iter().flatten().zip(before.iter().flatten()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
        assert!(moved > 0.002, "the hair moved at most {moved} m between the frames");
        let r = reference(&params, (&now, &along), &before, &camera, &camera);
        let what = format!("simulated hair, {:?} {:?}", params.transparency, params.raster);
        check(&what, &params, &agreement(&velocity, &r));
    }
}

/// A jittered frame's hair moves by the jitter; its motion vectors do not:
/// they are the unjittered pair's (within the tolerance on average) and the
/// reference's for the jittered pixels.
#[test]
fn motion_vectors_leave_out_the_jitter() {
    let gpu = Gpu::new();
    let before_camera = common::front_camera(0.6, (W, H));
    let camera =
        Camera { view: before_camera.view * Mat4::from_translation(Vec3::new(0.01, 0.0, 0.0)), ..before_camera };
    let params = params(Transparency::Exact, Raster::Compute, false);
    let mut s = scene(&gpu, &params, false);
    let mut mean_of = |first: &Camera, second: &Camera| {
        s.renderer.reset_motion();
        frame(&gpu, &mut s, first);
        let (velocity, now, along) = frame(&gpu, &mut s, second);
        let r = reference(&params, (&now, &along), &now, second, first);
        check(&format!("jitter {} then {}", first.jitter, second.jitter), &params, &agreement(&velocity, &r));
        let hair: Vec<Vec2> = velocity.into_iter().filter(|v| *v != CLEAR).collect();
        hair.iter().sum::<Vec2>() / hair.len() as f32
    };
    let still = mean_of(&before_camera, &camera);
    let jittered = mean_of(
        &before_camera.with_jitter(Vec2::new(0.4, -0.3)).expect("jitter"),
        &camera.with_jitter(Vec2::new(-0.35, 0.45)).expect("jitter"),
    );
    println!("mean motion: unjittered {still}, jittered {jittered}");
    // The jitters differ by (−0.75, 0.75) px: a vector that kept them would be that far off.
    assert!(still.distance(jittered) <= TOLERANCE, "the jitter moved the mean motion from {still} to {jittered}");
}

/// The host's conventions: NDC units, the other sign, a 32-bit float image —
/// the same motion; a reset frame's motion is zero; a frame drawn without a
/// velocity image leaves the history where it was; hairs numbered otherwise
/// move with the camera only; an image of another format is refused.
#[test]
fn motion_vectors_follow_the_hosts_conventions() {
    let gpu = Gpu::new();
    let camera = common::front_camera(0.6, (W, H));
    let moved = Camera { view: camera.view * Mat4::from_translation(Vec3::new(0.012, 0.004, 0.0)), ..camera };
    let pixels = params(Transparency::Exact, Raster::Compute, false);
    let ndc = RenderParams {
        motion: MotionParams {
            units: MotionUnits::Ndc,
            direction: MotionDirection::PreviousMinusCurrent,
            ..pixels.motion
        },
        ..pixels.clone()
    };
    let pair = |params: &RenderParams, format: vk::Format, reset: bool| {
        let mut s = scene(&gpu, params, false);
        s.offscreen.add_velocity(format, CLEAR).expect("velocity image");
        frame(&gpu, &mut s, &camera);
        if reset {
            s.renderer.reset_motion();
        }
        frame(&gpu, &mut s, &moved).0
    };
    let reference = pair(&pixels, vk::Format::R16G16_SFLOAT, false);
    let other = pair(&ndc, vk::Format::R32G32_SFLOAT, false);
    let to_pixels = Vec2::new(-0.5 * W as f32, -0.5 * H as f32);
    let (mut hair, mut worst) = (0, 0.0f32);
    for (a, b) in reference.iter().zip(&other) {
        assert_eq!(*a == CLEAR, *b == CLEAR, "the same pixels have motion vectors");
        if *a != CLEAR {
            hair += 1;
            worst = worst.max(a.distance(*b * to_pixels));
        }
    }
    println!("NDC, reversed, 32-bit: {hair} pixels, at most {worst} px from the pixels' vectors");
    // Half floats of up to 8 px hold 1/256 px (the motion is kept as half
    // floats whatever the image's format).
    assert!(hair > 300 && worst <= 0.01, "NDC and reversed: {worst} px off");
    let reset = pair(&pixels, vk::Format::R16G16_SFLOAT, true);
    let largest = reset.iter().filter(|v| **v != CLEAR).map(|v| v.length()).fold(0.0, f32::max);
    let covered = reset.iter().filter(|v| **v != CLEAR).count();
    println!("after a reset: {covered} pixels, the largest motion {largest} px");
    assert!(covered > 300 && largest == 0.0, "a frame after reset_motion moved {largest} px");

    // A frame without a velocity image between two with: the third moves from the first.
    let mut s = scene(&gpu, &pixels, false);
    let plain = Offscreen::new(gpu.ctx(), W, H).expect("offscreen");
    frame(&gpu, &mut s, &camera);
    let host = HostFrame { clear: Vec3::ZERO, before: None, after: None };
    let halfway = Camera { view: camera.view * Mat4::from_translation(Vec3::new(0.006, 0.002, 0.0)), ..camera };
    common::record_frame(&gpu, (&s.sim, &mut s.renderer), &plain, &halfway, &host);
    let skipped = frame(&gpu, &mut s, &moved).0;
    let worst =
        reference.iter().zip(&skipped).filter(|(a, _)| **a != CLEAR).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    println!("a frame without a velocity image between: at most {worst} px from the direct pair");
    assert!(worst <= 0.01, "the frame without a velocity image moved the history: {worst} px");
    // Grown hairs numbered otherwise (another hairs_per_key): the camera's motion only.
    let renumbered = RenderParams { hairs_per_key: 3, ..pixels.clone() };
    frame(&gpu, &mut s, &camera);
    s.renderer.set_params(&renumbered).expect("params");
    let still = frame(&gpu, &mut s, &camera).0;
    let largest = still.iter().filter(|v| **v != CLEAR).map(|v| v.length()).fold(0.0, f32::max);
    println!("renumbered hairs under a still camera: the largest motion {largest} px");
    assert!(largest == 0.0, "renumbered hairs moved {largest} px");
    let mut offscreen = Offscreen::new(gpu.ctx(), 8, 8).expect("offscreen");
    assert!(offscreen.add_velocity(vk::Format::R8G8_UNORM, Vec2::ZERO).is_err(), "an 8-bit velocity image");
    // A multisampled target with a velocity image (the opaque mode draws into
    // multisampled targets otherwise): refused before anything is recorded.
    let mut s = scene(&gpu, &params(Transparency::Off, Raster::Hardware, false), false);
    let mut multisampled = s.offscreen.target();
    multisampled.samples = vk::SampleCountFlags::TYPE_4;
    let mut refused = Ok(());
    gpu.ctx()
        .run_commands("a multisampled target with motion vectors", |cmd| {
            // SAFETY: a recording command buffer of the context's device; refused before recording.
            refused = unsafe {
                s.renderer
                    .record_prepare(cmd, &s.sim, Some(&camera), None)
                    .and_then(|_| s.renderer.record_draw(cmd, common::next_frame(), &multisampled, &camera, None))
            };
        })
        .expect("submit");
    let e = refused.expect_err("refused").to_string();
    assert!(e.contains("single-sample"), "{e}");
}

/// A host's mesh in front of the hair keeps its own motion: no pixel it covers
/// gets the hair's (the opaque mode's walk picks the nearest ribbon whatever
/// the host drew, and its write is tested against the host's depth; the
/// transparent modes pick only fragments their composite kept).
#[test]
fn a_mesh_in_front_of_the_hair_keeps_the_hosts_motion() {
    use vkhair::groom::mesh::TriMesh;
    use vkhair::headless::MeshDrawer;
    let gpu = Gpu::new();
    let before_camera = common::front_camera(0.6, (W, H));
    let camera =
        Camera { view: before_camera.view * Mat4::from_translation(Vec3::new(0.01, 0.0, 0.0)), ..before_camera };
    let centre = vkhair::groom::scenes::THESIS_HEAD_CENTER;
    let sphere = TriMesh::uv_sphere(centre + Vec3::new(0.0, -0.12, 0.3), 0.05, 12, 16).expect("sphere");
    let mesh = MeshDrawer::new(gpu.ctx(), &sphere).expect("mesh");
    for params in [
        params(Transparency::Off, Raster::Hardware, false),
        params(Transparency::Off, Raster::Hardware, true),
        params(Transparency::Exact, Raster::Compute, false),
        params(Transparency::Exact, Raster::Hardware, false),
    ] {
        let mut s = scene(&gpu, &params, false);
        let host = HostFrame { clear: Vec3::ZERO, before: Some(&mesh), after: None };
        common::record_frame(&gpu, (&s.sim, &mut s.renderer), &s.offscreen, &before_camera, &host);
        common::record_frame(&gpu, (&s.sim, &mut s.renderer), &s.offscreen, &camera, &host);
        let velocity = s.offscreen.read_velocity().expect("velocity");
        let colour = s.offscreen.read_linear().expect("colour");
        let (now, along) = drawn(&s.renderer);
        let (hair, _) = reference(&params, (&now, &along), &now, &camera, &before_camera);
        // The sphere's pixels: green (the host's meshes are lit green) where the hair would be.
        let covered: Vec<usize> = (0..velocity.len())
            .filter(|&i| colour[i].y > 2.0 * colour[i].x.max(colour[i].z) && hair[i].is_some())
            .collect();
        let hair_motion = covered.iter().filter(|&&i| velocity[i] != CLEAR).count();
        let elsewhere = velocity.iter().filter(|v| **v != CLEAR).count();
        let what = format!("{:?} {:?} ss {}", params.transparency, params.raster, params.supersampling);
        println!(
            "{what}: {} sphere pixels over hair, {hair_motion} with the hair's motion; {elsewhere} hair pixels",
            covered.len()
        );
        assert!(covered.len() > 50 && elsewhere > 300, "{what}: the sphere covers {} hair pixels", covered.len());
        assert!(
            hair_motion * 100 <= covered.len(),
            "{what}: {hair_motion} of {} pixels of the sphere took the hair's motion",
            covered.len()
        );
    }
}
