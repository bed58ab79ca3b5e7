//! Every layer of a USD stage checked before the USD library opens any of
//! them ([`check_layers`]): the library reads what a stage names without
//! bounds and goes without a layer, a reference or a payload it cannot use
//! in silence.

use std::collections::{HashMap, HashSet};
use std::io::Read as _;
use std::path::{Path, PathBuf};

use openusd::sdf::{Path as SdfPath, SpecType};

use super::usd_stacks::{canonical, Links, Stacks, Written};
use super::usda_arcs::Arcs;
use super::usda_check::Takes;
use crate::error::{Error, FileFormat, Result};

/// Most layers a stage may pull in through its layers' `subLayers`,
/// `references` and `payload`, the root included.
pub const MAX_USD_LAYERS: usize = 256;

/// Most references and payloads to other layers a stage's layers may hold
/// together: the library composes the layer each takes again every time
/// (20,000 took it about 10 s).
pub const MAX_USD_REFERENCES: usize = 10_000;

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// A prim's fields that may bring prims under it no layer declares.
const COMPOSING: [&str; 5] = ["references", "payload", "inheritPaths", "specializes", "variantSetNames"];

/// What a text layer offers a reference or payload.
struct Targets {
    /// It has sublayers, which may hold the prim an arc takes (left to the
    /// stage to judge).
    sublayers: bool,
    /// Its prims' paths.
    prims: HashSet<String>,
    /// The default prim it names.
    default: Option<String>,
    /// Its prims with composition arcs or variant sets of their own (which
    /// may bring prims under them that no layer declares).
    composing: HashSet<String>,
}

impl Targets {
    /// Why the layer lacks what an arc `takes` of it, if it does.
    fn missing(&self, takes: &Takes) -> Option<String> {
        match takes {
            Takes::Layer => None,
            Takes::Prim(p) if !p.starts_with('/') => {
                Some(format!("a reference or payload takes its prim <{p}>, a relative path (it must be absolute)"))
            }
            // The prim a default names may come from a sublayer, but the name
            // is this layer's own metadata (a sublayer's does not stand in).
            Takes::DefaultPrim if self.sublayers && self.default.is_none() => Some(
                "it names no default prim (its sublayers' do not count), and a reference or payload without a \
                 prim path takes it"
                    .into(),
            ),
            _ if self.sublayers => None,
            // A malformed path is the library's to judge.
            Takes::Prim(p) if SdfPath::new(p).is_err() => None,
            // Only the root prim is judged: a prim under it may come from the
            // root's own arcs or variants.
            Takes::Prim(p) => {
                let root = format!("/{}", p.trim_start_matches('/').split('/').next().unwrap_or_default());
                (!self.prims.contains(&root))
                    .then(|| format!("it has no prim {root}, which a reference or payload takes"))
            }
            Takes::DefaultPrim => match &self.default {
                Some(name) if self.prims.contains(&format!("/{name}")) => None,
                Some(name) => {
                    Some(format!("its default prim {name:?} is not there, and a reference or payload takes it"))
                }
                None => {
                    Some("it names no default prim, and a reference or payload without a prim path takes it".into())
                }
            },
        }
    }
}

/// The library's parse of text layer `text` (its errors with line and
/// column), on a guarded thread: what the layer offers an arc.
fn parse(text: &str, sublayers: bool) -> std::result::Result<Targets, String> {
    crate::files::read_guarded(|| {
        let mut parser = openusd::usda::parser::Parser::new(text);
        let specs = parser.parse().map_err(|e| {
            let at = parser.last_error_highlight().map(|h| format!("line {}, column {}: ", h.line, h.column));
            format!("the USD reader cannot parse it: {}{e:#}", at.unwrap_or_default())
        })?;
        let default = specs
            .get(&SdfPath::abs_root())
            .and_then(|root| root.fields.iter().find(|(key, _)| key == "defaultPrim"))
            .and_then(|(_, value)| value.try_as_token_ref().map(|t| t.as_str().to_owned()));
        let prim_specs = || specs.iter().filter(|(_, s)| s.ty == SpecType::Prim);
        let prims = prim_specs().map(|(p, _)| p.as_str().to_owned()).collect();
        let composing = prim_specs()
            .filter(|(_, s)| s.fields.iter().any(|(key, _)| COMPOSING.contains(&key.as_str())))
            .map(|(p, _)| p.as_str().to_owned())
            .collect();
        most_properties(specs.iter().map(|(p, s)| (p, s.ty)))?;
        Ok(Targets { sublayers, prims, default, composing })
    })
    .unwrap_or_else(|what| Err(format!("the USD reader stopped: {what}")))
}

