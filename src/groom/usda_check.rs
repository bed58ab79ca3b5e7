//! What a USD text layer must satisfy before the `openusd` crate reads it: the
//! crate recurses once per level of nesting (its time grows with the cube of
//! the depth: 8 s at 1,000 levels) and follows composition arcs without
//! looking for cycles (a class inheriting itself overflows its stack and
//! aborts the process). [`check`] scans the text once, without the crate:
//!
//! - nesting of `{`, `(` and `[` (prims, metadata, dictionaries, lists) at
//!   most [`MAX_USDA_DEPTH`] deep, and the prims' depths together bounded
//!   ([`MAX_USDA_DEPTH_WORK`]: the sum of each prim's depth squared, which
//!   the crate's time follows — many chains each within the depth limit took
//!   it 12 s at 300 chains of 125 levels);
//! - at most [`MAX_USD_PRIMS`] prims (the reader's time follows their
//!   number: 42 s for 400,000 empty prims), and at most
//!   [`MAX_USD_PROPERTIES`] statements in one prim's body (its time grows
//!   with the square of a prim's properties);
//! - every layer named by `subLayers` or by a composition arc, wherever the
//!   arc is written (a prim's metadata or a variant's), is returned for the
//!   same checks;
//! - the composition arcs between the layer's own prims (`inherits`,
//!   `specializes`, and `references`/`payload` without an asset path) form no
//!   cycle, and none targets its own prim, an ancestor or a descendant.
//!
//! Strings, comments and path literals are skipped as USD text writes them;
//! errors carry the line and column.

use std::collections::{HashMap, HashSet};

pub(super) use super::usda_arcs::Arcs;
use super::usda_arcs::{absolute, arc_targets, check_arcs};
pub use super::usda_tokens::position;
use super::usda_tokens::{tokens, Token};
use crate::error::{Error, FileFormat, Result};

/// Deepest nesting of brackets a USD text layer may have (prims inside prims,
/// dictionaries inside dictionaries): far beyond a real stage's, small enough
/// that the reader's recursion and time stay bounded.
pub const MAX_USDA_DEPTH: usize = 128;

/// Most prim-nesting work a USD text layer may ask for: the sum over its
/// prims of their depth squared (a prim at the root counts 1). A groom of
/// 10,000 prims five deep asks for 250,000; one chain at the depth limit for
/// 700,000; 300 chains of 125 levels for 198,000,000.
pub const MAX_USDA_DEPTH_WORK: u64 = 4_000_000;

/// The prim metadata of value clips (the `clips` dictionary, its sets, and
/// the fields of the older form): the library opens the layers they name
/// itself, unchecked, and vkhair reads no clip.
pub(super) const CLIP_FIELDS: [&str; 11] = [
    "clips",
    "clipSets",
    "clipAssetPaths",
    "clipManifestAssetPath",
    "clipTemplateAssetPath",
    "clipPrimPath",
    "clipActive",
    "clipTimes",
    "clipTemplateStartTime",
    "clipTemplateEndTime",
    "clipTemplateStride",
];

/// Why value clips and relocates are refused, for both kinds of layer.
pub(super) const CLIPS_REFUSED: &str = "value clips, which vkhair does not read (the USD library would open the \
     layers they name unchecked): flatten the stage (usdcat --flatten) and read that";
pub(super) const RELOCATES_REFUSED: &str = "relocates, which vkhair does not read (the USD library went without \
     the relocated prims in silence): flatten the stage (usdcat --flatten) and read that";

/// Most prims a chain of composition arcs (inherits, specializes, internal
/// references) may pass through within a layer stack: the reader's time
/// grows with the cube of the chain (1,000 links took it 13 s).
pub const MAX_USDA_ARC_CHAIN: usize = super::usda_arcs::MAX_ARC_CHAIN;

/// Most prims a USD stage may declare, over all its layers: the USD reader
/// composes about ten thousand a second (400,000 empty prims took it 42 s),
/// and a groom keeps many curves in one `BasisCurves` prim.
pub const MAX_USD_PRIMS: usize = 100_000;

