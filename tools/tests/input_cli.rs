//! What the user gives the tool: grooms of any size framed in the picture,
//! options that need others, defective real assets, and the messages for each.

use crate::common;

use std::time::Duration;

use common::{run, run_line};
use glam::Vec3;

const LIMIT: Duration = Duration::from_secs(300);

/// Renders frame 0 of `groom` at 160 × 120 and returns the share of the image
/// that is not background.
fn coverage_of(dir: &std::path::Path, groom: &std::path::Path) -> f64 {
    let out = dir.join(format!("{}-frames", groom.file_stem().and_then(|s| s.to_str()).unwrap_or("g")));
    let args = format!(
        "render --input {} --frames 1 --width 160 --height 120 --shadow-resolution 64 --out {}",
        groom.display(),
        out.display()
    );
    run_line(&args, LIMIT).assert_ok();
    let (_, _, rgba) = common::read_png(&out.join("frame_0000.png"));
    common::coverage(&rgba)
}

/// The camera frames the groom: a 5-unit groom and a 1-cm groom both cover
/// between 5 % and 80 % of the image (the thesis camera flooded the first).
#[test]
fn grooms_of_any_size_are_framed() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, radius) in [("five_units", 1.6), ("one_cm", 0.003), ("head_size", 0.1)] {
        let groom = dir.path().join(format!("{name}.hair"));
        common::write_groom(&groom, &common::cap_groom(150, 8, radius));
        let covered = coverage_of(dir.path(), &groom);
        eprintln!("{name}: {:.1} % of the image", 100.0 * covered);
        assert!((0.05..=0.8).contains(&covered), "{name}: the groom covers {:.1} % of the image", 100.0 * covered);
    }
}

/// A flat groom (every root in one plane) gets a stand-in head and renders.
#[test]
fn a_flat_groom_renders() {
    let dir = tempfile::tempdir().expect("temp dir");
    let strands: Vec<Vec<Vec3>> = (0..60)
        .map(|i| {
            let x = 0.004 * i as f32;
            (0..6).map(|k| Vec3::new(x, -0.02 * k as f32, 0.0)).collect()
        })
        .collect();
    let groom = dir.path().join("flat.hair");
    common::write_groom(&groom, &strands);
    let covered = coverage_of(dir.path(), &groom);
    assert!(covered > 0.01, "the flat groom covers {:.2} % of the image", 100.0 * covered);
}

