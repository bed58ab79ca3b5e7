//! The windowed viewer example (`examples/viewer`) under a virtual X server:
//! 60 frames through a real swapchain with validation and synchronization
//! validation on and a resize half way, the screenshot showing hair, the
//! overlay present, and the floor the host draws after vkhair's hair relying on
//! the state vkhair documents it leaves (opaque, exact transparency and
//! supersampled hair). Run it through `cargo test`, which builds the example
//! (`cargo test --test viewer` alone does not rebuild it). Skipped, saying why, where no X server
//! can be started (Debian: `apt install xvfb`, which tools/setup-debian.sh does).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A virtual X server for the test, stopped on drop.
struct Xvfb(Child);

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// An X display: a new Xvfb when the binary is there, else `$DISPLAY`.
fn display() -> Result<(String, Option<Xvfb>), String> {
    let xvfb = std::env::var_os("PATH")
        .and_then(|paths| std::env::split_paths(&paths).map(|p| p.join("Xvfb")).find(|p| p.is_file()));
    if let Some(xvfb) = xvfb {
        let free = (90..190).find(|n| {
            !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && !Path::new(&format!("/tmp/.X{n}-lock")).exists()
        });
        let n = free.ok_or("no free X display number in :90..:190")?;
        let child = Command::new(xvfb)
            .args([
                format!(":{n}"),
                "-screen".into(),
                "0".into(),
                "1024x768x24".into(),
                "-nolisten".into(),
                "tcp".into(),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| format!("Xvfb did not start: {e}"))?;
        let server = Xvfb(child);
        let start = Instant::now();
        while !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
            if start.elapsed() > Duration::from_secs(20) {
                return Err("Xvfb did not open its socket in 20 s".into());
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        return Ok((format!(":{n}"), Some(server)));
    }
    match std::env::var("DISPLAY") {
        Ok(d) if !d.is_empty() => Ok((d, None)),
        _ => Err("no Xvfb on PATH and no $DISPLAY (install Debian's xvfb)".into()),
    }
}

/// The example's binary, which `cargo test` builds beside the tests.
fn viewer() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    let dir = exe.parent().and_then(Path::parent).expect("target directory");
    let path = dir.join("examples").join(format!("viewer{}", std::env::consts::EXE_SUFFIX));
    assert!(path.is_file(), "{} is missing: cargo test builds the examples", path.display());
    path
}

/// Runs the viewer on `display` and returns its screenshot's size and RGBA pixels.
fn run(display: &str, out: &Path, args: &[&str]) -> (u32, u32, Vec<u8>) {
    let (w, h, pixels, _) = run_printing(display, out, args);
    (w, h, pixels)
}

/// [`run`], with what the viewer printed.
fn run_printing(display: &str, out: &Path, args: &[&str]) -> (u32, u32, Vec<u8>, String) {
    let output = Command::new(viewer())
        .env("DISPLAY", display)
        .args(["--validation", "--screenshot"])
        .arg(out)
        .args(args)
        .output()
        .expect("run the viewer");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "viewer {args:?}: {:?}\n{stdout}\n{stderr}", output.status);
    assert!(!stderr.contains("validation"), "viewer {args:?} had validation messages:\n{stderr}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(out).expect("screenshot")));
    let mut reader = decoder.read_info().expect("png header");
    let mut pixels = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut pixels).expect("png data");
    pixels.truncate(info.buffer_size());
    (info.width, info.height, pixels, stdout.into_owned())
}

/// Mean RGB over the rectangle `(x0, y0)..(x1, y1)` of an image `width` wide.
fn mean(pixels: &[u8], width: u32, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for y in y0..y1 {
        for x in x0..x1 {
            let i = ((y * width + x) * 4) as usize;
            (0..3).for_each(|c| sum[c] += f64::from(pixels[i + c]));
        }
    }
    sum.map(|s| s / f64::from((x1 - x0) * (y1 - y0)))
}

