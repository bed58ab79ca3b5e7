//! The composition arcs between prims of one namespace (`inherits`,
//! `specializes`, and `references`/`payload` without an asset path) as a
//! graph, checked before the USD library follows them: it follows arcs
//! without looking for cycles (a class inheriting itself, or two classes in
//! two sublayers inheriting each other, overflows its stack and aborts the
//! process) and its time grows with the cube of a chain. One text layer's
//! arcs are checked by [`super::usda_check::check`]; a layer stack's (a layer
//! and its sublayers, whose prims share one namespace) by
//! [`super::usd_layers`], each arc named where it is written.

use std::collections::HashMap;

use super::usda_tokens::Token;
use crate::error::{Error, Result};

/// Most prims a chain of composition arcs may pass through in one namespace.
pub const MAX_ARC_CHAIN: usize = 128;

/// Most paths of composition arcs from one prim within a namespace: the
/// reader composes a prim once along every path (a class inheriting 59
/// others, each inheriting those after it, never finished).
pub const MAX_ARC_PATHS: usize = 10_000;

/// Most work the arcs of one namespace may ask of the reader, counted as the
/// sum over prims with arcs of the longest chain from each, squared (about a
/// third of the chains' cubes): 110 chains of 90 inheriting classes, each
/// within every other bound, took the reader 7.5–10 s (2.7·10⁷); this bound
/// stands at about 4 s.
pub const MAX_ARC_WORK: u64 = 10_000_000;

/// Per prim path, the prims its arcs target and where each arc is written (`L`).
pub(crate) type Arcs<L> = HashMap<String, Vec<(String, L)>>;

/// `target` (a path literal's text, without its property part) as an
/// absolute prim path, from the prim at `at`.
pub(super) fn absolute(target: &str, at: &str) -> String {
    let target = target.split('.').next().unwrap_or_default().trim();
    if target.starts_with('/') {
        return target.trim_end_matches('/').to_owned();
    }
    let mut parts: Vec<&str> = at.split('/').filter(|p| !p.is_empty()).collect();
    for part in target.split('/').filter(|p| !p.is_empty()) {
        match part {
            ".." => {
                parts.pop();
            }
            "." => {}
            p => parts.push(p),
        }
    }
    format!("/{}", parts.join("/"))
}

/// Whether `a` is `b` or one of its ancestors.
fn contains(a: &str, b: &str) -> bool {
    a == b || (b.starts_with(a) && (a == "/" || b[a.len()..].starts_with('/')))
}

/// The prim paths of an arc's value (`tokens` start after its `=`): one path,
/// or a list of them; a path right after an asset path (`@a.usda@</P>`)
/// names a prim of another layer and is left out.
pub(super) fn arc_targets<'a>(tokens: &[(usize, Token<'a>)]) -> Vec<&'a str> {
    let internal = |i: usize| i == 0 || !matches!(tokens.get(i - 1), Some((_, Token::Asset(_))));
    match tokens.first() {
        Some((_, Token::Path(p))) => vec![*p],
        Some((_, Token::Open(b'['))) => tokens
            .iter()
            .enumerate()
            .skip(1)
            .take_while(|(_, (_, t))| !matches!(t, Token::Close(_) | Token::Open(_)))
            .filter_map(|(i, (_, t))| match t {
                Token::Path(p) if internal(i) => Some(*p),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// No arc targets its own prim, an ancestor or a descendant, the arcs form
/// no cycle, and no chain of them passes more than [`MAX_ARC_CHAIN`] prims.
/// A refusal is `fail(where the arc is written, what is wrong)`. Returns the
/// most arcs one chain passes (0 without arcs).
pub(super) fn check_arcs<L>(arcs: &Arcs<L>, fail: impl Fn(&L, String) -> Error) -> Result<usize> {
    let mut froms: Vec<&String> = arcs.keys().collect();
    froms.sort();
    for from in &froms {
        for (to, at) in &arcs[*from] {
            if contains(to, from) || contains(from, to) {
                let what = if to == *from { "itself" } else { "its own namespace" };
                return Err(fail(at, format!("prim {from} has a composition arc to {to}, {what}")));
            }
        }
    }
    // Depth-first search for a cycle; a prim also composes what arcs of its
    // ancestors bring, so an arc into a prim that (or whose descendant) leads
    // back counts.
    let mut state: HashMap<&str, u8> = HashMap::new();
    // Per finished prim, the most prims a chain of arcs from it passes.
    let mut longest: HashMap<&str, usize> = HashMap::new();
    // Per finished prim, the paths of arcs from it (itself counts one).
    let mut paths: HashMap<&str, usize> = HashMap::new();
    // The chains' work so far (see MAX_ARC_WORK).
    let mut work = 0u64;
    // The arcs leaving `node`: its own and its descendants' (found once per
    // node visited).
    let out_of = |node: &str| -> Vec<&(String, L)> {
        arcs.iter().filter(|(from, _)| contains(node, from)).flat_map(|(_, t)| t.iter()).collect()
    };
    for start in froms {
        if state.get(start.as_str()).copied().unwrap_or(0) != 0 {
            continue;
        }
        state.insert(start, 1);
        let mut stack = vec![(start.as_str(), out_of(start), 0usize)];
        while let Some((node, out, next)) = stack.last_mut() {
            let Some(arc) = out.get(*next).copied() else {
                // Every arc out of `node` is finished (no cycle): the longest
                // chain of arcs from it is one more than its targets' longest.
                let step = |arc: &&(String, L)| longest.get(arc.0.as_str()).copied().unwrap_or(0);
                let chain = 1 + out.iter().map(step).max().unwrap_or(0);
                if chain > MAX_ARC_CHAIN {
                    // Named at the arc the longest chain leaves by.
                    if let Some((_, at)) = out.iter().copied().max_by_key(|arc| step(arc)) {
                        return Err(fail(
                            at,
                            format!(
                                "the composition arcs from {node} chain through more than {MAX_ARC_CHAIN} prims \
                                 (the reader's time grows with the cube of the chain)"
                            ),
                        ));
                    }
                }
                let reached =
                    out.iter().fold(1usize, |n, arc| n.saturating_add(paths.get(arc.0.as_str()).copied().unwrap_or(1)));
                if reached > MAX_ARC_PATHS {
                    if let Some((_, at)) = out.first().copied() {
                        return Err(fail(
                            at,
                            format!(
                                "the composition arcs from {node} reach other prims along more than {MAX_ARC_PATHS} \
                                 paths (the reader composes a prim once along each)"
                            ),
                        ));
                    }
                }
                work = work.saturating_add((chain as u64).pow(2));
                if work > MAX_ARC_WORK {
                    if let Some((_, at)) = out.first().copied() {
                        return Err(fail(
                            at,
                            format!(
                                "the composition arcs chain too long all together: the sum over prims of their \
                                 longest chain squared passes {MAX_ARC_WORK} (the reader's time grows with the cube \
                                 of each chain)"
                            ),
                        ));
                    }
                }
                paths.insert(node, reached);
                longest.insert(node, chain);
                state.insert(node, 2);
                stack.pop();
                continue;
            };
            *next += 1;
            let (to, at) = (&arc.0, &arc.1);
            match state.get(to.as_str()).copied().unwrap_or(0) {
                1 => return Err(fail(at, format!("the composition arcs from {start} come back to {to}: a cycle"))),
                0 => {
                    state.insert(to, 1);
                    stack.push((to, out_of(to), 0));
                }
                _ => {}
            }
        }
    }
    Ok(longest.values().copied().max().map_or(0, |chain| chain - 1))
}
