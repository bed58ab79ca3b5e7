//! `vkhair bench` as a user meets it: a quick run reports every stage beside its
//! CPU reference with the keys the JSON promises, the one-dispatch step, and a
//! scaling chart.

use crate::common;

use std::time::Duration;

use common::run;

const LIMIT: Duration = Duration::from_secs(600);

#[test]
fn a_quick_bench_reports_every_stage_with_its_reference_and_writes_json_and_a_chart() {
    let dir = tempfile::tempdir().expect("temp dir");
    let json = dir.path().join("bench.json");
    let out = dir.path().join("charts");
    let (json_arg, out_arg) = (json.display().to_string(), out.display().to_string());
    // No Sintel here: its rows are skipped with the reason printed.
    let missing = dir.path().join("no-sintel").display().to_string();
    let args = [
        "bench",
        "--quick",
        "--samples",
        "8",
        // Every simulation figure past its budget at once: 5 samples each.
        "--figure-seconds",
        "0.001",
        "--scaling-samples",
        "1",
        "--json",
        &json_arg,
        "--out",
        &out_arg,
        "--sintel",
        &missing,
        "--iterations",
        "7",
    ];
    let r = run(&args, LIMIT);
    r.assert_ok();
    assert!(r.stdout.contains("skipped Sintel"), "{}", r.stdout);
    // The simulation knobs every simulating command takes reach bench's rows.
    assert!(r.stdout.contains("parameters: 7 iterations, Pbd solver"), "{}", r.stdout);
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parse");
    assert_eq!(v["iterations"], 7, "{v}");
    for key in [
        "gpu_ms_per_step",
        "cpu_ms_per_step",
        "dispatches_per_step",
        "barriers_per_step",
        "volume_gpu_ms_per_step",
        "volume_cpu_ms_per_step",
    ] {
        assert!(v[key].is_number(), "{key} missing or not a number: {}", v[key]);
    }
    assert_eq!(v["dispatches_per_step"], 1, "the step is one dispatch with the volume stage off");
    assert_eq!(v["barriers_per_step"], 2);
    let stages = v["stages"].as_array().expect("stages");
    for stage in ["sim, volume off", "sim, density friction 32³", "sim, FLIP 32³", "sim, FLIP 32³: volume stage alone"]
    {
        let rows: Vec<_> = stages.iter().filter(|s| s["stage"] == stage).collect();
        assert_eq!(rows.len(), 2, "{stage}: the thesis scene and the generated groom");
        for row in rows {
            assert!(row["gpu_ms_per_step"].as_f64().is_some_and(|x| x > 0.0), "{row}");
            assert!(row["cpu_ms_per_step"].as_f64().is_some_and(|x| x > 0.0), "{row}");
            assert!(row["bandwidth_bound_ms"]["H100 SXM"].is_number(), "{row}");
            assert_eq!(row["samples"], 5, "a figure past its budget keeps 5 samples: {row}");
        }
    }
    let frames: Vec<_> = stages.iter().filter(|s| s["per"] == "frame").collect();
    assert_eq!(frames.len(), 5, "the thesis frame in the default mode, off, fast, exact K = 4 and 16");
    for frame in &frames {
        assert!(frame["gpu_ms_per_frame"].as_f64().is_some_and(|x| x > 0.0), "{frame}");
        assert_eq!(frame["samples"], 8, "frames take every sample asked for: {frame}");
        assert!(frame["error_vs_reference_srgb_steps"].as_f64().is_some_and(|x| x > 0.0), "{frame}");
    }
    let error = |stage: &str| {
        let row = frames.iter().find(|f| f["stage"].as_str().is_some_and(|s| s.contains(stage))).expect(stage);
        row["error_vs_reference_srgb_steps"].as_f64().unwrap_or(f64::NAN)
    };
    // --quick draws a tenth of a scalp's hairs: 15 a cm², 9,661 over the thesis' scalp.
    let default_frame = frames.iter().find_map(|f| f["stage"].as_str().filter(|s| s.contains("segments")));
    assert!(default_frame.is_some_and(|s| s.contains(" 9661 hairs")), "{default_frame:?}");
    let (default, off) = (error("segments"), error("transparency off"));
    assert!(default < 0.5 * off, "the default (exact) frame's error {default} is not below half of off's {off}");
    let csv = std::fs::read_to_string(out.join("transparency.csv")).expect("transparency.csv");
    assert_eq!(csv.lines().count(), 6, "a header and a row per mode: {csv}");
    // The frame in the off and the default (exact) mode at the top level, the
    // figures of their rows; Sintel's are null where it was skipped.
    let figure = |stage: &str| {
        frames
            .iter()
            .find(|f| f["stage"].as_str().is_some_and(|s| s.contains(stage)))
            .map(|f| f["gpu_ms_per_frame"].clone())
    };
    assert_eq!(Some(v["frame_ms_off"].clone()), figure("transparency off"), "{v}");
    assert_eq!(Some(v["frame_ms_exact"].clone()), figure("segments"), "{v}");
    assert!(v["frame_ms_off"].is_number() && v["frame_ms_exact"].is_number(), "{v}");
    // Without Sintel its figures are null, and so is the ground-truth comparison.
    for key in ["sintel_frame_ms_off", "sintel_frame_ms_exact", "sintel_step_ms_4it", "sintel_step_ms_20it"] {
        assert!(v[key].is_null(), "{key}: {v}");
    }
    assert!(v["peer_work_step_ms_4it"].is_null() && v["sintel_truth"].is_null(), "{v}");
    // The FLIP stage's dispatches per step: those of the thesis' volume stage alone.
    let flip = stages
        .iter()
        .find(|s| s["stage"] == "sim, FLIP 32³: volume stage alone")
        .map(|s| s["dispatches_per_step"].clone())
        .expect("the FLIP row");
    assert!(v["flip_dispatches_per_step"].as_u64().is_some_and(|d| d > 1), "{v}");
    assert_eq!(v["flip_dispatches_per_step"], flip, "{v}");
    let (w, h, _) = common::read_png(&out.join("transparency.png"));
    assert_eq!((w, h), (1100, 500));
    let scaling = v["scaling"].as_array().expect("scaling");
    assert_eq!(scaling.len(), 5, "hairs, points, simulated hairs, grid, resolution");
    // The level-of-detail curve: half the quick run's 200 key hairs, then all.
    let simulated: Vec<_> =
        scaling[2]["points"].as_array().expect("points").iter().map(|p| p["work"].clone()).collect();
    assert_eq!(simulated, [serde_json::json!(100.0), serde_json::json!(200.0)], "{}", scaling[2]);
    assert!(scaling[2]["axis"].as_str().is_some_and(|a| a.starts_with("simulated key hairs")), "{}", scaling[2]);
    let pixels: Vec<_> = scaling[4]["points"].as_array().expect("points").iter().map(|p| p["work"].clone()).collect();
    assert_eq!(pixels, [serde_json::json!(160.0 * 120.0), serde_json::json!(1920.0 * 1080.0)], "a point at 1080p");
    assert!(scaling[0]["gpu_exponent"].is_number() && scaling[0]["cpu_exponent"].is_number(), "{}", scaling[0]);
    let png = out.join("scaling.png");
    let (w, h, _) = common::read_png(&png);
    assert_eq!((w, h), (1100, 900));
}

