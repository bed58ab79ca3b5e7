//! Authored strands drawn as followers of simulated guides.
//!
//! A dense groom (an artist's 20,000–150,000 strands) is simulated through a
//! few of its strands, the guides; every strand is drawn, each as a follower
//! of one guide or of the three guides whose roots make the triangle nearest
//! its root (barycentric weights of the nearest point). [`Followers::bind`]
//! stores, per follower point, its rest offset from the blend of its guides in
//! the blend of their frames:
//!
//! - follower point `i` of `n` sits at the parameter `s = i / (n − 1)` along
//!   each guide, at the smoothed guide vertex `s · (stride − 1)` (linearly
//!   between the two nearest), so a follower keeps its own length, curl and
//!   shape relative to guides that bend, twist and differ in length;
//! - a guide's frame there is the smoothed tangent and the guide's rest-plane
//!   normal made perpendicular to it (the frame the grown hairs use), turned
//!   with the head;
//! - `offset = M⁻¹ · (x − Σ wₖ pₖ)` with `M = Σ wₖ Fₖ` at rest, so at rest the
//!   drawn follower is the authored one resampled (to float precision), and in
//!   motion `x = Σ wₖ pₖ + M · offset` with the current guides. Where the
//!   blended frame is nearly singular (guides turned against each other: a
//!   determinant below 0.5, or an offset magnified more than 1.5×), the
//!   follower takes its heaviest guide alone;
//! - the root's offset is kept in the head's frame instead, so that a root
//!   stays where it grows on the scalp however its guides bend.
//!
//! A guide's own strand is its follower with weight 1. Followers are stored
//! in a stable pseudo-random order, so that level of detail drops them evenly
//! over the scalp by drawing a prefix; [`Followers::input_order`] maps drawn
//! hairs back to the file's strand order.
//!
//! GPU memory: 12 bytes per follower point (three f32 offsets) plus 64 bytes
//! per follower (three guide indices and weights; its colours and width
//! factors, [`Followers::with_colors`], [`Followers::with_width_factors`]) —
//! [`Followers::gpu_bytes`].

use glam::{Mat3, Quat, Vec3, Vec4};

use super::strand_frames::{key_frame, rest_plane_normals, smooth_strand};
use crate::error::{Error, Result};
use crate::gpu_types::FollowerBinding;
use crate::groom::binding::TriangleGrid;
use crate::groom::mesh::TriMesh;
use crate::groom::Groom;
use crate::hash::hash_u32;
use crate::sim::SimState;

/// Largest factor of the material's width a follower may be drawn at.
pub const MAX_WIDTH_FACTOR: f32 = 10.0;
/// Most points per follower (the GPU draws a follower as one hair of this many).
pub const MAX_FOLLOWER_POINTS: usize = 256;
/// A blended frame whose determinant is below this is taken as singular.
const SINGULAR: f32 = 0.5;
/// A blended frame that makes an offset longer than this many times the
/// distance it stands for is taken as singular.
const MAGNIFIED: f32 = 1.5;

/// Dense-groom strands bound to simulated guides (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Followers {
    points: u32,
    level: u32,
    bindings: Vec<FollowerBinding>,
    offsets: Vec<f32>,
    order: Vec<u32>,
    root_spacing: f32,
    /// Per follower (drawing order), its own albedo at the root and the tip.
    colors: Option<Vec<[Vec3; 2]>>,
    /// Per follower (drawing order), its width at the root and the tip as a
    /// factor of the material's.
    widths: Option<Vec<[f32; 2]>>,
}

/// The blend of guides `g` with weights `w` at parameter `s`: position and
/// frame (`root`, the head's rotation, at the root).
fn blend(
    guides: &[Vec<(Vec3, Vec3)>],
    references: &[Vec3],
    (g, w): ([u32; 3], [f32; 3]),
    s: f32,
    root: Mat3,
) -> (Vec3, Mat3) {
    let mut p = Vec3::ZERO;
    let mut m = Mat3::ZERO;
    for k in 0..3 {
        if w[k] == 0.0 {
            continue;
        }
        let guide = &guides[g[k] as usize];
        let u = s * (guide.len() - 1) as f32;
        let k0 = (u.floor() as usize).min(guide.len().saturating_sub(2));
        let a = u - k0 as f32;
        let k1 = (k0 + 1).min(guide.len() - 1);
        let pos = guide[k0].0.lerp(guide[k1].0, a);
        let t = guide[k0].1.lerp(guide[k1].1, a).normalize_or(guide[k0].1);
        let (b1, b2) = key_frame(t, references[g[k] as usize]);
        p += w[k] * pos;
        m += Mat3::from_cols(b1, b2, t) * w[k];
    }
    (p, if s == 0.0 { root } else { m })
}

