//! The crate's shape, checked on its sources: modules depend only downward
//! (no import cycle), and no source file outside the tests grows past 600 lines.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Top-level modules from the bottom up; a module may use only those in
/// earlier layers (the crate root, `lib.rs`, re-exports from all of them).
const LAYERS: &[&[&str]] = &[
    &["error", "hash", "limits", "codes"],
    &["files"],
    &["vk", "groom"],
    &["gpu_types", "requirements"],
    &["context"],
    &["profiler"],
    &["sim"],
    &["render", "character", "crowd"],
    &["schedule", "config"],
    &["headless"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|layer| layer.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Test code: `tests.rs` files and what follows a `#[cfg(test)]` line.
fn is_test_file(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n == "tests.rs")
}

/// The top-level modules `source` names through `crate::`, outside comments and
/// the items marked `#[cfg(test)]` (a `mod x;` line, or a braced block).
fn crate_references(source: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for code in production_code(source).lines() {
        for (i, _) in code.match_indices("crate::") {
            let name: String = code[i + 7..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            let before = code[..i].chars().next_back();
            if !before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') && !name.is_empty() {
                found.insert(name);
            }
        }
    }
    found
}

/// Skips the item after a `#[cfg(test)]` line: up to its `;`, or to the brace
/// closing its block.
fn skip_item<'a>(lines: &mut impl Iterator<Item = &'a str>) {
    let mut depth = 0i32;
    for line in lines {
        let code = line.split("//").next().unwrap_or_default();
        depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
        if depth <= 0 && (code.contains('}') || code.trim_end().ends_with(';')) {
            return;
        }
    }
}

#[test]
fn modules_depend_only_on_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut edges = 0;
    let mut violations = Vec::new();
    for file in &files {
        let relative = file.strip_prefix(&src).expect("under src");
        let top = relative.iter().next().and_then(|c| c.to_str()).expect("component");
        let module = top.trim_end_matches(".rs");
        if module == "lib" || is_test_file(file) {
            continue;
        }
        let Some(own) = layer_of(module) else {
            violations.push(format!("{}: module {module} is in no layer of this test", relative.display()));
            continue;
        };
        let source = std::fs::read_to_string(file).expect("source");
        for used in crate_references(&source) {
            if used == module {
                continue;
            }
            edges += 1;
            match layer_of(&used) {
                Some(layer) if layer < own => {}
                _ if used.starts_with(char::is_uppercase) => {
                    violations.push(format!("{}: crate::{used} hides its module; name the module", relative.display()))
                }
                _ => violations.push(format!("{}: {module} uses {used}, which is not below it", relative.display())),
            }
        }
    }
    assert!(violations.is_empty(), "layering broken:\n{}", violations.join("\n"));
    assert!(edges > 30, "the scan found only {edges} dependencies: it reads nothing");
}

#[test]
fn the_layer_check_sees_an_upward_reference() {
    let upward = "use crate::error::Result;\n// crate::schedule in a comment\nuse crate::schedule::FrameSync;\n";
    let found = crate_references(upward);
    assert_eq!(found, BTreeSet::from(["error".to_string(), "schedule".to_string()]));
    let tests_only = "use crate::vk::Device;\n#[cfg(test)]\nmod tests {\n    use crate::headless::Submit;\n}\n";
    assert_eq!(crate_references(tests_only), BTreeSet::from(["vk".to_string()]));
    // A `#[cfg(test)] mod tests;` line at the top hides only itself.
    let declared_first = "#[cfg(test)]\nmod tests;\nuse crate::schedule::FrameSync;\n";
    assert_eq!(crate_references(declared_first), BTreeSet::from(["schedule".to_string()]));
}

#[test]
fn no_source_file_outside_the_tests_exceeds_600_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["src", "examples", "benches", "tools/src"] {
        rust_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 50, "found only {} files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter(|f| !is_test_file(f))
        .filter_map(|f| {
            let lines = std::fs::read_to_string(f).expect("source").lines().count();
            (lines > 600).then(|| format!("{}: {lines} lines", f.strip_prefix(root).unwrap_or(f).display()))
        })
        .collect();
    assert!(long.is_empty(), "split these files:\n{}", long.join("\n"));
}

