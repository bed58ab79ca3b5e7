//! Where the tool's output goes when things go wrong: a closed pipe, a full
//! device, a killed run, absurd figures in a CSV, tiny images.

use crate::common;

use std::os::fd::{FromRawFd, OwnedFd};
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use common::{run, vkhair};

const LIMIT: Duration = Duration::from_secs(300);

/// A closed standard output ends the program quietly, as `head` expects: killed
/// by SIGPIPE (or exit status 141), no panic, nothing on stderr.
#[test]
fn a_closed_pipe_ends_the_program_quietly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("g.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 0.1));
    let out = dir.path().join("frames");
    let cases: Vec<Vec<String>> = vec![
        vec!["inspect".into(), groom.display().to_string()],
        vec!["config".into()],
        vec!["devices".into()],
        vec![
            "render".into(),
            "--frames".into(),
            "1".into(),
            "--width".into(),
            "32".into(),
            "--height".into(),
            "24".into(),
            "--shadow-resolution".into(),
            "32".into(),
            "--out".into(),
            out.display().to_string(),
        ],
    ];
    for args in cases {
        // A pipe whose reading end is closed before the program even starts (so
        // no other test's process, forked meanwhile, can hold it open).
        let mut fds = [0; 2];
        // SAFETY: `fds` has room for the two descriptors pipe2 writes.
        assert_eq!(unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) }, 0, "pipe");
        // SAFETY: both descriptors were just created and are owned here.
        let (read_end, write_end) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
        drop(read_end);
        let child =
            vkhair().args(&args).stdout(Stdio::from(write_end)).stderr(Stdio::piped()).spawn().expect("start vkhair");
        let output = child.wait_with_output().expect("wait");
        let stderr = String::from_utf8_lossy(&output.stderr);
        let quiet = output.status.signal() == Some(libc::SIGPIPE) || output.status.code() == Some(141);
        assert!(quiet, "{args:?}: {:?}\n{stderr}", output.status);
        assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "{args:?}: {stderr}");
    }
}

/// A full disk: standard output to /dev/full is an error naming standard output;
/// a file written to /dev/full is an error naming the file (and the device stays
/// a device).
#[test]
fn a_full_device_is_an_error_naming_what_was_written() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("SKIPPED: this system has no /dev/full");
        return;
    }
    let stdout = std::fs::OpenOptions::new().write(true).open(full).expect("open /dev/full");
    let out = vkhair().arg("config").stdout(stdout).stderr(Stdio::piped()).output().expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("standard output") && stderr.contains("No space left"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for args in [vec!["grow", "--strands", "10", "--out", "/dev/full"], vec!["convert", "--out", "/dev/full", "GROOM"]]
    {
        let dir = tempfile::tempdir().expect("temp dir");
        let groom = dir.path().join("g.hair");
        common::write_groom(&groom, &common::cap_groom(10, 6, 0.1));
        let args: Vec<&str> =
            args.iter().map(|a| if *a == "GROOM" { groom.to_str().expect("utf-8") } else { a }).collect();
        run(&args, LIMIT).assert_error("/dev/full");
        assert!(!std::fs::metadata(full).expect("still there").file_type().is_file(), "/dev/full was replaced");
    }
}

/// A killed render leaves every frame it wrote whole: each `frame_*.png` there
/// decodes completely.
#[test]
fn a_killed_render_leaves_only_whole_frames() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("frames");
    let mut child = vkhair()
        .args(["render", "--frames", "400", "--width", "320", "--height", "240", "--shadow-resolution", "64", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start vkhair");
    let start = Instant::now();
    let frames = |out: &Path| -> Vec<std::path::PathBuf> {
        let Ok(list) = std::fs::read_dir(out) else { return Vec::new() };
        let mut v: Vec<_> = list
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("frame_")))
            .collect();
        v.sort();
        v
    };
    while frames(&out).len() < 3 && start.elapsed() < LIMIT {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().expect("kill");
    child.wait().expect("wait");
    let written = frames(&out);
    assert!(written.len() >= 3, "the render wrote {} frames before the time limit", written.len());
    for path in &written {
        let (w, h, _) = common::read_png(path);
        assert_eq!((w, h), (320, 240), "{}", path.display());
    }
}

/// Sizes too small for an image (or for the half-size contact sheet) are refused
/// before any GPU work, and no file is written.
#[test]
fn tiny_images_are_refused_with_a_clear_message() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("frames");
    for (w, h) in [("1", "480"), ("640", "15")] {
        run(&["render", "--width", w, "--height", h, "--out", out.to_str().expect("utf-8")], LIMIT)
            .assert_error("--width and --height must be 16..=8192 pixels");
        assert!(!out.exists(), "a refused render created its output folder");
    }
    // The smallest size allowed gives valid images, the contact sheet included.
    let ok = ["render", "--width", "16", "--height", "16", "--frames", "2", "--shadow-resolution", "16", "--out"];
    let mut args = ok.to_vec();
    args.push(out.to_str().expect("utf-8"));
    run(&args, LIMIT).assert_ok();
    assert_eq!(common::read_png(&out.join("contact_sheet.png")).0, 16);
    assert_eq!(common::read_png(&out.join("frame_0001.png")).0, 16);
}