/// Most statements other than child prims (properties, variant sets) one
/// prim's body may hold in a USD text layer: the USD reader's time grows with the square of a prim's
/// properties (20,000 took it 3.8 s, 100,000 more than two minutes); a
/// groom's curves have a dozen.
pub const MAX_USD_PROPERTIES: usize = 10_000;

/// Most such statements a stage's text layers may hold all together: each
/// prim within [`MAX_USD_PROPERTIES`], twenty of them (200,000) took the
/// reader 10 s.
pub const MAX_USD_STAGE_PROPERTIES: usize = 100_000;

/// Metadata keys whose path values are composition arcs.
const ARCS: [&str; 4] = ["inherits", "specializes", "references", "payload"];

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// Most composition arcs between a layer's own prims [`check`] follows.
pub const MAX_USDA_ARCS: usize = 10_000;

/// The other layers a text layer composes: each asset path of its
/// `subLayers`, `references` and `payload`, with its byte offset.
pub type LayerAssets = Vec<LayerAsset>;

/// One layer a text layer names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LayerAsset {
    /// Its asset path, as written.
    pub path: String,
    /// Where it is written (a byte offset of the naming layer's text).
    pub at: usize,
    /// What of it the naming layer takes.
    pub takes: Takes,
    /// For a reference or payload, the prim (of the naming layer) whose arc
    /// it is.
    pub from: Option<String>,
}

/// What a layer takes of a layer it names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Takes {
    /// The whole layer (a sublayer).
    Layer,
    /// Its default prim (a reference or payload without a prim path).
    DefaultPrim,
    /// The prim at this path (`@layer@</Prim>`).
    Prim(String),
}

/// What [`check`] found in a layer: the other layers it names, and the
/// composition arcs between prims of its namespace (each with the byte
/// offset it is written at), which its sublayers share.
#[derive(Debug, Clone, Default)]
pub struct Checked {
    /// The layers it names.
    pub assets: LayerAssets,
    /// Its arcs between prims (see [`Arcs`]).
    pub(super) arcs: Arcs<usize>,
    /// The prims its references and payloads without an asset path take,
    /// each with where it is written.
    pub(super) internal: Vec<(String, usize)>,
    /// Its property statements (at most [`MAX_USD_STAGE_PROPERTIES`]).
    pub properties: usize,
}

