//! A dense, curly groom drawn as followers of simulated guides
//! (`render::Followers`): at rest the drawn strands are the authored ones
//! (measured against the authored polylines, not against the code's own
//! resampling), in motion they follow their guides with roots on the scalp,
//! the GPU evaluation matches the CPU reference, and level of detail draws a
//! prefix that covers the scalp. Under validation.

use glam::{Quat, Vec3, Vec4};
use vkhair::groom::guides;
use vkhair::render::reference::{rest_plane_normals, smooth_strand};
use vkhair::render::{Camera, Followers, Interpolator, RenderParams, Renderer};
use vkhair::sim::{HairSim, RigidTransform, SimParams, SimState};
use vkhair::Groom;

use crate::common;

use common::Gpu;

const LEVEL: u32 = 3;
/// Points per drawn follower.
const POINTS: usize = 48;
/// GPU against CPU evaluation, meters (float rounding of a few products).
const GPU_TOLERANCE_M: f32 = 2e-5;

/// Grown strands of 48 points, each wound into a helix of 4 mm radius and six
/// turns around its own root-to-tip line: curls a guide does not have.
fn curly(strands: usize) -> Groom {
    let grown = common::grown_groom(strands, 48, 11);
    let curled: Vec<Vec<Vec3>> = (0..grown.strand_count())
        .map(|s| {
            let p = grown.strand(s);
            let axis = (p[p.len() - 1] - p[0]).normalize();
            let (u, v) = axis.any_orthonormal_pair();
            let n = p.len();
            p.iter()
                .enumerate()
                .map(|(i, &x)| {
                    let t = i as f32 / (n - 1) as f32;
                    let a = t * 6.0 * std::f32::consts::TAU + s as f32;
                    // Grows from 0 at the root, so the root stays put.
                    let r = 0.004 * (4.0 * t).min(1.0);
                    x + r * (a.cos() * u + a.sin() * v)
                })
                .collect()
        })
        .collect();
    Groom::from_strands(&curled).expect("curly groom")
}

struct Scene {
    dense: Groom,
    guides: Vec<usize>,
    keys: Groom,
    followers: Followers,
}

fn scene(strands: usize, guide_count: usize) -> Scene {
    let dense = curly(strands);
    let guides = guides::spread(&dense, guide_count).expect("guides");
    let keys = dense.select(&guides).expect("guides").resampled(16).expect("resampled");
    let rest = SimState::from_groom(&keys, &SimParams::default(), &RigidTransform::default()).expect("rest");
    let followers = Followers::bind(&dense, &guides, &rest, LEVEL, POINTS).expect("bind");
    Scene { dense, guides, keys, followers }
}

/// Distance from `p` to the polyline `line`.
fn to_polyline(p: Vec3, line: &[Vec3]) -> f32 {
    line.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let t = ((p - w[0]).dot(d) / d.length_squared().max(1e-20)).clamp(0.0, 1.0);
            p.distance(w[0] + t * d)
        })
        .fold(f32::MAX, f32::min)
}

