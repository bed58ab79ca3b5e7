//! USD grooms (`vkhair::groom::usd`): fixtures written by Pixar's own library
//! (`tools/usd_fixtures.py`, usd-core 26.11; every expected value below is the
//! one that script wrote) and a real groom (arnold-usd's test 0184, its
//! expected points computed by usd-core's `ComputeLocalToWorldTransform`).

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use vkhair::groom::authored::{Basis, UpAxis};
use vkhair::groom::{usd, usda_check};
use vkhair::Error;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-6
}

/// The small stage: centimetres, Z up, a translated parent, a linear and a
/// cubic prim, and a mesh that is not read. Text and binary give the same.
#[test]
fn small_stage_reads_in_meters_y_up_with_its_attributes() {
    for file in ["usd/small_cm_zup.usda", "usd/small_cm_zup.usdc"] {
        let g = usd::open(data(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!((g.meters_per_unit, g.units_stated, g.up_axis), (0.01, true, UpAxis::Z), "{file}");
        let objects: Vec<(&str, usize, Basis)> =
            g.objects.iter().map(|o| (o.path.as_str(), o.curves, o.basis)).collect();
        assert_eq!(objects, [("/groom/linear", 3, Basis::Linear), ("/groom/cubic", 1, Basis::Bspline)], "{file}");
        let groom = &g.groom;
        assert_eq!((groom.strand_count(), groom.point_count()), (4, 14), "{file}");
        // Linear curve c, point i: (i, 10c, 0) cm under a (0, 0, 100) cm
        // translate, Z up → (0.01 i, 1, -0.1 c) m, Y up.
        for (c, n) in [2usize, 3, 4].into_iter().enumerate() {
            let strand = groom.strand(c);
            assert_eq!(strand.len(), n, "{file}");
            for (i, &p) in strand.iter().enumerate() {
                let want = Vec3::new(0.01 * i as f32, 1.0, -0.1 * c as f32);
                assert!(close(p, want), "{file}: curve {c} point {i}: {p} against {want}");
            }
        }
        // The cubic curve: (0, 50, 2i) cm → (0, 1 + 0.02 i, -0.5) m.
        for (i, &p) in groom.strand(3).iter().enumerate() {
            assert!(close(p, Vec3::new(0.0, 1.0 + 0.02 * i as f32, -0.5)), "{file}: cubic point {i}: {p}");
        }
        // Widths 0.2 - 0.05 i cm per vertex, then 0.1 cm constant, in meters.
        let thickness = groom.thickness().expect("widths");
        let want: Vec<f32> = [2usize, 3, 4]
            .into_iter()
            .flat_map(|n| (0..n).map(|i| 0.002 - 0.0005 * i as f32))
            .chain([0.001; 5])
            .collect();
        for (t, w) in thickness.iter().zip(&want) {
            assert!((t - w).abs() < 1e-9, "{file}: width {t} against {w}");
        }
        // displayColor per curve (red, green, blue), then constant grey.
        let colors = groom.colors().expect("colours");
        let per_strand = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::splat(0.5)];
        for (s, want) in per_strand.iter().enumerate() {
            for i in groom.strand_range(s) {
                assert_eq!(colors[i], *want, "{file}: strand {s}");
            }
        }
        // groom_guide on the linear prim only: the cubic strand is no guide.
        assert_eq!(g.guides.as_deref(), Some(&[true, false, true, false][..]), "{file}");
        assert_eq!(g.guide_count(), 2);
        // st on the linear prim only: dropped, and said.
        assert_eq!(g.root_uvs, None, "{file}");
        assert!(g.skipped.iter().any(|s| s.contains("root UVs") && s.contains("1 of 2")), "{file}: {:?}", g.skipped);
    }
}

#[test]
fn root_uvs_are_read_per_strand() {
    // The linear prim alone (the cubic one has no st): through a stage that
    // deactivates nothing but a copy without the cubic prim.
    let text = std::fs::read_to_string(data("usd/small_cm_zup.usda")).expect("fixture");
    let start = text.find("    def BasisCurves \"cubic\"").expect("cubic prim");
    let end = text.find("    def Mesh").expect("mesh prim");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("linear.usda");
    std::fs::write(&path, format!("{}{}", &text[..start], &text[end..])).expect("write");
    let g = usd::open(&path).expect("read");
    let uvs = g.root_uvs.expect("root UVs");
    assert_eq!(uvs, vec![Vec2::new(0.1, 0.2), Vec2::new(0.3, 0.4), Vec2::new(0.5, 0.6)]);
}

#[test]
fn a_real_groom_reads_with_its_transform_and_widths() {
    let g = usd::open(data("curves/arnold-usd_test_0184_groom_sphere.usda")).expect("arnold-usd groom");
    // 118 curves of 13 points, each pinned by three equal points at its root
    // and its tip: 9 points a strand once those are kept once.
    assert_eq!((g.groom.strand_count(), g.groom.point_count()), (118, 118 * 9));
    assert_eq!(g.objects[0].basis, Basis::Bspline);
    assert_eq!((g.meters_per_unit, g.up_axis), (1.0, UpAxis::Y));
    // usd-core: the prim's xformOp:scale of 2 applied (its points 0, 12, 13).
    let s0 = g.groom.strand(0);
    assert!(close(s0[0], Vec3::new(-0.030084286, 1.992629, -0.14639603)), "{}", s0[0]);
    assert!(close(s0[8], Vec3::new(-0.13392752, 2.0927486, -0.06023486)), "{}", s0[8]);
    assert!(close(g.groom.strand(1)[0], Vec3::new(-0.0050448216, 1.991179, 0.17870373)));
    // Widths per vertex, doubled by the scale: its fourth, 0.048067454 × 2, is
    // the strand's second point now.
    let t = g.groom.thickness().expect("widths");
    assert!((t[1] - 2.0 * 0.048_067_454).abs() < 1e-7, "{}", t[1]);
    assert_eq!(g.guides, None);
}

fn refused(name: &str) -> String {
    let e = usd::open(data(name)).expect_err(name);
    assert!(matches!(e, Error::Asset { .. }), "{name}: {e:?}");
    let text = e.to_string();
    assert!(text.contains(name.rsplit('/').next().unwrap_or(name)), "{name}: the file is not named: {text}");
    text
}

#[test]
fn defects_are_named_with_the_prim() {
    let text = refused("usd/periodic.usda");
    assert!(text.contains("/hair") && text.contains("periodic"), "{text}");
    let text = refused("usd/no_points.usda");
    assert!(text.contains("/hair") && text.contains("no points"), "{text}");
    let text = refused("usd/counts_mismatch.usda");
    assert!(text.contains("/hair") && text.contains("add up to 5 points but points holds 4"), "{text}");
    let text = refused("usd/nan.usda");
    assert!(text.contains("/hair") && text.contains("strand 0") && text.contains("point 1"), "{text}");
    // A curve object without curves (empty vertex counts and points: what a
    // binary layer relabelled as crate version 0.4 reads as) is said to hold
    // none, not "nothing left after repairing: nothing to repair".
    let dir = tempfile::tempdir().expect("tempdir");
    let empty = dir.path().join("empty.usda");
    std::fs::write(
        &empty,
        "#usda 1.0\ndef BasisCurves \"hair\" {\n    int[] curveVertexCounts = []\n    point3f[] points = []\n}\n",
    )
    .expect("write");
    for e in [usd::open(&empty).map(drop), usd::open_repairing(&empty).map(drop)] {
        let text = e.expect_err("no curves").to_string();
        assert!(
            text.contains("empty.usda") && text.contains("hold no curves (/hair: no curve vertex counts)"),
            "{text}"
        );
    }
    // Repairing passes over the loop, and then nothing is left to read.
    let e = usd::open_repairing(data("usd/periodic.usda")).expect_err("only a loop");
    assert!(e.to_string().contains("no BasisCurves prim") && e.to_string().contains("periodic"), "{e}");
    // A file that is not USD at all, and one cut short.
    let dir = tempfile::tempdir().expect("tempdir");
    let junk = dir.path().join("junk.usda");
    std::fs::write(&junk, "this is not a stage {").expect("write");
    let e = usd::open(&junk).expect_err("junk");
    assert!(e.to_string().contains("junk.usda"), "{e}");
    let bytes = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
    for cut in [8, 64, bytes.len() / 2, bytes.len() - 16] {
        let short = dir.path().join(format!("cut{cut}.usdc"));
        std::fs::write(&short, &bytes[..cut]).expect("write");
        let e = usd::open(&short).expect_err("truncated");
        assert!(e.to_string().contains(&format!("cut{cut}.usdc")), "{e}");
    }
    // A folder and a FIFO are not read.
    assert!(usd::open(dir.path()).is_err());
}

/// Mutations of the text fixture: every one read or refused, never a panic.
#[test]
fn mutated_stages_never_panic() {
    let text = std::fs::read_to_string(data("usd/small_cm_zup.usda")).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("m.usda");
    let mutations: Vec<String> = vec![
        text.replace("[2, 3, 4]", "[2, 3, -4]"),
        text.replace("[2, 3, 4]", "[2, 3, 40000000]"),
        text.replace("[(0.1, 0.2), (0.3, 0.4), (0.5, 0.6)]", "[(0.1, 0.2)]"),
        text.replace("[1, 0, 1]", "[1, 0]"),
        text.replace("metersPerUnit = 0.01", "metersPerUnit = -1"),
        text.replace("metersPerUnit = 0.01", "metersPerUnit = \"m\""),
        text.replace("upAxis = \"Z\"", "upAxis = \"X\""),
        text.replace("uniform token type = \"linear\"", "uniform token type = \"quintic\""),
        text.replace("(0, 0, 100)", "(0, 0, inf)"),
        text.replace("float[] widths = [0.2", "float[] widths = [nan"),
        text.replace("point3f[] points", "float[] points"),
    ];
    for (i, m) in mutations.iter().enumerate() {
        assert_ne!(m, &text, "mutation {i} changed nothing");
        std::fs::write(&path, m).expect("write");
        match usd::open(&path) {
            Ok(g) => panic!("mutation {i} was read: {} strands", g.groom.strand_count()),
            Err(e) => assert!(e.to_string().contains("m.usda"), "mutation {i}: {e}"),
        }
    }
}

#[test]
fn an_animated_stage_gives_its_first_sample() {
    // usd-core wrote points at times 5 (x = 0) and 10 (x = 1) only.
    let g = usd::open(data("usd/animated.usda")).expect("animated");
    let xs: Vec<f32> = g.groom.positions().iter().map(|p| p.x).collect();
    assert_eq!(xs, vec![0.0; 3], "not the first sample: {:?}", g.groom.positions());
}

#[test]
fn nested_rotations_scales_and_translations_compose_as_usd_core_does() {
    // usd-core's ComputeLocalToWorldTransform (tools/usd_fixtures.py prints them).
    let g = usd::open(data("usd/rotated.usda")).expect("rotated");
    let want = [Vec3::new(-0.1464466, 3.4783978, 3.7071068), Vec3::new(-0.3114437, 4.085_435, 3.3017896)];
    for (p, w) in g.groom.positions().iter().zip(want) {
        assert!((*p - w).length() < 1e-5, "{p} against usd-core's {w}");
    }
}

/// Text layers the USD library would recurse through without end or for
/// seconds — a class inheriting itself, two classes inheriting each other,
/// prims nested 5,000 deep, dictionaries nested 20,000 deep — are refused
/// before it reads them, each with the file, the line and what is wrong
/// (`groom::usda_check`).
#[test]
fn text_layers_that_recurse_without_bound_are_refused_before_reading() {
    let dir = tempfile::tempdir().expect("tempdir");
    let curves = STRAND;
    let deep_prims = format!(
        "{}{curves}{}",
        (0..5000).map(|i| format!("def Xform \"p{i}\" {{\n")).collect::<String>(),
        "}\n".repeat(5000)
    );
    let deep_dictionaries =
        format!("(\n customLayerData = {}{{}}{}\n)\n{curves}", "{ dictionary a = ".repeat(20_000), " }".repeat(20_000));
    let cases = [
        ("self.usda", format!("class \"A\" (\n    inherits = </A>\n)\n{{\n}}\n{curves}"), "line 3, column 5", "itself"),
        (
            "cycle.usda",
            format!("class \"A\" (\n inherits = </B>\n) {{ }}\nclass \"B\" (\n inherits = </A>\n) {{ }}\n{curves}"),
            "line 6",
            "a cycle",
        ),
        ("deep.usda", deep_prims, "line 130", "nesting deeper than 128"),
        ("dictionaries.usda", deep_dictionaries, "line 3", "nesting deeper than 128"),
    ];
    for (name, body, line, what) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("#usda 1.0\n{body}")).expect("write");
        let started = std::time::Instant::now();
        let err = usd::open(&path).expect_err(name).to_string();
        println!("{name}: {err} ({:?})", started.elapsed());
        for part in [name, line, what] {
            assert!(err.contains(part), "{name}: {part:?} missing from {err}");
        }
    }
}