impl Followers {
    /// Binds every strand of `authored` (head frame, the frame of `rest`) to
    /// the guides `guides` (indices into `authored`; `rest` holds them as the
    /// simulation does, in this order), each drawn with `points` points (its
    /// own when it has that many, else resampled by arc length), against the
    /// guides smoothed at `level` (the renderer's).
    pub fn bind(authored: &Groom, guides: &[usize], rest: &SimState, level: u32, points: usize) -> Result<Self> {
        if guides.len() != rest.strands {
            return Err(Error::incompatible(
                "guides",
                format!("{} guide indices for a simulation of {} key hairs", guides.len(), rest.strands),
            ));
        }
        if !(2..=MAX_FOLLOWER_POINTS).contains(&points) {
            return Err(Error::param("follower points", points, format!("2..={MAX_FOLLOWER_POINTS}")));
        }
        if level == 0 {
            return Err(Error::param("smoothing level", level, "at least 1"));
        }
        let strands = authored.strand_count();
        let mut guide_of = vec![u32::MAX; strands];
        for (g, &s) in guides.iter().enumerate() {
            if s >= strands || guide_of[s] != u32::MAX {
                return Err(Error::param("guides", s, format!("distinct strand indices below {strands}")));
            }
            guide_of[s] = g as u32;
        }
        let shapes = GuideShapes::of(rest, level);
        let roots = rest.rest_roots();
        let triangles = super::scalp::root_triangles(rest);
        let mesh = (!triangles.is_empty()).then(|| TriMesh::new(roots.clone(), triangles.clone())).transpose()?;
        let spacing = median_edge(&roots, &triangles).max(1e-6);
        let grid = mesh.as_ref().map(|m| TriangleGrid::new(m, 2.0 * spacing)).transpose()?;
        // A strand of `points` points keeps its own; others are resampled by
        // arc length.
        let uneven = (0..strands).any(|s| authored.strand_len(s) != points);
        let resampled = uneven.then(|| authored.resampled(points)).transpose()?;
        let mut order: Vec<u32> = (0..strands as u32).collect();
        order.sort_by_key(|&s| (hash_u32(s ^ 0x6a09_e667), s));
        let mut bindings = Vec::with_capacity(strands);
        let mut offsets = Vec::with_capacity(strands * points * 3);
        for &s in &order {
            let strand = match &resampled {
                Some(r) if authored.strand_len(s as usize) != points => r.strand(s as usize),
                _ => authored.strand(s as usize),
            };
            let root = authored.strand(s as usize)[0];
            let gw = match guide_of[s as usize] {
                u32::MAX => nearest_guides(root, &roots, grid.as_ref(), &triangles),
                g => ([g, g, g], [1.0, 0.0, 0.0]),
            };
            let ((g, w), point_offsets) = shapes.bind_strand(strand, gw);
            offsets.extend(point_offsets.iter().flat_map(|o| o.to_array()));
            bindings.push(FollowerBinding { guides: [g[0], g[1], g[2], 0], weights: [w[0], w[1], w[2], 0.0] });
        }
        let area: f32 = triangles.iter().map(|t| super::scalp::triangle_area(&roots, t)).sum();
        // The scalp's area: the guide-root triangles', else the roots' bounds.
        let area = if area > 0.0 { area } else { bounds_area(authored) };
        let root_spacing = (area / strands as f32).sqrt().max(1e-6);
        Ok(Followers::from_parts(points, level, (bindings, offsets), order, root_spacing))
    }

    /// Followers of `points` points bound at smoothing `level`: per follower
    /// (drawing order) its guides and weights and its points' offsets, the
    /// strand index each stands for, and the mean spacing of their roots (m).
    pub(super) fn from_parts(
        points: usize,
        level: u32,
        (bindings, offsets): (Vec<FollowerBinding>, Vec<f32>),
        order: Vec<u32>,
        root_spacing: f32,
    ) -> Followers {
        Followers { points: points as u32, level, bindings, offsets, order, root_spacing, colors: None, widths: None }
    }

