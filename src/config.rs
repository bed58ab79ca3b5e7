//! Parameter files: TOML whose keys are the parameter structs' field names.
//!
//! | section | struct |
//! | --- | --- |
//! | `[sim]` | [`SimParams`] |
//! | `[sim.volume]` | [`crate::sim::VolumeParams`] |
//! | `[render]`, `[render.lod]` | [`RenderParams`], [`crate::render::LodParams`] |
//! | `[[lights]]` | [`Light`], with `kind = "directional"`, `"point"` or `"spot"` |
//! | `[material]`, `[material.marschner]` | [`HairMaterial`], [`crate::render::MarschnerParams`] |
//! | `[mesh_collider]` | [`MeshColliderParams`] |
//! | `[scalp]` | [`ScalpHairParams`] |
//!
//! Every key is optional: a file sets what it names and keeps everything else
//! from the configuration it is applied to ([`Config::default`], or a tool's
//! own defaults). Vectors are arrays (`wind = [5.0, 0.0, 0.0]`), enums are
//! snake-case strings (`mode = "flip"`). A `[[lights]]` list replaces the
//! lights as a whole. Units and ranges are those documented on each field.
//!
//! An unknown key, a value of the wrong type and a value outside its range are
//! each an [`Error::Config`] naming the file, the line and the key; nothing
//! reaches the GPU before a file has been checked.
//!
//! ```
//! use vkhair::config::Config;
//!
//! let text = "[sim]\nwind = [5.0, 0.0, 0.0]\nwind_enabled = true\n\n[sim.volume]\nmode = \"flip\"\n";
//! let config = Config::default().apply(text, "styled.toml".as_ref())?;
//! assert!(config.sim.wind_enabled);
//! assert_eq!(config.sim.volume.mode, vkhair::sim::VolumeMode::Flip);
//! assert_eq!(config.sim.iterations, 20, "unnamed keys keep their defaults");
//!
//! let error = Config::default().apply("[sim]\nitrations = 4\n", "typo.toml".as_ref()).unwrap_err();
//! assert_eq!(error.to_string().lines().next(), Some("typo.toml:2: sim.itrations: unknown key"));
//! # Ok::<(), vkhair::Error>(())
//! ```

use std::path::Path;

use crate::error::{Error, Result};
use crate::render::{HairMaterial, Light, RenderParams, ScalpHairParams, MAX_LIGHTS};
use crate::sim::{MeshColliderParams, SimParams};

/// The most vkhair reads of a parameter file unless
/// [`crate::files::MAX_INPUT_ENV`] says otherwise: 1 MiB (the defaults take
/// about 2 KiB).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// Everything a parameter file can set.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// Simulation parameters (`[sim]`, `[sim.volume]`).
    pub sim: SimParams,
    /// Rendering parameters (`[render]`, `[render.lod]`).
    pub render: RenderParams,
    /// The lights (`[[lights]]`, at most [`MAX_LIGHTS`]). Default: none, which
    /// leaves the choice to the program (the `vkhair` tool lights the head with
    /// its own three).
    pub lights: Vec<Light>,
    /// The hair material (`[material]`, `[material.marschner]`).
    pub material: HairMaterial,
    /// How the mesh collider's field is built (`[mesh_collider]`).
    pub mesh_collider: MeshColliderParams,
    /// How drawn hairs are rooted over the scalp (`[scalp]`;
    /// [`crate::render::Followers::over_scalp`]).
    pub scalp: ScalpHairParams,
}

impl Config {
    /// Reads `path` (at most [`MAX_CONFIG_BYTES`], or
    /// [`crate::files::MAX_INPUT_ENV`]'s cap) and applies it over `self` (see
    /// [`Config::apply`]).
    pub fn load_over(&self, path: &Path) -> Result<Config> {
        let cap = crate::files::input_cap(MAX_CONFIG_BYTES)?;
        let data = crate::files::read_capped(path, cap, "a parameter file")?;
        let text = String::from_utf8(data).map_err(|e| {
            let valid = e.utf8_error().valid_up_to();
            let line = 1 + e.as_bytes()[..valid].iter().filter(|&&b| b == b'\n').count();
            Error::Config { path: path.into(), line: Some(line), key: String::new(), reason: "not UTF-8 text".into() }
        })?;
        self.apply(&text, path)
    }