/// Writes USD text `text` as a binary layer at `path` (the library's own writer).
fn write_binary(path: &Path, text: &str) {
    let data = openusd::usda::parse(text).expect("text");
    openusd::usdc::CrateWriter::write_to_file(&data, path).expect("binary");
}

/// One straight two-point strand: the curves of many of these tests' layers.
const STRAND: &str = "def BasisCurves \"c\" { int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0),(0,1,0)] }\n";

/// Writes text files under `dir` by name.
fn text_writer(dir: &Path) -> impl Fn(&str, &str) + '_ {
    move |name, text| std::fs::write(dir.join(name), text).expect("write")
}

/// Writes binary layers under `dir` by name, from their text.
fn binary_writer(dir: &Path) -> impl Fn(&str, &str) + '_ {
    move |name, text| write_binary(&dir.join(name), text)
}

/// Opens each `(root, parts)` stage under `dir`: refused, with every part in
/// the error (printed with the time it took).
fn refused_naming(dir: &Path, cases: &[(&str, &[&str])]) {
    for (root, parts) in cases {
        let started = std::time::Instant::now();
        let err = usd::open(dir.join(root)).expect_err(root).to_string();
        println!("{root}: {err} ({:?})", started.elapsed());
        for part in *parts {
            assert!(err.contains(part), "{root}: {part:?} missing from {err}");
        }
    }
}

/// Every layer a stage's text layers name is checked before the USD library
/// opens any: a sublayer that is there loads; a missing one, a FIFO in a
/// referenced layer's place (which the library would block on forever) and a
/// sublayer with a cycle of its own, and a reference without a prim path to
/// a layer of sublayers that names no default prim of its own, are errors
/// naming the layer, and the root layer and line that named it — never a
/// stage read without them; a default prim the layer names and a sublayer
/// holds reads.
#[test]
fn every_layer_a_stage_names_is_checked_and_none_is_dropped() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let curves = STRAND;
    write("curves.usda", &format!("#usda 1.0\n{curves}"));
    write("root.usda", "#usda 1.0\n(\n    subLayers = [\n        @./curves.usda@\n    ]\n)\n");
    let g = usd::open(dir.path().join("root.usda")).expect("a stage of a sublayer");
    assert_eq!(g.groom.strand_count(), 1);

    write("missing.usda", "#usda 1.0\n(\n    subLayers = [@./curves.usda@, @./gone.usda@]\n)\n");
    crate::common::mkfifo(&dir.path().join("pipe.usda"));
    write("fifo.usda", &format!("#usda 1.0\ndef Xform \"x\" (\n    references = @pipe.usda@</x>\n) {{ }}\n{curves}"));
    write("cyclic.usda", &format!("#usda 1.0\nclass \"A\" (\n    inherits = </A>\n) {{ }}\n{curves}"));
    write("names_cyclic.usda", "#usda 1.0\n(\n    subLayers = [@cyclic.usda@]\n)\n");
    // A layer of sublayers that names no default prim of its own (the one its
    // sublayer names does not count), taken by a reference without a prim path.
    write("defaulted.usda", &format!("#usda 1.0\n(\n    defaultPrim = \"c\"\n)\n{curves}"));
    write("no_default_over.usda", "#usda 1.0\n(\n    subLayers = [@defaulted.usda@]\n)\n");
    write("refs_no_default.usda", "#usda 1.0\ndef \"x\" (\n    references = @no_default_over.usda@\n) { }\n");
    // With its own default prim, found in its sublayer: read.
    write("default_over.usda", "#usda 1.0\n(\n    defaultPrim = \"c\"\n    subLayers = [@defaulted.usda@]\n)\n");
    write("refs_default.usda", "#usda 1.0\ndef \"x\" (\n    references = @default_over.usda@\n) { }\n");
    let g = usd::open(dir.path().join("refs_default.usda")).expect("a default prim from a sublayer");
    assert_eq!(g.groom.strand_count(), 1);
    refused_naming(
        dir.path(),
        &[
            (
                "refs_no_default.usda",
                &["refs_no_default.usda", "line 3", "no_default_over.usda", "names no default prim"][..],
            ),
            ("missing.usda", &["missing.usda", "line 3", "gone.usda"][..]),
            ("fifo.usda", &["fifo.usda", "line 3", "pipe.usda", "not a regular file"][..]),
            ("names_cyclic.usda", &["names_cyclic.usda", "line 3", "cyclic.usda", "line 3, column 5", "itself"][..]),
        ],
    );
}