    /// The same followers drawn in their own colours: per strand of the groom
    /// (the file's order) its linear RGB albedo at the root and at the tip
    /// (each component 0..=1), blended along the strand instead of the
    /// material's root and tip colours.
    pub fn with_colors(mut self, colors: &[[Vec3; 2]]) -> Result<Self> {
        let fits =
            |c: &[Vec3; 2]| c.iter().all(|c| c.is_finite() && c.cmpge(Vec3::ZERO).all() && c.cmple(Vec3::ONE).all());
        self.colors =
            Some(self.in_drawing_order(("follower colours", "colour"), colors, fits, "components in 0..=1")?);
        Ok(self)
    }

    /// The same followers drawn at their own widths: per strand of the groom
    /// (the file's order) its width at the root and at the tip as a factor of
    /// the material's root and tip widths (0..=[`MAX_WIDTH_FACTOR`]; 1 draws
    /// the material's), blended along the strand.
    pub fn with_width_factors(mut self, factors: &[[f32; 2]]) -> Result<Self> {
        let fits = |f: &[f32; 2]| f.iter().all(|f| (0.0..=MAX_WIDTH_FACTOR).contains(f));
        let allowed = format!("0..={MAX_WIDTH_FACTOR}");
        self.widths = Some(self.in_drawing_order(("follower width factors", "factor"), factors, fits, &allowed)?);
        Ok(self)
    }

