//! The `vkhair` tool as a hostile user meets it: several hundred runs with
//! devices, FIFOs, folders, truncated and garbage files as inputs, absurd flag
//! values, hostile parameter files, planted links and devices as outputs,
//! colliding outputs and odd environments. Every run must end by itself with
//! status 0 or 1 (no panic, no kill, no hang past its limit), say what went
//! wrong on a `vkhair: ` line when it fails, leave no validation message, no
//! `.partial` file and no file outside its own folder changed; the runs that
//! stand for a defect of the tool's first hostile round also check the
//! message that names it.

use crate::common;

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use common::{cap_groom, run_command, vkhair, write_groom};

const LIMIT: Duration = Duration::from_secs(120);

/// What a run must end with.
#[derive(Clone, Copy)]
enum Expect {
    /// Status 0 or 1, cleanly.
    Either,
    /// Status 0.
    Ok,
    /// Status 1 with this text on stderr.
    Error(&'static str),
}

struct Case {
    name: String,
    args: Vec<String>,
    env: Vec<(&'static str, OsString)>,
    expect: Expect,
}

/// The files the cases read, in one folder, and a victim file outside every
/// output folder that no run may change.
struct Fixtures {
    dir: tempfile::TempDir,
}

impl Fixtures {
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn arg(&self, name: &str) -> String {
        self.path(name).display().to_string()
    }