fn length(line: &[Vec3]) -> f32 {
    line.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The deviation of every authored point of `dense` from its drawn strand in
/// `drawn` (the file's order), as a share of the strand's length: its
/// quantile function (0: the least, 1: the largest), printed under `label`.
fn deviations(dense: &Groom, drawn: &[Vec<Vec3>], label: &str) -> impl Fn(f64) -> f32 {
    let mut d: Vec<f32> = (0..dense.strand_count())
        .flat_map(|i| {
            let authored = dense.strand(i);
            let len = length(authored);
            authored.iter().map(move |&p| to_polyline(p, &drawn[i]) / len).collect::<Vec<_>>()
        })
        .collect();
    d.sort_by(f32::total_cmp);
    let q = move |f: f64| d[((d.len() - 1) as f64 * f) as usize];
    println!("{label}: deviation p50 {:.2e}, p95 {:.2e}, max {:.2e} of strand length", q(0.5), q(0.95), q(1.0));
    q
}

/// The CPU evaluation of every follower for guides in `state` (world) under `head`.
fn cpu_followers(s: &Scene, state: &SimState, head: Quat) -> Vec<Vec3> {
    let guides: Vec<Vec<(Vec3, Vec3)>> =
        (0..state.strands).map(|g| smooth_strand(&state.strand(g).collect::<Vec<_>>(), LEVEL)).collect();
    s.followers.evaluate(&guides, &rest_plane_normals(state), head, s.followers.count()).expect("evaluate")
}

/// The drawn followers the GPU evaluates, in the file's strand order.
fn gpu_followers(renderer: &mut Renderer, sim: &HairSim, s: &Scene) -> Vec<Vec<Vec3>> {
    renderer.prepare_now(sim, None).expect("prepare");
    let (positions, _) = renderer.read_hairs().expect("hairs");
    s.followers.to_input_order(&positions).expect("whole followers").into_iter().map(|(_, strand)| strand).collect()
}

fn drawing_order(cpu: &[Vec3], s: &Scene) -> Vec<Vec<Vec3>> {
    let mut strands: Vec<(u32, Vec<Vec3>)> =
        cpu.chunks_exact(POINTS).zip(s.followers.input_order()).map(|(c, &i)| (i, c.to_vec())).collect();
    strands.sort_by_key(|(i, _)| *i);
    strands.into_iter().map(|(_, c)| c).collect()
}

fn params() -> RenderParams {
    RenderParams { smoothing_level: LEVEL, ..RenderParams::default() }
}

#[test]
fn at_rest_the_drawn_followers_are_the_authored_strands() {
    let gpu = Gpu::new();
    let s = scene(600, 48);
    assert_eq!(s.followers.count(), 600);
    // Memory: 12 bytes a point, 64 a follower.
    assert_eq!(s.followers.gpu_bytes(), (600 * POINTS * 12 + 600 * 64) as u64);
    let sim = HairSim::new(gpu.ctx(), &s.keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &params(), &s.followers).expect("renderer");
    assert_eq!(renderer.hair_counts(), (600, POINTS as u32));
    let drawn = gpu_followers(&mut renderer, &sim, &s);
    let q = deviations(&s.dense, &drawn, "drawn with their own points");
    // The strands have POINTS points: drawn as authored, to float precision.
    assert!(q(1.0) <= 1e-5, "an authored point is {:.5} % of its strand's length from its follower", 100.0 * q(1.0));
    // The GPU against the CPU reference.
    let state = sim.read_state().expect("state");
    let cpu = drawing_order(&cpu_followers(&s, &state, Quat::IDENTITY), &s);
    let worst = drawn.iter().flatten().zip(cpu.iter().flatten()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    println!("rest: GPU against CPU {worst:e} m");
    assert!(worst < GPU_TOLERANCE_M, "{worst} m");
}

/// Followers drawn with fewer points than authored (resampled by arc length)
/// stay within 0.5 % of the strand's length of the authored strands at rest.
#[test]
fn resampled_followers_stay_within_half_a_percent_of_the_authored_strands() {
    let gpu = Gpu::new();
    let dense = curly(400);
    let guides = guides::spread(&dense, 40).expect("guides");
    let keys = dense.select(&guides).expect("guides").resampled(16).expect("resampled");
    let rest = SimState::from_groom(&keys, &SimParams::default(), &RigidTransform::default()).expect("rest");
    let followers = Followers::bind(&dense, &guides, &rest, LEVEL, 40).expect("bind");
    let sim = HairSim::new(gpu.ctx(), &keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &params(), &followers).expect("renderer");
    renderer.prepare_now(&sim, None).expect("prepare");
    let (positions, _) = renderer.read_hairs().expect("hairs");
    let drawn: Vec<Vec<Vec3>> =
        followers.to_input_order(&positions).expect("whole followers").into_iter().map(|(_, s)| s).collect();
    let q = deviations(&dense, &drawn, "48 authored points drawn with 40");
    assert!(q(1.0) <= 0.005, "an authored point is {:.3} % of its strand's length from its follower", 100.0 * q(1.0));
}

#[test]
fn in_motion_followers_follow_their_guides_with_roots_on_the_scalp() {
    let gpu = Gpu::new();
    let s = scene(300, 30);
    let mut sim = HairSim::new(gpu.ctx(), &s.keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &params(), &s.followers).expect("renderer");
    let rest_drawn = gpu_followers(&mut renderer, &sim, &s);
    let head = |k: usize| RigidTransform {
        rotation: Quat::from_rotation_y(0.5 * (k as f32 / 10.0).min(1.0)),
        translation: Vec3::new(0.05 * (k as f32 / 10.0).min(1.0), 0.0, 0.0),
    };
    sim.run(20, |k| head(k + 1), None).expect("steps");
    let last = head(20);
    let drawn = gpu_followers(&mut renderer, &sim, &s);
    let state = sim.read_state().expect("state");
    let cpu = drawing_order(&cpu_followers(&s, &state, last.rotation), &s);
    let worst = drawn.iter().flatten().zip(cpu.iter().flatten()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    println!("motion: GPU against CPU {worst:e} m");
    assert!(worst < GPU_TOLERANCE_M, "{worst} m");
    // The tessellation stages grow the same followers as the compute dispatch.
    assert_eq!(renderer.interpolator(), Interpolator::Compute);
    let tessellation = RenderParams { interpolator: Interpolator::Tessellation, ..params() };
    let mut tess = Renderer::with_followers(gpu.ctx(), &sim, &tessellation, &s.followers).expect("renderer");
    assert_eq!(tess.interpolator(), Interpolator::Tessellation);
    let tess_drawn = gpu_followers(&mut tess, &sim, &s);
    let apart =
        drawn.iter().flatten().zip(tess_drawn.iter().flatten()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    println!("motion: tessellation against compute {apart:e} m");
    assert!(apart <= 1e-6, "the two interpolators' followers are {apart} m apart");
    // Roots: the authored roots carried by the head.
    let m = last.matrix();
    let root_error = (0..s.dense.strand_count())
        .map(|i| drawn[i][0].distance(m.transform_point3(s.dense.strand(i)[0])))
        .fold(0.0, f32::max);
    println!("motion: roots {root_error:e} m from the scalp");
    assert!(root_error < 1e-5, "a root is {root_error} m off the scalp");
    // The hair moved (the test tests something), and each follower stayed
    // with its guides: its tip no farther from the blend of its guides' tips
    // than 1.5 × at rest plus 1 mm.
    let blend = |i: usize, tips: &dyn Fn(usize) -> Vec3| -> Vec3 {
        s.followers.guides_of(i).expect("bound").iter().map(|&(g, w)| w * tips(g as usize)).sum()
    };
    let (mut moved, mut worst) = (0.0f32, 0.0f32);
    for i in 0..s.dense.strand_count() {
        let (tip, rest_tip) = (*drawn[i].last().expect("tip"), *rest_drawn[i].last().expect("tip"));
        moved = moved.max(tip.distance(rest_tip));
        let now = tip.distance(blend(i, &|g| state.strand(g).last().expect("tip")));
        let before = rest_tip.distance(blend(i, &|g| *s.keys.strand(g).last().expect("tip")));
        worst = worst.max(now - 1.5 * before);
    }
    println!("motion: tips moved up to {moved:.3} m; a tip's distance to its guides' blend grew by at most {worst:.4} m over 1.5 × rest");
    assert!(moved > 0.03, "the tips moved only {moved} m: the motion tests nothing");
    assert!(worst < 1e-3, "a follower tip left its guides by {worst} m more than 1.5 × its rest distance");
}

#[test]
fn a_rigid_move_moves_every_follower_rigidly() {
    let gpu = Gpu::new();
    let s = scene(200, 20);
    let params = SimParams { gravity_enabled: false, ..SimParams::default() };
    let mut sim = HairSim::new(gpu.ctx(), &s.keys, &params, &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &self::params(), &s.followers).expect("renderer");
    let rest = gpu_followers(&mut renderer, &sim, &s);
    let to = RigidTransform { rotation: Quat::from_rotation_y(1.2), translation: Vec3::new(0.3, -0.1, 2.0) };
    sim.teleport(&to).expect("teleport");
    sim.run(1, |_| to, None).expect("step");
    let moved = gpu_followers(&mut renderer, &sim, &s);
    let m = to.matrix();
    let worst = moved
        .iter()
        .flatten()
        .zip(rest.iter().flatten())
        .map(|(a, b)| a.distance(m.transform_point3(*b)))
        .fold(0.0, f32::max);
    println!("rigid move: followers {worst:e} m from the rest followers moved");
    assert!(worst < 1e-4, "a follower point is {worst} m from where the move takes it");
}

#[test]
fn level_of_detail_draws_a_prefix_spread_over_the_scalp() {
    let gpu = Gpu::new();
    let s = scene(400, 40);
    let sim = HairSim::new(gpu.ctx(), &s.keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let p = params();
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &p, &s.followers).expect("renderer");
    renderer.prepare_now(&sim, None).expect("prepare");
    let (full, _) = renderer.read_hairs().expect("hairs");
    // Far away: the share of hairs level of detail keeps.
    let far =
        Camera::look_at(Vec3::new(0.0, 1.6, 6.0), Vec3::new(0.0, 1.6, 0.0), 0.8, 1.0, 0.01, 100.0).expect("camera");
    renderer.prepare_now(&sim, Some(&far)).expect("prepare");
    let detail = renderer.detail();
    // The followers stay at the smoothing level they were bound at, so the
    // prefix is the same hairs to the bit.
    assert_eq!(detail.smoothing_level, LEVEL);
    let (drawn, per) = renderer.hair_counts();
    let want = (400.0 * detail.hairs_per_key as f32 / p.hairs_per_key as f32).round() as u32;
    assert!(detail.hairs_per_key < p.hairs_per_key, "the camera is not far enough to thin the hair");
    assert_eq!((drawn, per), (want, POINTS as u32));
    let (near_prefix, _) = renderer.read_hairs().expect("hairs");
    let same = near_prefix.iter().zip(&full).all(|(a, b): (&Vec4, &Vec4)| a == b);
    assert!(same, "the thinned hairs are not the first of the full set");
    // Spread: every guide has a drawn follower within 4 cm of its root.
    let roots: Vec<Vec3> = near_prefix.chunks_exact(POINTS).map(|h| h[0].truncate()).collect();
    for &g in &s.guides {
        let r = s.dense.strand(g)[0];
        let nearest = roots.iter().map(|x| x.distance(r)).fold(f32::MAX, f32::min);
        assert!(nearest < 0.04, "guide {g}: the nearest drawn root is {nearest} m away");
    }
}

#[test]
fn bad_bindings_are_refused() {
    let dense = curly(50);
    let keys = dense.select(&[0, 10, 20]).expect("keys").resampled(16).expect("resampled");
    let rest = SimState::from_groom(&keys, &SimParams::default(), &RigidTransform::default()).expect("rest");
    assert!(Followers::bind(&dense, &[0, 10], &rest, LEVEL, POINTS).is_err(), "a guide count that is not the sim's");
    assert!(Followers::bind(&dense, &[0, 10, 10], &rest, LEVEL, POINTS).is_err(), "a guide twice");
    assert!(Followers::bind(&dense, &[0, 10, 99], &rest, LEVEL, POINTS).is_err(), "a guide past the groom");
    assert!(Followers::bind(&dense, &[0, 10, 20], &rest, LEVEL, 1).is_err(), "one point");
    assert!(Followers::bind(&dense, &[0, 10, 20], &rest, 0, POINTS).is_err(), "level 0");
    // A renderer at another level than the binding's is refused.
    let gpu = Gpu::new();
    let f = Followers::bind(&dense, &[0, 10, 20], &rest, LEVEL, POINTS).expect("bind");
    let sim = HairSim::new(gpu.ctx(), &keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let other = RenderParams { smoothing_level: LEVEL + 1, ..RenderParams::default() };
    assert!(Renderer::with_followers(gpu.ctx(), &sim, &other, &f).is_err());
    let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &params(), &f).expect("renderer");
    let lower = RenderParams { smoothing_level: LEVEL - 1, ..params() };
    assert!(renderer.set_params(&lower).is_err(), "another smoothing level for bound followers");
    // The CPU evaluation and the read-back order refuse what does not fit.
    assert!(f.evaluate(&[], &[], Quat::IDENTITY, 1).is_err());
    assert!(f.to_input_order(&[Vec4::ZERO; POINTS + 1]).is_err());
}

/// Mean linear-ish RGB of the pixels that are not background.
fn hair_rgb(rgba: &[u8]) -> (Vec3, usize) {
    let hair: Vec<Vec3> = rgba
        .chunks_exact(4)
        .filter(|p| p[..3] != [0, 0, 0])
        .map(|p| Vec3::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2])))
        .collect();
    (hair.iter().copied().sum::<Vec3>() / hair.len().max(1) as f32, hair.len())
}

#[test]
fn followers_are_drawn_in_their_own_colours() {
    let gpu = Gpu::new();
    let s = scene(300, 30);
    let sim = HairSim::new(gpu.ctx(), &s.keys, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let offscreen = vkhair::headless::Offscreen::new(gpu.ctx(), 96, 96).expect("offscreen");
    let camera = common::front_camera(0.9, (96, 96));
    let host = common::HostFrame { clear: Vec3::ZERO, before: None, after: None };
    // Transparent strands: a strand thinner than a pixel covers its share of it.
    let p = RenderParams { transparency: vkhair::render::Transparency::Exact, ..params() };
    let draw = |followers: &Followers| {
        let mut r = Renderer::with_followers(gpu.ctx(), &sim, &p, followers).expect("renderer");
        hair_rgb(&common::draw_frame(&gpu, (&sim, &mut r), &offscreen, &camera, &host))
    };
    // The material's browns: red over green.
    let (material, n) = draw(&s.followers);
    assert!(n > 100 && material.x > material.y, "{n} hair pixels, mean {material}");
    // Green at the root, blue at the tip: no red, green and blue both there.
    let colors = vec![[Vec3::Y, Vec3::Z]; s.followers.count()];
    let coloured = s.followers.clone().with_colors(&colors).expect("colours");
    let (own, n) = draw(&coloured);
    println!("hair pixels: material {material}, own colours {own}");
    assert!(n > 100 && own.x < 0.5 && own.y > 2.0 && own.z > 2.0, "{n} hair pixels, mean {own}");
    // Their own widths: strands four times the material's width (far below a
    // pixel here) cover more of each pixel: the image is brighter.
    let wide = s.followers.clone().with_width_factors(&vec![[4.0, 4.0]; s.followers.count()]).expect("widths");
    let light = |(mean, n): (Vec3, usize)| (mean.x + mean.y + mean.z) * n as f32;
    let (wide_light, plain_light) = (light(draw(&wide)), light(draw(&s.followers)));
    println!("light from the hair at the material's width {plain_light}, at four times it {wide_light}");
    assert!(wide_light > 1.3 * plain_light, "{wide_light} against {plain_light}");
    assert!(s.followers.clone().with_width_factors(&vec![[1.0, 11.0]; s.followers.count()]).is_err());
    assert!(s.followers.clone().with_width_factors(&vec![[f32::NAN, 1.0]; s.followers.count()]).is_err());
    assert!(s.followers.clone().with_width_factors(&[[1.0, 1.0]]).is_err());
    // Refused: the wrong count, out of range, NaN.
    assert!(s.followers.clone().with_colors(&colors[1..]).is_err());
    let mut bad = colors.clone();
    bad[7][1] = Vec3::new(0.0, 1.5, 0.0);
    assert!(s.followers.clone().with_colors(&bad).is_err());
    bad[7][1] = Vec3::NAN;
    assert!(s.followers.clone().with_colors(&bad).is_err());
}

/// Guides turned against each other (one growing up, two down) blend to a
/// nearly singular frame: the follower between them takes its heaviest guide
/// alone instead of an offset the blend's inverse would magnify.
#[test]
fn a_nearly_singular_blend_falls_back_to_the_heaviest_guide() {
    let line = |x: f32, z: f32, dir: f32| (0..6).map(|i| Vec3::new(x, dir * 0.02 * i as f32, z)).collect::<Vec<_>>();
    let strands = vec![line(0.0, 0.0, 1.0), line(0.02, 0.0, -1.0), line(0.01, 0.02, -1.0), line(0.008, 0.006, 1.0)];
    let dense = Groom::from_strands(&strands).expect("groom");
    let keys = dense.select(&[0, 1, 2]).expect("guides");
    let rest = SimState::from_groom(&keys, &SimParams::default(), &RigidTransform::default()).expect("rest");
    let f = Followers::bind(&dense, &[0, 1, 2], &rest, LEVEL, 6).expect("bind");
    let bound = f.guides_of(3).expect("bound");
    let weights: Vec<f32> = bound.iter().map(|&(_, w)| w).filter(|&w| w > 0.0).collect();
    assert_eq!(weights, vec![1.0], "the follower blends {bound:?}");
}