    /// `values` (a root and a tip value per strand, the file's order) in
    /// drawing order, refused unless one per strand and each `fits`; errors
    /// name `what` (and `noun`, one of them) and what is `allowed`.
    fn in_drawing_order<T: Copy + std::fmt::Debug>(
        &self,
        (what, noun): (&'static str, &str),
        values: &[[T; 2]],
        fits: impl Fn(&[T; 2]) -> bool,
        allowed: &str,
    ) -> Result<Vec<[T; 2]>> {
        if values.len() != self.count() {
            return Err(Error::param(
                what,
                values.len(),
                format!("one root and tip {noun} per strand ({})", self.count()),
            ));
        }
        if let Some(s) = values.iter().position(|v| !fits(v)) {
            return Err(Error::param(what, format!("strand {s}: {:?}", values[s]), allowed));
        }
        Ok(self.order.iter().map(|&s| values[s as usize]).collect())
    }

    /// Each follower's width factors at the root and the tip, in drawing order.
    pub fn width_factors(&self) -> Option<&[[f32; 2]]> {
        self.widths.as_deref()
    }

    /// Each follower's own albedo at the root and the tip, in drawing order.
    pub fn colors(&self) -> Option<&[[Vec3; 2]]> {
        self.colors.as_deref()
    }

    /// Followers (every strand of the groom bound).
    pub fn count(&self) -> usize {
        self.bindings.len()
    }

    /// Points per follower.
    pub fn points(&self) -> usize {
        self.points as usize
    }

    /// The smoothing level the offsets were computed against.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// Mean spacing of the followers' roots, meters.
    pub fn root_spacing(&self) -> f32 {
        self.root_spacing
    }

    /// GPU bytes the binding takes: offsets, per-follower guides and weights,
    /// and per follower its colours and width factors (32 bytes).
    pub fn gpu_bytes(&self) -> u64 {
        (self.offsets.len() * 4 + self.bindings.len() * (std::mem::size_of::<FollowerBinding>() + 32)) as u64
    }

    pub(crate) fn gpu_bindings(&self) -> &[FollowerBinding] {
        &self.bindings
    }

    pub(crate) fn gpu_offsets(&self) -> &[f32] {
        &self.offsets
    }

    /// The guides strand `strand` (in the file's order) follows and their
    /// weights (one guide: the others weigh 0).
    pub fn guides_of(&self, strand: usize) -> Option<[(u32, f32); 3]> {
        let slot = self.order.iter().position(|&s| s as usize == strand)?;
        let b = &self.bindings[slot];
        Some([0, 1, 2].map(|k| (b.guides[k], b.weights[k])))
    }

    /// The file's strand index of each drawn hair (hairs are drawn in this order).
    pub fn input_order(&self) -> &[u32] {
        &self.order
    }

    /// The first `drawn` followers (in drawing order) evaluated on the CPU, as
    /// the interpolation stage evaluates them on the GPU: `guides` smoothed
    /// (position, tangent) per guide at any level, `references` the guides'
    /// rest-plane normals ([`rest_plane_normals`]) and the
    /// head's rotation `head`. Points follower after follower.
    /// Refused: fewer guides or references than the binding names, a guide of
    /// fewer than two points, more followers than bound.
    pub fn evaluate(
        &self,
        guides: &[Vec<(Vec3, Vec3)>],
        references: &[Vec3],
        head: Quat,
        drawn: usize,
    ) -> Result<Vec<Vec3>> {
        let most = self.bindings.iter().flat_map(|b| &b.guides[..3]).copied().max().unwrap_or(0) as usize;
        if guides.len() <= most || references.len() <= most {
            return Err(Error::incompatible(
                "guides",
                format!("{} guides and {} references for followers of guide {most}", guides.len(), references.len()),
            ));
        }
        if let Some(g) = guides.iter().position(|g| g.len() < 2) {
            return Err(Error::param("guide points", format!("guide {g}: {}", guides[g].len()), "at least 2"));
        }
        if drawn > self.count() {
            return Err(Error::param("drawn followers", drawn, format!("at most {}", self.count())));
        }
        let turned: Vec<Vec3> = references.iter().map(|r| head * *r).collect();
        let root = Mat3::from_quat(head);
        let n = self.points as usize;
        let mut out = Vec::with_capacity(drawn * n);
        for (f, b) in self.bindings.iter().take(drawn).enumerate() {
            let g = [b.guides[0], b.guides[1], b.guides[2]];
            let w = [b.weights[0], b.weights[1], b.weights[2]];
            for i in 0..n {
                let (p, m) = blend(guides, &turned, (g, w), i as f32 / (n - 1) as f32, root);
                let o = &self.offsets[(f * n + i) * 3..(f * n + i) * 3 + 3];
                out.push(p + m * Vec3::new(o[0], o[1], o[2]));
            }
        }
        Ok(out)
    }

    /// Drawn hair positions (`drawn × points`, drawing order, as the renderer
    /// reads them back) as strands in the file's order; strands not drawn are
    /// left out.
    /// Refused: a count of vertices that is not whole followers or more than
    /// all of them.
    pub fn to_input_order(&self, hairs: &[Vec4]) -> Result<Vec<(u32, Vec<Vec3>)>> {
        let n = self.points as usize;
        if !hairs.len().is_multiple_of(n) || hairs.len() > self.count() * n {
            return Err(Error::param(
                "drawn hair vertices",
                hairs.len(),
                format!("whole followers of {n} points, at most {}", self.count()),
            ));
        }
        let mut strands: Vec<(u32, Vec<Vec3>)> = hairs
            .chunks_exact(n)
            .zip(&self.order)
            .map(|(h, &s)| (s, h.iter().map(|p| p.truncate()).collect()))
            .collect();
        strands.sort_by_key(|(s, _)| *s);
        Ok(strands)
    }
}

/// The guides at rest, smoothed as the renderer smooths them, and their
/// rest-plane normals: what a strand is bound against.
pub(super) struct GuideShapes {
    smoothed: Vec<Vec<(Vec3, Vec3)>>,
    references: Vec<Vec3>,
}

impl GuideShapes {
    /// The guides of `rest` smoothed at `level`.
    pub(super) fn of(rest: &SimState, level: u32) -> Self {
        let smoothed = (0..rest.strands)
            .map(|g| {
                let keys: Vec<Vec3> =
                    rest.rest[g * rest.points..(g + 1) * rest.points].iter().map(|p| p.truncate()).collect();
                smooth_strand(&keys, level)
            })
            .collect();
        GuideShapes { smoothed, references: rest_plane_normals(rest) }
    }