pub use super::usda_check::MAX_USD_PROPERTIES;

/// Refuses a layer of `specs` (path, type) in which a prim declares more than
/// [`MAX_USD_PROPERTIES`] properties, naming it (text layers are refused
/// before they are parsed; binary ones here).
fn most_properties<'a>(specs: impl Iterator<Item = (&'a SdfPath, SpecType)>) -> std::result::Result<(), String> {
    let mut per_prim: HashMap<String, usize> = HashMap::new();
    for (path, ty) in specs {
        if matches!(ty, SpecType::Attribute | SpecType::Relationship) {
            let count = per_prim.entry(path.prim_path().as_str().to_owned()).or_default();
            *count += 1;
            if *count > MAX_USD_PROPERTIES {
                return Err(format!(
                    "its prim {} declares more than {MAX_USD_PROPERTIES} properties (the USD reader's time grows \
                     with the square of their number)",
                    path.prim_path().as_str()
                ));
            }
        }
    }
    Ok(())
}

/// What a binary layer names and holds, read by the library after
/// [`super::usdc_check`] has bounded it.
struct Binary {
    /// Its sublayers and every spec's references and payloads to other
    /// files: the asset path, what it takes, the prim whose arc it is.
    named: Vec<(String, Takes, String)>,
    /// What it offers an arc.
    targets: Targets,
    /// Its arcs between its own prims (`inheritPaths`, `specializes`, and
    /// references and payloads without an asset path): from, to, the field.
    arcs: Vec<(String, String, &'static str)>,
}

/// The paths of a list operation's items (a deletion or an ordering brings
/// none).
fn list_items<T: Default + Clone + PartialEq>(op: &openusd::sdf::ListOp<T>) -> impl Iterator<Item = &T> {
    [&op.explicit_items, &op.added_items, &op.prepended_items, &op.appended_items].into_iter().flatten()
}

/// Reads what a binary layer names, offers and composes between its own
/// prims (see [`Binary`]).
fn binary(path: &Path) -> std::result::Result<Binary, String> {
    use openusd::sdf::{AbstractData, Value};
    crate::files::read_guarded(|| {
        let data = openusd::usdc::read_file(path).map_err(|e| format!("the USD reader cannot read it: {e:#}"))?;
        let mut named = Vec::new();
        if let Ok(Some(v)) = data.try_field(&SdfPath::abs_root(), "subLayers") {
            if let Value::StringVec(layers) = v.as_ref() {
                named.extend(layers.iter().map(|l| (l.clone(), Takes::Layer, String::new())));
            }
        }
        let sublayers = !named.is_empty();
        let mut arcs = Vec::new();
        let mut prims = HashSet::new();
        let mut composing = HashSet::new();
        let typed: Vec<(SdfPath, SpecType)> =
            data.spec_paths().into_iter().filter_map(|p| data.spec_type(&p).map(|t| (p, t))).collect();
        most_properties(typed.iter().map(|(p, t)| (p, *t)))?;
        super::usdc_specs::check(&data, &typed)?;
        for (spec, ty) in &typed {
            // A variant's arcs are its prim's (`/P{v=a}C` → `/P/C`).
            let owner = spec.strip_all_variant_selections();
            let from = owner.as_str();
            if *ty == SpecType::Prim {
                prims.insert(from.to_owned());
                if COMPOSING.iter().any(|f| matches!(data.try_field(spec, f), Ok(Some(_)))) {
                    composing.insert(from.to_owned());
                }
            }
            // An arc to `prim` of `asset`: to another file, or (no asset
            // path) between this layer's prims.
            let mut take = |asset: &str, prim: &SdfPath, field: &'static str| match (asset, prim.as_str()) {
                ("", "") => {}
                ("", to) => arcs.push((from.to_owned(), super::usda_arcs::absolute(to, from), field)),
                (asset, "") => named.push((asset.to_owned(), Takes::DefaultPrim, from.to_owned())),
                (asset, to) => named.push((asset.to_owned(), Takes::Prim(to.to_owned()), from.to_owned())),
            };
            for field in ["references", "payload", "inheritPaths", "specializes"] {
                let Ok(Some(v)) = data.try_field(spec, field) else { continue };
                match v.as_ref() {
                    Value::ReferenceListOp(op) => list_items(op).for_each(|r| take(&r.asset_path, &r.prim_path, field)),
                    Value::PayloadListOp(op) => list_items(op).for_each(|p| take(&p.asset_path, &p.prim_path, field)),
                    Value::Payload(p) => take(&p.asset_path, &p.prim_path, field),
                    Value::PathListOp(op) if field != "references" && field != "payload" => {
                        list_items(op).for_each(|to| take("", to, field))
                    }
                    _ => {}
                }
            }
        }
        let most = super::usda_check::MAX_USDA_ARCS;
        if arcs.len() > most {
            return Err(format!(
                "more than {most} composition arcs between the layer's prims ({}; the reader's time grows with them)",
                arcs.len()
            ));
        }
        let default = data
            .try_field(&SdfPath::abs_root(), "defaultPrim")
            .ok()
            .flatten()
            .and_then(|v| v.try_as_token_ref().map(|t| t.as_str().to_owned()));
        Ok(Binary { named, targets: Targets { sublayers, prims, default, composing }, arcs })
    })
    .unwrap_or_else(|what| Err(format!("the USD reader stopped: {what}")))
}

