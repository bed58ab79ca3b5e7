//! The profile a user takes home from `vkhair render` and `vkhair simulate`:
//! the per-pass table, the Chrome trace and the JSON summary, all from the same
//! reports; and memory that does not grow with the frame count.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

use common::{run, Run};
use serde_json::Value;

const LIMIT: Duration = Duration::from_secs(300);

/// The table's rows: (track header, pass name) → mean ms, and each track's total.
fn table(stdout: &str) -> (BTreeMap<(String, String), f64>, BTreeMap<String, f64>) {
    let (mut rows, mut totals) = (BTreeMap::new(), BTreeMap::new());
    let mut track = None;
    for line in stdout.lines() {
        if let Some(rest) = line.strip_prefix("GPU pass (") {
            track = rest.split("), per ").next().map(str::to_owned);
            continue;
        }
        let Some(t) = &track else { continue };
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.first() == Some(&"total") {
            totals.insert(t.clone(), words[1].parse().expect("total"));
            track = None;
        } else if words.len() >= 4 && words[words.len() - 1].ends_with('%') {
            let name = words[..words.len() - 3].join(" ");
            rows.insert((t.clone(), name), words[words.len() - 3].parse().expect("mean"));
        }
    }
    (rows, totals)
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).expect("read")).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The summary's `field` of every pass, by (track, name).
fn summary_passes(summary: &Value, field: &str) -> BTreeMap<(String, String), Value> {
    let passes = summary["passes"].as_array().expect("passes");
    passes
        .iter()
        .map(|p| {
            let key = (p["track"].as_str().expect("track").to_owned(), p["name"].as_str().expect("name").to_owned());
            (key, p[field].clone())
        })
        .collect()
}

/// Checks that the trace is what Perfetto loads (complete events with numeric
/// times, properly nested per thread, named threads) and agrees with the
/// summary: the same passes, each as many times as the summary counts.
fn check_trace_against_summary(trace: &Value, summary: &Value) {
    let events = trace["traceEvents"].as_array().expect("traceEvents");
    let names: BTreeMap<u64, String> = events
        .iter()
        .filter(|e| e["ph"] == "M" && e["name"] == "thread_name")
        .map(|e| (e["tid"].as_u64().expect("tid"), e["args"]["name"].as_str().expect("name").to_owned()))
        .collect();
    let complete: Vec<&Value> = events.iter().filter(|e| e["ph"] == "X").collect();
    assert!(!complete.is_empty());
    let mut counts: BTreeMap<(String, String), u64> = BTreeMap::new();
    for e in &complete {
        let (ts, dur) = (e["ts"].as_f64().expect("ts"), e["dur"].as_f64().expect("dur"));
        assert!(ts.is_finite() && dur >= 0.0, "{e}");
        let thread = names.get(&e["tid"].as_u64().expect("tid")).expect("every event's thread is named");
        if let Some(track) = thread.strip_prefix("GPU: ") {
            *counts.entry((track.to_owned(), e["name"].as_str().expect("name").to_owned())).or_default() += 1;
        }
    }
    for tid in names.keys() {
        let mut spans: Vec<(f64, f64)> = complete
            .iter()
            .filter(|e| e["tid"].as_u64() == Some(*tid))
            .map(|e| {
                (e["ts"].as_f64().unwrap_or(0.0), e["ts"].as_f64().unwrap_or(0.0) + e["dur"].as_f64().unwrap_or(0.0))
            })
            .collect();
        spans.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (i, a) in spans.iter().enumerate() {
            for b in &spans[i + 1..] {
                assert!(b.0 >= a.1 || b.1 <= a.1, "thread {tid}: {a:?} and {b:?} overlap without nesting");
            }
        }
    }
    let summarised: BTreeMap<(String, String), u64> =
        summary_passes(summary, "events").into_iter().map(|(k, v)| (k, v.as_u64().expect("events"))).collect();
    assert_eq!(counts, summarised, "the trace's GPU events and the summary's passes differ");
    // Calibrated timestamps put the GPU on the CPU's clock: GPU events lie
    // within the CPU frame spans.
    if trace["otherData"]["gpu_clock"].as_str().is_some_and(|c| c.contains("calibrated")) {
        let on = |prefix: &str| -> Vec<(f64, f64)> {
            complete
                .iter()
                .filter(|e| names.get(&e["tid"].as_u64().unwrap_or(0)).is_some_and(|n| n.starts_with(prefix)))
                .map(|e| {
                    let ts = e["ts"].as_f64().unwrap_or(0.0);
                    (ts, ts + e["dur"].as_f64().unwrap_or(0.0))
                })
                .collect()
        };
        let cpu = on("CPU");
        let cpu_start = cpu.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
        let cpu_end = cpu.iter().map(|s| s.1).fold(0.0, f64::max);
        for (ts, _) in on("GPU") {
            assert!(
                ts >= cpu_start && ts <= cpu_end,
                "GPU event at {ts} µs outside the CPU spans {cpu_start}..{cpu_end}"
            );
        }
    } else {
        eprintln!("note: the device has no calibrated timestamps; GPU events stay on the device clock");
    }
}