/// Checks the USD text `text` (see the module docs): the other layers it
/// names and its arcs between prims ([`Checked`]).
pub fn check(text: &str, sublayer: bool) -> Result<Checked> {
    let tokens = tokens(text)?;
    // Brackets open; for each whether it opened a prim's body.
    let mut open: Vec<(u8, bool)> = Vec::new();
    // The prims whose bodies are open, outermost first.
    let mut prims: Vec<String> = Vec::new();
    // A prim declared (`def`/`class`/`over` … "name") whose body is not open yet.
    let mut pending: Option<String> = None;
    let mut declaring = false;
    let mut arcs: Arcs<usize> = HashMap::new();
    let mut count = 0usize;
    let mut declared = 0usize;
    let mut work = 0u64;
    let mut assets = LayerAssets::new();
    // The names of the prims declared at the root, and the targets (with
    // where they are written) of the references and payloads within the layer.
    let mut roots: HashSet<String> = HashSet::new();
    let mut internal: Vec<(String, usize)> = Vec::new();
    // Per open prim body, the statements begun on a new line in it other
    // than its child prims (properties, variant sets).
    let mut statements: Vec<usize> = Vec::new();
    let mut properties = 0usize;
    let mut previous = 0usize;
    for (k, (at, token)) in tokens.iter().enumerate() {
        let child_prim = matches!(token, Token::Word("def" | "class" | "over"));
        // Inside a prim's braces: its body, or a variant's (whose
        // properties the reader parses the same way).
        if open.last().is_some_and(|&(c, _)| c == b'{')
            && !prims.is_empty()
            && !child_prim
            && !matches!(token, Token::Close(_) | Token::Open(_))
            && text[previous..*at].contains('\n')
        {
            if let Some(n) = statements.last_mut() {
                *n += 1;
                properties += 1;
                if properties > MAX_USD_STAGE_PROPERTIES {
                    return Err(malformed(format!(
                        "{} more than {MAX_USD_STAGE_PROPERTIES} properties in the layer (the USD reader's time \
                         follows their number: a groom's curves have a dozen)",
                        position(text, *at)
                    )));
                }
                if *n > MAX_USD_PROPERTIES {
                    return Err(malformed(format!(
                        "{} its prim {} declares more than {MAX_USD_PROPERTIES} properties (the USD reader's time \
                         grows with the square of their number)",
                        position(text, *at),
                        prims.last().map_or("", String::as_str)
                    )));
                }
            }
        }
        previous = *at;
        match token {
            Token::Open(c) => {
                if open.len() >= MAX_USDA_DEPTH {
                    return Err(malformed(format!(
                        "{} nesting deeper than {MAX_USDA_DEPTH} levels (prims, metadata or dictionaries)",
                        position(text, *at)
                    )));
                }
                let body = *c == b'{' && pending.is_some() && !prims_metadata_open(&open);
                if body {
                    let name = pending.take().unwrap_or_default();
                    let parent = prims.last().map_or("", String::as_str);
                    if parent.is_empty() {
                        roots.insert(name.clone());
                    }
                    prims.push(format!("{parent}/{name}"));
                    statements.push(0);
                    declaring = false;
                    declared += 1;
                    if declared > MAX_USD_PRIMS {
                        return Err(malformed(format!(
                            "{} more than {MAX_USD_PRIMS} prims (the USD reader composes about ten thousand a \
                             second: keep many curves in one BasisCurves prim)",
                            position(text, *at)
                        )));
                    }
                    work += (prims.len() as u64).pow(2);
                    if work > MAX_USDA_DEPTH_WORK {
                        return Err(malformed(format!(
                            "{} the prims nest too deeply all together: the sum of their depths squared passes \
                             {MAX_USDA_DEPTH_WORK}",
                            position(text, *at)
                        )));
                    }
                }
                open.push((*c, body));
            }
            Token::Close(c) => {
                let expected = match c {
                    b'}' => b'{',
                    b')' => b'(',
                    _ => b'[',
                };
                match open.pop() {
                    Some((o, body)) if o == expected => {
                        if body {
                            prims.pop();
                            statements.pop();
                        }
                    }
                    _ => {
                        return Err(malformed(format!("{} '{}' closes nothing open", position(text, *at), *c as char)))
                    }
                }
            }
            Token::Word(w) => {
                let in_metadata = pending.is_some() && open.last().is_some_and(|(c, _)| *c == b'(');
                if matches!(*w, "def" | "class" | "over") && !prims_metadata_open(&open) {
                    declaring = true;
                    pending = None;
                } else if matches!(tokens.get(k + 1), Some((_, Token::Equals)))
                    && (in_metadata || (open.len() == 1 && prims.is_empty() && pending.is_none()))
                    && (CLIP_FIELDS.contains(w) || *w == "relocates")
                {
                    // Value clips name layers the library opens itself;
                    // relocates it went without in silence.
                    let why = match *w {
                        "relocates" => RELOCATES_REFUSED,
                        _ => CLIPS_REFUSED,
                    };
                    return Err(malformed(format!("{} `{w}`: {why}", position(text, *at))));
                } else if *w == "subLayers" && open.len() == 1 && prims.is_empty() && pending.is_none() {
                    assets.extend(asset_paths(&tokens[k + 1..], false));
                } else if ARCS.contains(w) && matches!(tokens.get(k + 1), Some((_, Token::Equals))) && !in_metadata {
                    // An arc outside a prim's own metadata (a variant's): its
                    // layers are checked like any other.
                    // Its arcs between the layer's prims are the owning
                    // prim's: a chain of them through variants is as slow to
                    // compose, and a cycle as fatal.
                    let from = prims.last().cloned();
                    assets.extend(
                        asset_paths(&tokens[k + 2..], true).into_iter().map(|a| LayerAsset { from: from.clone(), ..a }),
                    );
                    if let Some(from) = from {
                        for target in arc_targets(&tokens[k + 2..]) {
                            count_arc(&mut count, text, *at)?;
                            arcs.entry(from.clone()).or_default().push((absolute(target, &from), *at));
                        }
                    }
                } else if ARCS.contains(w) && in_metadata && matches!(tokens.get(k + 1), Some((_, Token::Equals))) {
                    let from =
                        format!("{}/{}", prims.last().map_or("", String::as_str), pending.as_deref().unwrap_or(""));
                    let named = asset_paths(&tokens[k + 2..], true);
                    assets.extend(named.into_iter().map(|a| LayerAsset { from: Some(from.clone()), ..a }));
                    for target in arc_targets(&tokens[k + 2..]) {
                        count_arc(&mut count, text, *at)?;
                        let target = absolute(target, &from);
                        if matches!(*w, "references" | "payload") {
                            internal.push((target.clone(), *at));
                        }
                        arcs.entry(from.clone()).or_default().push((target, *at));
                    }
                }
            }
            Token::Text(name) => {
                if declaring && pending.is_none() {
                    pending = Some((*name).to_owned());
                }
            }
            Token::Path(p) => {
                let elements = p.split('/').filter(|e| !e.is_empty()).count();
                if elements > MAX_USDA_DEPTH {
                    return Err(malformed(format!(
                        "{} a path of {elements} elements (no prim of a checked layer lies deeper than \
                         {MAX_USDA_DEPTH})",
                        position(text, *at)
                    )));
                }
            }
            Token::Asset(_) | Token::Equals => {}
        }
    }
    if let Some((c, _)) = open.last() {
        return Err(malformed(format!("a '{}' is never closed", *c as char)));
    }
    check_arcs(&arcs, |at, why| malformed(format!("{} {why}", position(text, *at)))).map(drop)?;
    // A reference or payload within the layer whose target's root prim the
    // layer does not declare brings nothing, and the stage says nothing (a
    // sublayer may declare it: then it is left to the stage).
    // (A layer used as a sublayer composes with its parent's and siblings'
    // prims: not judged either.)
    if !sublayer && !assets.iter().any(|a| a.takes == Takes::Layer) {
        for (target, at) in &internal {
            let root = target.trim_start_matches('/').split('/').next().unwrap_or_default();
            if !roots.contains(root) {
                return Err(malformed(format!(
                    "{} a reference or payload to {target}, a prim the layer does not have",
                    position(text, *at)
                )));
            }
        }
    }
    Ok(Checked { assets, arcs, internal, properties })
}