    /// Applies the TOML `text` of the file `path` over `self`: the keys the file
    /// names replace those of `self`. The file is checked on its own first (every
    /// key known, every value of its field's type), then the result is validated;
    /// either failure is an [`Error::Config`] naming `path`, the line and the key.
    pub fn apply(&self, text: &str, path: &Path) -> Result<Config> {
        let error = |offset: Option<usize>, key: Option<String>, reason: String| {
            let line = offset.map(|o| line_of(text, o));
            let key = key.or_else(|| offset.map(|o| key_at(text, o))).unwrap_or_default();
            Error::Config { path: path.into(), line, key, reason }
        };
        let file: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| error(e.span().map(|s| s.start), None, e.message().trim().to_owned()))?;
        // On its own, so that unknown keys and wrong types come with their place.
        toml::from_str::<Config>(text).map_err(|e| error(e.span().map(|s| s.start), None, describe(e.message())))?;
        let mut merged = toml::Table::try_from(self).map_err(|e| error(None, None, e.to_string()))?;
        merge(&mut merged, file);
        let config: Config =
            merged.try_into().map_err(|e: toml::de::Error| error(None, None, e.message().trim().to_owned()))?;
        config.validate().map_err(|e| match e {
            Error::InvalidParameter { name, value, allowed } => {
                // A light's field is looked for from its own `[[lights]]`
                // table on (the file's list replaces the lights whole).
                let from = config
                    .lights
                    .iter()
                    .position(|l| l.validate().is_err())
                    .filter(|_| name.starts_with("light ") || name.starts_with("light."))
                    .and_then(|i| nth_array_table(text, "lights", i))
                    .unwrap_or(0);
                let (offset, key) = find_key(&text[from..], name);
                // A rule over two fields names no one key: the light's table then.
                let offset = offset.map(|o| from + o).or((from > 0).then_some(from));
                error(offset, Some(key), format!("{value} is not allowed ({allowed})"))
            }
            other => error(None, None, other.to_string()),
        })?;
        Ok(config)
    }

    /// Checks every parameter; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        self.sim.validate()?;
        self.render.validate()?;
        self.material.validate()?;
        self.mesh_collider.validate()?;
        self.scalp.validate()?;
        if self.lights.len() > MAX_LIGHTS {
            return Err(Error::param("lights", self.lights.len(), format!("at most {MAX_LIGHTS}")));
        }
        self.lights.iter().try_for_each(Light::validate)
    }

    /// This configuration as TOML with every key commented out, under a header
    /// that says how to use it: what `vkhair config` prints (for the defaults).
    pub fn to_commented_toml(&self) -> Result<String> {
        let body = toml::to_string(self)
            .map_err(|e| Error::param("config", "a configuration", format!("one TOML can hold: {e}")))?;
        let mut out = String::from(
            "# vkhair parameters. Uncomment and change the keys you need; every key is\n\
             # optional and keeps the value shown when left out. Units and ranges are\n\
             # documented on the fields of SimParams ([sim]), VolumeParams ([sim.volume]),\n\
             # RenderParams ([render]), Light ([[lights]]), HairMaterial ([material]),\n\
             # MeshColliderParams ([mesh_collider]) and ScalpHairParams ([scalp]).\n",
        );
        for line in body.lines() {
            let header = line.starts_with('[') && !line.starts_with("[[");
            match (line.trim().is_empty(), header) {
                (true, _) => out.push('\n'),
                (false, true) => {
                    out.push_str(line);
                    out.push('\n');
                }
                (false, false) => {
                    out.push_str("# ");
                    out.push_str(line);
                    out.push('\n');
                }
            }
        }
        if self.lights.is_empty() {
            out.push_str(
                "\n# Lights, when listed, replace the program's own; for example:\n\
                 #     [[lights]]\n\
                 #     kind = \"directional\"\n\
                 #     direction = [0.0, -1.0, -1.0]\n\
                 #     color = [1.0, 1.0, 1.0]\n",
            );
        }
        Ok(out)
    }
}