/// `plot` with infinite or absurd figures is an error naming the row and the
/// column, within a time limit, and writes no PNG.
#[test]
fn plot_refuses_absurd_figures_quickly_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let header = "width,height,distance_m,segments,total_ms,ssaa";
    for (value, shown) in [("inf", "inf"), ("1e308", "1e308"), ("NaN", "NaN"), ("-1e300", "-1e300")] {
        let csv = dir.path().join("render.csv");
        std::fs::write(&csv, format!("{header}\n640,480,0.5,1000,2.5,0\n640,480,1.0,800,{value},0\n")).expect("csv");
        let started = Instant::now();
        let out = run(&["plot", csv.to_str().expect("utf-8")], Duration::from_secs(30));
        out.assert_error(&format!("line 3, column \"total_ms\": {shown} is not a plottable figure"));
        assert!(started.elapsed() < Duration::from_secs(30));
        assert!(!csv.with_extension("png").exists(), "a failed plot left a PNG behind");
    }
    // Messages are sentences, not Debug dumps.
    let csv = dir.path().join("other.csv");
    std::fs::write(&csv, "a,b\n1,2\n").expect("csv");
    let out = run(&["plot", csv.to_str().expect("utf-8")], Duration::from_secs(30));
    out.assert_error("has no column \"width\"");
    assert!(!out.stderr.contains("Err(") && !out.stderr.contains("{ "), "{}", out.stderr);
    let out = run(&["plot", dir.path().join("missing.csv").to_str().expect("utf-8")], Duration::from_secs(30));
    out.assert_error("cannot read");
    assert!(out.stderr.contains("missing.csv") && !out.stderr.contains("Os {"), "{}", out.stderr);
    // And a good CSV gives a whole PNG.
    let csv = dir.path().join("good.csv");
    std::fs::write(&csv, format!("{header}\n640,480,0.5,1000,2.5,0\n640,480,1.0,800,1.5,0\n")).expect("csv");
    run(&["plot", csv.to_str().expect("utf-8")], Duration::from_secs(60)).assert_ok();
    assert_eq!(common::read_png(&csv.with_extension("png")).0, 1100);
}

/// A FIFO as the output, read by a process that reads once (as `cat` or a
/// shell's `$(< fifo)` does): the run checks at its start that the FIFO has a
/// reader and keeps it open, so the reader gets the whole output, not the
/// end of an empty stream; a FIFO nobody reads is refused at the start.
#[test]
fn a_fifo_read_once_gets_the_whole_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("g.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 0.1));
    let fifo = dir.path().join("out.hair");
    let c = std::ffi::CString::new(fifo.to_str().expect("utf-8")).expect("path");
    // SAFETY: mkfifo with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
    let (g, f) = (groom.to_str().expect("utf-8"), fifo.to_str().expect("utf-8"));
    run(&["convert", g, "--out", f], LIMIT).assert_error("no process reads this FIFO");
    let path = fifo.clone();
    // One open, one read to the end of the stream.
    let reader = std::thread::spawn(move || std::fs::read(&path).expect("read the FIFO"));
    let started = Instant::now();
    run(&["convert", g, "--out", f], Duration::from_secs(60)).assert_ok();
    let bytes = reader.join().expect("reader");
    println!("{} bytes through the FIFO in {:?}", bytes.len(), started.elapsed());
    assert!(bytes.starts_with(b"HAIR"), "the reader got {} bytes, not the .hair file", bytes.len());
    let copy = dir.path().join("copy.hair");
    std::fs::write(&copy, &bytes).expect("write the copy");
    run(&["inspect", copy.to_str().expect("utf-8")], LIMIT).assert_ok();
}