/// Strands are drawn as wide as the groom file says (a cyHair thickness array,
/// scaled with the groom), vkhair's default when it says nothing or something no
/// hair could be (with a warning), and `--config` overrides both.
#[test]
fn strand_width_comes_from_the_groom_thickness() {
    let dir = tempfile::tempdir().expect("temp dir");
    let strands = common::cap_groom(150, 8, 10.0);
    let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
    let positions: Vec<Vec3> = strands.concat();
    let write = |name: &str, thickness: Option<f32>| {
        let path = dir.path().join(name);
        let attributes =
            vkhair::groom::Attributes { thickness: thickness.map(|t| vec![t; positions.len()]), ..Default::default() };
        let groom = vkhair::Groom::with_attributes(positions.clone(), &counts, attributes).expect("groom");
        vkhair::groom::cyhair::HairFile::new(groom, "t").save(&path).expect("save");
        path
    };
    // In centimetres, as a groom from a DCC is: --scale 0.01 gives meters.
    let thick = write("thick.hair", Some(0.03)); // 300 µm
    let none = write("none.hair", None);
    let absurd = write("absurd.hair", Some(5.0)); // 5 cm
    let config = dir.path().join("widths.toml");
    std::fs::write(&config, "[material]\nroot_width = 0.0002\ntip_width = 0.0001\n").expect("write config");
    // Clumps: pictures compared byte for byte want no pool overflow, whose
    // order follows the atomics (a full head over the scalp overflows here).
    let render = |name: &str, groom: &std::path::Path, extra: &str| {
        let out = dir.path().join(name);
        let args = format!(
            "render --input {} --scale 0.01 --frames 1 --width 160 --height 120 --shadow-resolution 64 --clumps --out {} {extra}",
            groom.display(),
            out.display()
        );
        let run = run_line(&args, LIMIT);
        run.assert_ok();
        let (_, _, rgba) = common::read_png(&out.join("frame_0000.png"));
        (run, rgba)
    };
    let (thick_run, thick_image) = render("thick", &thick, "");
    let (none_run, none_image) = render("none", &none, "");
    let (absurd_run, absurd_image) = render("absurd", &absurd, "");
    let (config_run, config_image) = render("config", &thick, &format!("--config {}", config.display()));
    let (config_none_run, config_none_image) = render("config_none", &none, &format!("--config {}", config.display()));
    let line = |r: &common::Run| {
        r.stdout.lines().find(|l| l.starts_with("strand width:")).map(str::to_owned).unwrap_or_default()
    };
    assert_eq!(line(&thick_run), "strand width: 300.0 µm at the root, 300.0 µm at the tip (the groom's thickness)");
    assert_eq!(line(&none_run), "strand width: 120.0 µm at the root, 50.0 µm at the tip (vkhair's default)");
    assert_eq!(line(&absurd_run), line(&none_run));
    assert!(absurd_run.stderr.contains("is not a hair's"), "{}", absurd_run.stderr);
    assert!(!thick_run.stderr.contains("warning"), "{}", thick_run.stderr);
    assert_eq!(line(&config_run), "strand width: 200.0 µm at the root, 100.0 µm at the tip (--config)");
    assert_eq!(line(&config_none_run), line(&config_run));
    // The picture follows: an implausible thickness draws exactly the default,
    // the config draws the same whatever the groom says, thick hair covers more.
    assert!(absurd_image == none_image, "an implausible thickness changed the picture");
    assert!(config_image == config_none_image, "--config widths did not override the groom's");
    let (thick_cover, none_cover) = (common::coverage(&thick_image), common::coverage(&none_image));
    eprintln!("coverage: 300 µm {:.2} %, default {:.2} %", 100.0 * thick_cover, 100.0 * none_cover);
    assert!(thick_cover > none_cover * 1.05, "300 µm strands cover {thick_cover}, the default's {none_cover}");
}

/// Options that mean something only with others are refused, saying what they
/// need, before any GPU work.
#[test]
fn options_that_need_others_say_so() {
    let cases: &[(&[&str], &str)] = &[
        (&["render", "--obj", "head.obj"], "--obj needs --input"),
        (&["render", "--scale", "0.01"], "--scale needs --input"),
        (&["render", "--points", "8"], "--points needs --input"),
        (&["render", "--strict"], "--strict needs --input"),
        (&["render", "--hand-off", "staging"], "--hand-off needs --schedule second-device"),
        (&["render", "--sim-device", "llvmpipe"], "--sim-device needs --schedule second-device"),
        (&["render", "--no-mesh-collider"], "--no-mesh-collider needs --obj"),
        (&["simulate", "--obj", "head.obj"], "--obj needs --input"),
        (&["simulate", "--scale", "0.01"], "--scale needs --input"),
        (&["simulate", "--points", "8"], "--points needs --input"),
        (&["simulate", "--no-mesh-collider"], "--no-mesh-collider needs --obj"),
        (&["render", "--animation", "run"], "--animation needs --gltf"),
        (&["render", "--head-joint", "head"], "--head-joint needs --gltf"),
        (&["render", "--gltf", "a.glb", "--obj", "head.obj"], "--obj cannot go with it"),
        (&["render", "--gltf", "a.glb", "--scale", "0.01"], "--scale needs --input"),
        (&["grow", "--scalp", "gltf", "--out", "g.hair"], "--scalp gltf needs --gltf"),
        (&["simulate", "--gltf", "a.glb", "--check"], "not --gltf"),
    ];
    for (args, message) in cases {
        let out = run(args, LIMIT);
        out.assert_error(message);
        assert!(!out.stdout.contains("key hairs"), "{args:?} started GPU work: {}", out.stdout);
    }
}