// The view list (src/gpu_types/views.rs) as a table: which members of which
// GLSL blocks are packed.
include!("../src/gpu_types/views_table.rs");
include!("../src/gpu_types/views.rs");

/// The simulation's shaders and the headers they share.
fn simulation_shaders() -> Vec<PathBuf> {
    let glsl = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    let mut files = Vec::new();
    let mut dirs = vec![glsl.join("sim"), glsl.join("include").join("constraints")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("shader folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                dirs.push(path);
            } else {
                files.push(path);
            }
        }
    }
    for header in ["sim.glsl", "volume.glsl", "volume_ops.glsl", "mesh_sdf.glsl", "sdf.glsl", "reduce.glsl"] {
        files.push(glsl.join("include").join(header));
    }
    files
}

/// `source`'s reads of a packed member (`.member` of a block with a view),
/// outside comments, as "line: .member".
fn packed_member_reads(source: &str) -> Vec<String> {
    let packed: BTreeSet<&str> = SHADER_VIEWS.iter().map(|f| f.member).collect();
    let mut found = Vec::new();
    for (number, line) in source.lines().enumerate() {
        let code = line.split("//").next().unwrap_or_default();
        for (i, _) in code.match_indices('.') {
            let name: String = code[i + 1..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            let before = code[..i].chars().next_back();
            let after_ident = before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ')' || c == ']');
            if after_ident && packed.contains(name.as_str()) {
                found.push(format!("{}: .{name}", number + 1));
            }
        }
    }
    found
}

/// The step kernel, the volume stage and the mesh collider build read their
/// parameter blocks only through the generated accessors (`views.glsl`): a
/// raw `params.counts.w` would bypass the one definition of the packing.
#[test]
fn simulation_shaders_read_packed_blocks_only_through_their_views() {
    let files = simulation_shaders();
    assert!(files.len() > 25, "found only {} simulation shaders", files.len());
    let mut violations = Vec::new();
    for file in &files {
        let source = std::fs::read_to_string(file).expect("shader source");
        for read in packed_member_reads(&source) {
            violations.push(format!("{}:{read}", file.display()));
        }
    }
    assert!(violations.is_empty(), "read these through their views' accessors:\n{}", violations.join("\n"));
}

#[test]
fn the_packed_member_check_sees_a_raw_read() {
    let source = "uint f = params.counts.w; // params.shape.x in a comment\nvec3 g = steps[i].gravity_dt.xyz;\n\
                  float ok = sim_dt(params);\nvec4 counts = vec4(1.0);\n";
    assert_eq!(packed_member_reads(source), vec!["1: .counts", "2: .gravity_dt"]);
    assert!(SHADER_VIEWS.len() > 80, "the view table has only {} fields", SHADER_VIEWS.len());
}

// The constraint list (src/gpu_types/constraints.rs) as a table.
include!("../src/gpu_types/constraints_table.rs");
include!("../src/gpu_types/constraints.rs");

/// The file stems in `dir`, less `skip`.
fn stems(dir: &Path, skip: &str) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .expect("folder")
        .map(|e| e.expect("entry").path())
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .filter(|s| s != skip)
        .collect()
}