/// The layers of one layer stack (a layer and its sublayers) share one
/// namespace: arcs that form a cycle only across two sublayers — classes that
/// inherit or specialise each other, or a chain through the root — are
/// refused naming the arc's layer and line (the USD library overflowed its
/// stack on each), while the same arcs without the cycle read; two stacks
/// (a reference) are judged apart; a layer's references to its own prims
/// through its own file count as arcs within it (a chain of them, a cycle).
/// A USDZ package, or a layer inside one, and an asset path that is an
/// expression are refused naming them (the library would inflate the package
/// past every bound, and evaluate the expression to a layer not checked).
#[test]
fn arcs_are_judged_over_the_sublayers_of_a_stack() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let curves = STRAND;
    let stage = |subs: &str| format!("#usda 1.0\n(\n    subLayers = [{subs}]\n)\n{curves}");
    write("a.usda", "#usda 1.0\nclass \"A\" (\n    inherits = </B>\n) { }\n");
    write("b.usda", "#usda 1.0\nclass \"B\" (\n    inherits = </A>\n) { }\n");
    write("inherits.usda", &stage("@a.usda@, @b.usda@"));
    write("sa.usda", "#usda 1.0\nclass \"A\" (\n    specializes = </B>\n) { }\n");
    write("sb.usda", "#usda 1.0\nclass \"B\" (\n    specializes = </A>\n) { }\n");
    write("specializes.usda", &stage("@sa.usda@, @sb.usda@"));
    // The root's own arc closes a cycle through a sublayer of a sublayer.
    write("deeper.usda", "#usda 1.0\n(\n    subLayers = [@b.usda@]\n)\n");
    write(
        "through_root.usda",
        &format!(
            "#usda 1.0\n(\n    subLayers = [@deeper.usda@]\n)\nclass \"A\" (\n    inherits = </B>\n) {{ }}\n{curves}"
        ),
    );
    // Without the cycle, and with each half in a stack of its own: read.
    write("b_plain.usda", "#usda 1.0\nclass \"B\" { }\n");
    write("plain.usda", &stage("@a.usda@, @b_plain.usda@"));
    let g = usd::open(dir.path().join("plain.usda")).expect("a chain without a cycle");
    assert_eq!(g.groom.strand_count(), 1);
    write("apart.usda", &format!("#usda 1.0\n(\n    subLayers = [@a.usda@]\n)\ndef Xform \"x\" (\n    references = @b.usda@</B>\n) {{ }}\n{curves}"));
    let g = usd::open(dir.path().join("apart.usda")).expect("a reference is a stack of its own");
    assert_eq!(g.groom.strand_count(), 1);
    // A package, or a layer inside one, which the library would inflate itself.
    write("pkg.usdz", "PK\u{3}\u{4}");
    write("pkg.usdz[inner.usda]", &format!("#usda 1.0\n{curves}"));
    write(
        "packaged.usda",
        &format!("#usda 1.0\ndef Xform \"x\" (\n    references = @./pkg.usdz[inner.usda]@</c>\n) {{ }}\n{curves}"),
    );
    write("package.usda", &stage("@pkg.usdz@"));
    // Brackets in a plain file's name or folder are no package (the library
    // takes a path as package-relative when it also ends with `]`): read.
    std::fs::create_dir(dir.path().join("a[1]b")).expect("folder");
    write("a[1]b/take[2].usda", &format!("#usda 1.0\n{curves}"));
    write("bracketed.usda", "#usda 1.0\ndef \"x\" (\n    references = @./a[1]b/take[2].usda@</c>\n) { }\n");
    let g = usd::open(dir.path().join("bracketed.usda")).expect("brackets in plain names");
    assert_eq!(g.groom.strand_count(), 1);
    assert_eq!(usd::open(dir.path().join("a[1]b/take[2].usda")).expect("a bracketed root").groom.strand_count(), 1);
    // An empty asset path with a prim path (`@@</c>`): the arc's line, not
    // "a layer named without an extension" at the layer's folder.
    write("empty_asset.usda", &format!("#usda 1.0\ndef Xform \"x\" (\n    references = @@</c>\n) {{ }}\n{curves}"));
    // References to prims of the layer itself, through its own file: a chain
    // of 200 (which took the library past 10 s at 2,000) and a cycle.
    let mut chain = String::from("#usda 1.0\n");
    for i in 0..200 {
        chain += &format!("def Xform \"P{i}\" (\n    references = @./self_chain.usda@</P{}>\n) {{ }}\n", i + 1);
    }
    write("self_chain.usda", &format!("{chain}def Xform \"P200\" {{ }}\n{curves}"));
    let cycle = "def Xform \"P0\" (\n    references = @self_cycle.usda@</P1>\n) { }\ndef Xform \"P1\" (\n    references = @self_cycle.usda@</P0>\n) { }\n";
    write("self_cycle.usda", &format!("#usda 1.0\n{cycle}{curves}"));
    // An asset path the library would evaluate as an expression.
    let expression =
        "(\n    expressionVariables = {\n        string X = \"a\"\n    }\n    subLayers = [@`\"${X}.usda\"`@]\n)\n";
    write("expression.usda", &format!("#usda 1.0\n{expression}{curves}"));
    // A chain of layers each referencing the next: the library builds a prim
    // nested past 100 arcs empty, without a word.
    let chain = |name: &str, n: usize| {
        for i in 0..n {
            let next = if i + 1 < n { format!("{name}{}.usda", i + 1) } else { "strand_g.usda".into() };
            write(
                &format!("{name}{i}.usda"),
                &format!("#usda 1.0\ndef Xform \"G\" (\n    references = @{next}@</G>\n) {{ }}\n"),
            );
        }
    };
    write("strand_g.usda", &format!("#usda 1.0\ndef Xform \"G\" {{\n{curves}}}\n"));
    chain("long", 99);
    chain("short", 40);
    let g = usd::open(dir.path().join("short0.usda")).expect("40 layers of references");
    assert_eq!(g.groom.strand_count(), 1, "the hair at the chain's end");
    refused_naming(
        dir.path(),
        &[
            ("long0.usda", &["long0.usda", "nest 100 arcs deep", "99 references", "without a word"][..]),
            ("self_chain.usda", &["self_chain.usda", "chain through more than 128 prims"][..]),
            ("self_cycle.usda", &["self_cycle.usda", "line 6", "a cycle"][..]),
            ("expression.usda", &["expression.usda", "line 6", "an expression"][..]),
            ("packaged.usda", &["packaged.usda", "line 3", "USDZ package", "pkg.usdz[inner.usda]"][..]),
            ("package.usda", &["package.usda", "line 3", "USDZ package"][..]),
            ("empty_asset.usda", &["empty_asset.usda", "line 3", "an empty asset path"][..]),
            ("inherits.usda", &["a cycle", "line 3", "sublayers of", "inherits.usda"][..]),
            ("specializes.usda", &["a cycle", "line 3", "specializes.usda"][..]),
            ("through_root.usda", &["a cycle", "through_root.usda"][..]),
        ],
    );
}

/// A reference or payload to a prim that cannot be there — below an existing
/// root prim, in a layer of sublayers, a reference without an asset path —
/// is refused naming the arc (the library went without it in silence: 2 of
/// 4 strands), while a prim a sublayer declares or an ancestor's variant
/// brings reads.
#[test]
fn an_arc_to_a_prim_that_cannot_be_there_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let curves = STRAND;
    write("b.usda", &format!("#usda 1.0\ndef Xform \"G\" {{\n{curves}}}\n"));
    write("e.usda", &format!("#usda 1.0\ndef Xform \"E\" {{\n{curves}}}\n"));
    write("stacked.usda", "#usda 1.0\n(\n    subLayers = [@e.usda@]\n)\n");
    let look = format!(
        "#usda 1.0\ndef Xform \"V\" (\n    variants = {{ string look = \"a\" }}\n    prepend variantSets = \"look\"\n) {{\n    \
         variantSet \"look\" = {{\n        \"a\" {{\n{curves}        }}\n    }}\n}}\n"
    );
    write("variant.usda", &look);
    let referencing = |name: &str, arc: &str| {
        // A typeless prim takes its type, BasisCurves, from what it references.
        write(name, &format!("#usda 1.0\ndef \"R\" (\n    references = {arc}\n) {{ }}\n{curves}"));
    };
    referencing("nested.usda", "@b.usda@</G/nope>");
    referencing("nested_ok.usda", "@b.usda@</G/c>");
    referencing("sublayered.usda", "@stacked.usda@</Nope>");
    referencing("sublayered_ok.usda", "@stacked.usda@</E/c>");
    referencing("variant_ok.usda", "@variant.usda@</V/c>");
    write(
        "internal.usda",
        &format!("#usda 1.0\ndef Xform \"G\" {{\n{curves}}}\ndef Xform \"R\" (\n    references = </G/nope>\n) {{ }}\n"),
    );
    for ok in ["nested_ok.usda", "sublayered_ok.usda", "variant_ok.usda"] {
        let g = usd::open(dir.path().join(ok)).unwrap_or_else(|e| panic!("{ok}: {e}"));
        assert_eq!(g.groom.strand_count(), 2, "{ok}: the root's strand and the referenced one");
    }
    refused_naming(
        dir.path(),
        &[
            ("nested.usda", &["nested.usda", "line 3", "/G/nope", "b.usda"][..]),
            ("sublayered.usda", &["sublayered.usda", "line 3", "/Nope", "stacked.usda", "sublayers"][..]),
            ("internal.usda", &["internal.usda", "line 7", "/G/nope"][..]),
        ],
    );
}

