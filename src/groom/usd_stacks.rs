//! The layer stacks of a USD stage (a layer and its sublayers, whose prims
//! share one namespace) and what [`super::usd_layers::check_layers`] judges
//! over them once every layer is read: the arcs between their prims
//! together, how deep a prim's composition may nest, and whether the prim an
//! arc takes can be there at all.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use super::usda_arcs::Arcs;
use super::usda_check::Takes;
use crate::error::{Error, FileFormat, Result};

/// Most arcs a prim's composition may nest, bounded from the stage's layers:
/// (the most references and payloads one chain of layers passes + 1) × (the
/// most arcs one chain between prims of a layer stack passes + 1). The USD
/// library abandons a prim whose composition nests more than 100 arcs and
/// builds it empty, without a word (a chain of 99 referencing layers lost
/// the hair at its end).
pub const MAX_USD_COMPOSITION_DEPTH: usize = 96;

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// Per layer, a value computed from the layers it names: `None` while its
/// own is being computed.
type Memo<'a> = HashMap<&'a PathBuf, Option<usize>>;

/// `layer`'s value in `memo`, computed once by `compute` (which recurses
/// through the memo); a layer met again while its own value is being
/// computed (a cycle of layers) counts 0.
fn memoized<'a>(layer: &'a PathBuf, memo: &mut Memo<'a>, compute: impl FnOnce(&mut Memo<'a>) -> usize) -> usize {
    match memo.get(layer) {
        Some(Some(n)) => return *n,
        Some(None) => return 0,
        None => {}
    }
    memo.insert(layer, None);
    let n = compute(memo);
    memo.insert(layer, Some(n));
    n
}

/// The layers one layer names: its sublayers, and what its references and
/// payloads take (each a layer stack of its own).
#[derive(Default)]
pub(super) struct Links {
    sublayers: Vec<PathBuf>,
    references: Vec<PathBuf>,
}

impl Links {
    /// Layer `named`, taken as `takes`; a reference's layer starts a stack.
    pub(super) fn add(&mut self, stacks: &mut Stacks, named: &Path, takes: &Takes, by: Written) {
        let key = canonical(named);
        match takes {
            Takes::Layer => self.sublayers.push(key),
            _ => {
                stacks.roots.insert(key.clone());
                if let Takes::Prim(prim) = takes {
                    if prim.starts_with('/') {
                        stacks.wanted.push((key.clone(), prim.clone(), by));
                    }
                }
                self.references.push(key);
            }
        }
    }
}

/// A path as the layers are keyed by: canonical where it exists.
pub(super) fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Where an arc between prims is written: its layer and "line L, column C:".
pub(super) type Written = (PathBuf, String);

/// The text layers of a stage as layer stacks (see [`check_layers`]).
#[derive(Default)]
pub(super) struct Stacks {
    /// Per layer: its arcs between prims (a text layer's), and the layers it names.
    pub layers: HashMap<PathBuf, (Arcs<Written>, Links)>,
    /// The layers that start a layer stack.
    pub roots: HashSet<PathBuf>,
    /// The stage's root layer.
    pub stage: PathBuf,
    /// Per layer read: its prims, and those with arcs or variant sets.
    pub offers: HashMap<PathBuf, (HashSet<String>, HashSet<String>)>,
    /// The prims references and payloads take of other layers: the layer,
    /// the prim, where the arc is written.
    pub wanted: Vec<(PathBuf, String, Written)>,
    /// The prims references and payloads without an asset path take: the
    /// naming layer, the prim, where the arc is written.
    pub internal: Vec<(PathBuf, String, Written)>,
}

impl Stacks {
    /// The arcs of each layer stack, all its layers' together (with a
    /// layer's references to its own prims),
    /// checked as one layer's are (no cycle, no arc into its own namespace, no
    /// chain too long): two sublayers whose classes inherit each other
    /// overflowed the library's stack. Named at the arc, in its layer. Then
    /// the composition's depth and the arcs' targets ([`Stacks::check_targets`]).
    pub(super) fn check(&self) -> Result<()> {
        let mut roots: Vec<&PathBuf> = self.roots.iter().collect();
        roots.sort();
        // Each stack's layers, found once for every check below.
        let stacks: HashMap<&PathBuf, Vec<&PathBuf>> = roots.iter().map(|&r| (r, self.members(r))).collect();
        let mut deepest_chain = 0usize;
        for root in roots {
            let members = &stacks[root];
            let mut arcs: Arcs<&Written> = HashMap::new();
            for (from, targets) in members.iter().filter_map(|m| self.layers.get(*m)).flat_map(|(a, _)| a) {
                arcs.entry(from.clone()).or_default().extend(targets.iter().map(|(to, at)| (to.clone(), at)));
            }
            let over = match members.len() {
                1 => String::new(),
                _ => format!(" (over the sublayers of {})", root.display()),
            };
            let chain = super::usda_arcs::check_arcs(&arcs, |(layer, line), why| {
                malformed(format!("{line} {why}{over}")).in_asset(layer)
            })?;
            deepest_chain = deepest_chain.max(chain);
        }
        let layers = self.reference_depth(&self.stage, &mut HashMap::new());
        let depth = (layers + 1) * (deepest_chain + 1);
        if depth > MAX_USD_COMPOSITION_DEPTH {
            return Err(malformed(format!(
                "its composition may nest {depth} arcs deep ({layers} references or payloads in a chain of layers, \
                 and chains of up to {deepest_chain} arcs between prims): the USD library builds a prim nested more \
                 than 100 deep empty, without a word (at most {MAX_USD_COMPOSITION_DEPTH} here)"
            ))
            .in_asset(&self.stage));
        }
        let composed = self.composed_prims(&self.stage, &stacks, &mut HashMap::new());
        let most = super::usda_check::MAX_USD_PRIMS;
        if composed > most {
            return Err(malformed(format!(
                "the stage composes more than {most} prims: its references and payloads bring their layers' prims \
                 again each time (up to {composed} here; the USD reader composes about ten thousand a second)"
            ))
            .in_asset(&self.stage));
        }
        self.check_targets(&stacks)
    }

