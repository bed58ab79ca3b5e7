//! The motion walk's two forms against each other.

use std::sync::atomic::Ordering;

use ash::vk;
use glam::{Mat4, Vec2, Vec3};

use crate::groom::{grow, scenes};
use crate::headless::{Offscreen, Submit};
use crate::render::{Camera, HairMaterial, Raster, RenderParams, Renderer, Transparency};
use crate::sim::{HairSim, RigidTransform, SimParams};
use crate::vk::tests::TestGpu;

/// Two frames of a grown groom seen by a camera moving sideways: the second
/// frame's velocity image, as bits.
fn velocity_bits(gpu: &TestGpu, raster: Raster) -> Vec<u32> {
    let params = grow::GrowParams { strands: 120, points_per_strand: 6, length: 0.35, ..Default::default() };
    let groom = grow::grow(&scenes::thesis_scalp(), &params).expect("groom");
    let sim = HairSim::new(gpu.ctx(), &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let params = RenderParams { transparency: Transparency::Exact, raster, hairs_per_key: 2, ..Default::default() };
    let mut renderer = Renderer::new(gpu.ctx(), &sim, &params).expect("renderer");
    let material = HairMaterial { root_width: 0.006, tip_width: 0.006, opacity: 1.0, ..HairMaterial::default() };
    renderer.set_material(&material).expect("material");
    let mut target = Offscreen::new(gpu.ctx(), 64, 48).expect("target");
    target.add_velocity(vk::Format::R32G32_SFLOAT, Vec2::splat(-1000.0)).expect("velocity");
    let centre = scenes::THESIS_HEAD_CENTER;
    let first = Camera::look_at(centre + Vec3::new(0.0, 0.0, 0.6), centre, 0.7, 4.0 / 3.0, 0.05, 10.0).expect("camera");
    let second = Camera { view: first.view * Mat4::from_translation(Vec3::new(0.01, 0.003, 0.0)), ..first };
    for (frame, camera) in [first, second].iter().enumerate() {
        let mut result = Ok(());
        gpu.ctx()
            .run_commands("motion frame", |cmd| {
                // SAFETY: a recording command buffer of the context's device.
                result = unsafe {
                    renderer.record_prepare(cmd, &sim, Some(camera), None).and_then(|_| {
                        target.record_clear(cmd, Vec3::ZERO);
                        renderer.record_draw(cmd, frame as u64, &target.target(), camera, None)
                    })
                };
            })
            .expect("submit");
        result.expect("frame");
    }
    target.read_velocity().expect("velocity").iter().flat_map(|v| v.to_array().map(f32::to_bits)).collect()
}

/// The 64-bit walk and the two 32-bit walks pick the same fragment for every
/// pixel: the velocity images are the same bits (a host that did not enable
/// 64-bit atomics gets the same motion vectors).
#[test]
fn the_one_pass_and_the_two_pass_walks_write_the_same_bits() {
    let gpu = TestGpu::new();
    let device = gpu.device().clone();
    if !device.int64_atomics.load(Ordering::Relaxed) {
        eprintln!("SKIPPED: this device has no 64-bit buffer atomics; only the 32-bit walk runs here");
        return;
    }
    for raster in [Raster::Compute, Raster::Hardware] {
        let one = velocity_bits(&gpu, raster);
        device.int64_atomics.store(false, Ordering::Relaxed);
        let two = velocity_bits(&gpu, raster);
        device.int64_atomics.store(true, Ordering::Relaxed);
        let hair = one.chunks(2).filter(|v| f32::from_bits(v[0]) != -1000.0).count();
        let moving = one.chunks(2).filter(|v| f32::from_bits(v[0]) != -1000.0 && f32::from_bits(v[0]) != 0.0).count();
        println!("{raster:?}: {hair} hair pixels, {moving} moving");
        assert!(hair > 200 && moving * 10 > hair * 9, "{raster:?}: {hair} hair pixels, {moving} moving");
        assert!(one == two, "{raster:?}: the 32-bit walks wrote other motion vectors than the 64-bit one");
    }
}
