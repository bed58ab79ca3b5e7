//! Every field of every parameter struct, walked with hostile values: NaN, ±∞,
//! 0, −1 and a huge value for each number (every element of an array too).
//! Each case must give a clean error — the value refused while reading, or by
//! `validate` with a message that names the field — or be one of the accepted
//! values listed below, each inside the range its field documents. A field
//! that starts to accept garbage (a minimum of 0 hairs, a NaN distance) is not
//! in the list and fails the test.

use std::collections::BTreeSet;

use glam::Vec3;
use serde::de::DeserializeOwned;
use serde::Serialize;
use vkhair::config::Config;
use vkhair::groom::grow::GrowParams;
use vkhair::render::{Light, ShadowCaster, ShadowParams};
use vkhair::Result;

/// (field path, value) pairs a struct accepts, each inside the field's
/// documented range (its doc comment states the range).
const ACCEPTED: &[(&str, &str)] = &[
    // Config: [sim]
    ("sim.wind_turbulence", "0"),
    ("sim.wind_frequency", "0"),
    ("sim.spring_stiffness", "0"),
    ("sim.bending_root", "0"),
    ("sim.bending_tip", "0"),
    ("sim.global_shape_stiffness", "0"),
    ("sim.global_shape_range", "0"),
    ("sim.local_shape_stiffness", "0"),
    ("sim.stretch_limit", "0"),
    ("sim.mesh_friction", "0"),
    ("sim.collider_friction", "0"),
    ("sim.damping", "0"),
    ("sim.dftl_damping", "0"),
    ("sim.pearl_radius_root", "0"),
    ("sim.pearl_radius_tip", "0"),
    ("sim.hairs_per_workgroup", "0"),
    ("sim.gravity[0]", "0"),
    ("sim.gravity[0]", "-1"),
    ("sim.gravity[1]", "0"),
    ("sim.gravity[1]", "-1"),
    ("sim.gravity[2]", "0"),
    ("sim.gravity[2]", "-1"),
    ("sim.wind[0]", "0"),
    ("sim.wind[0]", "-1"),
    ("sim.wind[1]", "0"),
    ("sim.wind[1]", "-1"),
    ("sim.wind[2]", "0"),
    ("sim.wind[2]", "-1"),
    // Config: [sim.volume]
    ("sim.volume.flip_ratio", "0"),
    ("sim.volume.friction", "0"),
    ("sim.volume.repulsion", "0"),
    // Config: [render]
    ("render.clump_width", "0"),
    ("render.root_width", "0"),
    ("render.tip_width", "0"),
    // Config: [render.oit]: 0 is the device's limit; any size from 64 KiB
    ("render.oit.max_buffer_bytes", "0"),
    ("render.oit.max_buffer_bytes", "4000000000"),
    // Config: [scalp]: 0° blends only guides combed alike; no clumping; no length variation
    ("scalp.parting_angle", "0"),
    ("scalp.clumping", "0"),
    ("scalp.length_variation", "0"),
    ("scalp.curl_radius", "0"),
    ("scalp.curl_variation", "0"),
    // Config: [material]
    ("material.ambient", "0"),
    ("material.diffuse_wrap", "0"),
    ("material.shift_jitter", "0"),
    ("material.highlight_breakup", "0"),
    ("material.primary_shift", "0"),
    ("material.primary_shift", "-1"),
    ("material.secondary_shift", "0"),
    ("material.secondary_shift", "-1"),
    ("material.least_pixel_width", "0"),
    ("material.root_color[0]", "0"),
    ("material.root_color[1]", "0"),
    ("material.root_color[2]", "0"),
    ("material.tip_color[0]", "0"),
    ("material.tip_color[1]", "0"),
    ("material.tip_color[2]", "0"),
    ("material.primary_color[0]", "0"),
    ("material.primary_color[1]", "0"),
    ("material.primary_color[2]", "0"),
    ("material.secondary_color[0]", "0"),
    ("material.secondary_color[1]", "0"),
    ("material.secondary_color[2]", "0"),
    ("material.marschner.glint", "0"),
    ("material.marschner.alpha", "0"),
    ("material.opacity", "0"),
    ("material.root_width", "0"),
    ("material.tip_width", "0"),
    ("mesh_collider.margin", "0"),
    // Config: [[lights]]
    ("lights[0].color[0]", "0"),
    ("lights[0].color[1]", "0"),
    ("lights[0].color[2]", "0"),
    ("lights[0].direction[0]", "0"),
    ("lights[0].direction[0]", "-1"),
    ("lights[0].direction[1]", "0"),
    ("lights[0].direction[1]", "-1"),
    ("lights[0].direction[2]", "0"),
    ("lights[0].direction[2]", "-1"),
    ("lights[1].color[0]", "0"),
    ("lights[1].color[1]", "0"),
    ("lights[1].color[2]", "0"),
    ("lights[1].position[0]", "0"),
    ("lights[1].position[0]", "-1"),
    ("lights[1].position[1]", "0"),
    ("lights[1].position[1]", "-1"),
    ("lights[1].position[2]", "0"),
    ("lights[1].position[2]", "-1"),
    ("lights[2].color[0]", "0"),
    ("lights[2].color[1]", "0"),
    ("lights[2].color[2]", "0"),
    ("lights[2].direction[0]", "0"),
    ("lights[2].direction[0]", "-1"),
    ("lights[2].direction[1]", "0"),
    ("lights[2].direction[1]", "-1"),
    ("lights[2].direction[2]", "0"),
    ("lights[2].direction[2]", "-1"),
    ("lights[2].inner_angle", "0"),
    ("lights[2].position[0]", "0"),
    ("lights[2].position[0]", "-1"),
    ("lights[2].position[1]", "0"),
    ("lights[2].position[1]", "-1"),
    ("lights[2].position[2]", "0"),
    ("lights[2].position[2]", "-1"),
    // ShadowParams
    ("shadows.casters[0].light", "0"),
    ("shadows.opacity", "0"),
    ("shadows.extinction", "0"),
    ("shadows.pcf_radius", "0"),
    ("shadows.volume_cross_section", "0"),
    // GrowParams
    ("grow.length_jitter", "0"),
    ("grow.droop", "0"),
    ("grow.direction_jitter", "0"),
    ("grow.seed", "0"),
    ("grow.seed", "4000000000"),
    ("grow.comb[0]", "0"),
    ("grow.comb[0]", "-1"),
    ("grow.comb[1]", "0"),
    ("grow.comb[1]", "-1"),
    ("grow.comb[2]", "0"),
    ("grow.comb[2]", "-1"),
    ("grow.face[0]", "0"),
    ("grow.face[0]", "-1"),
    ("grow.face[1]", "0"),
    ("grow.face[1]", "-1"),
    ("grow.face[2]", "0"),
    ("grow.face[2]", "-1"),
    ("grow.gravity[0]", "0"),
    ("grow.gravity[0]", "-1"),
    ("grow.gravity[1]", "-1"),
    ("grow.gravity[2]", "0"),
    ("grow.gravity[2]", "-1"),
];