/// A constraint is its include and its twin, listed once: an include or twin
/// not listed (never run), a listed one without either, a twin or include that
/// lacks a function its kind needs or never reads one of its knobs, and a step
/// kernel that calls a constraint but through the generated solve all fail.
fn constraint_problems(root: &Path) -> Vec<String> {
    let listed: BTreeSet<String> = SIM_CONSTRAINTS.iter().map(|c| c.name.to_owned()).collect();
    let includes_dir = root.join("glsl/include/constraints");
    let twins_dir = root.join("src/sim/reference/constraints");
    let mut problems = Vec::new();
    for (what, found) in [("include", stems(&includes_dir, "common")), ("twin", stems(&twins_dir, "mod"))] {
        for name in found.symmetric_difference(&listed) {
            problems.push(format!("{name}: {what} and list disagree"));
        }
    }
    let step = std::fs::read_to_string(root.join("glsl/sim/step.comp")).expect("glsl/sim/step.comp");
    for c in SIM_CONSTRAINTS {
        let include = std::fs::read_to_string(includes_dir.join(format!("{}.glsl", c.name))).unwrap_or_default();
        let twin = std::fs::read_to_string(twins_dir.join(format!("{}.rs", c.name))).unwrap_or_default();
        let glsl_needs: &[&str] = match c.kind {
            "pairs" => &["load", "on", "apply"],
            "sweep" => &["prepare", "on", "sweep"],
            _ => &["prepare", "on", "apply"],
        };
        for f in glsl_needs {
            if !include.contains(&format!(" {}_{f}(", c.name)) {
                problems.push(format!("{}: the include defines no {}_{f}", c.name, c.name));
            }
        }
        for f in ["on", "load", "apply"] {
            if !twin.contains(&format!("pub(super) fn {f}(")) {
                problems.push(format!("{}: the twin defines no {f}", c.name));
            }
        }
        for (knob, _) in c.knobs {
            if !include.contains(&format!("sim_{knob}(")) || !twin.contains(&format!("knobs.{knob}")) {
                problems.push(format!("{}: the knob {knob} is not read by both include and twin", c.name));
            }
        }
        if step.contains(&format!("{}_", c.name)) {
            problems.push(format!("{}: glsl/sim/step.comp calls it directly", c.name));
        }
    }
    problems
}

#[test]
fn every_constraint_is_one_include_and_one_twin_in_the_list() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert!(SIM_CONSTRAINTS.len() >= 6, "the list has {} constraints", SIM_CONSTRAINTS.len());
    let problems = constraint_problems(root);
    assert!(problems.is_empty(), "constraints:\n{}", problems.join("\n"));
}

/// The check above sees a twin that is not listed and an include without its
/// `on`: planted in a copy of the two folders.
#[test]
fn the_constraint_check_sees_an_unlisted_twin_and_a_missing_function() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copy = tempfile::tempdir().expect("temp dir");
    for folder in ["glsl/include/constraints", "src/sim/reference/constraints", "glsl/sim"] {
        let to = copy.path().join(folder);
        std::fs::create_dir_all(&to).expect("folder");
        for entry in std::fs::read_dir(root.join(folder)).expect("folder") {
            let path = entry.expect("entry").path();
            if path.is_file() {
                std::fs::copy(&path, to.join(path.file_name().expect("name"))).expect("copy");
            }
        }
    }
    assert!(constraint_problems(copy.path()).is_empty(), "the copy already has problems");
    let twins = copy.path().join("src/sim/reference/constraints");
    std::fs::write(twins.join("twist.rs"), "pub(super) fn on() {}").expect("plant");
    let include = copy.path().join("glsl/include/constraints/bending.glsl");
    let text = std::fs::read_to_string(&include).expect("include").replace("bool bending_on(", "bool bending_is_on(");
    std::fs::write(&include, text).expect("plant");
    let problems = constraint_problems(copy.path());
    assert!(problems.iter().any(|p| p.starts_with("twist: twin")), "{problems:?}");
    assert!(problems.iter().any(|p| p == "bending: the include defines no bending_on"), "{problems:?}");
}

/// The commands a source names through `commands::` (one name, or a braced
/// list) or `super::super::` (a sibling command seen from inside a command's
/// folder), outside comments.
fn commands_named(source: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or_default();
        for prefix in ["commands::", "super::super::"] {
            for (i, _) in code.match_indices(prefix) {
                let rest = &code[i + prefix.len()..];
                let names = match rest.strip_prefix('{') {
                    Some(list) => list.split('}').next().unwrap_or_default().to_owned(),
                    None => rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect(),
                };
                for name in names.split(',').map(|n| n.trim().split("::").next().unwrap_or_default().trim()) {
                    if !name.is_empty() {
                        found.insert(name.to_owned());
                    }
                }
            }
        }
    }
    found
}