/// Over the scalp the drawn count follows the density: a per-key count there
/// is refused, naming the flag and what it needs, not ignored; so is a
/// density where hairs are not rooted over the scalp.
#[test]
fn hairs_per_key_over_the_scalp_is_refused_not_ignored() {
    let out = run(&["render", "--frames", "1", "--width", "32", "--height", "32", "--hairs-per-key", "4"], LIMIT);
    out.assert_error("--hairs-per-key: 4");
    assert!(out.stderr.contains("--clumps") && out.stderr.contains("--density"), "{}", out.stderr);
    for other in [&["--clumps"][..], &["--barycentric"]] {
        let args = [&["render", "--frames", "1", "--width", "32", "--height", "32", "--density", "15"][..], other];
        let out = run(&args.concat(), LIMIT);
        out.assert_error("--density: 15");
        assert!(out.stderr.contains("--hairs-per-key"), "{other:?}: {}", out.stderr);
    }
}

/// `--interpolator` picks who grows the hairs and the tool says which: on this
/// device `auto` is the compute dispatch; the tessellation stages draw the
/// same PNG, byte for byte, with the hairs over the scalp (followers).
#[test]
fn the_interpolator_is_chosen_and_said() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut frames = Vec::new();
    for (flag, said) in [("auto", "a compute dispatch"), ("tessellation", "the tessellation stages")] {
        let out_dir = dir.path().join(flag);
        let out_arg = out_dir.to_str().expect("utf-8 path");
        let args =
            ["render", "--frames", "1", "--width", "64", "--height", "48", "--interpolator", flag, "--out", out_arg];
        let out = run(&args, LIMIT);
        out.assert_ok();
        assert!(out.stdout.contains(&format!("interpolation: hairs grown by {said}")), "{flag}: {}", out.stdout);
        frames.push(std::fs::read(out_dir.join("frame_0000.png")).expect("frame"));
    }
    assert!(frames[0] == frames[1], "the two interpolators drew different frames");
}

/// `render --raster tiles` says what the tiled rasteriser did: every
/// fragment sorted or in the tail, and, with bins too small for the frame
/// (`oit.tile_entries_per_vertex` at its least), that entries past the list
/// were not drawn and what to raise.
#[test]
fn the_tiled_rasteriser_says_when_its_list_was_too_small() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = dir.path().join("small_bins.toml");
    std::fs::write(&config, "[render.oit]\ntile_entries_per_vertex = 0.1\n").expect("config");
    let out_dir = dir.path().join("frames");
    let args = format!(
        "render --frames 1 --width 64 --height 48 --no-lod --raster tiles --config {} --out {}",
        config.display(),
        out_dir.display()
    );
    let out = run_line(&args, LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("strands drawn by the tiled compute rasteriser"), "{}", out.stdout);
    assert!(out.stdout.contains("every one sorted or in the tail"), "{}", out.stdout);
    assert!(
        out.stdout.contains("more than the list held") && out.stdout.contains("oit.tile_entries_per_vertex"),
        "{}",
        out.stdout
    );
}

/// `render --gltf` puts hair on the shared character and follows its run: the
/// PNGs show the hair (brown) and the body; an unknown animation or joint is
/// named with the ones the file has, before any GPU work.
#[test]
fn render_puts_hair_on_an_animated_gltf_character() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/mannequiny-0.3.0.glb");
    let out = dir.path().join("frames");
    let args = format!(
        "render --gltf {glb} --animation run --frames 3 --width 160 --height 160 --shadow-resolution 64 --out {}",
        out.display()
    );
    let run = run_line(&args, LIMIT);
    run.assert_ok();
    assert!(run.stdout.contains("head joint \"head\"") && run.stdout.contains("Mannequiny"), "{}", run.stdout);
    let (_, _, rgba) = common::read_png(&out.join("frame_0002.png"));
    // Hair: brown pixels (blue under two thirds of red; the pinkish grey body
    // and the grey background are never that saturated). From the front the
    // hair framing the face shows at its sides and crown: about 200 pixels.
    let brown = rgba.chunks_exact(4).filter(|p| p[0] > 40 && 3 * u32::from(p[2]) < 2 * u32::from(p[0])).count();
    assert!(brown > 120, "{brown} hair pixels");
    assert!(common::coverage(&rgba) > 0.1, "the character and hair cover the frame");
    for (flag, value, message) in
        [("--animation", "swim", "allowed: one of"), ("--head-joint", "tail", "a joint of the skin")]
    {
        let args = format!("render --gltf {glb} {flag} {value} --out {}", out.display());
        run_line(&args, LIMIT).assert_error(message);
    }
}