    fn new() -> Fixtures {
        let dir = tempfile::tempdir().expect("temp dir");
        let f = Fixtures { dir };
        let put = |name: &str, bytes: &[u8]| std::fs::write(f.path(name), bytes).expect("write fixture");
        put("victim.txt", b"precious");
        write_groom(&f.path("good.hair"), &cap_groom(40, 8, 0.1));
        put("good.obj", &sphere_obj());
        put("empty.hair", b"");
        put("text.hair", b"this is not a groom\n");
        put("random.hair", &(0..4096u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 11) as u8).collect::<Vec<_>>());
        let good = std::fs::read(f.path("good.hair")).expect("read");
        put("truncated.hair", &good[..good.len() / 2]);
        let mut huge = good.clone();
        huge[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        put("huge_counts.hair", &huge);
        let nan = |count: usize| {
            let mut strands = cap_groom(3, 4, 0.1);
            for s in strands.iter_mut().take(count) {
                s[1].x = f32::NAN;
            }
            strands
        };
        write_groom_unchecked(&f.path("all_nan.hair"), &nan(3));
        write_groom_unchecked(&f.path("some_nan.hair"), &nan(1));
        put("header_offset.tfx", &tfx(2, 4, 64));
        put("truncated.tfx", &tfx(2, 4, 160)[..200]);
        put("good.tfx", &tfx(2, 4, 160));
        put("polyline.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
        put("nan.obj", b"v 0 0 0\n# a vertex that is not a number\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
        put("empty.obj", b"");
        put("binary.obj", &[0xff, 0xfe, 0x00, 0x13, 0x80]);
        put(
            "lod_zero.toml",
            b"[render.lod]\nfull_detail_distance = 1e-6\nmin_hairs_per_key = 0\nmin_smoothing_level = 0\n",
        );
        put("lod_nan.toml", b"[render.lod]\nfull_detail_distance = nan\n");
        put("lod_negative.toml", b"[render.lod]\nfull_detail_distance = -1.0\n");
        put("frames_zero.toml", b"[render]\nframes_in_flight = 0\n");
        put("frames_huge.toml", b"[render]\nframes_in_flight = 1000\n");
        put("bogus_table.toml", b"[sim]\ndt = 0.01\n[bogus]\nx = 1\n");
        put("nan.toml", b"[sim]\ndt = nan\n");
        put("inf_gravity.toml", b"[sim]\ngravity = [0.0, -inf, 0.0]\n");
        put("wrong_type.toml", b"[sim]\niterations = \"many\"\n");
        put("binary.toml", &[0xff, 0xfe, 0x00, 0x13, 0x80]);
        put("huge.toml", &vec![b'#'; 2 << 20]);
        put("point_light.toml", b"[[lights]]\nkind = \"point\"\nposition = [0.0, 2.0, 1.0]\ncolor = [1.0, 1.0, 1.0]\n");
        put(
            "figures.csv",
            b"axis,unit,work,gpu_ms,cpu_ms\nkey hairs,particles,100,1.5,3.0\nkey hairs,particles,200,2.5,6.0\n",
        );
        put("no_rows.csv", b"scene,mode,gpu_ms,memory_mib,error_srgb_steps\nthesis,off,1,2,nan\nthesis,fast,1,2,x\n");
        let mut bad_rows = String::from("scene,mode,gpu_ms,memory_mib,error_srgb_steps\nthesis,off,1.0,2.0,3.0\n");
        for _ in 0..200_000 {
            bad_rows.push_str("thesis,fast,1,2,x\n");
        }
        put("bad_rows.csv", bad_rows.as_bytes());
        put("table.png", b"axis,unit,work,gpu_ms,cpu_ms\nkey hairs,particles,100,1.5,3.0\n");
        std::fs::create_dir(f.path("folder")).expect("mkdir");
        let fifo = std::ffi::CString::new(f.arg("fifo")).expect("path");
        // SAFETY: mkfifo with a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0, "mkfifo");
        f
    }
}

/// A `.hair` file written byte by byte, NaN points included (the library's
/// writer refuses them).
fn write_groom_unchecked(path: &Path, strands: &[Vec<glam::Vec3>]) {
    let mut b = b"HAIR".to_vec();
    let points: usize = strands.iter().map(Vec::len).sum();
    for v in [strands.len() as u32, points as u32, 3, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [1.0f32, 0.0, 1.0, 1.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; 88]);
    for s in strands {
        b.extend_from_slice(&((s.len() - 1) as u16).to_le_bytes());
    }
    for p in strands.iter().flatten() {
        for v in p.to_array() {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, b).expect("write");
}

/// A `.tfx` file of `strands` × `per` vertices whose positions start at byte
/// `at` (160: right after the header).
fn tfx(strands: u32, per: u32, at: u32) -> Vec<u8> {
    let mut b = 4.0f32.to_le_bytes().to_vec();
    for v in [strands, per, at, 0, 0, 0, 0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.resize(160.max(at as usize), 0);
    b.truncate(at as usize);
    for s in 0..strands {
        for k in 0..per {
            for v in [s as f32 * 0.01, -(k as f32) * 0.02, 0.0, if k == 0 { 0.0 } else { 1.0 }] {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    b.resize(b.len().max(160), 0);
    b
}

/// A small closed sphere as OBJ text.
fn sphere_obj() -> Vec<u8> {
    let mut text = String::new();
    let (stacks, slices) = (6, 8);
    for i in 0..=stacks {
        for j in 0..slices {
            let (t, p) =
                (std::f32::consts::PI * i as f32 / stacks as f32, std::f32::consts::TAU * j as f32 / slices as f32);
            text += &format!("v {} {} {}\n", 0.1 * t.sin() * p.cos(), 0.1 * t.cos(), 0.1 * t.sin() * p.sin());
        }
    }
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b) = (i * slices + j + 1, i * slices + (j + 1) % slices + 1);
            let (c, d) = (a + slices, b + slices);
            text += &format!("f {a} {b} {c}\nf {b} {d} {c}\n");
        }
    }
    text.into_bytes()
}

/// The cases: inputs × the commands that read them, flags × absurd values,
/// parameter files, outputs and environments.
fn cases(f: &Fixtures, out: &Path) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut n = 0;
    let mut add = |name: String, args: Vec<String>, env: Vec<(&'static str, OsString)>, expect: Expect| {
        cases.push(Case { name, args, env, expect });
    };
    let o = |name: String| out.join(name).display().to_string();
    let s = |args: &[&str]| args.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    let tiny = ["--frames", "1", "--width", "32", "--height", "32", "--no-shadows", "--shadow-resolution", "16"];

    // 1. Inputs: every hostile file to every command that reads one.
    let inputs = [
        "/dev/zero",
        "/dev/urandom",
        "/dev/null",
        &f.arg("fifo"),
        &f.arg("folder"),
        &f.arg("missing.hair"),
        &f.arg("empty.hair"),
        &f.arg("text.hair"),
        &f.arg("random.hair"),
        &f.arg("truncated.hair"),
        &f.arg("huge_counts.hair"),
        &f.arg("all_nan.hair"),
        &f.arg("header_offset.tfx"),
        &f.arg("truncated.tfx"),
        &f.arg("binary.obj"),
        &f.arg("polyline.obj"),
    ]
    .map(str::to_owned);
    for input in &inputs {
        n += 1;
        add(format!("inspect {input}"), s(&["inspect", input]), vec![], Expect::Error("vkhair: "));
        add(format!("inspect --strict {input}"), s(&["inspect", "--strict", input]), vec![], Expect::Error("vkhair: "));
        add(
            format!("convert {input}"),
            s(&["convert", input, "--out", &o(format!("c{n}.hair"))]),
            vec![],
            Expect::Error("vkhair: "),
        );
        let mut render = s(&["render", "--input", input, "--out", &o(format!("r{n}"))]);
        render.extend(s(&tiny));
        add(format!("render --input {input}"), render, vec![], Expect::Error("vkhair: "));
        add(
            format!("simulate --input {input}"),
            s(&["simulate", "--input", input, "--steps", "1"]),
            vec![],
            Expect::Error("vkhair: "),
        );
        add(
            format!("simulate --obj {input}"),
            s(&["simulate", "--input", &f.arg("good.hair"), "--obj", input, "--steps", "1"]),
            vec![],
            Expect::Error("vkhair: "),
        );
        add(
            format!("grow --obj {input}"),
            s(&["grow", "--scalp", "obj", "--obj", input, "--strands", "20", "--out", &o(format!("g{n}.hair"))]),
            vec![],
            Expect::Error("vkhair: "),
        );
        // An empty file, /dev/null and a FIFO nobody writes are an empty
        // parameter file: the defaults.
        add(
            format!("simulate --config {input}"),
            s(&["simulate", "--config", input, "--steps", "1"]),
            vec![],
            Expect::Either,
        );
        add(
            format!("plot {input}"),
            s(&["plot", input, "--out", &o(format!("p{n}.png"))]),
            vec![],
            Expect::Error("vkhair: "),
        );
    }
    // Named input defects.
    let named: [(&str, Vec<String>, &'static str); 12] = [
        ("render --input /dev/zero", s(&["render", "--input", "/dev/zero", "--frames", "1"]), "not a .hair file"),
        ("inspect /dev/urandom", s(&["inspect", "/dev/urandom"]), "not a .hair file"),
        (
            "--obj /dev/zero",
            s(&["simulate", "--input", &f.arg("good.hair"), "--obj", "/dev/zero", "--steps", "1"]),
            "the most vkhair reads of an OBJ mesh",
        ),
        ("--config /dev/zero", s(&["simulate", "--config", "/dev/zero"]), "the most vkhair reads of a parameter file"),
        (
            "plot /dev/zero",
            s(&["plot", "/dev/zero", "--out", &o("zero.png".into())]),
            "the most vkhair reads of a benchmark CSV",
        ),
        ("a FIFO nobody writes", s(&["inspect", &f.arg("fifo")]), "truncated"),
        (
            "a polyline OBJ",
            s(&["simulate", "--input", &f.arg("good.hair"), "--obj", &f.arg("polyline.obj")]),
            "no face",
        ),
        (
            "a NaN OBJ vertex",
            s(&["simulate", "--input", &f.arg("good.hair"), "--obj", &f.arg("nan.obj")]),
            "vertex 2 (line 3)",
        ),
        ("a .tfx offset into its header", s(&["inspect", &f.arg("header_offset.tfx")]), "inside the 160-byte header"),
        ("every strand NaN", s(&["inspect", &f.arg("all_nan.hair")]), "3 strands with NaN or infinite values"),
        ("a huge config", s(&["simulate", "--config", &f.arg("huge.toml")]), "more than 1048576 bytes"),
        ("a binary config", s(&["simulate", "--config", &f.arg("binary.toml")]), "not UTF-8"),
    ];
    for (name, args, text) in named {
        add(name.into(), args, vec![], Expect::Error(text));
    }
    add("some strands NaN".into(), s(&["inspect", &f.arg("some_nan.hair")]), vec![], Expect::Ok);
    add("a good .tfx".into(), s(&["inspect", &f.arg("good.tfx")]), vec![], Expect::Ok);

    // 2. Parameter files.
    let configs: [(&str, &'static str); 11] = [
        ("lod_zero.toml", "lod."),
        ("lod_nan.toml", "lod.full_detail_distance"),
        ("lod_negative.toml", "lod.full_detail_distance"),
        ("frames_zero.toml", "frames_in_flight"),
        ("frames_huge.toml", "frames_in_flight"),
        ("bogus_table.toml", ":3: bogus: unknown key"),
        ("nan.toml", "sim.dt"),
        ("inf_gravity.toml", "gravity"),
        ("wrong_type.toml", "sim.iterations"),
        ("binary.toml", "not UTF-8"),
        ("huge.toml", "more than"),
    ];
    for (file, text) in configs {
        let mut render = s(&["render", "--config", &f.arg(file), "--out", &o(format!("cfg_{file}"))]);
        render.extend(s(&tiny));
        add(format!("render --config {file}"), render, vec![], Expect::Error(text));
        add(
            format!("simulate --config {file}"),
            s(&["simulate", "--config", &f.arg(file), "--steps", "1"]),
            vec![],
            Expect::Error(text),
        );
    }
    let mut point =
        s(&["render", "--config", &f.arg("point_light.toml"), "--frames", "1", "--width", "32", "--height", "32"]);
    point.extend(s(&["--out", &o("point".into()), "--shadow-resolution", "16"]));
    add("a shadowed point light".into(), point, vec![], Expect::Error("--volume-shadows or --no-shadows"));

    // 3. Flags with absurd values: status 0 or 1 and a clean end whatever the value.
    let absurd = ["0", "-1", "nan", "inf", "-inf", "1e30", "4294967296", "", "abc"];
    let flags: [(&[&str], &[&str]); 6] = [
        (
            &["render", "--frames", "1", "--width", "32", "--height", "32", "--no-shadows"],
            &[
                "--width",
                "--height",
                "--frames",
                "--hairs-per-key",
                "--level",
                "--distance",
                "--sorted-fragments",
                "--fragments-per-pixel",
                "--shadow-resolution",
                "--scale",
                "--points",
                "--iterations",
                "--substeps",
                "--grid",
                "--max-iterations",
            ],
        ),
        (
            &["simulate", "--steps", "1"],
            &["--steps", "--iterations", "--substeps", "--grid", "--max-iterations", "--scale", "--points"],
        ),
        (
            &["grow", "--strands", "20"],
            &[
                "--strands",
                "--points",
                "--length",
                "--droop",
                "--max-angle",
                "--radius",
                "--center",
                "--min-height",
                "--min-up-dot",
                "--seed",
            ],
        ),
        (&["convert"], &["--points", "--key-hairs"]),
        (&["bench", "--quick"], &["--samples", "--scaling-samples", "--figure-seconds"]),
        (&["bench", "--quick", "--samples", "1"], &["--large"]),
    ];
    for (base, names) in flags {
        for flag in names {
            for value in absurd {
                n += 1;
                let mut args = s(base);
                if base[0] == "render" {
                    args.extend(s(&["--out", &o(format!("flag{n}"))]));
                }
                if base[0] == "grow" && *flag != "--out" {
                    args.extend(s(&["--scalp", "sphere", "--out", &o(format!("flag{n}.hair"))]));
                }
                if base[0] == "convert" {
                    args.extend(s(&[&f.arg("good.hair"), "--out", &o(format!("flag{n}.hair"))]));
                }
                let needs_input = ["--scale", "--points"].contains(flag) && base[0] != "grow" && base[0] != "convert";
                if needs_input {
                    args.extend(s(&["--input", &f.arg("good.hair")]));
                }
                args.extend(s(&[flag, value]));
                // The bench runs only the values it must refuse (a valid one would
                // start a whole benchmark).
                let expect = if base[0] == "bench" { Expect::Error("vkhair: ") } else { Expect::Either };
                if base[0] == "bench" && !["0", "-1", "nan", "", "abc"].contains(&value) {
                    continue;
                }
                // A huge value that is valid would start a huge run.
                if ["1e30", "4294967296", "inf"].contains(&value) && !["--distance", "--scale"].contains(flag) {
                    let parse_only = ["--seed", "--min-height", "--min-up-dot", "--droop", "--length"];
                    if !parse_only.contains(flag) {
                        add(format!("{} {flag} {value}", base[0]), args, vec![], Expect::Error("vkhair: "));
                        continue;
                    }
                }
                add(format!("{} {flag} {value:?}", base[0]), args, vec![], expect);
            }
        }
    }
    let named: [(&str, Vec<String>, &'static str); 5] = [
        ("--width 8193", s(&["render", "--width", "8193"]), "16..=8192"),
        (
            "--max-angle 999",
            s(&["grow", "--scalp", "sphere", "--max-angle", "999", "--out", &o("a.hair".into())]),
            "(0, 180] degrees",
        ),
        (
            "--max-angle -5",
            s(&["grow", "--scalp", "sphere", "--max-angle=-5", "--out", &o("b.hair".into())]),
            "(got -5)",
        ),
        ("--scaling-samples 0", s(&["bench", "--scaling-samples", "0"]), "--scaling-samples must be at least 1"),
        ("--samples 0", s(&["bench", "--samples", "0"]), "--samples must be at least 1"),
    ];
    for (name, args, text) in named {
        add(name.into(), args, vec![], Expect::Error(text));
    }

    // 4. Outputs.
    let victim = f.arg("victim.txt");
    let link = |name: &str| {
        let path = out.join(name);
        std::os::unix::fs::symlink(&victim, &path).expect("plant a link");
        path.display().to_string()
    };
    std::fs::create_dir_all(out.join("planted")).expect("mkdir");
    std::os::unix::fs::symlink(&victim, out.join("planted/frame_0000.png")).expect("plant a frame link");
    let mut planted = s(&["render", "--out", &o("planted".into())]);
    planted.extend(s(&tiny));
    let outputs: Vec<(&str, Vec<String>, &'static str)> = vec![
        ("render into a planted frame link", planted, "symbolic link"),
        ("grow --out a link", s(&["grow", "--out", &link("link.hair")]), "symbolic link"),
        ("convert --out a link", s(&["convert", &f.arg("good.hair"), "--out", &link("link2.hair")]), "symbolic link"),
        ("simulate --json a link", s(&["simulate", "--steps", "1", "--json", &link("link.json")]), "symbolic link"),
        ("simulate --trace a link", s(&["simulate", "--steps", "1", "--trace", &link("link2.json")]), "symbolic link"),
        ("simulate --out a link", s(&["simulate", "--steps", "1", "--out", &link("link3.hair")]), "symbolic link"),
        ("plot --out a link", s(&["plot", &f.arg("figures.csv"), "--out", &link("link.png")]), "symbolic link"),
        (
            "render --json /dev/full",
            s(&["render", "--json", "/dev/full", "--frames", "1", "--out", &o("full".into())]),
            "is a device",
        ),
        ("simulate --trace /dev/full", s(&["simulate", "--trace", "/dev/full"]), "is a device"),
        ("grow --out /dev/full", s(&["grow", "--out", "/dev/full"]), "is a device"),
        (
            "--json and --trace on one path",
            s(&["simulate", "--json", &o("x.json".into()), "--trace", &o("x.json".into())]),
            "both name",
        ),
        ("render --out and --json inside", s(&["render", "--out", &o("same".into()), "--json", &o("same".into())]), ""),
        ("plot into its own CSV", s(&["plot", &f.arg("table.png")]), "also this run's input"),
        ("plot --out its CSV", s(&["plot", &f.arg("figures.csv"), "--out", &f.arg("figures.csv")]), ".png"),
        (
            "convert onto its input",
            s(&["convert", &f.arg("good.hair"), "--out", &f.arg("good.hair")]),
            "also this run's input",
        ),
        (
            "simulate --out onto its input",
            s(&["simulate", "--input", &f.arg("good.hair"), "--out", &f.arg("good.hair")]),
            "also this run's input",
        ),
        ("simulate --out x.tfx", s(&["simulate", "--steps", "1", "--out", &o("x.tfx".into())]), ".hair files"),
        ("grow --out g.obj", s(&["grow", "--out", &o("g.obj".into())]), ".hair files"),
        ("simulate --json x.txt", s(&["simulate", "--steps", "1", "--json", &o("x.txt".into())]), ".json files"),
        ("grow into a missing folder", s(&["grow", "--out", &o("no/such/folder/g.hair".into())]), "does not exist"),
        ("grow --out a folder", s(&["grow", "--out", &f.arg("folder")]), "is a folder"),
        ("render --out a file", s(&["render", "--out", &f.arg("good.obj"), "--frames", "1"]), "is a file"),
        (
            "plot with no usable row",
            s(&["plot", &f.arg("no_rows.csv"), "--out", &o("rows.png".into())]),
            "no row has an error figure",
        ),
    ];
    for (name, args, text) in outputs {
        let expect = if text.is_empty() { Expect::Error("vkhair: ") } else { Expect::Error(text) };
        add(name.into(), args, vec![], expect);
    }
    add(
        "plot 200,000 bad rows".into(),
        s(&["plot", &f.arg("bad_rows.csv"), "--out", &o("bad.png".into())]),
        vec![],
        Expect::Ok,
    );
    add(
        "simulate --json /dev/stdout".into(),
        s(&["simulate", "--steps", "1", "--json", "/dev/stdout"]),
        vec![],
        Expect::Ok,
    );
    add("grow --out /dev/null".into(), s(&["grow", "--strands", "10", "--out", "/dev/null"]), vec![], Expect::Ok);

    // 5. Environments.
    let env = |name: &'static str, value: &[u8]| {
        use std::os::unix::ffi::OsStringExt;
        vec![(name, OsString::from_vec(value.to_vec()))]
    };
    add(
        "VKHAIR_DEVICE=nonexistent devices".into(),
        s(&["devices"]),
        env("VKHAIR_DEVICE", b"nonexistent"),
        Expect::Error("matches no usable device"),
    );
    add(
        "VKHAIR_DEVICE=nonexistent simulate".into(),
        s(&["simulate", "--steps", "1"]),
        env("VKHAIR_DEVICE", b"nonexistent"),
        Expect::Error("nonexistent"),
    );
    add(
        "VKHAIR_DEVICE not UTF-8".into(),
        s(&["devices"]),
        env("VKHAIR_DEVICE", b"\xff\xfe"),
        Expect::Error("matches no usable device"),
    );
    add(
        "VKHAIR_MAX_INPUT_BYTES=abc".into(),
        s(&["simulate", "--config", &f.arg("nan.toml")]),
        env("VKHAIR_MAX_INPUT_BYTES", b"abc"),
        Expect::Error("VKHAIR_MAX_INPUT_BYTES"),
    );
    add(
        "VKHAIR_MAX_INPUT_BYTES=10".into(),
        s(&["simulate", "--config", &f.arg("nan.toml")]),
        env("VKHAIR_MAX_INPUT_BYTES", b"10"),
        Expect::Error("more than 10 bytes"),
    );
    add("VKHAIR_VALIDATION=garbage".into(), s(&["devices"]), env("VKHAIR_VALIDATION", b"\xff"), Expect::Ok);
    cases
}

/// Runs one case and returns what is wrong with how it ended (`.partial` files
/// are looked for once every run has ended: another run may be writing one).
fn check(case: &Case, victim: &Path) -> Option<String> {
    let mut command = vkhair();
    command.args(&case.args).stdin(std::process::Stdio::null());
    for (k, v) in &case.env {
        command.env(k, v);
    }
    let run = run_command(&mut command, LIMIT);
    // clap refuses a value it cannot parse with status 2 and an `error: ` line,
    // as command-line tools do for usage errors.
    let usage_error = run.status.code() == Some(2) && run.stderr.starts_with("error: ");
    let code = if usage_error { Some(1) } else { run.status.code() };
    let mut problems = Vec::new();
    if !matches!(code, Some(0 | 1)) {
        problems.push(format!("ended with {:?}", run.status));
    }
    if run.stderr.contains("panicked") {
        problems.push("panicked".into());
    }
    if run.stderr.contains("vulkan: ") {
        problems.push("a validation message".into());
    }
    if code == Some(1) && !usage_error && !run.stderr.lines().any(|l| l.starts_with("vkhair: ")) {
        problems.push("failed without saying why".into());
    }
    match case.expect {
        Expect::Either => {}
        Expect::Ok if code != Some(0) => problems.push("failed".into()),
        Expect::Error(text) if code != Some(1) || !(run.stderr.contains(text) || usage_error && text == "vkhair: ") => {
            problems.push(format!("expected an error with {text:?}"))
        }
        _ => {}
    }
    if std::fs::read(victim).ok().as_deref() != Some(&b"precious"[..]) {
        problems.push("changed the victim file".into());
    }
    if case.name == "plot 200,000 bad rows" && run.stdout.lines().count() > 20 {
        problems.push(format!("printed {} lines", run.stdout.lines().count()));
    }
    (!problems.is_empty()).then(|| {
        format!("{}: {}\n  args {:?}\n  stderr {}", case.name, problems.join(", "), case.args, run.stderr.trim())
    })
}

/// `.partial` files anywhere under `dir`.
fn partial_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.to_string_lossy().ends_with(".partial") {
                found.push(path);
            }
        }
    }
    found
}

#[test]
fn a_hostile_user_gets_clean_errors_and_nothing_clobbered() {
    let fixtures = Fixtures::new();
    let out = tempfile::tempdir().expect("output folder");
    let cases = cases(&fixtures, out.path());
    assert!(cases.len() >= 400, "only {} scenarios", cases.len());
    let victim = fixtures.path("victim.txt");
    let queue = Mutex::new(cases.iter());
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let next = queue.lock().expect("queue").next();
                let Some(case) = next else { break };
                if let Some(problem) = check(case, &victim) {
                    failures.lock().expect("failures").push(problem);
                }
            });
        }
    });
    let failures = failures.into_inner().expect("failures");
    assert!(
        failures.is_empty(),
        "{} of {} scenarios went wrong:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
    for dir in [fixtures.dir.path(), out.path()] {
        assert!(partial_files(dir).is_empty(), "left behind: {:?}", partial_files(dir));
    }
    println!("{} hostile scenarios ended cleanly", cases.len());
}

