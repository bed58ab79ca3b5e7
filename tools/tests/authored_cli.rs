//! USD and Alembic grooms through the tool: `inspect` (table and `--json`),
//! `convert` to `.hair` and `.abc` and back, `render` and `simulate`.

use crate::common;

use std::path::{Path, PathBuf};
use std::time::Duration;

use common::{run, run_line};

const LIMIT: Duration = Duration::from_secs(300);

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data").join(name)
}

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout).unwrap_or_else(|e| panic!("not JSON ({e}):\n{stdout}"))
}

#[test]
fn inspect_tells_guides_units_axes_and_objects() {
    let usd = data("usd/small_cm_zup.usda");
    let out = run(&["inspect", usd.to_str().expect("utf-8")], LIMIT);
    out.assert_ok();
    for line in [
        "/groom/linear (3 linear curves), /groom/cubic (1 cubic B-spline curve)",
        "guides             2 marked by the file (groom_guide), 2 followers",
        "0.01 m per unit (stated)",
        "Z up in the file, turned to Y up",
        "root UVs no",
    ] {
        assert!(out.stdout.contains(line), "{line:?} missing from:\n{}", out.stdout);
    }
    let out = run(&["inspect", "--json", usd.to_str().expect("utf-8")], LIMIT);
    out.assert_ok();
    let j = json(&out.stdout);
    assert_eq!((j["strands"].as_u64(), j["points"].as_u64()), (Some(4), Some(14)));
    assert_eq!((j["guides_marked"].as_u64(), j["followers"].as_u64()), (Some(2), Some(2)));
    assert_eq!(j["meters_per_unit"].as_f64(), Some(0.01));
    assert_eq!(j["up_axis"].as_str(), Some("Z"));
    assert_eq!(j["attributes"]["thickness"].as_bool(), Some(true));
    assert_eq!(j["curve_objects"][1]["path"].as_str(), Some("/groom/cubic"));
    // Alembic: no unit stated, a periodic object passed over and said.
    let abc = data("curves/cortex_curves.abc");
    let out = run(&["inspect", "--json", abc.to_str().expect("utf-8")], LIMIT);
    out.assert_ok();
    let j = json(&out.stdout);
    assert_eq!((j["strands"].as_u64(), j["units_stated"].as_bool()), (Some(2), Some(false)));
    assert!(out.stderr.contains("/nurbsCircle/object"), "{}", out.stderr);
    run(&["inspect", "--strict", abc.to_str().expect("utf-8")], LIMIT).assert_error("/nurbsCircle/object");
}

#[test]
fn convert_round_trips_through_alembic_and_hair() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = data("curves/arnold-usd_test_0184_groom_sphere.usda");
    let abc = dir.path().join("groom.abc");
    let hair = dir.path().join("groom.hair");
    let line = format!("convert {} --out {}", usd.display(), abc.display());
    run_line(&line, LIMIT).assert_ok();
    run_line(&format!("convert {} --out {}", abc.display(), hair.display()), LIMIT).assert_ok();
    let counts = |path: &Path| {
        let out = run(&["inspect", "--json", path.to_str().expect("utf-8")], LIMIT);
        out.assert_ok();
        let j = json(&out.stdout);
        let b = &j["bounds"];
        (j["strands"].as_u64(), j["points"].as_u64(), b["min"].to_string(), b["max"].to_string())
    };
    let want = counts(&usd);
    assert_eq!(want.0, Some(118));
    assert_eq!(counts(&abc), want);
    assert_eq!(counts(&hair), want);
    // Anything else is refused before reading.
    let bad = dir.path().join("groom.usda");
    run_line(&format!("convert {} --out {}", usd.display(), bad.display()), LIMIT).assert_error("--out");
}