/// Hair grown on the character frames its face: over a whole cycle of the
/// run (20 frames at 30 per second, 0.63 s), the hair hides at most 5 % of
/// the face's pixels (`render`'s `face_covered` in `--json`: a pixel of the
/// face's front-facing triangles, projected, that the hair's passes changed by
/// more than `coverage::COVERED_STEPS`). Hair grown without the face framing
/// (combed back only, the groom before it) hid 8.7 % at 1280×720.
#[test]
fn grown_hair_leaves_the_characters_face_visible_through_its_run() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/mannequiny-0.3.0.glb");
    let json = dir.path().join("run.json");
    let args = format!(
        "render --gltf {glb} --animation run --frames 20 --width 640 --height 360 --out {} --json {}",
        dir.path().join("frames").display(),
        json.display()
    );
    let run = run_line(&args, LIMIT);
    run.assert_ok();
    assert!(run.stdout.contains("face: hair covers"), "{}", run.stdout);
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parse");
    let face = &v["run"]["face_covered"];
    let share = face["share"].as_f64().expect("face_covered.share");
    let worst = face["worst_frame_share"].as_f64().expect("face_covered.worst_frame_share");
    eprintln!("face covered: {:.2} % over the run, {:.2} % in the worst frame", 100.0 * share, 100.0 * worst);
    assert_eq!(face["frames"].as_u64(), Some(20));
    assert!(share <= 0.05, "hair hides {:.2} % of the face over the run", 100.0 * share);
    assert!(worst >= share, "the worst frame {worst} below the mean {share}");
}

/// `simulate --gltf` follows the character's run and writes, in `--json`, how
/// far the roots got from the skinned scalp points they were grown on (the
/// roots ride their triangles of the skinned mesh, which the tool writes into a
/// GPU buffer every step: a few micrometres, the bind pose's rounding at the
/// character's scale) and the share of points inside the body: at most 0.5 %
/// with the body near the head one mesh collider that follows the bones, its
/// enclosed inner layer left out of the field and of the scalp the hair is
/// grown on (0.2 % measured; 1.0 % with roots grown on the inner layer; 2.2 %
/// with the inner layer in the field too; 7.5 % with the head's rigid field and
/// the capsules alone).
#[test]
fn simulate_measures_roots_and_penetration_on_an_animated_character() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/mannequiny-0.3.0.glb");
    let json = dir.path().join("run.json");
    let args = format!("simulate --gltf {glb} --animation run --steps 20 --volume off --json {}", json.display());
    run_line(&args, LIMIT).assert_ok();
    let text = std::fs::read_to_string(&json).expect("json");
    let v: serde_json::Value = serde_json::from_str(&text).expect("parse");
    let root = v["run"]["root_error_max_m"].as_f64().expect("root_error_max_m");
    let inside = v["run"]["inside_fraction_max"].as_f64().expect("inside_fraction_max");
    eprintln!("root error {root:e} m, inside {inside}");
    assert!(root < 2e-5, "roots {root} m from their skinned scalp points");
    assert!((0.0..=0.005).contains(&inside), "inside fraction {inside}");
}