/// One more arc between the layer's prims, written at `at`: refused past
/// [`MAX_USDA_ARCS`].
fn count_arc(count: &mut usize, text: &str, at: usize) -> Result<()> {
    *count += 1;
    if *count > MAX_USDA_ARCS {
        return Err(malformed(format!(
            "{} more than {MAX_USDA_ARCS} composition arcs between the layer's prims",
            position(text, at)
        )));
    }
    Ok(())
}

/// The asset paths of a value (`tokens` start after its key, at `=` or at
/// the value): one, or those of a list, to the list's end.
fn asset_paths<'a>(tokens: &[(usize, Token<'a>)], arc: bool) -> LayerAssets {
    let tokens = match tokens.first() {
        Some((_, Token::Equals)) => &tokens[1..],
        _ => tokens,
    };
    // What an arc's asset at `i` takes: the prim path right after it, else
    // the default prim; a sublayer takes the layer.
    let takes = |i: usize| match (arc, tokens.get(i + 1)) {
        (false, _) => Takes::Layer,
        (true, Some((_, Token::Path(p)))) => Takes::Prim((*p).to_owned()),
        (true, _) => Takes::DefaultPrim,
    };
    let asset = |i: usize, a: &str, at: usize| LayerAsset { path: a.to_owned(), at, takes: takes(i), from: None };
    match tokens.first() {
        Some((at, Token::Asset(a))) => vec![asset(0, a, *at)],
        Some((_, Token::Open(b'['))) => {
            let mut depth = 0usize;
            let mut out = Vec::new();
            for (i, (at, t)) in tokens.iter().enumerate() {
                match t {
                    Token::Open(_) => depth += 1,
                    Token::Close(_) => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    // Only the list's own entries: not an asset inside a
                    // reference's metadata.
                    Token::Asset(a) if depth == 1 => out.push(asset(i, a, *at)),
                    _ => {}
                }
            }
            out
        }
        _ => Vec::new(),
    }
}

