//! `vkhair simulate` as a user meets it: a --check that states its tolerance and
//! holds the README's promises, progress on long runs, the violent motion.

use crate::common;

use std::process::Command;
use std::time::Duration;

use common::run;

const LIMIT: Duration = Duration::from_secs(600);

/// Without FLIP (volume off, density friction) the GPU and the CPU reference
/// agree bit for bit on lavapipe, as the README says; with FLIP single steps
/// agree within the stated tolerance. Each run states the tolerance.
#[test]
fn check_states_its_tolerance_and_holds_the_readme_promises() {
    for (volume, whole_run) in [("off", true), ("friction", true), ("flip", false)] {
        let out = run(&["simulate", "--steps", "20", "--grid", "16", "--volume", volume, "--check"], LIMIT);
        out.assert_ok();
        assert!(out.stdout.contains("(tolerance 1e-5 m)"), "{volume}: {}", out.stdout);
        let lavapipe = out.stdout.contains("llvmpipe");
        if whole_run {
            let line = out.stdout.lines().find(|l| l.contains("the whole run")).expect("whole-run line");
            if lavapipe {
                assert!(line.contains("0 (bit for bit)"), "{volume}: {line}");
            } else {
                eprintln!("not lavapipe: {line}");
            }
        } else {
            assert!(!out.stdout.contains("the whole run"), "{}", out.stdout);
        }
        // A friction run has no pressure solve to call unconverged.
        if volume == "friction" {
            assert!(
                out.stdout.contains("no pressure solve") && !out.stdout.contains("not converged"),
                "{}",
                out.stdout
            );
        }
    }
}

/// The violent motion exists for soak runs and stays finite.
#[test]
fn violent_motion_runs() {
    let out = run(&["simulate", "--steps", "30", "--motion", "violent", "--volume", "off"], LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("tip drift from rest") && !out.stdout.contains("NaN"), "{}", out.stdout);
}

/// On a terminal, a long run shows a progress bar with an ETA (`script` gives
/// the program a terminal).
#[test]
fn long_runs_show_progress_on_a_terminal() {
    let Ok(status) = Command::new("script").arg("--version").output() else {
        eprintln!("SKIPPED: no `script` (bsdutils) to give the program a terminal");
        return;
    };
    assert!(status.status.success());
    let command = format!("{} simulate --steps 120 --volume off", env!("CARGO_BIN_EXE_vkhair"));
    let out = common::run_command(Command::new("script").args(["-qec", &command, "/dev/null"]), LIMIT);
    assert!(out.status.success(), "{}{}", out.stdout, out.stderr);
    assert!(out.stdout.contains("steps") && out.stdout.contains("(eta "), "no progress bar:\n{}", out.stdout);
}

/// `--simulated` simulates a share of the key hairs, the others following
/// them: it says how many, records the followers' pass, and the GPU still
/// matches the CPU reference bit for bit on lavapipe; a share outside (0, 1]
/// is refused before any GPU work.
#[test]
fn a_share_of_the_key_hairs_is_simulated_and_checked() {
    let out = run(&["simulate", "--steps", "20", "--volume", "off", "--simulated", "0.5", "--check"], LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("simulated: 875 of 1750 key hairs"), "{}", out.stdout);
    assert!(out.stdout.contains("vkhair sim: followers"), "{}", out.stdout);
    let line = out.stdout.lines().find(|l| l.contains("the whole run")).expect("whole-run line");
    if out.stdout.contains("llvmpipe") {
        assert!(line.contains("0 (bit for bit)"), "{line}");
    }
    for bad in ["0", "1.5", "nan", "-0.2"] {
        let out = run(&["simulate", "--steps", "2", &format!("--simulated={bad}")], LIMIT);
        out.assert_error("--simulated must be a share of the key hairs above 0 and at most 1");
        assert!(!out.stdout.contains("llvmpipe"), "{bad}: GPU work before the refusal: {}", out.stdout);
    }
}

/// `render --simulated` sets the level of detail through the frame scheduler,
/// on one queue and on a second device (its worker thread), and the followers'
/// pass shows in the simulation's table; a bad share is refused before any GPU
/// work, as in `bench`.
#[test]
fn render_takes_a_share_on_one_queue_and_on_a_second_device() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().display().to_string();
    for schedule in ["single", "second-device"] {
        let args = ["render", "--frames", "2", "--width", "96", "--height", "64", "--simulated", "0.5"];
        let r = run(&[&args[..], &["--schedule", schedule, "--out", &out]].concat(), LIMIT);
        r.assert_ok();
        assert!(r.stdout.contains("simulated: 875 of 1750 key hairs"), "{schedule}: {}", r.stdout);
        assert!(r.stdout.contains("vkhair sim: followers"), "{schedule}: {}", r.stdout);
    }
    for command in ["render", "bench"] {
        let r = run(&[command, "--simulated", "1.01", "--out", &out], LIMIT);
        r.assert_error("--simulated must be a share of the key hairs above 0 and at most 1");
        assert!(!r.stdout.contains("llvmpipe"), "{command}: GPU work before the refusal: {}", r.stdout);
    }
}

/// `simulate --dispatches` lists the last steps' kernels with the work each
/// launches: the particle kernels' workgroups grow with the groom (8× the
/// strands, 8× the workgroups), the dispatched solve's invocations loop a few
/// hundred times at most (its coarse cycle's sweeps), and the solve in one
/// workgroup is one invocation looping tens of thousands of times.
#[test]
fn dispatches_lists_the_work_each_kernel_launches_and_it_follows_the_groom() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Per kernel: (dispatches a step, workgroups a step, loop trips).
    let rows = |strands: u32, pressure: &str| -> std::collections::HashMap<String, (u64, u64, u64)> {
        let groom = dir.path().join(format!("g{strands}.hair"));
        let g = groom.to_str().expect("utf-8");
        run(&["grow", "--scalp", "sphere", "--strands", &strands.to_string(), "--points", "32", "--out", g], LIMIT)
            .assert_ok();
        let args =
            ["simulate", "--input", g, "--guides", "all", "--points", "32", "--steps", "2", "--pressure", pressure];
        let out = run(&[&args[..], &["--dispatches"]].concat(), LIMIT);
        out.assert_ok();
        let table: Vec<&str> =
            out.stdout.lines().skip_while(|l| !l.starts_with("compute dispatches a step")).skip(2).collect();
        table
            .iter()
            .take_while(|l| l.starts_with("sim/"))
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                let n = |i: usize| f[i].trim_end_matches('*').parse::<u64>().expect("a count");
                (f[0].to_owned(), (n(1), n(2), n(5)))
            })
            .collect()
    };
    let (small, large) = (rows(1000, "dispatched"), rows(8000, "dispatched"));
    let scatter = |r: &std::collections::HashMap<String, (u64, u64, u64)>| {
        r.iter().find(|(k, _)| k.starts_with("sim/volume/scatter.comp")).map(|(_, v)| *v).expect("a scatter row")
    };
    assert_eq!(scatter(&small).1 * 8, scatter(&large).1, "scatter workgroups: {small:?} / {large:?}");
    assert_eq!(small["sim/step.comp"].1 * 8, large["sim/step.comp"].1);
    let most = large.values().map(|v| v.2).max().expect("rows");
    assert!(most <= 500, "an invocation of the dispatched solve loops {most} times: {large:?}");
    assert!(large.contains_key("sim/volume/mg_cycle.comp"), "{large:?}");
    let one = rows(1000, "workgroup");
    assert!(one["sim/volume/pcg_workgroup.comp"].2 > 10_000, "{one:?}");
}
