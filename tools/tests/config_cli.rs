//! `vkhair config` and `--config` as a user meets them: the printed defaults
//! are a valid file, a bad file is rejected with its place before any GPU
//! work, and flags win over the file.

use std::path::PathBuf;
use std::process::Command;

/// The binary with validation on: a validation message shows as `vulkan: …`
/// on stderr, which [`clean`] refuses.
fn vkhair() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_vkhair"));
    c.env("VKHAIR_VALIDATION", "1");
    c
}

/// A successful run without a validation message; its standard output.
fn clean(out: &std::process::Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("vulkan: "), "validation message:\n{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vkhair-config-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path
}

#[test]
fn printed_defaults_are_a_valid_parameter_file() {
    let out = vkhair().arg("config").output().expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).expect("utf-8");
    assert!(text.contains("[sim.volume]") && text.contains("# iterations = 20"), "{text}");
    // Uncommented, it is a file that sets every default explicitly.
    let uncommented: String = text
        .lines()
        .map(|l| l.strip_prefix("# ").filter(|r| r.contains(" = ") && !r.starts_with(' ')).unwrap_or(l))
        .filter(|l| !l.starts_with("# ") && !l.starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    let path = temp("defaults.toml", &uncommented);
    let out =
        vkhair().args(["simulate", "--steps", "1", "--volume", "off", "--config"]).arg(&path).output().expect("run");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("parameters: 20 iterations, Pbd solver, volume Off"), "{stdout}");
}

#[test]
fn a_bad_file_is_rejected_with_its_place_before_any_gpu_work() {
    let cases = [
        ("unknown.toml", "[sim]\ndt = 0.01\nitrations = 4\n", "unknown.toml:3: sim.itrations: unknown key"),
        ("type.toml", "[sim.volume]\nmode = 3\n", "type.toml:2: sim.volume.mode"),
        ("range.toml", "[render]\nhairs_per_key = 2000\n", "range.toml:2: render.hairs_per_key: 2000 is not allowed"),
    ];
    for (name, text, expected) in cases {
        let path = temp(name, text);
        for command in ["simulate", "render"] {
            let out = vkhair().args([command, "--config"]).arg(&path).output().expect("run");
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{command} {name}: {stderr}");
            assert!(stderr.contains(expected), "{command} {name}: {stderr}");
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(!stdout.contains("simulation") && !stdout.contains("key hairs"), "GPU work started: {stdout}");
        }
    }
}

#[test]
fn flags_win_over_the_file() {
    let path = temp("styled.toml", "[sim]\niterations = 5\nwind = [5.0, 0.0, 0.0]\nwind_enabled = true\n[sim.volume]\nmode = \"friction\"\nresolution = [8, 8, 8]\n");
    let run = |extra: &[&str]| {
        let out = vkhair().args(["simulate", "--steps", "1", "--config"]).arg(&path).args(extra).output().expect("run");
        clean(&out)
    };
    let from_file = run(&[]);
    assert!(from_file.contains("parameters: 5 iterations, Pbd solver, volume Friction at [8, 8, 8]"), "{from_file}");
    let overridden = run(&["--iterations", "7", "--volume", "off"]);
    assert!(overridden.contains("parameters: 7 iterations, Pbd solver, volume Off at [8, 8, 8]"), "{overridden}");
}

