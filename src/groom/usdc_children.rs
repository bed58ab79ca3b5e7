//! A USD binary (crate) layer's namespace, checked before the `openusd` crate
//! composes it. Each prim's `primChildren` (and `propertyChildren`) lists the
//! names of its children, and the crate's composition walks those names to
//! the children's specs: a changed byte that made a prim list a name it has
//! no child of (one byte of `small_cm_zup.usdc`: a token index 5 → 1) sent
//! the composition round a loop that never ends. [`check`] reads the
//! layer's paths, specs and those lists with the crate's own reader (after
//! [`super::usdc_values::check`] has bounded their counts) and refuses a
//! list with an empty, malformed or repeated name, or a name whose path
//! (`/Parent/name`, `/Parent.name`) the layer has no spec for — each error
//! naming the prim and the name.

use std::collections::HashSet;
use std::path::Path;

use crate::error::{Error, FileFormat, Result};

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// The child path of `parent` named `name` in a list of `field`
/// (`primChildren` or `propertyChildren`).
fn child_path(parent: &str, field: &str, name: &str) -> String {
    match (field, parent) {
        ("primChildren", "/") => format!("/{name}"),
        // A prim inside a variant: `/A{v=s}B`.
        ("primChildren", _) if parent.ends_with('}') => format!("{parent}{name}"),
        ("primChildren", _) => format!("{parent}/{name}"),
        _ => format!("{parent}.{name}"),
    }
}

/// Why `name` cannot name a child in a list of `field`, if it cannot: a prim's
/// name is an identifier; a property's may hold namespace colons.
fn bad_name(field: &str, name: &str) -> Option<&'static str> {
    let ok_char = |c: char| c == '_' || c.is_alphanumeric() || (field == "propertyChildren" && c == ':');
    if name.is_empty() {
        Some("an empty name")
    } else if !name.chars().all(ok_char) || name.starts_with(|c: char| c.is_ascii_digit()) {
        Some("a name that is not an identifier")
    } else {
        None
    }
}

/// The crate types of a token vector and of a token (an array of them with
/// the array bit): USD's writer stores children as the first, others as the
/// second.
const TOKEN_VECTOR: u64 = 41;
const TOKEN: u64 = 11;

/// Why value representation `rep` cannot be read as a list of tokens, if it
/// cannot: not a token vector or token array, or one inlined. Its count and
/// every token it lists were checked against the file and the table by
/// [`super::usdc_values::check`], which runs first.
fn not_a_token_list(rep: u64) -> Option<String> {
    let (ty, array, inlined) = ((rep >> 48) & 0xFF, rep & (1 << 63) != 0, rep & (1 << 62) != 0);
    match (ty, array) {
        (TOKEN_VECTOR, _) | (TOKEN, true) if inlined => {
            Some(format!("is not a list of tokens stored out of line (value type {ty})"))
        }
        (TOKEN_VECTOR, _) | (TOKEN, true) => None,
        _ => Some(format!("is not a list of tokens (value type {ty})")),
    }
}

/// Checks the children lists of the crate file at `path`.
pub fn check(path: &Path) -> Result<()> {
    let found = crate::files::read_guarded(|| -> std::result::Result<Option<String>, String> {
        let file = std::fs::File::open(path).map_err(|e| format!("{e}"))?;
        let mut layer = openusd::usdc::CrateFile::open(std::io::BufReader::new(file)).map_err(|e| format!("{e:#}"))?;
        let known: HashSet<String> = layer.paths.iter().map(|p| p.as_str().to_owned()).collect();
        let (specs, fieldsets, fields) = (layer.specs.clone(), layer.fieldsets.clone(), layer.fields.clone());
        for spec in &specs {
            let parent = layer.paths.get(spec.path_index).map(|p| p.as_str().to_owned()).unwrap_or_default();
            let listed = fieldsets.get(spec.fieldset_index..).unwrap_or_default().iter().map_while(|f| *f);
            for field in listed.filter_map(|f| fields.get(f)) {
                let Some(name) = layer.tokens.get(field.token_index).cloned() else { continue };
                if name != "primChildren" && name != "propertyChildren" {
                    continue;
                }
                if let Some(why) = not_a_token_list(field.value_rep.0) {
                    return Ok(Some(format!("{parent}'s {name} {why}")));
                }
                let children = match layer.value(field.value_rep).map_err(|e| format!("{e:#}"))? {
                    openusd::sdf::Value::TokenVec(children) => children,
                    other => return Ok(Some(format!("{parent}'s {name} is not a token list ({other:?})"))),
                };
                let mut seen = HashSet::new();
                for child in &children {
                    let child = child.as_str();
                    if let Some(why) = bad_name(&name, child) {
                        return Ok(Some(format!("{parent}'s {name} lists {why}: {child:?}")));
                    }
                    if !seen.insert(child) {
                        return Ok(Some(format!("{parent}'s {name} lists {child:?} twice")));
                    }
                    if !known.contains(&child_path(&parent, &name, child)) {
                        return Ok(Some(format!("{parent}'s {name} lists {child:?}, which the layer has no path for")));
                    }
                }
            }
        }
        Ok(None)
    })
    .unwrap_or_else(|what| Err(format!("the USD reader stopped: {what}")))
    .map_err(|why| malformed(format!("its namespace cannot be read: {why}")))?;
    match found {
        Some(problem) => Err(malformed(format!("a prim's children do not match its paths: {problem}"))),
        None => Ok(()),
    }
}