/// Checks the root layer at `path` and, transitively, every layer its text
/// layers name, before the USD library opens any: each a regular file, all
/// of them together within `cap` bytes, at most [`MAX_USD_LAYERS`]; text
/// layers start with `#usda`, pass [`super::usda_check`] and parse with the
/// library's text parser (its errors with line and column); the prim a
/// reference or payload takes (or the default prim one without a prim path
/// takes) is in the layer it names, unless that layer has sublayers. A layer
/// that cannot be read, parsed or used is an error naming it and the layer
/// and line that named it, never a layer the stage goes without. Binary layers
/// are checked by [`super::usdc_check`] before the library reads what they
/// name (sublayers, references, payloads), which is checked the same way.
pub(super) fn check_layers(path: &Path, cap: u64) -> Result<()> {
    let mut queue = vec![(path.to_path_buf(), None::<(PathBuf, String)>, Takes::Layer)];
    // The layer stacks (a layer and its sublayers, one namespace): per text
    // layer its arcs between prims and its sublayers, and the layers that
    // start a stack (the root, and what a reference or payload names).
    let mut stacks = Stacks { stage: canonical(path), ..Stacks::default() };
    stacks.roots.insert(canonical(path));
    // Per text layer read, what it offers the arcs that name it again.
    let mut seen: HashMap<PathBuf, Option<Targets>> = HashMap::new();
    let mut total = 0u64;
    // Prims the layers declare, all together.
    let mut prims = 0usize;
    let mut count_prims = |targets: &Targets| {
        prims += targets.prims.len();
        if prims > super::usda_check::MAX_USD_PRIMS {
            return Err(malformed(format!(
                "the stage's layers declare more than {} prims (the USD reader composes about ten thousand a \
                 second: keep many curves in one BasisCurves prim)",
                super::usda_check::MAX_USD_PRIMS
            ))
            .in_asset(path));
        }
        Ok(())
    };
    // Property statements of the text layers, all together.
    let mut properties = 0usize;
    let mut count_properties = |n: usize| {
        properties += n;
        if properties > super::usda_check::MAX_USD_STAGE_PROPERTIES {
            return Err(malformed(format!(
                "the stage's text layers hold more than {} properties (the USD reader's time follows their \
                 number: a groom's curves have a dozen)",
                super::usda_check::MAX_USD_STAGE_PROPERTIES
            ))
            .in_asset(path));
        }
        Ok(())
    };
    let mut references = 0usize;
    let mut count_references = |n: usize| {
        references += n;
        if references > MAX_USD_REFERENCES {
            return Err(malformed(format!(
                "the stage's layers hold more than {MAX_USD_REFERENCES} references and payloads to other layers (the \
                 USD reader composes the layer each takes again every time)"
            ))
            .in_asset(path));
        }
        Ok(())
    };
    while let Some((layer, named_by, takes)) = queue.pop() {
        let named = |e: Error| match &named_by {
            None => e,
            Some((by, line)) => malformed(format!("{line} a layer it names cannot be used: {e}")).in_asset(by),
        };
        // The library opens a package (`.usdz`) and a layer inside one
        // (`pkg.usdz[inner.usda]`) itself, inflating what the package holds
        // beyond any bound checked here: refused.
        let text_path = layer.to_string_lossy();
        if text_path.contains('`') {
            let why = "an asset path that is an expression (`\"${VAR}.usda\"`), which vkhair does not evaluate";
            return Err(named(malformed(why.to_owned()).in_asset(&layer)));
        }
        // (A path is package-relative to the library when it holds a `[` and
        // ends with `]`; `take[2].usda` is a plain file.)
        let package = layer.extension().is_some_and(|e| e.eq_ignore_ascii_case("usdz"));
        if package || (text_path.contains('[') && text_path.ends_with(']')) {
            let why = "a USDZ package or a layer inside one (`pkg.usdz[layer.usda]`), which vkhair does not read: \
                       unpack it and name its .usda or .usdc layer";
            return Err(named(malformed(why.to_owned()).in_asset(&layer)));
        }
        // The library picks a layer's reader by its name's extension and goes
        // without a layer it has none for (`.txt`, none at all) in silence.
        let extension = layer.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
        if !matches!(extension.as_str(), "usd" | "usda" | "usdc") {
            let why = format!(
                "a layer named {}: the USD library reads only layers named .usd, .usda or .usdc and goes without \
                 any other in silence",
                if extension.is_empty() { "without an extension".to_owned() } else { format!(".{extension}") }
            );
            return Err(named(malformed(why).in_asset(&layer)));
        }
        crate::files::check_regular(&layer, cap, "a USD layer").map_err(named)?;
        let key = std::fs::canonicalize(&layer).unwrap_or_else(|_| layer.clone());
        if let Some(targets) = seen.get(&key) {
            if let Some(why) = targets.as_ref().and_then(|t| t.missing(&takes)) {
                return Err(named(malformed(why).in_asset(&layer)));
            }
            continue;
        }
        if seen.len() >= MAX_USD_LAYERS {
            return Err(malformed(format!("the stage pulls in more than {MAX_USD_LAYERS} layers")).in_asset(path));
        }
        // A regular file (checked above): its length bounds the stage, and only
        // a text layer is read here (the library reads the binary ones).
        let io = |source| named(Error::Io { path: layer.clone(), source });
        let len = std::fs::metadata(&layer).map_err(io)?.len();
        total += len;
        if total > cap {
            return Err(malformed(format!(
                "the stage's layers add up to more than {cap} bytes (set VKHAIR_MAX_INPUT_BYTES to read more)"
            ))
            .in_asset(path));
        }
        let mut head = Vec::with_capacity(64);
        std::fs::File::open(&layer).and_then(|f| f.take(64).read_to_end(&mut head)).map_err(io)?;
        let magic = &head[..head.len().min(8)];
        // The library picks a layer's reader by its name: a binary layer named
        // `.usda` or a text one named `.usdc` would be dropped in silence.
        let binary_bytes = magic == b"PXR-USDC";
        let text_head =
            head.iter().position(|b| !b" \t\r\n".contains(b)).is_some_and(|at| head[at..].starts_with(b"#usda"));
        if extension == "usdc" && !binary_bytes && !text_head {
            // Neither a binary layer nor a text one: a damaged bootstrap.
            let shown: String = magic.iter().map(|&b| std::ascii::escape_default(b).to_string()).collect();
            let why = format!("not a USD binary layer: it starts with \"{shown}\", not the PXR-USDC bootstrap");
            return Err(named(malformed(why).in_asset(&layer)));
        }
        if (binary_bytes && extension == "usda") || (!binary_bytes && extension == "usdc") {
            let (is, called) = if binary_bytes { ("binary", ".usda") } else { ("text", ".usdc") };
            let why = format!("a {is} USD layer named {called}: the USD library reads a layer as its name says");
            return Err(named(malformed(why).in_asset(&layer)));
        }
        if magic == b"PXR-USDC" {
            // Its bootstrap, table of contents, section heads and values,
            // before the library trusts them; then what it names.
            super::usdc_check::check(&layer, len).map_err(|e| named(e.in_asset(&layer)))?;
            let Binary { named: assets, targets, arcs: own } =
                binary(&layer).map_err(|why| named(malformed(why).in_asset(&layer)))?;
            if let Some(why) = targets.missing(&takes) {
                return Err(named(malformed(why).in_asset(&layer)));
            }
            count_prims(&targets)?;
            count_references(assets.iter().filter(|(_, takes, _)| *takes != Takes::Layer).count())?;
            stacks.offers.insert(key.clone(), (targets.prims.clone(), targets.composing.clone()));
            seen.insert(key.clone(), Some(targets));
            let dir = layer.parent().map(Path::to_path_buf).unwrap_or_default();
            // Its arcs between its own prims are judged with its layer
            // stack's (a cycle among them overflows the library's stack as a
            // text layer's does), a reference to its own file among them.
            let mut arcs: Arcs<Written> = Arcs::new();
            for (from, to, field) in own {
                let at = (layer.clone(), format!("prim {from}'s {field}:"));
                if field == "references" || field == "payload" {
                    stacks.internal.push((key.clone(), to.clone(), at.clone()));
                }
                arcs.entry(from).or_default().push((to, at));
            }
            let mut links = Links::default();
            for (asset, takes, from) in assets {
                if let (Takes::Prim(target), false) = (&takes, from.is_empty()) {
                    if canonical(&dir.join(&asset)) == key {
                        let to = super::usda_arcs::absolute(target, &from);
                        let at = (layer.clone(), format!("prim {from}'s arc to {asset:?}:"));
                        arcs.entry(from.clone()).or_default().push((to, at));
                    }
                }
                let by = (layer.clone(), format!("its arc to {asset:?}:"));
                links.add(&mut stacks, &dir.join(&asset), &takes, by);
                if asset.is_empty() {
                    let whose = if from.is_empty() { "its subLayers".to_owned() } else { format!("prim {from}") };
                    let why = format!("{whose}: an empty asset path (`@@`)");
                    return Err(malformed(why).in_asset(&layer));
                }
                queue.push((dir.join(&asset), Some((layer.clone(), format!("its arc to {asset:?}:"))), takes));
            }
            stacks.layers.insert(key, (arcs, links));
            continue;
        }
        // Every other layer is read as text, whatever it starts with (the
        // library takes a layer led by blank space as text too): one that is
        // not text is refused here rather than dropped by the library.
        let bytes = crate::files::read_capped(&layer, cap, "a USD layer").map_err(named)?;
        let text = std::str::from_utf8(&bytes)
            .map_err(|e| named(malformed(format!("the text is not UTF-8 ({e})")).in_asset(&layer)))?;
        if !text.trim_start_matches([' ', '\t', '\r', '\n']).starts_with("#usda") {
            let what = if text.starts_with('\u{feff}') { "a byte-order mark" } else { "something else" };
            return Err(named(
                malformed(format!("not a USD layer: it starts with {what}, not the `#usda` header")).in_asset(&layer),
            ));
        }
        let checked = super::usda_check::check(text, takes == Takes::Layer && named_by.is_some())
            .map_err(|e| named(e.in_asset(&layer)))?;
        count_properties(checked.properties)?;
        let assets = checked.assets;
        let targets = parse(text, assets.iter().any(|a| a.takes == Takes::Layer))
            .map_err(|why| named(malformed(why).in_asset(&layer)))?;
        if let Some(why) = targets.missing(&takes) {
            return Err(named(malformed(why).in_asset(&layer)));
        }
        count_prims(&targets)?;
        count_references(assets.iter().filter(|a| a.takes != Takes::Layer).count())?;
        stacks.offers.insert(key.clone(), (targets.prims.clone(), targets.composing.clone()));
        seen.insert(key.clone(), Some(targets));
        let dir = layer.parent().map(Path::to_path_buf).unwrap_or_default();
        let located = |at: &usize| (layer.clone(), super::usda_check::position(text, *at));
        let mut arcs: Arcs<Written> = checked
            .arcs
            .into_iter()
            .map(|(from, to)| (from, to.into_iter().map(|(target, at)| (target, located(&at))).collect()))
            .collect();
        // A reference to a prim of this very layer (`@./self.usda@</P>`) is an
        // arc within its namespace as much as one without an asset path: its
        // chains and cycles are judged with the layer's own arcs.
        for asset in &assets {
            if let (Takes::Prim(target), Some(from)) = (&asset.takes, &asset.from) {
                if canonical(&dir.join(&asset.path)) == key {
                    let to = super::usda_arcs::absolute(target, from);
                    arcs.entry(from.clone()).or_default().push((to, located(&asset.at)));
                }
            }
        }
        let mut links = Links::default();
        for asset in assets {
            let line = super::usda_check::position(text, asset.at);
            if asset.path.is_empty() {
                let why = format!(
                    "{line} an empty asset path (`@@`): a reference to a prim of this layer is written without one \
                     (`</Prim>`)"
                );
                return Err(malformed(why).in_asset(&layer));
            }
            let named = dir.join(&asset.path);
            links.add(&mut stacks, &named, &asset.takes, (layer.clone(), line.clone()));
            queue.push((named, Some((layer.clone(), line)), asset.takes));
        }
        for (target, at) in &checked.internal {
            stacks.internal.push((key.clone(), target.clone(), located(at)));
        }
        stacks.layers.insert(key, (arcs, links));
    }
    stacks.check()
}