/// `grow --scalp gltf` writes hair grown on the character's head in its bind
/// pose, and `render`/`simulate --gltf --input` bind that groom's roots to the
/// skinned mesh: the roots ride it as closely as the grown hair's do. A groom
/// whose roots are not on the character is refused, naming a strand.
#[test]
fn a_groom_grown_on_a_gltf_character_is_loaded_and_bound() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/mannequiny-0.3.0.glb");
    let groom = dir.path().join("grown.hair");
    let args = format!("grow --scalp gltf --gltf {glb} --strands 300 --points 12 --out {}", groom.display());
    let grown = run_line(&args, LIMIT);
    grown.assert_ok();
    assert!(grown.stdout.contains("grown on joint \"head\""), "{}", grown.stdout);
    let json = dir.path().join("run.json");
    let args = format!(
        "simulate --gltf {glb} --input {} --animation run --steps 20 --volume off --json {}",
        groom.display(),
        json.display()
    );
    let sim = run_line(&args, LIMIT);
    sim.assert_ok();
    assert!(sim.stdout.contains("300 key hairs"), "{}", sim.stdout);
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parse");
    let root = v["run"]["root_error_max_m"].as_f64().expect("root_error_max_m");
    eprintln!("loaded groom: root error {root:e} m");
    assert!(root < 2e-5, "roots {root} m from their skinned scalp points");
    let out = dir.path().join("frames");
    let args = format!(
        "render --gltf {glb} --input {} --frames 2 --width 160 --height 160 --shadow-resolution 64 --out {}",
        groom.display(),
        out.display()
    );
    run_line(&args, LIMIT).assert_ok();
    let (_, _, rgba) = common::read_png(&out.join("frame_0001.png"));
    let brown = rgba.chunks_exact(4).filter(|p| p[0] > 40 && 3 * u32::from(p[2]) < 2 * u32::from(p[0])).count();
    assert!(brown > 120, "{brown} hair pixels");
    // A groom of the thesis head, nowhere near the character's scalp.
    let far = dir.path().join("far.hair");
    common::write_groom(&far, &common::cap_groom(20, 6, 0.1));
    let args = format!("render --gltf {glb} --input {} --frames 1 --out {}", far.display(), out.display());
    run_line(&args, LIMIT).assert_error("strand");
}