/// `simulate --motion still --out` with the bob preset: the drift line says the
/// style held, and the written file has one strand per input strand.
#[test]
fn simulate_reports_the_drift_and_writes_the_final_strands() {
    let out_path = temp("final.hair", "");
    let preset = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../presets/bob.toml");
    let run = |extra: &[&str]| {
        let out = vkhair()
            .args(["simulate", "--steps", "60", "--volume", "off", "--motion", "still", "--out"])
            .arg(&out_path)
            .args(extra)
            .output()
            .expect("run");
        let stdout = clean(&out);
        let line = stdout.lines().find(|l| l.starts_with("tip drift from rest:")).expect("drift line").to_owned();
        let p95: f32 =
            line.split("p95 ").nth(1).and_then(|r| r.split(' ').next()).and_then(|v| v.parse().ok()).expect("p95");
        p95
    };
    let styled = run(&["--config", preset.to_str().expect("path")]);
    let unstyled = run(&[]);
    assert!(styled < 2.0, "the bob preset let the tips drift {styled} %");
    assert!(unstyled > 10.0 * styled, "defaults {unstyled} % against the preset's {styled} %");
    let file = vkhair::groom::cyhair::HairFile::open(&out_path).expect("written file");
    assert_eq!(file.groom.strand_count(), 1750);
    assert_eq!(file.groom.point_count(), 1750 * 6);
}

/// An `--input` groom is simulated with the styled parameters
/// (`SimParams::styled`: global shape over the whole strand, sag-free, spring
/// off) unless a file says otherwise; the thesis scene keeps its spring.
#[test]
fn an_input_groom_is_held_in_its_style_by_default() {
    let groom = temp("g.hair", "");
    let strands: Vec<Vec<glam::Vec3>> = (0..20)
        .map(|i| (0..6).map(|k| glam::Vec3::new(0.01 * i as f32, 1.7 - 0.02 * k as f32, 0.0)).collect())
        .collect();
    let file = vkhair::groom::cyhair::HairFile::new(vkhair::Groom::from_strands(&strands).expect("groom"), "t");
    file.save(&groom).expect("save");
    let styled = clean(
        &vkhair().args(["simulate", "--steps", "1", "--volume", "off", "--input"]).arg(&groom).output().expect("run"),
    );
    let s = vkhair::sim::SimParams::styled();
    let expected = format!(
        "style: global shape {:.2} over {:.2} of the strand, local shape {:.2}, rest-shape spring off, sag-free on",
        s.global_shape_stiffness, s.global_shape_range, s.local_shape_stiffness
    );
    assert!(styled.contains(&expected), "{styled}");
    let thesis = clean(&vkhair().args(["simulate", "--steps", "1", "--volume", "off"]).output().expect("run"));
    assert!(thesis.contains("rest-shape spring on"), "{thesis}");
    let path = temp("unstyled.toml", "[sim]\nglobal_shape_stiffness = 0.0\n");
    let from_file = clean(
        &vkhair()
            .args(["simulate", "--steps", "1", "--volume", "off", "--config"])
            .arg(&path)
            .arg("--input")
            .arg(&groom)
            .output()
            .expect("run"),
    );
    assert!(from_file.contains("style: global shape 0.00"), "{from_file}");
}

/// The simulation knobs are one argument group: every flag works the same on
/// `simulate` and `render` (and `bench`, tools/tests/bench_cli.rs), reaching
/// the parameters the simulation runs with.
#[test]
fn every_simulation_knob_flag_works_on_every_command_that_simulates() {
    let knobs = [
        "--iterations",
        "7",
        "--substeps",
        "2",
        "--dftl",
        "--volume",
        "friction",
        "--grid",
        "12",
        "--jacobi",
        "--max-iterations",
        "9",
        "--pressure",
        "dispatched",
        "--motion",
        "still",
    ];
    let expected = "parameters: 7 iterations, Dftl solver, volume Friction at [12, 12, 12], 2 sub-steps, \
                    Jacobi pressure solve (Dispatched) capped at 9 iterations, motion Still";
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("frames").display().to_string();
    let render = ["render", "--frames", "1", "--width", "32", "--height", "32", "--no-shadows", "--out", &out];
    for command in [&["simulate", "--steps", "2"][..], &render[..]] {
        let out = vkhair().args(command).args(knobs).output().expect("run");
        let stdout = clean(&out);
        assert!(stdout.contains(expected), "{}: {stdout}", command[0]);
    }
    // A flag the scene cannot honour is refused before any work.
    let out = vkhair().args(["render", "--volume", "off", "--volume-shadows"]).output().expect("run");
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--volume-shadows needs the simulation's volume stage"));
}
