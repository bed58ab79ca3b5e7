//! Every file in `presets/` is a valid parameter file, and the styled ones turn
//! the shape constraint on (all but `thesis`, the thesis' model, and
//! `peer_work`, the work of another package's step for benchmarks).

use std::path::Path;

use crate::common;
use vkhair::config::Config;

#[test]
fn every_preset_is_a_valid_parameter_file() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("presets folder") {
        let path = entry.expect("entry").path();
        let config = Config::default().load_over(&path).unwrap_or_else(|e| panic!("{e}"));
        let name = path.file_stem().and_then(|s| s.to_str()).expect("name").to_owned();
        if name == "peer_work" {
            assert!(!config.sim.bending_enabled && config.sim.local_shape_stiffness > 0.0, "peer_work");
            assert!(config.sim.global_shape_stiffness > 0.0 && config.sim.global_shape_range <= 0.2, "peer_work");
        } else if name != "thesis" {
            assert!(config.sim.global_shape_stiffness > 0.0, "{name} holds no style");
            assert!(config.sim.sag_free, "{name} sags");
        }
        names.push(name);
    }
    names.sort();
    assert_eq!(names, ["bob", "curly", "long_straight", "mohawk", "peer_work", "thesis"]);
}

/// Each styled preset holds a groom of its style on a still head after 200
/// steps, as the README says: tip drift p95 within 2 % of the strand length for
/// the bob, the mohawk and the curls; within 3 % for long straight hair, whose
/// hanging lengths (outside the shape constraint's range) stretch under gravity
/// by the solver's compliance.
#[test]
fn each_styled_preset_holds_its_groom_on_a_still_head() {
    use vkhair::sim::{motion, Collider, HairSim, RigidTransform};
    let gpu = common::Gpu::new();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets");
    // The mohawk and the curls stand on a 10 cm sphere at the origin, the bob
    // grows on the thesis head, and the long straight hair (held near the scalp
    // only) hangs 30 cm straight down from the sphere's equator.
    let sphere = vec![Collider::Sphere { center: glam::Vec3::ZERO, radius: 0.1 }];
    let hanging: Vec<Vec<glam::Vec3>> = (0..120)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / 120.0;
            let root = 0.103 * glam::Vec3::new(a.cos(), 0.0, a.sin());
            (0..16).map(|k| root - glam::Vec3::new(0.0, 0.02 * k as f32, 0.0)).collect()
        })
        .collect();
    let grooms = [
        ("bob", common::grown_groom(150, 12, 3), motion::thesis_colliders(), 0.02),
        ("mohawk", common::mohawk(200, 8), sphere.clone(), 0.02),
        ("curly", common::curls(60), sphere.clone(), 0.02),
        ("long_straight", vkhair::Groom::from_strands(&hanging).expect("groom"), sphere, 0.03),
    ];
    for (name, groom, colliders, bound) in grooms {
        let config = Config::default().load_over(&dir.join(format!("{name}.toml"))).expect("preset");
        let still = RigidTransform::default();
        let mut sim = HairSim::new(gpu.ctx(), &groom, &config.sim, &still).expect("sim");
        sim.set_colliders(&colliders).expect("colliders");
        sim.run(200, |_| still, None).expect("run");
        let drift = common::tip_drift_of(&sim.read_state().expect("readback"), &still);
        let p95 = common::p(&drift, 95);
        eprintln!("{name}: tip drift p95 {p95:.4} of the strand length");
        assert!(p95 <= bound, "{name}: tip drift p95 {p95} (bound {bound})");
    }
}