/// Values out of range name their option; library functions are never suggested.
#[test]
fn bad_values_name_their_option() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("g.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 0.1));
    let g = groom.to_str().expect("utf-8");
    let grown = dir.path().join("grown.hair");
    let o = grown.to_str().expect("utf-8");
    let cases: &[(&[&str], &str)] = &[
        (&["render", "--input", g, "--scale", "nan"], "--scale must be a finite number above 0 (got NaN)"),
        (&["simulate", "--input", g, "--scale=-1"], "--scale must be a finite number above 0 (got -1)"),
        (&["simulate", "--input", g, "--points", "100"], "--points must be 2..=64 (got 100)"),
        (&["render", "--input", g, "--points", "1"], "--points must be 2..=64 (got 1)"),
        (&["render", "--distance", "inf"], "--distance must be a finite number above 0"),
        (&["render", "--distance", "1e30"], "--distance must be at most 1e6"),
        (&["render", "--input", g, "--scale", "1e30"], "--scale must be within 1e-6..=1e6 (got 1e30)"),
        (&["simulate", "--input", g, "--scale", "1e-30"], "--scale must be within 1e-6..=1e6 (got 1e-30)"),
        (&["render", "--frames", "0"], "--frames must be at least 1"),
        (&["simulate", "--steps", "0"], "--steps must be at least 1"),
        (&["render", "--distance", "1e-30"], "--distance must be at least 1e-6"),
        (&["simulate", "--steps", "18446744073709551615"], "--steps must be at most 10000000"),
        (&["render", "--frames", "1000001"], "--frames must be at most 1000000"),
        // Parameters a flag sets are named by the flag, not by the library's name.
        (&["render", "--input", g, "--hairs-per-key", "0", "--clumps"], "invalid parameter --hairs-per-key: 0"),
        (&["render", "--input", g, "--level", "0"], "invalid parameter --level: 0 (allowed: 1..=64)"),
        (&["render", "--input", g, "--sorted-fragments", "33"], "invalid parameter --sorted-fragments: 33"),
        (&["render", "--input", g, "--fragments-per-pixel", "0"], "invalid parameter --fragments-per-pixel: 0"),
        (&["render", "--input", g, "--grid", "0"], "invalid parameter --grid: 0 cells"),
        (&["simulate", "--input", g, "--max-iterations", "0"], "invalid parameter --max-iterations: 0"),
        (&["simulate", "--input", g, "--iterations", "0"], "invalid parameter --iterations: 0"),
        (&["render", "--input", g, "--density", "1e9"], "invalid parameter --density: 1000000000"),
        (&["grow", "--scalp", "sphere", "--points", "0", "--out", o], "invalid parameter --points: 0"),
        (&["grow", "--scalp", "sphere", "--radius", "1e30", "--out", o], "--radius \"1e30\": each"),
        (&["grow", "--scalp", "sphere", "--center=NaN,0,0", "--out", o], "--center \"NaN,0,0\": each component"),
        (&["grow", "--scalp", "sphere", "--radius", "1e5", "--out", o], "--radius and --center put the hair 1.000e5"),
        (&["grow", "--scalp", "sphere", "--radius", "1e5", "--out", o], "across, length 0.3, the default)"),
        (&["grow", "--scalp", "sphere", "--radius", "1e5", "--length", "0.2", "--out", o], "across, --length 0.2)"),
        (&["grow", "--scalp", "sphere", "--face=NaN,0,0", "--out", o], "invalid parameter --face: [NaN, 0, 0]"),
        (&["convert", g, "--points", "1", "--out", o], "invalid parameter --points: 1"),
        (&["convert", g, "--key-hairs", "21", "--out", o], "invalid parameter --key-hairs: 21"),
        (&["bench", "--quick", "--grid", "0", "--out", o], "invalid parameter --grid: 0 cells"),
        (&["bench", "--quick", "--large", "0", "--out", o], "--large must be at least 1"),
    ];
    for (args, message) in cases {
        let out = run(args, LIMIT);
        out.assert_error(message);
        assert!(!out.stderr.contains("Groom::") && !out.stdout.contains("NaN ms"), "{args:?}: {}", out.stderr);
        // The bench checks its flags before its first row.
        assert!(args[0] != "bench" || !out.stdout.contains("key hairs"), "{args:?} ran rows first:\n{}", out.stdout);
    }
}

/// Reading errors name the file and say what is wrong with it.
#[test]
fn file_errors_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().expect("temp dir");
    let missing = dir.path().join("no-such.hair");
    run(&["inspect", missing.to_str().expect("utf-8")], LIMIT).assert_error("no-such.hair");
    let groom = dir.path().join("g.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 0.1));
    let binary = dir.path().join("head.obj");
    std::fs::write(&binary, [b'v', b' ', 0xff, 0xfe, 0x00, 0x13]).expect("write");
    let out =
        run(&["render", "--input", groom.to_str().expect("utf-8"), "--obj", binary.to_str().expect("utf-8")], LIMIT);
    out.assert_error("head.obj");
    out.assert_error("not UTF-8 text");
    // A groom whose bounding box overflows f32 is reported as such.
    let huge = dir.path().join("huge.hair");
    let strands = vec![
        vec![Vec3::new(-3e38, 0.0, 0.0), Vec3::new(-1e38, 0.0, 0.0)],
        vec![Vec3::new(3e38, 0.0, 0.0), Vec3::new(2e38, 1e38, 0.0)],
    ];
    std::fs::write(&huge, huge_hair_bytes(&strands)).expect("write");
    run(&["inspect", huge.to_str().expect("utf-8")], LIMIT).assert_error("overflows f32");
}