/// The floor's colour in the screenshot: the viewer's floor albedo (0.12, 0.12,
/// 0.13) lit as `examples/viewer/scene.rs` lights it (0.3 + 0.7 · n·l with n up
/// and l = normalize(−0.4, 0.6, 0.7)), in sRGB.
fn floor_srgb() -> [f64; 3] {
    let l = 0.6 / (0.16f64 + 0.36 + 0.49).sqrt();
    let srgb = |v: f64| 255.0 * (1.055 * v.powf(1.0 / 2.4) - 0.055);
    [0.12, 0.12, 0.13].map(|a| srgb(a * (0.3 + 0.7 * l)))
}

#[test]
fn the_viewer_runs_clean_in_a_window_and_shows_hair_overlay_and_floor() {
    let (display, _server) = match display() {
        Ok(d) => d,
        Err(why) => {
            println!("SKIPPED the viewer test: {why}");
            eprintln!("SKIPPED the viewer test: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let shot = |name: &str| dir.path().join(name);
    // 60 frames with validation, the window resized at frame 20: the screenshot
    // has the new size, so the swapchain was recreated.
    let (w, h, full) = run(
        &display,
        &shot("full.png"),
        &["--frames", "60", "--width", "320", "--height", "240", "--resize", "400x300", "--resize-frame", "20"],
    );
    assert_eq!((w, h), (400, 300), "the resize did not reach the swapchain");
    let size = ["--width", "400", "--height", "300"];
    let (_, _, plain) = run(&display, &shot("plain.png"), &[&["--frames", "10", "--no-overlay"][..], &size].concat());
    let (_, _, bare) =
        run(&display, &shot("bare.png"), &[&["--frames", "10", "--no-overlay", "--no-hair"][..], &size].concat());
    // Hair: pixels that differ from the host's scene alone.
    let differs = plain
        .chunks_exact(4)
        .zip(bare.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).take(3).any(|(x, y)| x.abs_diff(*y) > 24));
    let hair = differs.count() as f64 / f64::from(400 * 300);
    println!("hair covers {:.1} % of the window", 100.0 * hair);
    assert!(hair > 0.05, "the screenshot shows hair on {:.2} % of the window", 100.0 * hair);
    // The overlay: its corner differs from the same corner without it.
    let corner = (0, 0, 200, 100);
    let (with, without) = (mean(&full, 400, corner), mean(&plain, 400, corner));
    let diff: f64 = with.iter().zip(without).map(|(a, b)| (a - b).abs()).sum();
    println!("overlay corner: {with:?} against {without:?} without it");
    assert!(diff > 20.0, "the overlay is not in the top-left corner ({with:?} vs {without:?})");
    // The floor, drawn after vkhair's hair with only the host's pipeline and push
    // constants set again, is where it should be, in its colour, with and without hair.
    // The same after the exact transparency's composite and the supersampling's
    // resolve, the last passes of those modes.
    let mut modes = Vec::new();
    for (name, toml) in
        [("exact", "[render]\ntransparency = \"exact\"\n"), ("ssaa", "[render]\nsupersampling = true\n")]
    {
        let config = dir.path().join(format!("{name}.toml"));
        std::fs::write(&config, toml).expect("write config");
        let config = config.to_string_lossy().into_owned();
        let args = [&["--frames", "4", "--no-overlay", "--config", &config][..], &size].concat();
        modes.push((name, run(&display, &shot(&format!("{name}.png")), &args).2));
    }
    let patch = (60, 285, 120, 299);
    let expected = floor_srgb();
    let images = [("with hair", &plain), ("without hair", &bare)].into_iter().chain(modes.iter().map(|(n, i)| (*n, i)));
    for (name, image) in images {
        let got = mean(image, 400, patch);
        println!("floor {name}: {got:?}, expected {expected:?}");
        assert!(
            got.iter().zip(expected).all(|(g, e)| (g - e).abs() <= 6.0),
            "the floor {name} is {got:?}, expected {expected:?}"
        );
    }
}

/// `--taa`: the viewer as a TAA host (a jittered camera, vkhair's motion
/// vectors into its velocity image, a resolve blending each pixel with its
/// reprojected history into the swapchain image), with the head moving,
/// through a resize (new images, a new history) and in the opaque and exact
/// modes: validation clean, hair shown, the still floor resolved to its
/// colour, and the motion vectors' pass timed exactly when they are asked for.
#[test]
fn the_viewer_resolves_taa_with_the_hairs_motion_vectors() {
    let (display, _server) = match display() {
        Ok(d) => d,
        Err(why) => {
            println!("SKIPPED the viewer TAA test: {why}");
            eprintln!("SKIPPED the viewer TAA test: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let exact = dir.path().join("exact.toml");
    std::fs::write(&exact, "[render]\ntransparency = \"exact\"\n").expect("write config");
    let exact = exact.to_string_lossy().into_owned();
    let common = ["--taa", "--moving", "--no-overlay", "--frame-time", "0.0167", "--width", "320", "--height", "240"];
    let resize = ["--frames", "10", "--resize", "400x300", "--resize-frame", "4"];
    let (_, _, bare, _) =
        run_printing(&display, &dir.path().join("bare.png"), &[&common[..], &resize, &["--no-hair"]].concat());
    // The least share of the window the hair changes: transparent strands
    // change fewer pixels by that much (measured 11 % opaque, 3.8 % exact).
    let cases: [(&str, Vec<&str>, bool, f64); 3] = [
        ("opaque", vec![], true, 0.05),
        ("opaque, no motion vectors", vec!["--no-motion-vectors"], false, 0.05),
        ("exact", vec!["--config", &exact], true, 0.02),
    ];
    for (name, extra, motion, least) in cases {
        let shot = dir.path().join(format!("{}.png", name.replace([' ', ','], "_")));
        let (w, h, image, printed) = run_printing(&display, &shot, &[&common[..], &resize, &extra].concat());
        assert_eq!((w, h), (400, 300), "{name}: the resize did not reach the swapchain");
        let hair = image
            .chunks_exact(4)
            .zip(bare.chunks_exact(4))
            .filter(|(a, b)| a.iter().zip(b.iter()).take(3).any(|(x, y)| x.abs_diff(*y) > 24))
            .count() as f64
            / f64::from(400 * 300);
        let floor = mean(&image, 400, (60, 285, 120, 299));
        println!("TAA, {name}: hair on {:.1} % of the window, floor {floor:?}", 100.0 * hair);
        assert!(hair > least, "{name}: hair on {:.2} % of the window", 100.0 * hair);
        assert!(
            floor.iter().zip(floor_srgb()).all(|(g, e)| (g - e).abs() <= 6.0),
            "{name}: the floor is {floor:?} under TAA, expected {:?}",
            floor_srgb()
        );
        assert_eq!(
            printed.contains("vkhair render: motion vectors"),
            motion,
            "{name}: the motion vectors' pass is timed only when they are asked for:\n{printed}"
        );
    }
}

/// `--gltf`: the viewer, as a host with a skinned character, skins the mesh on
/// the GPU every frame, draws it, and hands the skinned vertices to vkhair:
/// after 40 frames of the run (fixed frame times, so that runs with and
/// without hair see the same poses) the key hairs' roots are within 50 µm of
/// their points on the mesh skinned on the CPU at the same time of the
/// animation (GPU against CPU rounding at the character's scale), the body
/// is drawn and the hair differs from the body alone; validation clean.
#[test]
fn the_viewer_puts_hair_on_a_skinned_character() {
    let (display, _server) = match display() {
        Ok(d) => d,
        Err(why) => {
            println!("SKIPPED the viewer character test: {why}");
            eprintln!("SKIPPED the viewer character test: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let args = [
        "--gltf",
        glb,
        "--animation",
        "run",
        "--frames",
        "40",
        "--frame-time",
        "0.02",
        "--no-overlay",
        "--width",
        "320",
        "--height",
        "320",
    ];
    let (_, _, hair, printed) = run_printing(&display, &dir.path().join("hair.png"), &args);
    let (_, _, bare) = run(&display, &dir.path().join("bare.png"), &[&args[..], &["--no-hair"]].concat());
    let error: f64 = printed
        .lines()
        .find_map(|l| l.strip_prefix("viewer: roots within "))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no root error printed:\n{printed}"));
    println!("roots from the CPU-skinned mesh: {error:e} m");
    assert!(error < 5e-5, "the roots are {error} m from their points on the skinned mesh");
    // The body: lit albedo (0.45, 0.30, 0.24), reddish, in the frame without hair.
    let body = bare.chunks_exact(4).filter(|p| p[0] > 60 && u32::from(p[0]) > u32::from(p[2]) + 25).count();
    let differs = hair
        .chunks_exact(4)
        .zip(bare.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).take(3).any(|(x, y)| x.abs_diff(*y) > 24))
        .count();
    let share = |n: usize| n as f64 / f64::from(320 * 320);
    println!("body {:.1} %, hair {:.1} % of the window", 100.0 * share(body), 100.0 * share(differs));
    assert!(share(body) > 0.02, "the body covers {:.2} % of the window", 100.0 * share(body));
    assert!(share(differs) > 0.01, "the hair covers {:.2} % of the window", 100.0 * share(differs));
}

/// `--crowd 4 --gltf`: two characters and two thesis heads in one vkhair
/// simulation and renderer, each drawn by the host at its place: hair shows
/// on both sides of the window (the members stand apart on a grid seen from
/// a corner) beside the bodies and heads, the viewer says what the crowd
/// holds, and the run is validation clean.
#[test]
fn the_viewer_draws_a_crowd_of_characters_and_heads() {
    let (display, _server) = match display() {
        Ok(d) => d,
        Err(why) => {
            println!("SKIPPED the viewer crowd test: {why}");
            eprintln!("SKIPPED the viewer crowd test: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mannequiny-0.3.0.glb");
    let (w, h) = (240u32, 180u32);
    let (ws, hs) = (w.to_string(), h.to_string());
    let args = [
        "--crowd",
        "4",
        "--gltf",
        glb,
        "--animation",
        "run",
        "--moving",
        "--frames",
        "6",
        "--frame-time",
        "0.02",
        "--no-overlay",
        "--width",
        &ws,
        "--height",
        &hs,
    ];
    let (_, _, hair, printed) = run_printing(&display, &dir.path().join("crowd.png"), &args);
    let (_, _, bare) = run(&display, &dir.path().join("bare.png"), &[&args[..], &["--no-hair"]].concat());
    let body = bare.chunks_exact(4).filter(|p| p[0] > 60 && u32::from(p[0]) > u32::from(p[2]) + 25).count();
    // The grid seen from a corner: two members left of the middle, two right.
    let mut halves = [0usize; 2];
    for (i, (a, b)) in hair.chunks_exact(4).zip(bare.chunks_exact(4)).enumerate() {
        if a.iter().zip(b.iter()).take(3).any(|(x, y)| x.abs_diff(*y) > 24) {
            halves[usize::from(i as u32 % w >= w / 2)] += 1;
        }
    }
    let share = |n: usize| n as f64 / f64::from(w * h);
    let percent = |n: usize| (1000.0 * share(n)).round() / 10.0;
    println!(
        "bodies and heads {:.1} %; hair left and right of the middle {:?} %",
        100.0 * share(body),
        halves.map(percent)
    );
    assert!(share(body) > 0.01, "the bodies and heads cover {:.2} % of the window", 100.0 * share(body));
    for (half, n) in ["left", "right"].iter().zip(halves) {
        assert!(share(n) > 0.005, "the {half} half of the window shows {:.2} % hair", 100.0 * share(n));
    }
    let line = printed.lines().find(|l| l.starts_with("viewer: crowd of")).unwrap_or_else(|| panic!("{printed}"));
    assert!(line.contains("4 members") && line.contains("2 characters"), "{line}");
}

/// Values out of range are refused before any window opens, naming the option.
#[test]
fn the_viewer_refuses_bad_options_by_name() {
    for (args, named) in [
        (&["--width", "0"][..], "--width"),
        (&["--scale", "nan"][..], "--scale"),
        (&["--frames", "0"][..], "--frames"),
        (&["--resize", "10x5000"][..], "--resize"),
        (&["--frame-time", "0"][..], "--frame-time"),
        (&["--animation", "run"][..], "--gltf"),
        (&["--crowd", "0"][..], "--crowd"),
        (&["--crowd", "65"][..], "--crowd"),
    ] {
        let output = Command::new(viewer()).args(args).env_remove("DISPLAY").output().expect("run the viewer");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(named) && !stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    let output = Command::new(viewer()).args(["--screenshot", "x.png"]).output().expect("run the viewer");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--screenshot needs --frames"), "{stderr}");
}