/// Puts every key of `file` into `base`, descending into tables both have.
fn merge(base: &mut toml::Table, file: toml::Table) {
    for (key, value) in file {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(value)) => merge(inner, value),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// serde's "unknown field `x`, expected one of …" as "unknown key"; other
/// messages as they are.
fn describe(message: &str) -> String {
    let message = message.trim();
    if message.starts_with("unknown field") {
        "unknown key".to_owned()
    } else {
        message.to_owned()
    }
}

/// The 1-based line of byte `offset`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The dotted key of the line holding `offset` (`section.key`), from the last
/// `[section]` header above it.
fn key_at(text: &str, offset: usize) -> String {
    let line = line_of(text, offset);
    let lines: Vec<&str> = text.lines().collect();
    let own = lines.get(line - 1).copied().unwrap_or_default();
    if let Some(table) = header_name(own) {
        // A table header names itself, whatever table came before it.
        return table;
    }
    let key = own.split('=').next().unwrap_or_default().trim().trim_matches(['[', ']']).trim();
    let section = lines[..line.saturating_sub(1).min(lines.len())].iter().rev().find_map(|l| header_name(l));
    match section {
        Some(s) if !s.is_empty() && !key.starts_with(&s) => format!("{s}.{key}"),
        _ => key.to_owned(),
    }
}

/// The table a header line opens (`[render.lod]`, `[[ lights ]] # note`),
/// or None for any other line.
fn header_name(line: &str) -> Option<String> {
    let header = line.split('#').next().unwrap_or_default().trim();
    let inner = header.strip_prefix('[')?.strip_suffix(']')?;
    let inner = inner.strip_prefix('[').and_then(|i| i.strip_suffix(']')).unwrap_or(inner);
    Some(inner.trim().to_owned())
}

/// The byte offset of the line opening the `n`-th (0-based) `[[table]]` of
/// `text`, if it has that many.
fn nth_array_table(text: &str, table: &str, n: usize) -> Option<usize> {
    let mut offset = 0;
    let mut seen = 0;
    for line in text.split_inclusive('\n') {
        let array = line.trim_start().starts_with("[[");
        if array && header_name(line).as_deref() == Some(table) {
            if seen == n {
                return Some(offset);
            }
            seen += 1;
        }
        offset += line.len();
    }
    None
}

/// Where the parameter a validation error names is set in `text`: the first
/// line whose dotted key (table included) ends with the name, its words
/// joined by dots (`"volume resolution"` → `sim.volume.resolution`,
/// `lod.full_detail_distance` → `render.lod.full_detail_distance`). The byte
/// offset of that line, and its dotted key.
fn find_key(text: &str, name: &str) -> (Option<usize>, String) {
    // Parameter names are dotted below their table (`lod.full_detail_distance`)
    // or spaced (`volume max_iterations`); the file's key holds them at its end.
    let mut dotted = name.replace(' ', ".");
    // Parameters whose name is their type's, not their table's.
    for (named, table) in [("light.", "lights."), ("sdf.", "mesh_collider.")] {
        if let Some(rest) = dotted.strip_prefix(named) {
            dotted = format!("{table}{rest}");
        }
    }
    let ends = |key: &str, tail: &str| key == tail || key.ends_with(&format!(".{tail}"));
    let field = dotted.rsplit('.').next().unwrap_or(&dotted).to_owned();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let key = line.split('=').next().unwrap_or_default().trim();
        if line.contains('=') && ends(key, &field) {
            let full = key_at(text, offset);
            if ends(&full, &dotted) {
                return (Some(offset), full);
            }
        }
        offset += line.len();
    }
    (None, dotted)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn apply(text: &str) -> Result<Config> {
        Config::default().apply(text, Path::new("test.toml"))
    }

    fn config_error(text: &str) -> (Option<usize>, String, String) {
        match apply(text) {
            Err(Error::Config { path, line, key, reason }) => {
                assert_eq!(path, Path::new("test.toml"));
                (line, key, reason)
            }
            other => panic!("expected a config error, got {other:?}"),
        }
    }

    #[test]
    fn the_defaults_round_trip() {
        let defaults = Config::default();
        let text = toml::to_string(&defaults).expect("serialise");
        assert_eq!(apply(&text).expect("parse"), defaults);
        // The commented form parses (every key commented out) and, uncommented,
        // gives the defaults back.
        let commented = defaults.to_commented_toml().expect("commented");
        assert_eq!(apply(&commented).expect("parse commented"), defaults);
        let uncommented: String = commented
            .lines()
            .map(|l| l.strip_prefix("# ").filter(|r| r.contains(" = ") && !r.starts_with(' ')).unwrap_or(l))
            .collect::<Vec<_>>()
            .join("\n");
        assert_eq!(apply(&uncommented).expect("parse uncommented"), defaults);
    }

    #[test]
    fn a_file_sets_only_what_it_names() {
        let base = Config { sim: SimParams { iterations: 7, ..SimParams::default() }, ..Config::default() };
        let text = "[sim]\nwind = [5.0, 0.0, 0.0]\nwind_enabled = true\n[sim.volume]\nresolution = [16, 16, 8]\n\
                    [[lights]]\nkind = \"spot\"\nposition = [0.0, 2.0, 1.0]\ndirection = [0.0, -1.0, -0.5]\n\
                    outer_angle = 0.5\ninner_angle = 0.3\ncolor = [2.0, 2.0, 2.0]\n";
        let c = base.apply(text, Path::new("test.toml")).expect("apply");
        assert_eq!(c.sim.iterations, 7, "kept from the base");
        assert_eq!(c.sim.wind, glam::Vec3::new(5.0, 0.0, 0.0));
        assert!(c.sim.wind_enabled);
        assert_eq!(c.sim.volume.resolution, [16, 16, 8]);
        assert_eq!(c.sim.volume.mode, crate::sim::VolumeMode::Off, "kept from the base");
        assert!(matches!(c.lights.as_slice(), [Light::Spot { outer_angle, .. }] if *outer_angle == 0.5));
    }

    #[test]
    fn an_unknown_key_names_its_line_and_key() {
        let (line, key, reason) = config_error("[sim]\ndt = 0.01\n\n[sim.volume]\nresolutoin = [8, 8, 8]\n");
        assert_eq!((line, key.as_str(), reason.as_str()), (Some(5), "sim.volume.resolutoin", "unknown key"));
        let (line, key, _) = config_error("colour = 1\n");
        assert_eq!((line, key.as_str()), (Some(1), "colour"));
        // An unknown table after another names itself, not a key of the one before.
        let (line, key, reason) = config_error("[sim]\ndt = 0.01\n[bogus]\nx = 1\n");
        assert_eq!((line, key.as_str(), reason.as_str()), (Some(3), "bogus", "unknown key"));
    }

    #[test]
    fn a_wrong_type_names_its_line_and_key() {
        let (line, key, reason) = config_error("[render]\nhairs_per_key = 16\nsupersampling = \"yes\"\n");
        assert_eq!((line, key.as_str()), (Some(3), "render.supersampling"));
        assert!(reason.contains("bool"), "{reason}");
        let (line, key, _) = config_error("[sim.volume]\nmode = \"turbulent\"\n");
        assert_eq!((line, key.as_str()), (Some(2), "sim.volume.mode"));
    }

    #[test]
    fn an_out_of_range_value_names_its_line_and_key() {
        let (line, key, reason) = config_error("[sim]\nwind_enabled = true\niterations = 0\n");
        assert_eq!((line, key.as_str()), (Some(3), "sim.iterations"));
        assert!(reason.contains("1..=1000"), "{reason}");
        let (line, key, _) = config_error("[material]\nambient = 2.0\n");
        assert_eq!((line, key.as_str()), (Some(2), "material.ambient"));
        let (line, key, _) = config_error("[sim.volume]\nresolution = [8, 8, 300]\n");
        assert_eq!((line, key.as_str()), (Some(2), "sim.volume.resolution"));
    }

    /// Keys in nested tables, in arrays of tables and in tables whose
    /// parameters carry their type's name are named as the file writes them,
    /// with their line (`lod.full_detail_distance` in `[render.lod]` had been
    /// named without a line, as a key the file does not have).
    #[test]
    fn nested_keys_name_their_line_and_table() {
        let cases = [
            (
                "[render]\nclump_width = 0.01\n[render.lod]\nfull_detail_distance = -1\n",
                4,
                "render.lod.full_detail_distance",
            ),
            ("[render.oit]\ntile_entries_per_vertex = 0\n", 2, "render.oit.tile_entries_per_vertex"),
            ("[render]\nmotion.threshold = nan\n", 2, "render.motion.threshold"),
            ("[scalp]\ndensity = 1e9\n", 2, "scalp.density"),
            ("[mesh_collider]\nresolution = 1000000\n", 2, "mesh_collider.resolution"),
            (
                "[[lights]]\nkind = \"directional\"\ndirection = [0.0, -1.0, 0.0]\ncolor = [inf, 1.0, 1.0]\n",
                4,
                "lights.color",
            ),
        ];
        for (text, expected_line, expected_key) in cases {
            let (line, key, _) = config_error(text);
            assert_eq!((line, key.as_str()), (Some(expected_line), expected_key), "{text}");
        }
    }

    /// A bad field of a later light is named at that light's line, not at the
    /// first light's line of the same key.
    #[test]
    fn a_later_lights_bad_field_names_its_own_line() {
        let light = |color: &str| {
            format!("[[lights]]\nkind = \"directional\"\ndirection = [0.0, -1.0, 0.0]\ncolor = {color}\n")
        };
        let good = light("[1.0, 1.0, 1.0]");
        let text = format!(
            "{good}{good}\n[[ lights ]] # the third\n{}",
            light("[1.0, -1.0, 1.0]").replacen("[[lights]]\n", "", 1)
        );
        let (line, key, _) = config_error(&text);
        assert_eq!((line, key.as_str()), (Some(13), "lights.color"), "{text}");
        assert_eq!(nth_array_table(&text, "lights", 3), None);
        // A rule over two of a later light's fields: named at that light's table.
        let spot = "[[lights]]\nkind = \"spot\"\nposition = [0.0, 2.0, 1.0]\ndirection = [0.0, -1.0, -0.5]\n\
                    outer_angle = 0.3\ninner_angle = 0.5\ncolor = [2.0, 2.0, 2.0]\n";
        let (line, _, reason) = config_error(&format!("{good}{spot}"));
        assert_eq!(line, Some(5), "{reason}");
    }

    #[test]
    fn a_syntax_error_names_its_line() {
        let (line, _, _) = config_error("[sim]\ndt = 0.01\nwind = [1.0, 2.0\n");
        assert!(matches!(line, Some(3) | Some(4)), "{line:?}");
    }
}