/// Each of the tool's commands lives in its own folder under
/// tools/src/commands/ and imports no other command: what two commands share
/// lives beside `commands/`.
#[test]
fn no_command_imports_another() {
    let commands = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/src/commands");
    let mut names = Vec::new();
    let mut violations = Vec::new();
    for entry in std::fs::read_dir(&commands).expect("tools/src/commands") {
        let path = entry.expect("entry").path();
        if !path.is_dir() {
            continue;
        }
        let own = path.file_name().and_then(|n| n.to_str()).expect("folder name").to_owned();
        names.push(own.clone());
        let mut files = Vec::new();
        rust_files(&path, &mut files);
        for file in files {
            let source = std::fs::read_to_string(&file).expect("source");
            for other in commands_named(&source).into_iter().filter(|n| *n != own) {
                violations.push(format!("{}: imports the {other} command", file.display()));
            }
        }
    }
    assert!(names.len() >= 9, "found only the commands {names:?}");
    assert!(violations.is_empty(), "commands importing commands:\n{}", violations.join("\n"));
}

#[test]
fn the_command_check_sees_an_import() {
    let source = "use crate::commands::render::bench_frames;\nuse crate::commands::{plot, bench::measure};\n\
                  use super::super::simulate::check;\n// crate::commands::grow in a comment\nuse super::frames;\n";
    let names: Vec<String> = commands_named(source).into_iter().collect();
    assert_eq!(names, ["bench", "plot", "render", "simulate"]);
}

/// The module path of a source file under `src/` (`sim/lod.rs` → `sim::lod`,
/// `sim/mod.rs` → `sim`).
fn module_of(relative: &Path) -> Vec<String> {
    let mut parts: Vec<String> = relative.iter().map(|c| c.to_string_lossy().into_owned()).collect();
    let last = parts.pop().unwrap_or_default();
    if last != "mod.rs" {
        parts.push(last.trim_end_matches(".rs").to_owned());
    }
    parts
}

/// The source file of module `path` under `src`, if it has one of its own.
fn file_of(src: &Path, path: &[String]) -> Option<PathBuf> {
    if path.is_empty() {
        return None;
    }
    let base: PathBuf = path.iter().collect();
    [src.join(&base).with_extension("rs"), src.join(&base).join("mod.rs")].into_iter().find(|f| f.is_file())
}

/// `source` without comments and without the items under `#[cfg(test)]`.
fn production_code(source: &str) -> String {
    let mut code = String::new();
    let mut lines = source.lines();
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("#[cfg(test)]") {
            skip_item(&mut lines);
            continue;
        }
        code.push_str(line.split("//").next().unwrap_or_default());
        code.push('\n');
    }
    code
}

/// Every path a `use` tree names, braces expanded (`a::{b, c::{d}}` → `a::b`,
/// `a::c::d`).
fn expand_use(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let (Some(open), Some(close)) = (tree.find('{'), tree.rfind('}')) else { return vec![tree] };
    if close < open {
        return vec![tree[..open].to_owned()];
    }
    let prefix = &tree[..open];
    let inner = &tree[open + 1..close];
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts.into_iter().filter(|p| !p.is_empty()).flat_map(|p| expand_use(&format!("{prefix}{p}"))).collect()
}

