//! Sintel's step in the configurations compared with TressFX 4.1's kernels at
//! equal work: the styled groom as `vkhair simulate --input` runs it (volume
//! off) at 4 and 20 iterations, and `presets/peer_work.toml` (the peer's work:
//! distance constraints, a global shape constraint near the root, one
//! local-shape sweep, no bending) with three sphere colliders.

use vkhair::config::Config;
use vkhair::groom::Groom;
use vkhair::sim::{Collider, SimParams, VolumeMode};

use super::measure::{measure_sim, SimCase};
use super::{sim_rows, Bench, Row};
use crate::output::Error;

/// The peer's work, as a parameter file (also in `presets/`).
const PEER_WORK: &str = include_str!("../../../../presets/peer_work.toml");

/// The stages of the rows, for the report's keys.
pub const STYLED_4: &str = "sim, styled, 4 iterations";
pub const STYLED_20: &str = "sim, styled, 20 iterations";
pub const PEER_WORK_4: &str = "sim, peer's work (presets/peer_work.toml, 3 spheres)";

/// The parameters of `presets/peer_work.toml`.
pub fn peer_work() -> Result<SimParams, Error> {
    let config = Config::default().apply(PEER_WORK, "presets/peer_work.toml".as_ref())?;
    Ok(config.sim)
}

/// Three spheres for a groom's head and shoulders: one inside the roots
/// (centred on their bounding box, its radius 90 % of the nearest root's
/// distance) and one under each side of it, where shoulders would be.
pub fn three_spheres(groom: &Groom) -> Vec<Collider> {
    let roots: Vec<glam::Vec3> = (0..groom.strand_count()).filter_map(|s| groom.strand(s).first().copied()).collect();
    let (lo, hi) = roots
        .iter()
        .fold((glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)), |(lo, hi), r| (lo.min(*r), hi.max(*r)));
    let center = (lo + hi) * 0.5;
    let radius = 0.9 * roots.iter().map(|r| r.distance(center)).fold(f32::MAX, f32::min);
    let radius = if radius.is_finite() && radius > 0.0 { radius } else { 0.1 };
    let shoulder = |side: f32| Collider::Sphere {
        center: center + glam::Vec3::new(side * 1.3 * radius, -1.8 * radius, 0.0),
        radius: 0.8 * radius,
    };
    vec![Collider::Sphere { center, radius }, shoulder(-1.0), shoulder(1.0)]
}

/// Sintel's rows (see the module docs), each with the CPU reference beside it.
pub fn rows(b: &Bench<'_>, scene: &str, groom: &Groom) -> Result<Vec<Row>, Error> {
    let volume_off = |mut p: SimParams| {
        p.volume.mode = VolumeMode::Off;
        p
    };
    let spheres = three_spheres(groom);
    let cases = [
        (STYLED_4, volume_off(SimParams { iterations: 4, ..SimParams::styled() }), &[][..]),
        (STYLED_20, volume_off(SimParams { iterations: 20, ..SimParams::styled() }), &[][..]),
        (PEER_WORK_4, volume_off(peer_work()?), &spheres[..]),
    ];
    let mut rows = Vec::new();
    for (stage, params, colliders) in cases {
        let case = SimCase { groom, colliders, params, cpu: true, motion: b.args.sim.motion, simulated: None };
        let f = measure_sim(b.ctx, &case, b.args.samples, b.budget())?;
        rows.extend(sim_rows(scene, stage, &f, b.clock, None));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_peer_work_is_distance_global_shape_near_the_root_and_one_local_sweep() {
        let p = peer_work().expect("presets/peer_work.toml");
        assert_eq!(p.iterations, 4);
        assert!(!p.bending_enabled && !p.spring_enabled && !p.sag_free, "{p:?}");
        assert!(p.global_shape_stiffness > 0.0 && p.global_shape_range == 0.2, "{p:?}");
        assert!(p.local_shape_stiffness > 0.0, "{p:?}");
    }

    #[test]
    fn the_head_sphere_lies_inside_the_roots_and_the_shoulders_below() {
        // Roots on a 10 cm sphere's upper half, centred at (0, 1.6, 0).
        let center = glam::Vec3::new(0.0, 1.6, 0.0);
        let strands: Vec<Vec<glam::Vec3>> = (0..50)
            .map(|i| {
                let (a, b) = (i as f32 * 0.7, 0.2 + (i % 7) as f32 * 0.2);
                let dir = glam::Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos());
                vec![center + dir * 0.1, center + dir * 0.2]
            })
            .collect();
        let groom = Groom::from_strands(&strands).expect("groom");
        let spheres = three_spheres(&groom);
        assert_eq!(spheres.len(), 3);
        let Collider::Sphere { center: head, radius } = spheres[0] else { panic!("{spheres:?}") };
        for s in &strands {
            assert!(s[0].distance(head) >= radius / 0.9 - 1e-5, "a root inside the head sphere");
        }
        for s in &spheres[1..] {
            let Collider::Sphere { center, .. } = *s else { panic!("{spheres:?}") };
            assert!(center.y < head.y - radius, "a shoulder above the head: {spheres:?}");
        }
    }
}