#[test]
fn render_and_simulate_take_usd_and_alembic() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = data("curves/arnold-usd_test_0184_groom_sphere.usda");
    let abc = dir.path().join("groom.abc");
    run_line(&format!("convert {} --out {}", usd.display(), abc.display()), LIMIT).assert_ok();
    for input in [usd, abc] {
        let out = dir.path().join(format!("{}-frames", input.extension().and_then(|e| e.to_str()).unwrap_or("x")));
        let line = format!(
            "render --input {} --frames 1 --width 160 --height 120 --shadow-resolution 64 --out {}",
            input.display(),
            out.display()
        );
        run_line(&line, LIMIT).assert_ok();
        let (_, _, rgba) = common::read_png(&out.join("frame_0000.png"));
        let covered = common::coverage(&rgba);
        assert!(covered > 0.02, "{}: the groom covers {:.2} % of the image", input.display(), 100.0 * covered);
        let line = format!("simulate --input {} --steps 2", input.display());
        run_line(&line, LIMIT).assert_ok();
    }
}

#[test]
fn usd_and_alembic_reads_are_bounded() {
    for name in ["usd/small_cm_zup.usdc", "curves/cortex_curves.abc"] {
        let path = data(name);
        let mut command = common::vkhair();
        command.env("VKHAIR_MAX_INPUT_BYTES", "1000").args(["inspect", path.to_str().expect("utf-8")]);
        let out = common::run_command(&mut command, LIMIT);
        out.assert_error("more than 1000 bytes");
    }
    // A FIFO: nothing bounds what the USD library would take from it.
    let dir = tempfile::tempdir().expect("temp dir");
    let fifo = dir.path().join("pipe.usda");
    let c = std::ffi::CString::new(fifo.to_str().expect("utf-8")).expect("path");
    // SAFETY: mkfifo with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    run(&["inspect", fifo.to_str().expect("utf-8")], LIMIT).assert_error("not a regular file");
}

/// A dense groom written by usd-core (`tools/usd_dense_groom.py`: 1,500 curly
/// strands of 24 points, meters, Z up; its head sphere as an OBJ): rendered
/// as followers of guides colliding with the head, and
/// `simulate --drawn-out` writes every authored strand as drawn, in the file's
/// order, close to the authored one after one still step.
#[test]
fn a_dense_groom_draws_its_authored_strands_as_followers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = data("usd/dense_curly.usdc");
    let frames = dir.path().join("frames");
    let line = format!(
        "render --input {} --obj {} --guides 0.1 --frames 1 --width 160 --height 120 --shadow-resolution 64 --out {}",
        usd.display(),
        data("usd/dense_curly_head.obj").display(),
        frames.display()
    );
    let out = run_line(&line, LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("followers: 1500 strands drawn as followers of 150 guides"), "{}", out.stdout);
    assert!(out.stdout.contains("mesh collider"), "{}", out.stdout);
    let (_, _, rgba) = common::read_png(&frames.join("frame_0000.png"));
    assert!(common::coverage(&rgba) > 0.05, "the groom covers {:.2} % of the image", 100.0 * common::coverage(&rgba));
    // The same through Alembic: converted, then read with its own reader.
    let abc = dir.path().join("dense.abc");
    run_line(&format!("convert {} --out {}", usd.display(), abc.display()), LIMIT).assert_ok();
    let drawn = dir.path().join("drawn.hair");
    let line = format!(
        "simulate --input {} --guides 150 --steps 1 --motion still --drawn-out {}",
        abc.display(),
        drawn.display()
    );
    let out = run_line(&line, LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("guides: 150 of 1500 strands"), "{}", out.stdout);
    let drawn = vkhair::groom::cyhair::HairFile::open(&drawn).expect("drawn strands").groom;
    let authored = vkhair::groom::usd::open(&usd).expect("authored").groom;
    assert_eq!(drawn.strand_count(), authored.strand_count());
    let mut worst_root = 0.0f32;
    let mut deviations = Vec::new();
    for s in 0..authored.strand_count() {
        let (a, d) = (authored.strand(s), drawn.strand(s));
        worst_root = worst_root.max(a[0].distance(d[0]));
        let length: f32 = a.windows(2).map(|w| w[0].distance(w[1])).sum();
        for p in a {
            let near = d
                .windows(2)
                .map(|w| {
                    let e = w[1] - w[0];
                    let t = ((*p - w[0]).dot(e) / e.length_squared()).clamp(0.0, 1.0);
                    p.distance(w[0] + t * e)
                })
                .fold(f32::MAX, f32::min);
            deviations.push(near / length);
        }
    }
    deviations.sort_by(f32::total_cmp);
    let p95 = deviations[deviations.len() * 95 / 100];
    println!(
        "drawn against authored after one still step: roots within {worst_root:e} m, p95 {:.3} % of the strand length",
        100.0 * p95
    );
    assert!(worst_root < 1e-4, "a drawn root is {worst_root} m from its authored root: not the file's order?");
    assert!(p95 < 0.01, "p95 deviation {:.3} % of the strand length", 100.0 * p95);
}