/// The ways round the layer checks a probe found, each closed: a deep layer
/// led by blank space, a variant's reference to a FIFO, many chains each
/// within the depth limit, a sublayer the library cannot parse (refused with
/// its line and column, not dropped), sublayers that are not USD text at
/// all (no header, a byte-order mark), arcs that chain through 200 prims or
/// name a path of 200 elements, references within a layer to a root prim it
/// does not declare, and references or payloads to a prim
/// their layer does not have (or to a default prim it does not name) — each
/// refused in well under a second, naming the layer; references that do find
/// their prim read.
#[test]
fn layers_that_slipped_past_the_checks_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let curves = STRAND;
    write("curves.usda", &format!("#usda 1.0\n{curves}"));
    let deep = |levels: usize| {
        let open: String = (0..levels).map(|i| format!("def Xform \"p{i}\" {{\n")).collect();
        format!("{open}{}", "}\n".repeat(levels))
    };
    write("blank_led.usda", &format!("\n  #usda 1.0\n{}", deep(1500)));
    crate::common::mkfifo(&dir.path().join("pipe.usda"));
    write(
        "variant.usda",
        &format!(
            "#usda 1.0\ndef Xform \"x\" (\n    variants = {{ string v = \"a\" }}\n    prepend variantSets = \"v\"\n) {{\n    \
             variantSet \"v\" = {{\n        \"a\" (\n            references = @pipe.usda@</x>\n        ) {{ }}\n    }}\n}}\n{curves}"
        ),
    );
    let chains: String = (0..300).map(|i| deep(125).replacen("\"p0\"", &format!("\"chain{i}\""), 1)).collect();
    write("wide.usda", &format!("#usda 1.0\n{chains}"));
    write("bad_value.usda", &format!("#usda 1.0\ndef Xform \"x\" {{\n    int a = two\n}}\n{curves}"));
    // A chain of 200 classes, each inheriting the next (the reader took 13 s
    // at 1,000), and an arc to a path of 200 elements (10,000: past 15 s).
    let chain: String =
        (0..200).map(|i| format!("class \"c{i}\" (\n    inherits = </c{}>\n) {{ }}\n", i + 1)).collect();
    write("chain.usda", &format!("#usda 1.0\n{chain}{curves}"));
    let long: String = "/a".repeat(200);
    write("long_path.usda", &format!("#usda 1.0\ndef \"x\" (\n    inherits = <{long}>\n) {{ }}\n{curves}"));
    write("garbage.usda", "hello, not a stage\n");
    write("bom.usda", &format!("\u{feff}#usda 1.0\n{curves}"));
    // A reference to a prim its layer does not have, a payload likewise, and
    // a reference without a prim path to a layer without a default prim: the
    // stage read 2 of 3 strands without a word.
    write("strand.usda", &format!("#usda 1.0\n(\n    defaultPrim = \"c\"\n)\n{curves}"));
    write("no_default.usda", &format!("#usda 1.0\n{curves}"));
    let arc = |name: &str, arc: &str| {
        write(name, &format!("#usda 1.0\ndef Xform \"x\" (\n    {arc}\n) {{ }}\n{curves}"));
    };
    arc("ref_missing.usda", "references = @strand.usda@</gone>");
    arc("payload_missing.usda", "payload = @strand.usda@</gone>");
    arc("ref_no_default.usda", "references = @no_default.usda@");
    arc("ref_default.usda", "references = @strand.usda@");
    arc("ref_prim.usda", "references = @no_default.usda@</c>");
    arc("ref_twice.usda", "references = [@strand.usda@</c>, @strand.usda@</gone>]");
    arc("ref_relative.usda", "references = @strand.usda@<c>");
    arc("internal_missing.usda", "references = </Nope>");
    arc("internal_good.usda", "references = </c>");
    // A text layer named .usdc (the library would read it as binary and drop it).
    write("text.usdc", &format!("#usda 1.0\n{curves}"));
    write("names_text_usdc.usda", "#usda 1.0\n(\n    subLayers = [@text.usdc@]\n)\n");
    // A binary layer named .usda, and a .usdc whose bootstrap is damaged.
    let data = openusd::usda::parse(&format!("#usda 1.0\n{curves}")).expect("text");
    openusd::usdc::CrateWriter::write_to_file(&data, dir.path().join("binary.usda")).expect("binary");
    write("names_binary_usda.usda", "#usda 1.0\n(\n    subLayers = [@binary.usda@]\n)\n");
    write("damaged.usdc", &format!("PXR-USDX{}", "\0".repeat(80)));
    write("names_damaged.usda", "#usda 1.0\n(\n    subLayers = [@damaged.usdc@]\n)\n");
    for good in ["ref_default.usda", "ref_prim.usda", "internal_good.usda"] {
        usd::open(dir.path().join(good)).unwrap_or_else(|e| panic!("{good}: {e}"));
    }
    for sub in ["bad_value.usda", "garbage.usda", "bom.usda"] {
        write(&format!("names_{sub}"), &format!("#usda 1.0\n(\n    subLayers = [@curves.usda@, @{sub}@]\n)\n"));
    }
    refused_naming(
        dir.path(),
        &[
            ("blank_led.usda", &["blank_led.usda", "nesting deeper than 128"][..]),
            ("variant.usda", &["variant.usda", "line 8", "pipe.usda", "not a regular file"][..]),
            ("wide.usda", &["wide.usda", "nest too deeply all together"][..]),
            (
                "names_bad_value.usda",
                &["names_bad_value.usda", "line 3", "bad_value.usda", "cannot parse", "line 3, column"][..],
            ),
            ("names_garbage.usda", &["garbage.usda", "not a USD layer"][..]),
            ("names_bom.usda", &["bom.usda", "byte-order mark"][..]),
            ("chain.usda", &["chain.usda", "line ", "chain through more than 128 prims"][..]),
            ("long_path.usda", &["long_path.usda", "line 3", "a path of 200 elements"][..]),
            ("ref_missing.usda", &["ref_missing.usda", "line 3", "strand.usda", "no prim /gone"][..]),
            ("payload_missing.usda", &["payload_missing.usda", "strand.usda", "no prim /gone"][..]),
            ("ref_twice.usda", &["ref_twice.usda", "strand.usda", "no prim /gone"][..]),
            ("ref_relative.usda", &["ref_relative.usda", "<c>, a relative path"][..]),
            (
                "internal_missing.usda",
                &["internal_missing.usda", "line 3", "to /Nope, a prim the layer does not have"][..],
            ),
            ("names_text_usdc.usda", &["names_text_usdc.usda", "text.usdc", "a text USD layer named .usdc"][..]),
            ("names_binary_usda.usda", &["binary.usda", "a binary USD layer named .usda"][..]),
            ("names_damaged.usda", &["damaged.usdc", "not a USD binary layer", "PXR-USDX"][..]),
            ("ref_no_default.usda", &["ref_no_default.usda", "no_default.usda", "names no default prim"][..]),
        ],
    );
}

/// A binary layer's values nested in others — dictionaries in dictionaries,
/// time samples, references with custom data, payloads — are walked before
/// the USD library reads them: the library writer's layer of each reads,
/// while a dictionary entry pointing back at its own dictionary (the library
/// recursed until its stack ended) and a reference list counting 2⁴⁰ items
/// are refused naming the field.
#[test]
fn values_nested_in_a_binary_layer_are_walked_before_the_library_reads_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let curves = STRAND;
    std::fs::write(dir.path().join("strand.usda"), format!("#usda 1.0\n{curves}")).expect("write");
    let text = format!(
        "#usda 1.0\n(\n    customLayerData = {{\n        dictionary inner = {{\n            string note = \"a\"\n            \
         double[] values = [1, 2]\n        }}\n        int count = 3\n    }}\n)\n\
         def Xform \"x\" (\n    references = @strand.usda@</c> (customData = {{ string why = \"test\" }})\n    \
         payload = @strand.usda@</c>\n) {{\n    double weight.timeSamples = {{ 0: 1, 1: 2 }}\n}}\n{curves}"
    );
    let path = dir.path().join("nested.usdc");
    openusd::usdc::CrateWriter::write_to_file(&openusd::usda::parse(&text).expect("text"), &path).expect("binary");
    usd::open(&path).expect("the library writer's nested values read");
    // Each field's value representation, by the field's name.
    let reps = {
        let file = std::io::BufReader::new(std::fs::File::open(&path).expect("open"));
        let crate_file = openusd::usdc::CrateFile::open(file).expect("crate");
        crate_file.fields.iter().map(|f| (crate_file.tokens[f.token_index].clone(), f.value_rep.0)).collect::<Vec<_>>()
    };
    let payload_of = |name: &str| {
        let rep = reps.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no {name} field: {reps:?}")).1;
        (rep & ((1 << 48) - 1)) as usize
    };
    let bytes = std::fs::read(&path).expect("read");
    let mutated = |name: &str, change: &dyn Fn(&mut Vec<u8>)| {
        let mut b = bytes.clone();
        change(&mut b);
        let out = dir.path().join(format!("{name}.usdc"));
        std::fs::write(&out, b).expect("write");
        out
    };
    // The dictionary's first entry's value becomes the dictionary itself.
    let dict = payload_of("customLayerData");
    let looped = mutated("looped", &|b| {
        let offset_at = dict + 8 + 4;
        let offset = i64::from_le_bytes(b[offset_at..offset_at + 8].try_into().expect("8 bytes"));
        let rep_at = (offset_at as i64 + offset) as usize;
        b[rep_at..rep_at + 8].copy_from_slice(&((31u64 << 48) | dict as u64).to_le_bytes());
    });
    let e = usd::open(&looped).expect_err("a dictionary holding itself").to_string();
    assert!(e.contains("looped.usdc") && e.contains("customLayerData") && e.contains("more than 64 deep"), "{e}");
    // The references' first list counts 2⁴⁰ items.
    let refs = payload_of("references");
    let counted = mutated("counted", &|b| b[refs + 1..refs + 9].copy_from_slice(&(1u64 << 40).to_le_bytes()));
    let e = usd::open(&counted).expect_err("a reference list past the file").to_string();
    assert!(e.contains("counted.usdc") && e.contains("references") && e.contains("more than the file holds"), "{e}");
}