/// A folder of 35 frames from an earlier run: a 2-frame run removes the 33 it
/// does not overwrite (and says so), and leaves other files alone.
#[test]
fn a_run_into_an_earlier_runs_folder_keeps_only_its_own_frames() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    std::fs::create_dir(&out).expect("mkdir");
    for i in 0..35 {
        std::fs::write(out.join(format!("frame_{i:04}.png")), b"old").expect("write");
    }
    std::fs::write(out.join("notes.txt"), b"mine").expect("write");
    let args = ["render", "--frames", "2", "--width", "32", "--height", "32", "--no-shadows", "--out"];
    let run = run_command(vkhair().args(args).arg(&out), LIMIT);
    run.assert_ok();
    assert!(run.stdout.contains("removed 33 frames of an earlier run"), "{}", run.stdout);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["contact_sheet.png", "frame_0000.png", "frame_0001.png", "notes.txt"]);
}

/// SIGTERM during a run ends it with status 143 and no `.partial` file (SIGINT
/// the same with 130).
#[test]
fn a_signal_ends_a_run_without_leaving_a_partial_file() {
    for (signal, status) in [(libc::SIGTERM, 143), (libc::SIGINT, 130)] {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("frames");
        let mut child = vkhair()
            .args(["render", "--frames", "400", "--width", "320", "--height", "240", "--no-shadows", "--out"])
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start");
        // Wait for the first frames, so that the signal lands while frames are written.
        let started = std::time::Instant::now();
        while !out.join("frame_0002.png").exists() {
            assert!(started.elapsed() < LIMIT, "no frame after {LIMIT:?}");
            assert!(child.try_wait().expect("wait").is_none(), "the run ended before the signal");
            std::thread::sleep(Duration::from_millis(20));
        }
        // SAFETY: kill with the child's own pid.
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let code = child.wait().expect("wait").code();
        assert_eq!(code, Some(status), "signal {signal}");
        assert!(partial_files(dir.path()).is_empty(), "signal {signal}: {:?}", partial_files(dir.path()));
    }
}