/// Whether the innermost open bracket is a prim's metadata `(`…`)` or a
/// list/dictionary inside it (not a prim body).
fn prims_metadata_open(open: &[(u8, bool)]) -> bool {
    open.last().is_some_and(|(c, _)| *c != b'{')
        || open.iter().rev().take_while(|(_, body)| !body).any(|(c, _)| *c == b'(')
}

#[cfg(test)]
mod tests {
    use super::*;

    const CURVES: &str =
        "def BasisCurves \"c\" { int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0),(0,1,0)] }\n";

    #[test]
    fn a_plain_stage_with_arcs_between_prims_passes() {
        let text = format!(
            "#usda 1.0\n(\n  metersPerUnit = 0.01\n  customLayerData = {{ string note = \"a ) in a string {{\" }}\n)\n\
             class \"Base\" {{ }}\ndef Xform \"groom\" (\n  inherits = </Base>\n  references = @other.usda@</Thing>\n) {{\n  \
             {CURVES} }}\n# a comment with {{ ( [\n"
        );
        check(&text, false).expect("passes");
    }

    #[test]
    fn nesting_past_the_limit_is_refused_with_its_line() {
        let deep = |n: usize| {
            let mut t = String::from("#usda 1.0\n");
            for i in 0..n {
                t += &format!("def Xform \"p{i}\" {{\n");
            }
            t += CURVES;
            t += &"}\n".repeat(n);
            t
        };
        // The curves prim adds three levels (its body, a list and a tuple).
        check(&deep(MAX_USDA_DEPTH - 3), false).expect("within the limit");
        let err = check(&deep(MAX_USDA_DEPTH + 5), false).expect_err("too deep").to_string();
        assert!(
            err.contains("nesting deeper than 128") && err.contains(&format!("line {}", MAX_USDA_DEPTH + 2)),
            "{err}"
        );
        let dictionaries = format!(
            "#usda 1.0\n(\n customLayerData = {}{{}}{}\n)\n",
            "{ dictionary a = ".repeat(500),
            " }".repeat(500)
        );
        assert!(check(&dictionaries, false).expect_err("too deep").to_string().contains("nesting deeper"));
    }

    #[test]
    fn arcs_to_themselves_their_namespace_or_round_a_cycle_are_refused() {
        let cases = [
            ("class \"A\" (\n inherits = </A>\n) { }\n", "prim /A has a composition arc to /A, itself"),
            ("def Xform \"A\" { def Xform \"B\" (\n specializes = </A>\n) { } }\n", "its own namespace"),
            ("class \"A\" (\n inherits = </B>\n) { }\nclass \"B\" (\n inherits = [</C>]\n) { }\nclass \"C\" (\n prepend references = </A>\n) { }\n", "a cycle"),
            ("class \"A\" { class \"Child\" (\n inherits = </B>\n) { } }\nclass \"B\" (\n inherits = </A>\n) { }\n", "a cycle"),
        ];
        for (body, what) in cases {
            let text = format!("#usda 1.0\n{body}{CURVES}");
            let err = check(&text, false).expect_err(what).to_string();
            assert!(err.contains(what) && err.contains("line "), "{what}: {err}");
        }
        // A chain without a cycle, and an arc into another layer, pass.
        let chain = "class \"A\" (\n inherits = </B>\n) { }\nclass \"B\" { }\ndef Xform \"C\" (\n references = @a.usda@</C>\n) { }\n";
        check(&format!("#usda 1.0\n{chain}{CURVES}"), false).expect("no cycle");
    }