/// A binary layer's sublayers, references and payloads are checked like a
/// text layer's: a FIFO it sublayers is refused (not waited on), a reference
/// to a prim its layer lacks is refused naming both, and a good reference
/// reads (the binary layers written from text by the USD library's writer).
#[test]
fn the_layers_a_binary_layer_names_are_checked_too() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let binary = binary_writer(dir.path());
    let curves = STRAND;
    write("strand.usda", &format!("#usda 1.0\n(\n    defaultPrim = \"c\"\n)\n{curves}"));
    crate::common::mkfifo(&dir.path().join("pipe.usda"));
    binary("fifo.usdc", &format!("#usda 1.0\n(\n    subLayers = [@pipe.usda@]\n)\n{curves}"));
    let arc = |arc: &str| format!("#usda 1.0\ndef Xform \"x\" (\n    {arc}\n) {{ }}\n");
    binary("missing.usdc", &arc("references = @strand.usda@</gone>"));
    // A typeless prim takes its type, BasisCurves, from what it references.
    binary("good.usdc", "#usda 1.0\ndef \"x\" (\n    references = @strand.usda@</c>\n) { }\n");
    let g = usd::open(dir.path().join("good.usdc")).expect("a binary layer referencing a strand");
    assert_eq!(g.groom.strand_count(), 1);
    // Children inside a variant (`/x{look=a}c`), listed as that writer lists
    // them (a token array): read, not refused by the children check.
    let variant = format!(
        "#usda 1.0\n(\n    defaultPrim = \"x\"\n)\ndef Xform \"x\" (\n    variants = {{\n        string look = \"a\"\n    }}\n    \
         prepend variantSets = \"look\"\n)\n{{\n    variantSet \"look\" = {{\n        \"a\" {{\n{curves}        }}\n    }}\n}}\n"
    );
    binary("variant.usdc", &variant);
    let v = usd::open(dir.path().join("variant.usdc")).expect("a binary layer with a variant");
    assert_eq!(v.groom.strand_count(), 1);
    refused_naming(
        dir.path(),
        &[
            ("fifo.usdc", &["fifo.usdc", "pipe.usda", "not a regular file"][..]),
            ("missing.usdc", &["missing.usdc", "strand.usda", "no prim /gone"][..]),
        ],
    );
}

/// A binary layer's arcs between its own prims are judged as a text layer's:
/// a class inheriting itself, two classes specializing each other, an
/// internal reference cycle, a reference to its own prims through its own
/// file, and a cycle closed across a text and a binary sublayer are refused
/// naming the binary layer and the prim (the first had read without a
/// word); an internal reference to a prim it lacks is refused; a chain
/// without a cycle reads.
#[test]
fn a_binary_layers_arcs_between_its_prims_are_judged_as_a_text_layers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let binary = binary_writer(dir.path());
    let curves = STRAND;
    let layer = |body: &str| format!("#usda 1.0\n{body}{curves}");
    binary("self.usdc", &layer("class \"A\" (\n    inherits = </A>\n) { }\n"));
    binary(
        "mutual.usdc",
        &layer("class \"A\" (\n    specializes = </B>\n) { }\nclass \"B\" (\n    specializes = </A>\n) { }\n"),
    );
    binary(
        "internal.usdc",
        &layer("def Xform \"P\" (\n    references = </Q>\n) { }\ndef Xform \"Q\" (\n    references = </P>\n) { }\n"),
    );
    binary(
        "own_file.usdc",
        &layer("def Xform \"P\" (\n    references = @./own_file.usdc@</Q>\n) { }\ndef Xform \"Q\" (\n    references = @own_file.usdc@</P>\n) { }\n"),
    );
    binary("missing.usdc", &layer("def Xform \"P\" (\n    references = </Nowhere>\n) { }\n"));
    binary("half.usdc", "#usda 1.0\nclass \"B\" (\n    inherits = </A>\n) { }\n");
    write("half.usda", "#usda 1.0\nclass \"A\" (\n    inherits = </B>\n) { }\n");
    write("across.usda", &format!("#usda 1.0\n(\n    subLayers = [@half.usda@, @half.usdc@]\n)\n{curves}"));
    binary("chain.usdc", &layer("class \"A\" (\n    inherits = </B>\n) { }\nclass \"B\" { }\n"));
    let g = usd::open(dir.path().join("chain.usdc")).expect("a chain of arcs without a cycle");
    assert_eq!(g.groom.strand_count(), 1);
    refused_naming(
        dir.path(),
        &[
            ("self.usdc", &["self.usdc", "prim /A's inheritPaths", "itself"][..]),
            ("mutual.usdc", &["mutual.usdc", "specializes", "a cycle"][..]),
            ("internal.usdc", &["internal.usdc", "references", "a cycle"][..]),
            ("own_file.usdc", &["own_file.usdc", "own_file.usdc\"", "a cycle"][..]),
            ("missing.usdc", &["missing.usdc", "prim /P's references", "/Nowhere"][..]),
            ("across.usda", &["a cycle", "sublayers of", "across.usda"][..]),
        ],
    );
}

/// What the USD library would open unchecked or go without in silence is
/// refused naming it: value clips in a text or a binary layer, in the
/// dictionary form and the older one (a clip naming a FIFO had blocked
/// forever, one naming an 8 GiB file aborted the process asking for it);
/// relocates in a text or a binary layer (the relocated prims were dropped);
/// a layer named other than .usd, .usda or .usdc (dropped); a binary layer
/// nesting prims past 128 deep (2,000 took the library past 10 s, 500 about
/// 10 s). Curves under instanceable prims are read, once per instance (they
/// were dropped).
#[test]
fn clips_relocates_odd_names_and_deep_binary_nesting_are_refused_and_instances_read() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let binary = binary_writer(dir.path());
    let curves = STRAND;
    crate::common::mkfifo(&dir.path().join("pipe.usda"));
    let clipped = |clips: &str| {
        format!("#usda 1.0\n{curves}def BasisCurves \"k\" (\n    {clips}\n) {{\n    int[] curveVertexCounts\n}}\n")
    };
    let clips =
        "clips = {\n        dictionary default = {\n            asset[] assetPaths = [@pipe.usda@]\n            \
                 string primPath = \"/k\"\n        }\n    }";
    write("clips.usda", &clipped(clips));
    write("legacy_clips.usda", &clipped("clipAssetPaths = [@pipe.usda@]"));
    binary("clips.usdc", &clipped(clips));
    let relocates = format!(
        "#usda 1.0\n(\n    relocates = {{\n        </g/a>: </g/b>\n    }}\n)\ndef Xform \"g\" {{\n{curves}}}\n"
    );
    write("relocates.usda", &relocates);
    binary("relocates.usdc", &relocates);
    write("strand.txt", &format!("#usda 1.0\n{curves}"));
    write("noext", &format!("#usda 1.0\n{curves}"));
    write("sub_txt.usda", &format!("#usda 1.0\n(\n    subLayers = [@strand.txt@]\n)\n{curves}"));
    write("ref_noext.usda", &format!("#usda 1.0\ndef Xform \"x\" (\n    references = @noext@</c>\n) {{ }}\n{curves}"));
    let nested = |depth: usize| {
        let open: String = (0..depth).map(|i| format!("def Xform \"p{i}\" {{\n")).collect();
        format!("#usda 1.0\n{curves}{open}{}", "}\n".repeat(depth))
    };
    binary("deep.usdc", &nested(200));
    // Seven chains of 125, each within the depth bound: 4.6 M depths squared.
    let chains: String = (0..7)
        .map(|c| {
            let open: String = (0..125).map(|i| format!("def Xform \"c{c}p{i}\" {{\n")).collect();
            format!("{open}{}", "}\n".repeat(125))
        })
        .collect();
    binary("chains.usdc", &format!("#usda 1.0\n{curves}{chains}"));
    binary("nested.usdc", &nested(100));
    let g = usd::open(dir.path().join("nested.usdc")).expect("100 nested prims");
    assert_eq!(g.groom.strand_count(), 1);
    refused_naming(
        dir.path(),
        &[
            ("clips.usda", &["clips.usda", "line 5", "`clips`", "value clips"][..]),
            ("legacy_clips.usda", &["legacy_clips.usda", "`clipAssetPaths`", "value clips"][..]),
            ("clips.usdc", &["clips.usdc", "prim /k", "value clips"][..]),
            ("relocates.usda", &["relocates.usda", "line 3", "relocates, which vkhair does not read"][..]),
            ("relocates.usdc", &["relocates.usdc", "relocates, which vkhair does not read"][..]),
            ("sub_txt.usda", &["sub_txt.usda", "line 3", "strand.txt", "a layer named .txt"][..]),
            ("ref_noext.usda", &["ref_noext.usda", "noext", "without an extension"][..]),
            ("deep.usdc", &["deep.usdc", "nests 129 deep (at most 128)", "…"][..]),
            ("chains.usdc", &["chains.usdc", "depths squared passes 4000000"][..]),
        ],
    );
    // Instances: each instanceable prim's referenced curves, read once per instance.
    write("group.usda", "#usda 1.0\ndef Xform \"g\" {\n    def BasisCurves \"c\" { int[] curveVertexCounts = [2, 2, 2]\n point3f[] points = [(0,0,0),(0,1,0),(1,0,0),(1,1,0),(2,0,0),(2,1,0)] }\n}\n");
    let instance = |name: &str| {
        format!("def Xform \"{name}\" (\n    instanceable = true\n    references = @group.usda@</g>\n) {{ }}\n")
    };
    write("instances.usda", &format!("#usda 1.0\n{curves}{}{}", instance("a"), instance("b")));
    let g = usd::open(dir.path().join("instances.usda")).expect("instances");
    assert_eq!(g.groom.strand_count(), 1 + 3 + 3, "the root's strand and three of each instance");
}