#[test]
fn require_gpu_refuses_a_cpu_device() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("never");
    let r = run(&["bench", "--require-gpu", "--quick", "--out", out.to_str().expect("utf-8")], LIMIT);
    if r.stdout.contains("llvmpipe") || r.stderr.contains("CPU implementation") {
        r.assert_error("--require-gpu");
        assert!(!out.exists(), "the refused run left its --out folder behind");
    } else {
        eprintln!("a GPU is present: --require-gpu accepted it (nothing to refuse here)");
    }
}

/// `tools/gpu-bench.sh --smoke` runs every goal of the GPU report (the thesis
/// frame, the four simulation steps, the drawn strands with transparency, the
/// frame's goals for each rasteriser, the interpolation's cost a segment both
/// ways) at toy sizes and writes one report naming each with the device and a
/// GPU figure, each step and frame goal's figure beside its bound.
#[test]
fn the_gpu_bench_script_runs_every_goal_and_writes_one_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/gpu-bench.sh");
    let mut command = std::process::Command::new("bash");
    command
        .arg(&script)
        .arg("--smoke")
        .env("VKHAIR_BIN", env!("CARGO_BIN_EXE_vkhair"))
        .env("VKHAIR_OUT", dir.path())
        .env("VKHAIR_VALIDATION", "1");
    let r = common::run_command(&mut command, LIMIT);
    assert!(r.status.success(), "{}\n{}", r.stdout, r.stderr);
    let report = std::fs::read_to_string(dir.path().join("report.txt")).expect("report.txt");
    let goals = [
        "a. thesis full frame",
        "b. simulation of 300 guides × 32 points, FLIP",
        "b2. simulation of 300 guides × 32 points, density friction",
        "b3. the thesis scene's simulation, FLIP",
        "b4. simulation of 300 guides × 32 points, FLIP on a 32³ grid",
        "c. 7000 drawn strands",
    ];
    for goal in goals {
        assert!(report.contains(goal), "{goal} missing from:\n{report}");
    }
    let figures: Vec<f64> = report
        .lines()
        .filter_map(|l| l.split_once("GPU ms per frame or step (timestamps, mean): "))
        .map(|(_, x)| x.trim().parse().expect("a number"))
        .collect();
    assert_eq!(figures.len(), 6, "{report}");
    assert!(figures.iter().all(|&x| x > 0.0), "{report}");
    assert_eq!(report.matches(" key hairs × ").count(), 6, "each goal names its device and scene:\n{report}");
    let step_goals: Vec<&str> = report.lines().filter(|l| l.contains("ms a step: ")).collect();
    assert_eq!(step_goals.len(), 4, "the simulation goals, each beside its bound:\n{report}");
    assert!(step_goals.iter().all(|l| l.ends_with(": met") || l.ends_with(": missed")), "{report}");
    for json in
        ["thesis_frame.json", "guides_step.json", "friction_step.json", "thesis_step.json", "friction_flip_step.json"]
            .into_iter()
            .chain(["strands_frame.json"])
    {
        let text = std::fs::read_to_string(dir.path().join("goals").join(json)).expect(json);
        let v: serde_json::Value = serde_json::from_str(&text).expect("parse");
        assert!(v["passes"].as_array().is_some_and(|p| !p.is_empty()), "{json}: {v}");
    }
    let log = std::fs::read_to_string(dir.path().join("goals/log.txt")).expect("log");
    assert!(!log.contains("vulkan: ") && !log.contains("panicked"), "{log}");
    // The frame's goals: per rasteriser, the thesis (opaque, exact, and their
    // ratio), the strands, the dense groom, the memory, and Sintel's two where
    // its files are here; each a number beside its bound.
    assert!(report.contains("d. the frame's goals"), "{report}");
    let sintel = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/sintel/sintel_hair.tfx");
    let per_raster = if sintel.exists() { 8 } else { 6 };
    for raster in ["hardware", "compute", "tiles"] {
        let section = report.split(&format!(" --raster {raster}\n")).nth(1).expect("the rasteriser's section");
        let lines: Vec<&str> = section.lines().take_while(|l| !l.starts_with(" --raster")).collect();
        let goals: Vec<&str> = lines.iter().copied().filter(|l| l.contains("goal ≤")).collect();
        assert_eq!(goals.len(), per_raster, "{raster}: {goals:#?}\n{report}");
        for line in goals {
            // "name   figure unit   goal ≤ bound unit: met"
            let before_goal: Vec<&str> = line.split("goal ≤").next().unwrap_or("").split_whitespace().collect();
            let figure: f64 = before_goal
                .len()
                .checked_sub(2)
                .and_then(|i| before_goal[i].parse().ok())
                .unwrap_or_else(|| panic!("no figure in {line:?}"));
            assert!(figure > 0.0, "{line}");
            assert!(line.ends_with(": met") || line.ends_with(": missed"), "{line}");
        }
    }
    // The interpolation's ns a drawn segment: the compute dispatch (thesis,
    // strands) and the tessellation stages (thesis), each a number.
    let section = report.split(" interpolation, ns a drawn segment").nth(1).expect("the interpolation's lines");
    let ns: Vec<f64> = section
        .lines()
        .filter_map(|l| l.trim_end().strip_suffix(" ns"))
        .map(|l| l.split_whitespace().last().and_then(|x| x.parse().ok()).expect("a figure"))
        .collect();
    assert_eq!(ns.len(), 3, "{report}");
    assert!(ns.iter().all(|&x| x > 0.0), "{report}");
    for entry in std::fs::read_dir(dir.path().join("frame")).expect("frame/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "txt") {
            let text = std::fs::read_to_string(&path).expect("a frame goal's output");
            assert!(!text.contains("vulkan: ") && !text.contains("panicked"), "{}: {text}", path.display());
        }
    }
    assert!(report.contains("smoke sizes") && !report.contains("bench:"), "the smoke run skips the bench:\n{report}");
}