    /// At most how many prims the stack `layer` starts composes: its
    /// layers' own, and again every layer a reference or payload of theirs
    /// takes (all of its prims, whichever one it takes: a bound, not a count);
    /// a layer met again on the chain counts nothing more. `stacks`: each
    /// stack root's layers.
    fn composed_prims<'a>(
        &'a self,
        layer: &'a PathBuf,
        stacks: &HashMap<&'a PathBuf, Vec<&'a PathBuf>>,
        memo: &mut Memo<'a>,
    ) -> usize {
        memoized(layer, memo, |memo| {
            let own;
            let members = match stacks.get(layer) {
                Some(members) => members.as_slice(),
                None => {
                    own = self.members(layer);
                    own.as_slice()
                }
            };
            let mut total = 0usize;
            for &member in members {
                total = total.saturating_add(self.offers.get(member).map_or(0, |(prims, _)| prims.len()));
                for reference in self.layers.get(member).map(|(_, l)| l.references.as_slice()).unwrap_or_default() {
                    total = total.saturating_add(self.composed_prims(reference, stacks, memo));
                }
            }
            total
        })
    }

    /// The most references and payloads one chain of layers from `layer`
    /// passes (sublayers add none; a layer met again on the chain ends it).
    fn reference_depth<'a>(&'a self, layer: &'a PathBuf, memo: &mut Memo<'a>) -> usize {
        memoized(layer, memo, |memo| {
            let Some((_, links)) = self.layers.get(layer) else { return 0 };
            let steps = links.sublayers.iter().map(|l| (l, 0)).chain(links.references.iter().map(|l| (l, 1)));
            steps.map(|(l, step)| step + self.reference_depth(l, memo)).max().unwrap_or(0)
        })
    }

    /// The layers of the stack `root` starts: it and its sublayers, all the way down.
    fn members<'a>(&'a self, root: &'a PathBuf) -> Vec<&'a PathBuf> {
        let mut members = vec![root];
        let mut k = 0;
        while let Some(layer) = members.get(k).copied() {
            k += 1;
            for sub in self.layers.get(layer).map(|(_, l)| l.sublayers.as_slice()).unwrap_or_default() {
                if !members.contains(&sub) {
                    members.push(sub);
                }
            }
        }
        members
    }

    /// Whether prim `prim` can be in the stack of `members`: a layer of it
    /// declares the prim, or an ancestor with arcs or variant sets that may
    /// bring it.
    fn offers(&self, members: &[&PathBuf], prim: &str) -> bool {
        let offered = members.iter().filter_map(|m| self.offers.get(*m));
        let mut ancestors = std::iter::successors(Some(prim), |p| p.rfind('/').filter(|&i| i > 0).map(|i| &p[..i]));
        let declared = |p: &str| offered.clone().any(|(prims, _)| prims.contains(p));
        let composing = |p: &str| offered.clone().any(|(_, composing)| composing.contains(p));
        declared(prim) || ancestors.any(|a| a != prim && composing(a))
    }

    /// Every prim a reference or payload takes can be in the layer stack it
    /// names (judged over its sublayers too, and below the root prim), and
    /// every prim one without an asset path takes in some stack its layer is
    /// part of: the USD library goes without an arc to a prim that is not
    /// there in silence. Named at the arc. `stacks`: each stack root's layers
    /// (every layer an arc takes a prim of is one).
    fn check_targets(&self, stacks: &HashMap<&PathBuf, Vec<&PathBuf>>) -> Result<()> {
        let missing = |(layer, line): &Written, why: String| malformed(format!("{line} {why}")).in_asset(layer);
        for (target, prim, by) in &self.wanted {
            let members = stacks.get(target).map(Vec::as_slice).unwrap_or_default();
            if self.offers.contains_key(target) && !self.offers(members, prim) {
                let why = format!(
                    "a reference or payload takes {prim} of {}, which neither it nor its sublayers has (nor an \
                     ancestor whose arcs or variants could bring it)",
                    target.display()
                );
                return Err(missing(by, why));
            }
        }
        for (layer, prim, by) in &self.internal {
            let within = stacks.values().filter(|members| members.contains(&layer));
            if within.clone().next().is_some() && !within.clone().any(|members| self.offers(members, prim)) {
                let why = format!(
                    "a reference or payload takes {prim}, which the layer and the layers it is composed with do \
                     not have (nor an ancestor whose arcs or variants could bring it)"
                );
                return Err(missing(by, why));
            }
        }
        Ok(())
    }
}