/// Names from files and paths reach the terminal escaped: a control character
/// (here the escape that starts a terminal sequence) is printed as `\u{1b}`,
/// on standard output and in errors alike, and so is an object's name read
/// from inside a file, in the listing and in JSON.
#[test]
fn control_characters_in_names_are_printed_escaped() {
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = dir.path().join("clear\u{1b}[2J\u{7}.hair");
    common::write_groom(&groom, &common::cap_groom(20, 6, 0.1));
    let out = run(&["inspect", groom.to_str().expect("utf-8")], LIMIT);
    out.assert_ok();
    assert!(
        !out.stdout.contains('\u{1b}') && !out.stdout.contains('\u{7}'),
        "raw control characters:\n{:?}",
        out.stdout
    );
    assert!(out.stdout.contains("clear\\u{1b}[2J\\u{7}.hair"), "{}", out.stdout);
    let missing = dir.path().join("gone\u{1b}]0;title\u{7}.hair");
    let out = run(&["inspect", missing.to_str().expect("utf-8")], LIMIT);
    assert_eq!(out.status.code(), Some(1), "{}", out.stderr);
    assert!(
        !out.stderr.contains('\u{1b}') && !out.stderr.contains('\u{7}'),
        "raw control characters:\n{:?}",
        out.stderr
    );
    assert!(out.stderr.contains("gone\\u{1b}]0;title\\u{7}.hair"), "{}", out.stderr);
    // A name from inside a file: an Alembic object named with escapes, in
    // the text listing and in JSON.
    let strands = common::cap_groom(20, 6, 0.1);
    let counts: Vec<u32> = strands.iter().map(|s| s.len() as u32).collect();
    let groom = vkhair::Groom::new(strands.concat(), &counts).expect("groom");
    let object = vkhair::groom::alembic::write::CurvesObject {
        name: "hair\u{1b}[31m\u{7}",
        groom: &groom,
        guides: None,
        root_uvs: None,
        transform: None,
    };
    let abc = dir.path().join("named.abc");
    std::fs::write(&abc, vkhair::groom::alembic::write::to_bytes(&[object]).expect("written")).expect("write");
    for json in [false, true] {
        let mut args = vec!["inspect", abc.to_str().expect("utf-8")];
        if json {
            args.push("--json");
        }
        let out = run(&args, LIMIT);
        out.assert_ok();
        assert!(
            !out.stdout.contains('\u{1b}') && !out.stdout.contains('\u{7}'),
            "raw control characters:\n{:?}",
            out.stdout
        );
        assert!(
            out.stdout.contains("hair\\u{1b}[31m\\u{7}") || out.stdout.contains("hair\\u001b[31m\\u0007"),
            "{}",
            out.stdout
        );
    }
}

/// A folder in the place of a frame the run writes is found before rendering:
/// the run stops at once naming it, with no GPU work done.
#[test]
fn a_folder_in_a_frames_place_is_refused_before_rendering() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("frames");
    std::fs::create_dir_all(out.join("frame_0001.png")).expect("a folder named like a frame");
    let o = out.to_str().expect("utf-8");
    let run = run(&["render", "--frames", "3", "--width", "32", "--height", "24", "--out", o], LIMIT);
    run.assert_error("frame_0001.png is in the place of a file this run writes");
    assert!(!run.stdout.contains("key hairs"), "GPU work started: {}", run.stdout);
    assert!(!out.join("frame_0000.png").exists(), "a frame was written");
}

/// A run refused after its outputs were checked leaves no folder it made:
/// `render` and `bench` make a missing `--out` folder (and the folders above
/// it) during the check, and take them away again when the run is refused
/// later; a folder that was there before stays, and so does one a run wrote into.
#[test]
fn a_refused_run_leaves_no_folder_it_made() {
    let dir = tempfile::tempdir().expect("temp dir");
    let made = dir.path().join("new");
    let deep = made.join("deeper").join("frames");
    let d = deep.to_str().expect("utf-8");
    // Refused by the library's parameter check, after the outputs' check.
    run(&["render", "--level", "0", "--out", d], LIMIT).assert_error("invalid parameter --level: 0");
    assert!(!made.exists(), "render left {} behind", made.display());
    // Refused reading a damaged Sintel, after the outputs' check.
    let sintel = dir.path().join("sintel");
    std::fs::create_dir(&sintel).expect("mkdir");
    std::fs::write(sintel.join("sintel_hair.tfx"), b"not a groom").expect("write");
    std::fs::write(sintel.join("sintel_bust.obj"), b"v 0 0 0\n").expect("write");
    let s = sintel.to_str().expect("utf-8");
    run(&["bench", "--quick", "--sintel", s, "--out", d], LIMIT).assert_error("sintel_hair.tfx");
    assert!(!made.exists(), "bench left {} behind", made.display());
    // A folder that existed stays, empty or not; the ones made below it go.
    std::fs::create_dir(&made).expect("mkdir");
    run(&["render", "--level", "0", "--out", d], LIMIT).assert_error("invalid parameter --level: 0");
    assert!(made.is_dir() && !made.join("deeper").exists(), "render removed too much or too little");
    // A path through `..`: the existing folder it names stays.
    let through = dir.path().join("nowhere").join("..").join("new");
    run(&["render", "--level", "0", "--out", through.to_str().expect("utf-8")], LIMIT)
        .assert_error("invalid parameter --level: 0");
    assert!(made.is_dir(), "render removed a folder it did not make through ..");
    std::fs::create_dir_all(&deep).expect("mkdir");
    run(&["render", "--level", "0", "--out", d], LIMIT).assert_error("invalid parameter --level: 0");
    assert!(deep.is_dir(), "render removed a folder it did not make");
    // A run that writes keeps the folder it made.
    std::fs::remove_dir_all(&made).expect("rm");
    let ok = run(&["render", "--frames", "1", "--width", "32", "--height", "24", "--density", "5", "--out", d], LIMIT);
    ok.assert_ok();
    assert!(deep.join("frame_0000.png").is_file(), "the frame is missing: {}", ok.stdout);
}