#[test]
fn guides_options_are_checked() {
    run_line("render --guides 10", LIMIT).assert_error("--guides needs --input");
    let usd = data("usd/dense_curly.usdc");
    for (bad, says) in [("0", "at least 1"), ("1.5", "a share between 0 and 1"), ("many", "`all`")] {
        run_line(&format!("simulate --input {} --guides {bad} --steps 1", usd.display()), LIMIT).assert_error(says);
    }
    // `all`: every strand a key hair, no followers.
    let out = run_line(&format!("simulate --input {} --guides all --steps 1", usd.display()), LIMIT);
    out.assert_ok();
    assert!(out.stdout.contains("1500 key hairs") && !out.stdout.contains("guides:"), "{}", out.stdout);
}

/// Writes a `w` × `h` RGB PNG of `texel(x, y)`.
fn write_png(path: &Path, (w, h): (u32, u32), texel: impl Fn(u32, u32) -> [u8; 3]) {
    let file = std::fs::File::create(path).expect("png file");
    let mut encoder = png::Encoder::new(file, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let data: Vec<u8> = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).flat_map(|(x, y)| texel(x, y)).collect();
    encoder.write_header().expect("header").write_image_data(&data).expect("pixels");
}

/// Mean RGB of the pixels that are not the background.
fn hair_rgb(path: &Path) -> [f64; 3] {
    let (_, _, rgba) = common::read_png(path);
    let bg = [rgba[0], rgba[1], rgba[2]];
    let hair: Vec<&[u8]> = rgba.chunks_exact(4).filter(|p| p[..3] != bg).collect();
    let n = hair.len().max(1) as f64;
    [0, 1, 2].map(|c| hair.iter().map(|p| f64::from(p[c])).sum::<f64>() / n)
}

#[test]
fn followers_take_the_file_colours_or_a_scalp_texture() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = data("usd/dense_curly.usdc");
    let render = |extra: &str, out: &str| {
        let frames = dir.path().join(out);
        let line = format!(
            "render --input {} --guides 0.1 --no-shadows --frames 1 --width 120 --height 120 --out {} {extra}",
            usd.display(),
            frames.display()
        );
        let run = run_line(&line, LIMIT);
        run.assert_ok();
        (run.stdout.clone(), hair_rgb(&frames.join("frame_0000.png")))
    };
    // The file's displayColor: browns, red over green over blue.
    let (stdout, file) = render("", "file");
    assert!(stdout.contains("the file's colours"), "{stdout}");
    assert!(file[0] > file[1] && file[1] > file[2], "the file's browns drawn as {file:?}");
    // A green scalp texture, sampled at the root UVs.
    let texture = dir.path().join("green.png");
    write_png(&texture, (2, 2), |_, _| [0, 200, 0]);
    let (stdout, green) = render(&format!("--scalp-texture {}", texture.display()), "green");
    assert!(stdout.contains("the scalp texture at the root UVs colours"), "{stdout}");
    assert!(green[1] > 2.0 * green[0] && green[1] > 2.0 * green[2], "a green texture drawn as {green:?}");
    // No root UVs, no dense groom, no image: said.
    let arnold = data("curves/arnold-usd_test_0184_groom_sphere.usda");
    let line = format!("render --input {} --guides 20 --scalp-texture {}", arnold.display(), texture.display());
    run_line(&line, LIMIT).assert_error("has no root UVs");
    let line = format!("render --input {} --scalp-texture {}", arnold.display(), texture.display());
    run_line(&line, LIMIT).assert_error("give --guides");
    // An image that declares 9000 × 9000 texels is refused before decoding.
    let huge = dir.path().join("huge.png");
    let file = std::fs::File::create(&huge).expect("png file");
    let mut encoder = png::Encoder::new(file, 9000, 9000);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::One);
    encoder.write_header().expect("header").write_image_data(&vec![0u8; 1125 * 9000]).expect("pixels");
    let line = format!("render --input {} --guides 0.1 --scalp-texture {}", usd.display(), huge.display());
    run_line(&line, LIMIT).assert_error("at most 67108864 texels");
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"not a png").expect("write");
    let line = format!("render --input {} --guides 0.1 --scalp-texture {}", usd.display(), junk.display());
    run_line(&line, LIMIT).assert_error("not a PNG image");
}