fn check_table_against_summary(out: &Run, summary: &Value) {
    let (rows, totals) = table(&out.stdout);
    let summarised: BTreeMap<(String, String), f64> =
        summary_passes(summary, "mean_ms").into_iter().map(|(k, v)| (k, v.as_f64().expect("mean"))).collect();
    assert_eq!(rows.keys().collect::<Vec<_>>(), summarised.keys().collect::<Vec<_>>(), "{}", out.stdout);
    for (key, mean) in &rows {
        assert!(
            (mean - summarised[key]).abs() <= 0.0005 + 1e-3 * mean,
            "{key:?}: table {mean}, summary {}",
            summarised[key]
        );
    }
    assert!(totals.values().all(|t| *t > 0.0), "a track's total is zero:\n{}", out.stdout);
}

/// Runs `vkhair <args>` (split at spaces) with --trace and --json (and for
/// `render`, --out) in a temporary folder, checks that the table, the summary
/// and the trace agree, and returns the run and the summary.
fn profiled(args: &str) -> (Run, Value) {
    let dir = tempfile::tempdir().expect("temp dir");
    let (trace, summary) = (dir.path().join("trace.json"), dir.path().join("run.json"));
    let mut all: Vec<String> = args.split_whitespace().map(str::to_owned).collect();
    if all[0] == "render" {
        all.extend(["--out".into(), dir.path().join("frames").display().to_string()]);
    }
    all.extend(["--trace".into(), trace.display().to_string(), "--json".into(), summary.display().to_string()]);
    let out = run(&all.iter().map(String::as_str).collect::<Vec<_>>(), LIMIT);
    out.assert_ok();
    let summary = json(&summary);
    check_table_against_summary(&out, &summary);
    check_trace_against_summary(&json(&trace), &summary);
    (out, summary)
}

#[test]
fn render_lists_every_pass_and_writes_a_trace_and_summary_that_agree() {
    let (out, summary) =
        profiled("render --frames 3 --width 64 --height 48 --shadow-resolution 64 --ssaa --schedule single");
    let (rows, totals) = table(&out.stdout);
    let track = "graphics queue".to_owned();
    for pass in [
        "vkhair sim: step",
        "vkhair render: smooth",
        "vkhair render: interpolate",
        "vkhair render: shadow depth",
        "vkhair render: shadow depth, light 0",
        "vkhair render: shadow depth, light 1",
        "vkhair render: shadow opacity",
        "vkhair render: shadow opacity, light 0",
        "vkhair render: shadow opacity, light 1",
        "vkhair render: draw",
        "vkhair render: draw, vertex shading",
        "vkhair render: draw, build",
        "vkhair render: resolve",
    ] {
        assert!(rows.contains_key(&(track.clone(), pass.to_owned())), "{pass} missing from the table:\n{}", out.stdout);
    }
    assert!(totals[&track] > 0.0, "{}", out.stdout);
    assert!(rows[&(track.clone(), "vkhair render: draw".to_owned())] > 0.0);
    assert_eq!(summary["run"]["frames"], 3);
    assert_eq!(summary["per"], "frame");
    // The compute rasteriser's frame names its resolve in compute.
    let (out, _) = profiled("render --frames 2 --width 64 --height 48 --raster compute --schedule single");
    let (rows, _) = table(&out.stdout);
    for pass in ["vkhair render: draw, build", "vkhair render: composite, resolve in compute"] {
        assert!(rows.contains_key(&(track.clone(), pass.to_owned())), "{pass} missing from the table:\n{}", out.stdout);
    }
}