/// A `.hair` file of four 1 cm-segment strands, one with a point thrown
/// 100 km away: without `--strict` that strand alone is dropped and named as
/// an outlier (strand, point, value) and the other three keep every segment
/// (judged against the whole groom's 100 km extent, their segments had been
/// "zero-length" and dropped, the broken strand kept); with `--strict` the
/// file is refused naming the outlier.
#[test]
fn a_file_with_one_far_point_loses_that_strand_alone() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("outlier.hair");
    let strand = |x: f32| (0..6).map(|i| glam::Vec3::new(x, -0.01 * i as f32, 0.0)).collect::<Vec<_>>();
    let mut broken = strand(0.2);
    broken[3] = glam::Vec3::new(1e5, 0.0, 0.0);
    write_groom_unchecked(&path, &[strand(0.0), strand(0.1), broken, strand(0.3)]);
    let run = run_command(vkhair().arg("inspect").arg(&path), LIMIT);
    run.assert_ok();
    let said = format!("{}{}", run.stdout, run.stderr);
    assert!(said.contains("dropped 1 strand with an outlier point") && said.contains("strand 2 point 3"), "{said}");
    assert!(said.contains("strands            3"), "{said}");
    assert!(!said.contains("zero-length"), "{said}");
    let strict = run_command(vkhair().args(["inspect", "--strict"]).arg(&path), LIMIT);
    assert!(strict.stderr.contains("strand 2") && strict.stderr.contains("100000"), "{}", strict.stderr);
}