/// `.usdc` files the USD library stopped on with a panic (a `todo!()` for
/// chunked LZ4, a token index past the end of its table) are refused by the
/// crate's own checks before the library reads them: one error line naming
/// the file and the value, no panic message or backtrace on stderr; the
/// files are the test's own byte edits of the shared fixture.
#[test]
fn a_usdc_the_usd_library_panicked_on_is_refused_first_in_one_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let original = std::fs::read(data("usd/small_cm_zup.usdc")).expect("read the fixture");
    let edits: [(&str, &[(usize, u8)]); 3] = [
        ("its section \"SPECS\": a compressed block of 219 chunks", &[(1689, 219)]),
        ("value (type 0) starts at byte 75812, past the file's end", &[(1350, 33)]),
        ("field 10 (\"properties\")'s value (type 41) names token 603979799 of 44", &[(203, 36)]),
    ];
    for (k, (what, bytes)) in edits.iter().enumerate() {
        let mut edited = original.clone();
        for &(at, value) in bytes.iter() {
            edited[at] = value;
        }
        let path = dir.path().join(format!("edited_{k}.usdc"));
        std::fs::write(&path, &edited).expect("write");
        let out = run(&["inspect", path.to_str().expect("utf-8")], LIMIT);
        out.assert_error(what);
        assert!(out.stderr.contains(&format!("edited_{k}.usdc")), "case {k} names no file: {}", out.stderr);
        assert!(!out.stderr.contains("stack backtrace") && !out.stderr.contains("thread '"), "{}", out.stderr);
        assert_eq!(out.stderr.lines().count(), 1, "case {k}: one line, the error:\n{}", out.stderr);
    }
}

/// The USD cap bounds a stage's layers together: a root and a sublayer each
/// within it but over it together are refused, naming the bound.
#[test]
fn a_stage_whose_layers_add_up_past_the_cap_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let pad = format!("# {}\n", "x".repeat(600));
    let curves = "def BasisCurves \"c\" { int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0),(0,1,0)] }\n";
    std::fs::write(dir.path().join("curves.usda"), format!("#usda 1.0\n{pad}{curves}")).expect("write");
    let root = dir.path().join("root.usda");
    std::fs::write(&root, format!("#usda 1.0\n{pad}(\n    subLayers = [@curves.usda@]\n)\n")).expect("write");
    let inspect = |cap: &str| {
        let mut c = common::vkhair();
        c.env("VKHAIR_MAX_INPUT_BYTES", cap).args(["inspect", root.to_str().expect("utf-8")]);
        common::run_command(&mut c, LIMIT)
    };
    inspect("4000").assert_ok();
    inspect("1000").assert_error("the stage's layers add up to more than 1000 bytes");
}