/// Composition that multiplies or hides its arcs is bounded: a class
/// inheriting 40 others that each inherit those after them (paths of arcs
/// past 10,000: the reader composes along each and never finished), layers
/// referencing the next one twice, 20 deep (2²⁰ prims), chains of arcs
/// written in variants, in a text and in a binary layer (the check had
/// counted only a prim's own arcs: 300 took the reader past 10 s), and a
/// binary layer of more than 10,000 arcs, and layers of more than 10,000
/// references to other layers (20,000 took the reader about 10 s) — each
/// refused naming the file; so is what the library reports it could not
/// compose (a cycle of references through two files, a layer sublayering
/// itself: it dropped the arc and went on). A fan of 10 and a diamond 5 deep
/// read.
#[test]
fn composition_that_multiplies_or_hides_its_arcs_is_bounded() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = text_writer(dir.path());
    let curves = STRAND;
    let fan = |n: usize| {
        let classes: String = (0..n)
            .map(|i| {
                let targets: Vec<String> = (i + 1..n).map(|j| format!("</C{j}>")).collect();
                format!("class \"C{i}\" (\n    inherits = [{}]\n) {{ }}\n", targets.join(", "))
            })
            .collect();
        format!("#usda 1.0\n{classes}{curves}")
    };
    write("fan.usda", &fan(40));
    write("small_fan.usda", &fan(10));
    let diamond = |name: &str, depth: usize| {
        for i in 0..depth {
            let next = format!("{name}{}.usda", i + 1);
            let child = |c: &str| format!("    def \"{c}\" (\n        references = @{next}@\n    ) {{ }}\n");
            write(
                &format!("{name}{i}.usda"),
                &format!("#usda 1.0\n(\n    defaultPrim = \"d\"\n)\ndef \"d\" {{\n{}{}}}\n", child("l"), child("r")),
            );
        }
        write(
            &format!("{name}{depth}.usda"),
            &format!("#usda 1.0\n(\n    defaultPrim = \"d\"\n)\ndef \"d\" {{\n{curves}}}\n"),
        );
        write(&format!("{name}.usda"), &format!("#usda 1.0\ndef \"x\" (\n    references = @{name}0.usda@\n) {{ }}\n"));
    };
    diamond("wide", 20);
    diamond("narrow", 5);
    let variant_chain = |n: usize| {
        let prims: String = (0..n)
            .map(|i| {
                format!(
                    "def Xform \"A{i}\" (\n    variants = {{\n        string v = \"a\"\n    }}\n    prepend variantSets = \"v\"\n)\n\
                     {{\n    variantSet \"v\" = {{\n        \"a\" (\n            inherits = </A{}>\n        ) {{ }}\n    }}\n}}\n",
                    i + 1
                )
            })
            .collect();
        format!("#usda 1.0\n{prims}def Xform \"A{n}\" {{ }}\n{curves}")
    };
    write("variants.usda", &variant_chain(200));
    write_binary(&dir.path().join("variants.usdc"), &variant_chain(200));
    let many: String = (0..10_001).map(|i| format!("class \"K{i}\" (\n    inherits = </B>\n) {{ }}\n")).collect();
    write_binary(&dir.path().join("many.usdc"), &format!("#usda 1.0\nclass \"B\" {{ }}\n{many}{curves}"));
    write("strand_default.usda", &format!("#usda 1.0\n(\n    defaultPrim = \"c\"\n)\n{curves}"));
    let refs: String =
        (0..10_001).map(|i| format!("def \"x{i}\" (\n    references = @strand_default.usda@\n) {{ }}\n")).collect();
    write("references.usda", &format!("#usda 1.0\n{refs}"));
    // A cycle through two files' references, and a layer sublayering itself:
    // past the checks, the library drops the arc and says so only when asked.
    write(
        "cycle_a.usda",
        &format!("#usda 1.0\n{curves}def Xform \"A\" (\n    references = @./cycle_b.usda@</B>\n) {{ }}\n"),
    );
    write("cycle_b.usda", "#usda 1.0\ndef Xform \"B\" (\n    references = @./cycle_a.usda@</A>\n) { }\n");
    write("sub_self.usda", &format!("#usda 1.0\n(\n    subLayers = [@./sub_self.usda@]\n)\n{curves}"));
    for readable in ["small_fan.usda", "narrow.usda"] {
        let g = usd::open(dir.path().join(readable)).expect(readable);
        assert!(g.groom.strand_count() >= 1, "{readable}");
    }
    assert_eq!(usd::open(dir.path().join("narrow.usda")).expect("narrow").groom.strand_count(), 32, "2⁵ strands");
    refused_naming(
        dir.path(),
        &[
            ("fan.usda", &["fan.usda", "more than 10000 paths"][..]),
            ("wide.usda", &["wide.usda", "composes more than 100000 prims"][..]),
            ("variants.usda", &["variants.usda", "chain through more than 128 prims"][..]),
            ("variants.usdc", &["variants.usdc", "inheritPaths", "chain through more than 128 prims"][..]),
            ("many.usdc", &["many.usdc", "more than 10000 composition arcs"][..]),
            ("references.usda", &["references.usda", "more than 10000 references and payloads"][..]),
            ("cycle_a.usda", &["cycle_a.usda", "could not compose the stage", "cycle"][..]),
            ("sub_self.usda", &["sub_self.usda", "could not compose the stage", "sublayer cycle"][..]),
        ],
    );
}

/// A negative width (a diameter) is a defect: refused strictly, naming the
/// prim and strand; when repairing, the widths are passed over and said, the
/// strands kept.
#[test]
fn a_negative_width_is_refused_strictly_and_passed_over_when_repairing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("widths.usda");
    std::fs::write(
        &path,
        "#usda 1.0\n(\n    metersPerUnit = 1\n)\ndef BasisCurves \"hair\"\n{\n    uniform token type = \"linear\"\n    \
         int[] curveVertexCounts = [2, 2]\n    point3f[] points = [(0,0,0), (0,-0.1,0), (0.1,0,0), (0.1,-0.1,0)]\n    \
         float[] widths = [0.001, 0.001, 0.001, -0.0005] (\n        interpolation = \"vertex\"\n    )\n}\n",
    )
    .expect("write");
    let err = usd::open(&path).expect_err("strict").to_string();
    assert!(err.contains("/hair") && err.contains("strand 1 has a negative width (-0.0005)"), "{err}");
    let (g, _) = usd::open_repairing(&path).expect("repairing");
    assert_eq!(g.groom.strand_count(), 2);
    assert!(g.groom.end_thickness().is_none(), "the widths were read");
    assert!(g.skipped.iter().any(|s| s.contains("negative width")), "{:?}", g.skipped);
    // A width of 1e30 m is no hair's either.
    let text = std::fs::read_to_string(&path).expect("read").replace("-0.0005", "1e30");
    std::fs::write(&path, text).expect("write");
    let err = usd::open(&path).expect_err("strict").to_string();
    assert!(
        err.contains("/hair") && err.contains("strand 1 has a width of 1e30") && err.contains("at most 1 m"),
        "{err}"
    );
    let (g, _) = usd::open_repairing(&path).expect("repairing");
    assert!(g.groom.end_thickness().is_none() && g.groom.strand_count() == 2, "the absurd widths were read");
    // An infinite width is not a width: its strand is judged as any
    // non-finite value (it had been called "thicker than any hair, inf m").
    let text = std::fs::read_to_string(&path).expect("read").replace("1e30", "inf");
    std::fs::write(&path, text).expect("write");
    let err = usd::open(&path).expect_err("strict").to_string();
    assert!(err.contains("/hair: strand 1 point 1: thickness is not finite") && !err.contains("inf m"), "{err}");
    let (g, repairs) = usd::open_repairing(&path).expect("repairing");
    assert_eq!(g.groom.strand_count(), 1);
    assert!(repairs.to_string().contains("strand 1 point 1, its thickness"), "{repairs}");
}

/// A stage pulls in at most `usd::MAX_USD_LAYERS` layers: a chain of
/// sublayers one longer is refused naming the limit.
#[test]
fn a_stage_of_too_many_layers_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let curves = STRAND;
    let chain = |n: usize| {
        for i in 0..n {
            let text = if i + 1 < n {
                format!("#usda 1.0\n(\n    subLayers = [@l{}.usda@]\n)\n", i + 1)
            } else {
                format!("#usda 1.0\n{curves}")
            };
            std::fs::write(dir.path().join(format!("l{i}.usda")), text).expect("write");
        }
        usd::open(dir.path().join("l0.usda"))
    };
    chain(usd::MAX_USD_LAYERS).expect("as many layers as the limit");
    let err = chain(usd::MAX_USD_LAYERS + 1).expect_err("one more").to_string();
    assert!(err.contains("more than 256 layers"), "{err}");
}