    #[test]
    fn more_arcs_than_the_limit_are_refused() {
        let arcs = |n: usize| {
            let mut t = String::from("#usda 1.0\nclass \"Base\" { }\n");
            for i in 0..n {
                t += &format!("def Xform \"p{i}\" (\n inherits = </Base>\n) {{ }}\n");
            }
            t + CURVES
        };
        check(&arcs(MAX_USDA_ARCS), false).expect("at the limit");
        let err = check(&arcs(MAX_USDA_ARCS + 1), false).expect_err("past it").to_string();
        assert!(err.contains("more than 10000 composition arcs"), "{err}");
    }

    /// Many chains of inheriting classes, each within the chain and arc
    /// bounds, are bounded all together (`usda_arcs::MAX_ARC_WORK`): 41 chains
    /// of 90 are refused at a line (110 took the library 7.5–10 s), 40 pass.
    #[test]
    fn many_long_arc_chains_are_bounded_all_together() {
        let chains = |n: usize| {
            let mut t = String::from("#usda 1.0\n");
            for c in 0..n {
                for k in 0..90 {
                    let arc = if k + 1 < 90 { format!(" (\n inherits = </C{c}_{}>\n)", k + 1) } else { String::new() };
                    t += &format!("class \"C{c}_{k}\"{arc} {{ }}\n");
                }
            }
            t + CURVES
        };
        check(&chains(40), false).expect("40 chains of 90");
        let err = check(&chains(41), false).expect_err("41 chains of 90").to_string();
        assert!(err.contains("line ") && err.contains("chain too long all together"), "{err}");
    }

    #[test]
    fn comments_and_line_ends_are_read_as_the_library_reads_them() {
        let deep = |end: &str, n: usize| {
            let mut t = format!("#usda 1.0{end}# a comment{end}");
            for i in 0..n {
                t += &format!("def Xform \"p{i}\" {{{end}");
            }
            t + CURVES + &"}".repeat(n)
        };
        // A lone CR ends a comment (and a line): what follows is read, and the
        // lines are counted as the library counts them.
        let err = check(&deep("\r", MAX_USDA_DEPTH + 5), false).expect_err("too deep").to_string();
        assert!(err.contains("nesting deeper") && err.contains(&format!("line {}", MAX_USDA_DEPTH + 3)), "{err}");
        let err = check(&deep("\r\n", MAX_USDA_DEPTH + 5), false).expect_err("too deep").to_string();
        assert!(err.contains(&format!("line {}", MAX_USDA_DEPTH + 3)), "{err}");
        // A block comment hides what it holds, and only that.
        let hidden = format!("#usda 1.0\n/* {} */\n{CURVES}", "def Xform \"x\" {".repeat(500));
        check(&hidden, false).expect("a comment's text is not read");
        let after = format!("#usda 1.0\n/* {{ */ {}{CURVES}{}", "def Xform \"x\" {".repeat(500), "}".repeat(500));
        assert!(check(&after, false).expect_err("read").to_string().contains("nesting deeper"));
        let open = check("#usda 1.0\n/* def Xform \"a\" { }\n", false).expect_err("unterminated").to_string();
        assert!(open.contains("a comment that never ends"), "{open}");
        // A string may span lines, as the library's do.
        let multi = format!("#usda 1.0\n(\n doc = \"two\nlines {{\"\n)\n{CURVES}");
        check(&multi, false).expect("a string over two lines");
    }

    #[test]
    fn unbalanced_or_unterminated_text_is_refused() {
        for (text, what) in [
            ("#usda 1.0\ndef Xform \"a\" { ]\n", "closes nothing"),
            ("#usda 1.0\ndef Xform \"a\" {\n", "never closed"),
            ("#usda 1.0\ndef Xform \"a { }\n", "a string that never ends"),
            ("#usda 1.0\ndef Xform \"a\" (inherits = </A) { }\n", "a path that never ends"),
        ] {
            let err = check(text, false).expect_err(what).to_string();
            assert!(err.contains(what), "{what}: {err}");
        }
    }
}