    /// The blend of guides `g` with weights `w` at parameter `s` along them,
    /// at rest: its position (as [`blend`] places it).
    pub(super) fn position_at(&self, (g, w): ([u32; 3], [f32; 3]), s: f32) -> Vec3 {
        let mut p = Vec3::ZERO;
        for k in 0..3 {
            if w[k] == 0.0 {
                continue;
            }
            let guide = &self.smoothed[g[k] as usize];
            let u = s * (guide.len() - 1) as f32;
            let k0 = (u.floor() as usize).min(guide.len().saturating_sub(2));
            let k1 = (k0 + 1).min(guide.len() - 1);
            p += w[k] * guide[k0].0.lerp(guide[k1].0, u - k0 as f32);
        }
        p
    }

    /// `strand` (point `i` of `n` at parameter `i / (n − 1)`) bound to guides
    /// `g` with weights `w`: the guides and weights it keeps and each point's
    /// offset in their blend. Where the blend is nearly singular anywhere
    /// along the strand (its inverse would magnify the offset, and motion with
    /// it), the heaviest guide alone (one guide's frame is a rotation).
    pub(super) fn bind_strand(
        &self,
        strand: &[Vec3],
        (g, w): ([u32; 3], [f32; 3]),
    ) -> (([u32; 3], [f32; 3]), Vec<Vec3>) {
        let n = strand.len().max(2);
        let offsets_in = |(g, w), strict: bool| -> Option<Vec<Vec3>> {
            strand
                .iter()
                .enumerate()
                .map(|(i, &x)| {
                    let s = i as f32 / (n - 1) as f32;
                    let (p, m) = blend(&self.smoothed, &self.references, (g, w), s, Mat3::IDENTITY);
                    let (d, o) = (x - p, m.inverse() * (x - p));
                    let singular = m.determinant().abs() < SINGULAR || o.length() > MAGNIFIED * d.length() + 1e-6;
                    (!(strict && singular)).then_some(o)
                })
                .collect()
        };
        if let Some(o) = offsets_in((g, w), true) {
            return ((g, w), o);
        }
        let k = (0..3).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
        let alone = ([g[k]; 3], [1.0, 0.0, 0.0]);
        (alone, offsets_in(alone, false).unwrap_or_default())
    }
}

/// Rejects `followers` for a renderer of `strands` key hairs smoothed at `level`.
pub(super) fn check(followers: &Followers, strands: usize, level: u32) -> Result<()> {
    if followers.level != level {
        return Err(Error::incompatible(
            "followers",
            format!("bound at smoothing level {}, the renderer draws at {level}", followers.level),
        ));
    }
    let most = followers.bindings.iter().flat_map(|b| &b.guides[..3]).copied().max().unwrap_or(0);
    if most as usize >= strands {
        return Err(Error::incompatible(
            "followers",
            format!("bound to guide {most}, the simulation has {strands} key hairs"),
        ));
    }
    Ok(())
}

/// The largest face of the box around `groom`'s roots (0 for one root).
fn bounds_area(groom: &Groom) -> f32 {
    let roots = (0..groom.strand_count()).map(|s| groom.strand(s)[0]);
    let (lo, hi) = roots.fold((Vec3::MAX, Vec3::MIN), |(lo, hi), r| (lo.min(r), hi.max(r)));
    let d = (hi - lo).max(Vec3::ZERO);
    (d.x * d.y).max(d.y * d.z).max(d.z * d.x)
}

/// The median edge of `triangles` of `roots` (0 without triangles).
fn median_edge(roots: &[Vec3], triangles: &[[u32; 3]]) -> f32 {
    let mut edges: Vec<f32> = triangles
        .iter()
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| roots[i as usize]);
            [(a - b).length(), (b - c).length(), (c - a).length()]
        })
        .collect();
    edges.sort_by(f32::total_cmp);
    edges.get(edges.len() / 2).copied().unwrap_or(0.0)
}

/// The guides of the nearest point of the guide-root triangles within the
/// grid's radius, else the nearest guide root alone.
fn nearest_guides(
    root: Vec3,
    roots: &[Vec3],
    grid: Option<&TriangleGrid<'_>>,
    triangles: &[[u32; 3]],
) -> ([u32; 3], [f32; 3]) {
    if let Some(n) = grid.and_then(|g| g.nearest(root)) {
        return (triangles[n.binding.triangle as usize], n.binding.weights);
    }
    let g = (0..roots.len())
        .min_by(|&a, &b| roots[a].distance_squared(root).total_cmp(&roots[b].distance_squared(root)))
        .unwrap_or(0) as u32;
    ([g; 3], [1.0, 0.0, 0.0])
}