/// A binary layer's bootstrap and table of contents are checked before the
/// USD library trusts them: a version it cannot read, a table of contents
/// outside the file, too many sections, a section past the end, a cut
/// bootstrap — each refused naming the file and the value; the file itself
/// reads.
#[test]
fn binary_layers_are_checked_before_the_reader_trusts_them() {
    let bytes = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("b.usdc");
    std::fs::write(&path, &bytes).expect("write");
    assert_eq!(usd::open(&path).expect("the fixture reads").groom.strand_count(), 4);
    let toc = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes")) as usize;
    let set = |at: usize, value: &[u8]| {
        let mut b = bytes.clone();
        b[at..at + value.len()].copy_from_slice(value);
        b
    };
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (set(8, &[0, 3, 0]), "crate version 0.3.0"),
        (set(8, &[1, 0, 0]), "crate version 1.0.0"),
        (set(16, &(bytes.len() as u64 + 100).to_le_bytes()), "its table of contents is at byte"),
        (set(toc, &100u64.to_le_bytes()), "lists 100 sections"),
        (set(toc, &0u64.to_le_bytes()), "lists 0 sections"),
        (set(toc + 8 + 24, &u64::MAX.to_le_bytes()), "section \"TOKENS\""),
        (set(toc + 8 + 32 + 16, &(bytes.len() as u64).to_le_bytes()), "section \"STRINGS\""),
        (bytes[..20].to_vec(), "without a whole PXR-USDC bootstrap"),
    ];
    for (i, (b, expected)) in cases.iter().enumerate() {
        std::fs::write(&path, b).expect("write");
        let e = usd::open(&path).expect_err("refused").to_string();
        assert!(e.contains(expected) && e.contains("b.usdc"), "case {i}: {e}");
    }
}

/// A compressed array's block is checked against the file before the USD
/// library allocates it: the dense fixture relabelled as crate version 0.5.0
/// or 0.6.0 (whose arrays count their elements in 32 bits, not 64) has the
/// library read a compressed size of 80 GiB from the count's high bytes —
/// it aborted the process — and is refused naming the field and the size;
/// as 0.7.0, the layout it has, it reads.
#[test]
fn a_compressed_array_block_past_the_file_is_refused_before_the_reader_allocates_it() {
    let bytes = std::fs::read(data("usd/dense_curly.usdc")).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("v.usdc");
    for (version, refused) in [([0u8, 5, 0], true), ([0, 6, 0], true), ([0, 7, 0], false)] {
        let mut b = bytes.clone();
        b[8..11].copy_from_slice(&version);
        std::fs::write(&path, &b).expect("write");
        match usd::open(&path) {
            Err(e) if refused => {
                let e = e.to_string();
                assert!(e.contains("v.usdc") && e.contains("has a compressed block of 85899345920 bytes"), "{e}");
            }
            Ok(g) if !refused => assert_eq!(g.groom.strand_count(), 1500, "{version:?}"),
            other => panic!("crate version {version:?}: {:?}", other.map(|g| g.groom.strand_count())),
        }
    }
}

/// The counts and block sizes at the head of the sections the USD library
/// reads first, each byte set to 0xFF, 0x7F and 0x20 in turn (the bytes a
/// probe's sweep found aborting the process with a request for up to 9 × 10¹⁸
/// bytes): every mutant is read or refused as a file error — the test process
/// would not survive an abort — and a count past its blocks is refused naming
/// its section.
#[test]
fn counts_inside_binary_sections_are_bounded_before_the_reader_allocates() {
    let bytes = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("b.usdc");
    let toc = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes")) as usize;
    let sections = u64::from_le_bytes(bytes[toc..toc + 8].try_into().expect("8 bytes")) as usize;
    let mut heads = Vec::new();
    for k in 0..sections {
        let entry = &bytes[toc + 8 + 32 * k..toc + 8 + 32 * (k + 1)];
        let name: String = entry[..16].iter().take_while(|&&b| b != 0).map(|&b| char::from(b)).collect();
        let start = u64::from_le_bytes(entry[16..24].try_into().expect("8 bytes")) as usize;
        let size = u64::from_le_bytes(entry[24..32].try_into().expect("8 bytes")) as usize;
        if ["TOKENS", "STRINGS", "FIELDS", "FIELDSETS", "PATHS", "SPECS"].contains(&name.as_str()) {
            heads.push((name, start, size));
        }
    }
    assert_eq!(heads.len(), 6, "{heads:?}");
    let (mut read, mut refused) = (0, 0);
    for (_, start, size) in &heads {
        for at in *start..start + size.min(&40) {
            for value in [0xFFu8, 0x7F, 0x20] {
                let mut b = bytes.clone();
                b[at] = value;
                std::fs::write(&path, &b).expect("write");
                match usd::open(&path) {
                    Ok(_) => read += 1,
                    Err(e) => {
                        assert!(e.to_string().contains("b.usdc"), "byte {at} = {value:#x}: {e}");
                        refused += 1;
                    }
                }
            }
        }
    }
    println!("{read} mutants read, {refused} refused");
    assert!(refused > 100, "only {refused} of the mutants were refused");
    // The field count of FIELDS at 2⁶² is refused by the check, naming it.
    let (_, fields, _) = heads.iter().find(|(n, _, _)| n == "FIELDS").expect("FIELDS");
    let mut b = bytes.clone();
    b[*fields..fields + 8].copy_from_slice(&(1u64 << 62).to_le_bytes());
    std::fs::write(&path, &b).expect("write");
    let e = usd::open(&path).expect_err("a huge count").to_string();
    assert!(e.contains("section \"FIELDS\"") && e.contains("4611686018427387904 fields"), "{e}");
}

/// A point thrown beyond 10 km from the origin by the stage's values and
/// units is refused naming the prim, the strand and the point; a curve
/// object its units shrink below 0.1 µm is refused naming it and the units.
#[test]
fn a_point_far_beyond_any_scene_is_refused_naming_it() {
    let text = std::fs::read_to_string(data("usd/small_cm_zup.usda")).expect("fixture");
    let far = text.replace("(0, 0, 100)", "(0, 0, 1e12)");
    assert_ne!(far, text);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("far.usda");
    std::fs::write(&path, far).expect("write");
    let e = usd::open(&path).expect_err("refused").to_string();
    assert!(e.contains("far.usda") && e.contains("point") && e.contains("within 1e4 m of the origin"), "{e}");
    // Past f32's range (a translation of 1e300 cm, 1e298 m): named as far, not as
    // a NaN or infinite value.
    std::fs::write(&path, text.replace("(0, 0, 100)", "(0, 0, 1e300)")).expect("write");
    let e = usd::open(&path).expect_err("refused").to_string();
    assert!(e.contains("e298") && e.contains("within 1e4 m of the origin") && !e.contains("NaN"), "{e}");
    // Shrunk to nothing by a units value: named with the span and the units,
    // not left to the repairs to drop every segment as zero-length.
    let tiny = text.replace("metersPerUnit = 0.01", "metersPerUnit = 1e-30");
    assert_ne!(tiny, text);
    std::fs::write(&path, tiny).expect("write");
    let e = usd::open(&path).expect_err("refused").to_string();
    assert!(e.contains("far.usda") && e.contains("its curves span") && e.contains("metersPerUnit"), "{e}");
}

/// A binary layer's children lists are checked against its paths before the
/// USD library composes them. The fixture's root lists its one child as token
/// 5 (the four bytes at 104); set to the empty token (1) the library's
/// composition went round a loop that never ended. That, a name the layer has
/// no path for, a token past the table (a panic inside the library) and a
/// name that is no identifier are each refused, naming the prim and what it
/// lists, within seconds (a hang fails the test instead of stalling it).
#[test]
fn a_binary_prims_children_must_be_among_its_paths() {
    let bytes = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
    assert_eq!(bytes[104..108], [5, 0, 0, 0], "the fixture's root's primChildren moved");
    let dir = tempfile::tempdir().expect("tempdir");
    for (token, expected) in [
        (1u8, "lists an empty name"),
        (2, "lists \"metersPerUnit\", which the layer has no path for"),
        // Caught with every token index a value holds, before the children lists.
        (44, "names token 44 of 44"),
        (0, "a name that is not an identifier"),
    ] {
        let path = dir.path().join(format!("b{token}.usdc"));
        let mut b = bytes.clone();
        b[104] = token;
        std::fs::write(&path, &b).expect("write");
        let (send, receive) = std::sync::mpsc::channel();
        let opened = path.clone();
        std::thread::spawn(move || send.send(usd::open(&opened).map(|_| ()).map_err(|e| e.to_string())));
        let result = receive
            .recv_timeout(std::time::Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("token {token}: the reader did not return within a minute"));
        let e = result.expect_err("refused");
        assert!(e.contains(expected) && e.contains(&format!("b{token}.usdc")) && e.contains("primChildren"), "{e}");
    }
}