/// The probes of a float field and of an integer field, with their labels.
fn float_probes() -> [(f64, &'static str); 6] {
    [(f64::NAN, "NaN"), (f64::INFINITY, "inf"), (f64::NEG_INFINITY, "-inf"), (0.0, "0"), (-1.0, "-1"), (1e30, "1e30")]
}

const INT_PROBES: [(i64, &str); 3] = [(0, "0"), (-1, "-1"), (4_000_000_000, "4000000000")];

/// Every numeric leaf under `value`: its path and whether it is a float.
fn leaves(value: &toml::Value, path: String, out: &mut Vec<(String, bool)>) {
    match value {
        toml::Value::Table(t) => {
            for (k, v) in t {
                let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                leaves(v, p, out);
            }
        }
        toml::Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                leaves(v, format!("{path}[{i}]"), out);
            }
        }
        toml::Value::Float(_) => out.push((path, true)),
        toml::Value::Integer(_) => out.push((path, false)),
        _ => {}
    }
}

/// The leaf at `path` under `value`, mutably.
fn leaf_mut<'a>(value: &'a mut toml::Value, path: &str) -> &'a mut toml::Value {
    let mut here = value;
    for part in path.split('.') {
        let (key, indices) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        here = &mut here.as_table_mut().expect("a table")[key];
        for index in indices.split(['[', ']']).filter(|s| !s.is_empty()) {
            here = &mut here.as_array_mut().expect("an array")[index.parse::<usize>().expect("an index")];
        }
    }
    here
}