/// A `.hair` file written byte by byte (the library refuses to build such grooms).
fn huge_hair_bytes(strands: &[Vec<Vec3>]) -> Vec<u8> {
    let points: usize = strands.iter().map(Vec::len).sum();
    let mut b = b"HAIR".to_vec();
    for v in [strands.len() as u32, points as u32, 0b11, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [1.0f32, 0.0, 1.0, 1.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; 88]);
    for s in strands {
        b.extend_from_slice(&(s.len() as u16 - 1).to_le_bytes());
    }
    for p in strands.iter().flatten() {
        for v in p.to_array() {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

/// A TressFX file with one zero-length segment (as TressFX's own `mohawk.tfx`):
/// repaired with a warning that counts what was dropped, refused with --strict.
#[test]
fn a_degenerate_strand_is_repaired_with_a_warning_or_refused_when_strict() {
    let dir = tempfile::tempdir().expect("temp dir");
    let tfx = dir.path().join("mohawk.tfx");
    let (strands, per) = (40u32, 6u32);
    let mut positions: Vec<[f32; 4]> = (0..strands)
        .flat_map(|s| {
            (0..per).map(move |k| [0.01 * s as f32, 0.1 + 0.02 * k as f32, 0.0, if k == 0 { 0.0 } else { 1.0 }])
        })
        .collect();
    positions[(35 * per + 1) as usize] = positions[(35 * per) as usize]; // strand 35, segment 0
    let mut bytes = 4.0f32.to_le_bytes().to_vec();
    for v in [strands, per, 160, 0, 0, 0, 0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.resize(160, 0);
    for p in &positions {
        for v in p {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(&tfx, bytes).expect("write");
    let path = tfx.to_str().expect("utf-8");
    let out = run(&["inspect", path], LIMIT);
    out.assert_ok();
    assert!(out.stderr.contains("warning") && out.stderr.contains("dropped 1 zero-length segment"), "{}", out.stderr);
    assert!(out.stderr.contains("40 strands remain"), "{}", out.stderr);
    assert!(out.stdout.contains("strands            40"), "{}", out.stdout);
    let out = run(&["inspect", path, "--strict"], LIMIT);
    out.assert_error("strand 35 segment 0 has zero length");
    out.assert_error("--strict");
    let frames = dir.path().join("frames");
    let out = run(
        &[
            "render",
            "--input",
            path,
            "--frames",
            "1",
            "--width",
            "32",
            "--height",
            "32",
            "--shadow-resolution",
            "32",
            "--out",
            frames.to_str().expect("utf-8"),
        ],
        LIMIT,
    );
    out.assert_ok();
    assert!(out.stderr.contains("dropped 1 zero-length segment"), "{}", out.stderr);
    run(&["simulate", "--input", path, "--strict", "--steps", "1"], LIMIT).assert_error("zero length");
}

/// The help a command-line user reads names options and files, never library
/// functions.
#[test]
fn help_never_points_at_library_functions() {
    for command in ["devices", "inspect", "grow", "simulate", "render", "config", "plot", "convert", "bench"] {
        let out = run(&[command, "--help"], LIMIT);
        out.assert_ok();
        assert!(!out.stdout.contains("::"), "`vkhair {command} --help` names a library item:\n{}", out.stdout);
    }
}

/// `inspect --drawn` reports the hairs `render` roots over the scalp a groom's
/// roots cover: the density × the area (to one hair), the mean spacing of the
/// roots, and the largest root-free disk within 3 × it at full detail and at
/// a quarter of the hairs; bad values name their option.
#[test]
fn inspect_drawn_reports_how_the_hairs_cover_the_scalp() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("grown.hair");
    let args = format!("grow --scalp sphere --strands 300 --points 8 --out {}", groom.display());
    run_line(&args, LIMIT).assert_ok();
    let g = groom.to_str().expect("utf-8");
    let out = run(&["inspect", g, "--drawn", "--density", "20", "--json"], LIMIT);
    out.assert_ok();
    let v: serde_json::Value = serde_json::from_str(&out.stdout).expect("json");
    let d = &v["drawn"];
    let area = d["scalp_area_cm2"].as_f64().expect("area");
    let hairs = d["full"]["hairs"].as_f64().expect("hairs");
    eprintln!("{area:.1} cm², {hairs} hairs, gap ratios {} and {}", d["full"]["gap_ratio"], d["quarter"]["gap_ratio"]);
    assert!(area > 100.0, "a sphere cap of radius 0.1 m covers {area} cm²");
    assert!((hairs - 20.0 * area).abs() <= 1.0, "{hairs} hairs over {area} cm² at 20 per cm²");
    let spacing = d["full"]["spacing_m"].as_f64().expect("spacing");
    assert!((spacing - (area * 1e-4 / hairs).sqrt()).abs() < 1e-6 * spacing.max(1.0));
    assert!((d["quarter"]["hairs"].as_f64().expect("quarter") - 0.25 * hairs).abs() <= 1.0);
    for level in ["full", "quarter"] {
        let ratio = d[level]["gap_ratio"].as_f64().expect("gap ratio");
        assert!((0.3..=3.0).contains(&ratio), "{level}: a root-free disk {ratio} × the spacing");
    }
    let table = run(&["inspect", g, "--drawn", "--density", "20"], LIMIT);
    table.assert_ok();
    assert!(table.stdout.contains("largest root-free disk"), "{}", table.stdout);
    run(&["inspect", g, "--drawn", "--scale", "0"], LIMIT).assert_error("--scale must be a finite number above 0");
    run(&["inspect", g, "--drawn", "--density", "5000"], LIMIT).assert_error("scalp.density");
    run(&["inspect", g, "--density", "20"], LIMIT).assert_error("--drawn");
}

/// A groom whose size is absurd for the tool's scene (a nanometre across, or
/// 10⁸ units) is refused at load naming the file, its size and `--scale`,
/// not by an internal parameter derived from it; one large but within the
/// bound (600 units across, whose lights and scalp once failed as
/// `light color` and `scalp.density`) is drawn.
#[test]
fn an_absurdly_sized_groom_is_refused_naming_the_file_and_its_size() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, radius) in [("tiny.hair", 1e-9f32), ("huge.hair", 1e8)] {
        let groom = dir.path().join(name);
        common::write_groom(&groom, &common::cap_groom(20, 6, radius));
        let args = format!("render --input {} --frames 1 --out {}", groom.display(), dir.path().join("f").display());
        let out = run_line(&args, LIMIT);
        out.assert_error(name);
        for words in ["spans", "--scale"] {
            assert!(out.stderr.contains(words), "{name}: {}", out.stderr);
        }
        assert!(!out.stderr.contains("invalid parameter"), "{name}: an internal parameter named: {}", out.stderr);
    }
    // Large but within the bound (a groom 600 units across: its lights 1,300
    // times as far as the thesis', its scalp too large to root): drawn, its
    // hairs grown around the key hairs, with a warning naming --scale.
    let groom = dir.path().join("large.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 300.0));
    let args = format!(
        "render --input {} --frames 1 --width 32 --height 32 --out {}",
        groom.display(),
        dir.path().join("l").display()
    );
    let out = run_line(&args, LIMIT);
    out.assert_ok();
    assert!(out.stderr.contains("--scale") && out.stderr.contains("in clumps"), "{}", out.stderr);
    assert!(!out.stderr.contains("invalid parameter"), "an internal parameter named: {}", out.stderr);
}

/// `grow` without `--scalp` grows the reference scene, whatever the strand
/// flags say: it says so when they are given, rather than writing 1,750
/// strands of 6 points to someone who asked for 300 of 12.
#[test]
fn grow_says_when_the_reference_scene_ignores_its_strand_flags() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("g.hair");
    let run = run(&["grow", "--strands", "300", "--points", "12", "--out", out.to_str().expect("utf-8")], LIMIT);
    run.assert_ok();
    assert!(run.stderr.contains("--strands, --points and --length are ignored"), "{}", run.stderr);
    assert!(run.stdout.contains("1750 strands"), "{}", run.stdout);
    let sphere = dir.path().join("s.hair");
    let args =
        ["grow", "--scalp", "sphere", "--strands", "300", "--points", "12", "--out", sphere.to_str().expect("utf-8")];
    let run = common::run(&args, LIMIT);
    run.assert_ok();
    assert!(!run.stderr.contains("ignored") && run.stdout.contains("300 strands"), "{}", run.stdout);
}