/// Every byte of the binary fixture set, one at a time, to each of four
/// telling values (6,803 files): each reads, or is refused naming the file —
/// and none reaches a panic inside the USD library (which the reader catches
/// and names, but which means a check it should have had first). Before the
/// checks of the structure's blocks and of every index a value holds, 928 of
/// 13,699 such files (seven values a byte) stopped the library with a panic:
/// tokens, strings and paths indexed past their tables, path trees walked
/// out of their entries, decoded blocks sliced past their end, chunked LZ4
/// blocks, arrays marked inlined or compressed against their type (the
/// sweep with seven values a byte finds none now; this one runs four).
#[test]
fn every_one_byte_change_of_a_binary_layer_is_read_or_refused_without_a_library_panic() {
    let original = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("changed.usdc");
    let mut panics: std::collections::BTreeMap<String, Vec<(usize, u8)>> = Default::default();
    let (mut read, mut refused) = (0, 0);
    let mut bytes = original.clone();
    for i in 0..original.len() {
        for value in [0x00u8, 0x01, 0x80, 0xFF] {
            if original[i] == value {
                continue;
            }
            bytes[i] = value;
            std::fs::write(&path, &bytes).expect("write");
            match usd::open(&path) {
                Ok(_) => read += 1,
                Err(e) => {
                    let message = e.to_string();
                    assert!(message.contains("changed.usdc"), "byte {i} = {value:#x}: {message}");
                    match message.split_once("the USD reader stopped: ") {
                        Some((before, what)) => {
                            let stage =
                                if before.contains("structure cannot be read") { "structure: " } else { "values: " };
                            panics.entry(format!("{stage}{what}")).or_default().push((i, value))
                        }
                        None => refused += 1,
                    }
                }
            }
            bytes[i] = original[i];
        }
    }
    let caught: usize = panics.values().map(Vec::len).sum();
    println!("{read} read, {refused} refused, {caught} stopped by a panic in the library");
    let mut kinds: std::collections::BTreeMap<String, Vec<usize>> = Default::default();
    for (what, cases) in &panics {
        let kind: String = what.chars().map(|c| if c.is_ascii_digit() { '#' } else { c }).collect();
        kinds.entry(kind).or_default().extend(cases.iter().map(|c| c.0));
    }
    for (kind, mut at) in kinds {
        at.sort_unstable();
        at.dedup();
        println!("  {} bytes ({}..={}) × {kind}", at.len(), at[0], at[at.len() - 1]);
    }
    assert!(panics.is_empty(), "{caught} one-byte changes reached a panic inside the USD library");
}

/// A stage of more prims than [`usda_check::MAX_USD_PRIMS`] is refused before
/// the USD library composes it (400,000 empty prims took it 42 s): in one
/// layer, at the line of the prim past the bound; over two sublayers that
/// each stay within it, naming the root layer.
#[test]
fn a_stage_of_too_many_prims_is_refused_before_it_is_composed() {
    use vkhair::groom::usda_check::MAX_USD_PRIMS;
    let dir = tempfile::tempdir().expect("tempdir");
    let curves =
        "def BasisCurves \"c\" {\n    uniform token type = \"linear\"\n    int[] curveVertexCounts = [2]\n    \
                  point3f[] points = [(0, 0, 0), (0, -1, 0)]\n}\n";
    let layer = |name: &str, header: &str, prims: usize| {
        let mut text = format!("#usda 1.0\n{header}\n{curves}");
        for k in 0..prims {
            text.push_str(&format!("def \"{name}{k}\" {{}}\n"));
        }
        let path = dir.path().join(format!("{name}.usda"));
        std::fs::write(&path, text).expect("write");
        path
    };
    let start = std::time::Instant::now();
    let one = layer("one", "", MAX_USD_PRIMS);
    let e = usd::open(&one).expect_err("one prim too many").to_string();
    assert!(e.contains("one.usda") && e.contains(&format!("line {}", MAX_USD_PRIMS + 7)), "{e}");
    assert!(e.contains(&format!("more than {MAX_USD_PRIMS} prims")), "{e}");
    layer("a", "", MAX_USD_PRIMS * 3 / 5);
    layer("b", "", MAX_USD_PRIMS * 3 / 5);
    let root = layer("root", "(\n    subLayers = [@a.usda@, @b.usda@]\n)", 0);
    let e = usd::open(&root).expect_err("too many over the layers").to_string();
    assert!(e.contains("root.usda") && e.contains("the stage's layers declare more than"), "{e}");
    let took = start.elapsed().as_secs_f64();
    println!("written and refused in {took:.1} s");
    assert!(took < 5.0, "writing and refusing took {took:.1} s");
}

/// A stage's text layers hold at most
/// [`usda_check::MAX_USD_STAGE_PROPERTIES`] properties all together, each
/// prim within its own bound: eleven prims of 9,999 in one layer are refused
/// at the line of the property past the bound (twenty had taken the library
/// 10 s), two sublayers of 60,000 each naming the root layer; ten prims of
/// 9,999 pass the check, and ten of 99 read through the stage.
#[test]
fn a_stage_of_too_many_properties_all_together_is_refused() {
    use vkhair::groom::usda_check::MAX_USD_STAGE_PROPERTIES;
    let dir = tempfile::tempdir().expect("tempdir");
    let prims = |n: usize, per: usize| {
        let mut text = String::from("#usda 1.0\n");
        for p in 0..n {
            text.push_str(&format!("def \"p{p}\" {{\n"));
            for k in 0..per {
                text.push_str(&format!("    float a{k} = 1\n"));
            }
            text.push_str("}\n");
        }
        text
    };
    let path = dir.path().join("many.usda");
    std::fs::write(&path, prims(11, 9_999) + STRAND).expect("write");
    let start = std::time::Instant::now();
    let e = usd::open(&path).expect_err("past the stage's bound").to_string();
    // The 100,001st property: prim 10 (lines of 10,001 each), its 11th.
    let line = 1 + 10 * 10_001 + 1 + 11;
    assert!(e.contains("many.usda") && e.contains(&format!("line {line},")), "{e}");
    assert!(e.contains(&format!("more than {MAX_USD_STAGE_PROPERTIES} properties in the layer")), "{e}");
    assert!(start.elapsed().as_secs_f64() < 1.0, "refused in {:?}", start.elapsed());
    for k in 0..2 {
        std::fs::write(dir.path().join(format!("s{k}.usda")), prims(6, 10_000)).expect("write");
    }
    let root = dir.path().join("root.usda");
    std::fs::write(&root, format!("#usda 1.0\n(\n    subLayers = [@s0.usda@, @s1.usda@]\n)\n{STRAND}")).expect("write");
    let e = usd::open(&root).expect_err("past the stage's bound").to_string();
    assert!(e.contains("root.usda") && e.contains("text layers hold more than 100000 properties"), "{e}");
    // Within the bound the check passes the layer to the library (which then
    // takes some 20 s to parse 99,990 properties: the check alone is asked).
    let within = prims(10, 9_999) + STRAND;
    let checked = usda_check::check(&within, false).expect("within the bound");
    assert_eq!(checked.properties, 99_990 + 1, "the strand's second line is one");
    // Braces on lines of their own are not properties (ten child prims so
    // written had made 99,991 properties count past 100,000).
    let braced = prims(10, 9_999).replace("def \"", "    def \"").replace("\" {\n", "\"\n    {\n");
    let text = format!("#usda 1.0\ndef Xform \"root\"\n{{\n{}}}\n{STRAND}", braced.trim_start_matches("#usda 1.0\n"));
    let checked = usda_check::check(&text, false).expect("braces on their own lines");
    assert_eq!(checked.properties, 99_990 + 1);
    // And a layer of the same shape, smaller, reads whole through the stage.
    std::fs::write(&path, prims(10, 99) + STRAND).expect("write");
    assert_eq!(usd::open(&path).expect("within the bound").groom.strand_count(), 1);
}

/// A prim of more properties than [`usda_check::MAX_USD_PROPERTIES`] is
/// refused before the USD library parses it (its time grows with their
/// square: 100,000 attributes took it more than two minutes), naming the
/// prim and the line; one of as many child prims reads.
#[test]
fn a_prim_of_too_many_properties_is_refused_before_it_is_parsed() {
    use vkhair::groom::usda_check::MAX_USD_PROPERTIES;
    let dir = tempfile::tempdir().expect("tempdir");
    let curves = "    uniform token type = \"linear\"\n    int[] curveVertexCounts = [2]\n    \
                  point3f[] points = [(0, 0, 0), (0, -1, 0)]\n";
    let mut text = format!("#usda 1.0\ndef BasisCurves \"c\" {{\n{curves}");
    for k in 0..MAX_USD_PROPERTIES {
        text.push_str(&format!("    float a{k} = 1\n"));
    }
    text.push_str("}\n");
    let path = dir.path().join("attributes.usda");
    std::fs::write(&path, &text).expect("write");
    let start = std::time::Instant::now();
    let e = usd::open(&path).expect_err("one property too many").to_string();
    let line = MAX_USD_PROPERTIES + 3;
    assert!(e.contains("attributes.usda") && e.contains("its prim /c declares more than 10000 properties"), "{e}");
    assert!(e.contains(&format!("line {line}")), "{e}");
    assert!(start.elapsed().as_secs_f64() < 1.0, "refused in {:?}", start.elapsed());
    // As many child prims under one parent: not properties.
    let mut text = format!("#usda 1.0\ndef Xform \"root\" {{\n    def BasisCurves \"c\" {{\n{curves}    }}\n");
    for k in 0..MAX_USD_PROPERTIES {
        text.push_str(&format!("    def \"p{k}\" {{}}\n"));
    }
    text.push_str("}\n");
    std::fs::write(&path, &text).expect("write");
    let read = usd::open(&path).expect("child prims are not properties");
    assert_eq!(read.groom.strand_count(), 1);
    // A binary layer of one property too many (written by the USD library's
    // writer from text): refused once the library has read its structure.
    let mut text = format!("#usda 1.0\ndef BasisCurves \"c\" {{\n{curves}");
    for k in 0..MAX_USD_PROPERTIES - 2 {
        text.push_str(&format!("    float a{k} = 1\n"));
    }
    text.push_str("}\n");
    let data = openusd::usda::parse(&text).expect("text");
    let binary = dir.path().join("attributes.usdc");
    openusd::usdc::CrateWriter::write_to_file(&data, &binary).expect("binary");
    let e = usd::open(&binary).expect_err("one property too many").to_string();
    assert!(e.contains("attributes.usdc") && e.contains("its prim /c declares more than 10000 properties"), "{e}");
}