/// The paths of `code` that may name a module of this crate: `use` trees (a
/// statement from a line starting `use` or `pub … use` to its `;`), and `a::b`
/// chains elsewhere, outside string literals.
fn named_paths(code: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    let mut other = String::new();
    let mut statement: Option<String> = None;
    for line in code.lines() {
        let trimmed = line.trim_start();
        let starts_use = trimmed.starts_with("use ")
            || (trimmed.starts_with("pub")
                && trimmed.split_once(' ').is_some_and(|(_, rest)| rest.starts_with("use ")));
        if statement.is_none() && starts_use {
            statement = Some(String::new());
        }
        match &mut statement {
            Some(text) => {
                text.push_str(line);
                if let Some(end) = text.find(';') {
                    let tree = text[..end].split_once("use ").map(|(_, t)| t).unwrap_or_default();
                    paths.extend(expand_use(tree).iter().map(|p| p.split("::").map(str::to_owned).collect()));
                    statement = None;
                }
            }
            None => {
                // String literals out: their text names nothing.
                for (k, part) in line.split('"').enumerate() {
                    if k % 2 == 0 {
                        other.push_str(part);
                        other.push(' ');
                    }
                }
                other.push('\n');
            }
        }
    }
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let chars: Vec<char> = other.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if ident(chars[i]) && (i == 0 || !ident(chars[i - 1])) {
            let mut segments = Vec::new();
            let mut j = i;
            loop {
                let start = j;
                while j < chars.len() && ident(chars[j]) {
                    j += 1;
                }
                segments.push(chars[start..j].iter().collect::<String>());
                if j + 2 < chars.len() && chars[j] == ':' && chars[j + 1] == ':' && ident(chars[j + 2]) {
                    j += 2;
                } else {
                    break;
                }
            }
            if segments.len() > 1 {
                paths.push(segments);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    paths
}

/// The files of this crate `path` leads to from `module`: the deepest module
/// along it with a file of its own (`crate::`, `super::`, `self::` or a child
/// module of `module`).
fn resolve(src: &Path, module: &[String], path: &[String]) -> Option<PathBuf> {
    let mut at: Vec<String> = module.to_vec();
    let mut rest = path;
    match path.first().map(String::as_str) {
        Some("crate") => {
            at.clear();
            rest = &path[1..];
        }
        Some("self") => rest = &path[1..],
        Some("super") => {
            while rest.first().is_some_and(|s| s == "super") {
                at.pop();
                rest = &rest[1..];
            }
        }
        _ => {}
    }
    let mut found = None;
    let mut full = at.clone();
    for segment in rest {
        full.push(segment.clone());
        match file_of(src, &full) {
            Some(file) => found = Some(file),
            None => break,
        }
    }
    found
}

/// File-to-file imports of `src` (test files and `lib.rs` left out; a file's
/// uses of its own ancestors' `mod.rs`, where a module keeps what its files
/// share, are not counted).
fn file_imports(src: &Path) -> std::collections::BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut graph = std::collections::BTreeMap::new();
    for file in files.iter().filter(|f| !is_test_file(f) && !f.ends_with("lib.rs")) {
        let relative = file.strip_prefix(src).expect("under src");
        let module = module_of(relative);
        let code = production_code(&std::fs::read_to_string(file).expect("source"));
        let ancestors: Vec<PathBuf> = (1..module.len()).filter_map(|n| file_of(src, &module[..n])).collect();
        let targets: BTreeSet<PathBuf> = named_paths(&code)
            .iter()
            .filter_map(|p| resolve(src, &module, p))
            .filter(|t| t != file && !ancestors.contains(t) && !t.ends_with("lib.rs"))
            .collect();
        graph.insert(file.clone(), targets);
    }
    graph
}

/// The import cycles of `graph`: each a list of files, one per strongly
/// connected group of more than one file.
fn cycles(graph: &std::collections::BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    let reaches = |from: &PathBuf| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(f) = stack.pop() {
            for t in graph.get(&f).into_iter().flatten() {
                if seen.insert(t.clone()) {
                    stack.push(t.clone());
                }
            }
        }
        seen
    };
    let reach: std::collections::BTreeMap<&PathBuf, BTreeSet<PathBuf>> =
        graph.keys().map(|f| (f, reaches(f))).collect();
    let mut groups: Vec<Vec<PathBuf>> = Vec::new();
    for f in graph.keys() {
        if groups.iter().any(|g| g.contains(f)) || !reach[f].contains(f) {
            continue;
        }
        groups.push(graph.keys().filter(|g| reach[f].contains(*g) && reach[*g].contains(f)).cloned().collect());
    }
    groups
}

/// No circle of imports between the files of a module (or across modules):
/// a file uses only files that do not use it back, directly or through others.
#[test]
fn no_import_cycle_between_source_files() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = file_imports(&src);
    let edges: usize = graph.values().map(BTreeSet::len).sum();
    assert!(edges > 200, "the scan found only {edges} imports between files: it reads nothing");
    let found: Vec<String> = cycles(&graph)
        .iter()
        .map(|g| {
            g.iter().map(|f| f.strip_prefix(&src).unwrap_or(f).display().to_string()).collect::<Vec<_>>().join(", ")
        })
        .collect();
    assert!(found.is_empty(), "files importing each other:\n{}", found.join("\n"));
}