/// The last word of a path (`lights[0].color[2]` → `color`).
fn field(path: &str) -> &str {
    let last = path.rsplit('.').next().unwrap_or(path);
    last.split('[').next().unwrap_or(last)
}

/// Walks `base` (named `name` in the paths) and returns the accepted cases;
/// panics on an error that does not name its field.
fn walk<T: Serialize + DeserializeOwned>(name: &str, base: &T, validate: impl Fn(&T) -> Result<()>) -> Vec<String> {
    validate(base).expect("the base value is valid");
    let root = toml::Value::try_from(base).expect("serialise");
    let mut all = Vec::new();
    leaves(&root, String::new(), &mut all);
    assert!(!all.is_empty(), "{name}: no numeric field found");
    let mut accepted = Vec::new();
    for (path, float) in all {
        let probes: Vec<(toml::Value, &str)> = if float {
            float_probes().iter().map(|&(v, l)| (toml::Value::Float(v), l)).collect()
        } else {
            INT_PROBES.iter().map(|&(v, l)| (toml::Value::Integer(v), l)).collect()
        };
        for (probe, label) in probes {
            let mut value = root.clone();
            *leaf_mut(&mut value, &path) = probe;
            let full = format!("{name}.{path}");
            let Ok(parsed) = value.try_into::<T>() else { continue };
            match validate(&parsed) {
                Ok(()) => accepted.push(format!("{full} = {label}")),
                Err(e) => {
                    let text = e.to_string();
                    let f = field(&path);
                    assert!(
                        text.contains(f) || text.contains(&f.replace('_', " ")),
                        "{full} = {label}: the error does not name the field: {text}"
                    );
                }
            }
        }
    }
    accepted
}

#[test]
fn every_parameter_field_refuses_hostile_values_or_accepts_a_documented_one() {
    let lights = vec![
        Light::Directional { direction: Vec3::new(0.2, -1.0, 0.1), color: Vec3::ONE },
        Light::Point { position: Vec3::new(0.5, 2.0, 1.0), color: Vec3::ONE },
        Light::Spot {
            position: Vec3::new(-0.5, 2.0, 1.0),
            direction: Vec3::new(0.5, -0.4, -1.0),
            outer_angle: 0.6,
            inner_angle: 0.4,
            color: Vec3::ONE,
        },
    ];
    let config = Config { lights, ..Config::default() };
    let shadows = ShadowParams { casters: vec![ShadowCaster::from(1)], ..ShadowParams::default() };
    let mut accepted = walk("", &config, Config::validate);
    accepted.extend(walk("shadows", &shadows, ShadowParams::validate));
    accepted.extend(walk("grow", &GrowParams::default(), GrowParams::validate));
    let accepted: BTreeSet<String> = accepted.into_iter().map(|a| a.trim_start_matches('.').to_owned()).collect();
    let documented: BTreeSet<String> = ACCEPTED.iter().map(|(p, v)| format!("{p} = {v}")).collect();
    let undocumented: Vec<&String> = accepted.difference(&documented).collect();
    let refused: Vec<&String> = documented.difference(&accepted).collect();
    assert!(undocumented.is_empty(), "accepted but not documented as accepted:\n{undocumented:#?}");
    assert!(refused.is_empty(), "documented as accepted but refused (update the list):\n{refused:#?}");
}