#[test]
fn simulate_writes_a_trace_and_summary_that_agree_with_its_table() {
    let (out, summary) = profiled("simulate --steps 25 --volume flip --grid 16");
    assert_eq!(summary["per"], "step");
    let (rows, _) = table(&out.stdout);
    for pass in ["vkhair sim: step", "vkhair sim: volume scatter", "vkhair sim: volume pressure"] {
        assert!(rows.keys().any(|(_, name)| name == pass), "{pass} missing:\n{}", out.stdout);
    }
}

/// Frames stream to disk: the peak resident memory of 40 frames is within 10 %
/// of 10 frames' (keeping every 1024 × 768 frame would add 94 MB).
#[test]
fn render_memory_does_not_grow_with_the_frame_count() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("g.hair");
    common::write_groom(&groom, &common::cap_groom(40, 8, 0.1));
    let peak = |frames: u32| {
        let args = format!(
            "render --input {} --motion still --no-shadows --clumps --hairs-per-key 1 --width 1024 --height 768 --frames {frames}",
            groom.display()
        );
        profiled(&args).1["peak_resident_bytes"].as_f64().expect("peak")
    };
    let (ten, forty) = (peak(10), peak(40));
    eprintln!("peak resident memory: 10 frames {:.1} MB, 40 frames {:.1} MB", ten / 1e6, forty / 1e6);
    assert!(ten > 0.0);
    assert!(forty <= 1.1 * ten, "40 frames peak at {forty} bytes, 10 frames at {ten}");
}

/// Nothing grows per frame in the default mode (soft hair, two shadowed
/// lights): the peak resident memory of 80 frames is within 5 % of 10 frames'.
/// lavapipe renders single-threaded here (`LP_NUM_THREADS=0`): with its
/// rasterizer threads, whether two of its scenes overlap at some moment moves
/// the peak by about 13 MB either way, for 10 frames as for 80.
#[test]
fn memory_stays_flat_however_many_frames_are_rendered() {
    let dir = tempfile::tempdir().expect("temp dir");
    let peak = |frames: u32| {
        let summary = dir.path().join(format!("run{frames}.json"));
        let out = dir.path().join(format!("frames{frames}"));
        let frames = frames.to_string();
        let args = [
            "render",
            "--width",
            "32",
            "--height",
            "32",
            "--shadow-resolution",
            "64",
            "--clumps",
            "--hairs-per-key",
            "1",
        ];
        let mut command = common::vkhair();
        command
            .env("LP_NUM_THREADS", "0")
            .args(args)
            .args(["--frames", &frames, "--out"])
            .arg(&out)
            .arg("--json")
            .arg(&summary);
        common::run_command(&mut command, LIMIT).assert_ok();
        json(&summary)["peak_resident_bytes"].as_f64().expect("peak")
    };
    let (ten, eighty) = (peak(10), peak(80));
    eprintln!("peak resident memory: 10 frames {:.1} MB, 80 frames {:.1} MB", ten / 1e6, eighty / 1e6);
    assert!(ten > 0.0);
    assert!(eighty <= 1.05 * ten, "80 frames peak at {eighty} bytes, 10 frames at {ten}");
}

/// With the simulation on a second device, the table and the trace have one
/// track per device, and still agree.
#[test]
fn a_second_device_gets_its_own_track() {
    let (out, _) = profiled("render --schedule second-device --frames 3 --width 32 --height 32 --shadow-resolution 32");
    let (rows, totals) = table(&out.stdout);
    let sim = "simulation, second device".to_owned();
    assert!(rows.contains_key(&(sim.clone(), "vkhair sim: step".to_owned())), "{}", out.stdout);
    assert!(rows.contains_key(&("graphics queue".to_owned(), "vkhair render: draw".to_owned())), "{}", out.stdout);
    assert_eq!(totals.len(), 2, "{}", out.stdout);
}