#[test]
fn the_file_cycle_check_sees_a_planted_cycle() {
    let dir = tempfile::tempdir().expect("temp dir");
    let src = dir.path();
    std::fs::create_dir_all(src.join("sim")).expect("folder");
    let files = [
        ("lib.rs", "pub mod sim;\n"),
        ("sim/mod.rs", "mod a;\nmod b;\nmod c;\npub use a::A;\n"),
        ("sim/a.rs", "use super::b::B;\n// use super::c::C in a comment\npub struct A(B);\n"),
        ("sim/b.rs", "use crate::sim::{c::{self, C}};\npub struct B(C);\n"),
        (
            "sim/c.rs",
            "pub struct C;\nfn f() { let _ = super::a::A; }\n#[cfg(test)]\nmod t {\n    use super::super::b::B;\n}\n",
        ),
    ];
    for (name, text) in files {
        std::fs::write(src.join(name), text).expect("write");
    }
    let graph = file_imports(src);
    let names: Vec<Vec<String>> = cycles(&graph)
        .iter()
        .map(|g| g.iter().map(|f| f.strip_prefix(src).unwrap_or(f).display().to_string()).collect())
        .collect();
    assert_eq!(names, [["sim/a.rs", "sim/b.rs", "sim/c.rs"]]);
    // Without c's use of a, no cycle: b → c is one way, and the test module's use is not counted.
    std::fs::write(src.join("sim/c.rs"), "pub struct C;\n#[cfg(test)]\nmod t {\n    use super::super::b::B;\n}\n")
        .expect("write");
    assert!(cycles(&file_imports(src)).is_empty());
}

/// Production code takes nothing from the CPU references (the tests'
/// oracles): what both need (shared math, strand frames) lives beside the
/// production code and the references import it. `sim/cpu.rs`, the public
/// CPU simulation, is built from the references by design.
#[test]
fn production_code_does_not_import_the_references() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let is_reference =
        |f: &Path| f.strip_prefix(&src).is_ok_and(|r| r.iter().any(|c| c.to_string_lossy().starts_with("reference")));
    let graph = file_imports(&src);
    let oracle_users: Vec<String> = graph
        .iter()
        .filter(|(from, _)| !is_reference(from) && !from.ends_with("sim/cpu.rs"))
        .flat_map(|(from, to)| to.iter().filter(|t| is_reference(t)).map(move |t| (from, t)))
        .map(|(from, to)| format!("{} imports {}", from.display(), to.display()))
        .collect();
    assert!(oracle_users.is_empty(), "production code importing a reference:\n{}", oracle_users.join("\n"));
    assert!(graph.keys().filter(|f| is_reference(f)).count() >= 4, "the scan found no reference file");
}

/// What records or builds a barrier by hand (not through the frame graph).
const HAND_BARRIERS: &[&str] = &[
    "cmd_barrier",
    "cmd_transition",
    "cmd_pipeline_barrier",
    "barrier::memory(",
    "barrier::image(",
    "barrier::subresources(",
    "barrier::buffer(",
];

/// The lines of `source`'s production code that place a barrier by hand.
fn hand_barriers(source: &str) -> Vec<String> {
    production_code(source)
        .lines()
        .filter(|line| HAND_BARRIERS.iter().any(|h| line.contains(h)))
        .map(|line| line.trim().to_string())
        .collect()
}

/// `render/pass.rs` promises that every barrier the render passes record is
/// one their frame graph derived from the declared uses (`render/graph.rs`
/// is the one place that records them).
#[test]
fn the_render_passes_record_only_barriers_their_frame_graph_derives() {
    let render = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render");
    let mut files = Vec::new();
    rust_files(&render, &mut files);
    let mut found = Vec::new();
    for path in files.iter().filter(|p| !is_test_file(p) && !p.ends_with("graph.rs")) {
        let source = std::fs::read_to_string(path).expect("source file");
        found.extend(hand_barriers(&source).into_iter().map(|line| format!("{}: {line}", path.display())));
    }
    assert!(found.is_empty(), "barriers placed by hand under src/render:\n{}", found.join("\n"));
}

#[test]
fn the_hand_barrier_check_sees_one() {
    assert_eq!(hand_barriers("    unsafe { d.cmd_barrier(cmd, &[m], &[], &[]) };").len(), 1);
    assert_eq!(hand_barriers("let b = barrier::memory(&[A], &[B]);").len(), 1);
    assert!(hand_barriers("// d.cmd_barrier(cmd, …)\ngraph.record(d, cmd, &uses);").is_empty());
}
