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
    &["render", "character"],
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
    let mut lines = source.lines();
    while let Some(line) = lines.next() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            skip_item(&mut lines);
            continue;
        }
        if code.starts_with("//") {
            continue;
        }
        let code = code.split("//").next().unwrap_or_default();
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
    let mut dirs = vec![glsl.join("sim")];
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
