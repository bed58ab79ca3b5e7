//! Simulation level of detail: which key hairs are simulated when only some
//! are, and whom the others follow.
//!
//! The key hairs are put in a spatially progressive order once, from their
//! roots at rest: level L of a grid of cubes 2^L times finer than the roots'
//! bounding box gives every cube that holds a root and no hair ordered before
//! it one representative (the lowest-numbered hair in it), appended to the
//! order. So the first n hairs of the order are spread over the scalp at
//! every n. With the first n simulated, every other hair follows its *guide*:
//! the simulated hair whose rest shape is nearest its own, by the distance
//! between the strands' centroids at rest, so that a neighbour on the far side
//! of a parting (near at the root, growing the other way) is not taken
//! (`LodOrder::guides`).
//!
//! A follower takes its own rest segments turned as its guide's segments are
//! turned (the guide's frame, carried down the guide from the head's), each
//! point placed at its segment's rest length from the one before and out of
//! the bodies (`glsl/sim/follow.comp` gives the rule): it bends and swings as
//! its neighbour does and keeps its own shape and lengths. Roots stay pinned to
//! the head as simulated roots are. Its deviation from that rule when it stops being
//! simulated fades by [`FOLLOW_FADE`] per step (so nothing pops when the level
//! drops), and a hair that rejoins the simulation starts from where it was
//! drawn, with the velocity it moved at.

use glam::Vec3;

use super::state::SimState;
use crate::error::{Error, Result};

/// The share of a follower's deviation from its guide's shape kept per step:
/// 0.85 halves it in about 4 steps and leaves 5 % after 18 (0.3 s at 60 Hz).
pub const FOLLOW_FADE: f32 = 0.85;

/// Levels of the grid before the rest of the hairs (roots closer than
/// 2⁻²⁴ of the box) are appended in index order.
const MAX_LEVELS: u32 = 24;

/// The order of the key hairs (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct LodOrder {
    /// Key hairs in simulation order.
    pub order: Vec<u32>,
    /// Each key hair's position in `order`.
    pub rank: Vec<u32>,
    /// Each key hair's centroid at rest (head frame).
    centroids: Vec<Vec3>,
}

impl LodOrder {
    /// The order of `state`'s key hairs, from their roots at rest.
    pub(crate) fn new(state: &SimState) -> Self {
        let strands = state.strands;
        let roots: Vec<Vec3> = (0..strands).map(|s| state.rest[s * state.points].truncate()).collect();
        let (lo, hi) =
            roots.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), r| (lo.min(*r), hi.max(*r)));
        let size = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let mut order: Vec<u32> = Vec::with_capacity(strands);
        let mut placed = vec![false; strands];
        if strands > 0 {
            order.push(0);
            placed[0] = true;
        }
        for level in 1..=MAX_LEVELS {
            if order.len() == strands {
                break;
            }
            let cells = f64::from(1u32 << level);
            let cube = |r: Vec3| {
                let g = (r - lo) / size;
                let clamp = |x: f32| ((f64::from(x) * cells).max(0.0) as u64).min(cells as u64 - 1);
                (clamp(g.x), clamp(g.y), clamp(g.z))
            };
            let mut representative = std::collections::HashMap::new();
            for &s in &order {
                representative.entry(cube(roots[s as usize])).or_insert(s);
            }
            for s in 0..strands {
                if !placed[s] {
                    let key = cube(roots[s]);
                    if let std::collections::hash_map::Entry::Vacant(e) = representative.entry(key) {
                        e.insert(s as u32);
                        placed[s] = true;
                        order.push(s as u32);
                    }
                }
            }
        }
        order.extend((0..strands as u32).filter(|&s| !placed[s as usize]));
        let mut rank = vec![0u32; strands];
        for (k, &s) in order.iter().enumerate() {
            rank[s as usize] = k as u32;
        }
        let centroids = (0..strands)
            .map(|s| {
                let points = &state.rest[s * state.points..(s + 1) * state.points];
                points.iter().map(|p| p.truncate()).sum::<Vec3>() / state.points as f32
            })
            .collect();
        LodOrder { order, rank, centroids }
    }

    /// Each key hair's guide when the first `simulated` of the order are
    /// simulated: itself for those, else the simulated hair whose centroid at
    /// rest is nearest its own (the lowest-numbered of equals).
    pub(crate) fn guides(&self, simulated: usize) -> Vec<u32> {
        let simulated = simulated.clamp(1, self.order.len().max(1));
        let strands = self.order.len();
        if simulated >= strands {
            return (0..strands as u32).collect();
        }
        let grid = PointGrid::new(&self.centroids, &self.order[..simulated]);
        (0..strands as u32)
            .map(|s| {
                if (self.rank[s as usize] as usize) < simulated {
                    s
                } else {
                    grid.nearest(self.centroids[s as usize])
                }
            })
            .collect()
    }
}

/// Points in a uniform grid of about one per cell, for nearest-point queries.
struct PointGrid<'a> {
    points: &'a [Vec3],
    lo: Vec3,
    cell: f32,
    dims: [i64; 3],
    /// Hairs by cell (x fastest), each cell's hairs in increasing number.
    cells: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl<'a> PointGrid<'a> {
    fn new(points: &'a [Vec3], members: &[u32]) -> Self {
        let (lo, hi) = members.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &s| {
            (lo.min(points[s as usize]), hi.max(points[s as usize]))
        });
        let extent = (hi - lo).max(Vec3::splat(1e-6));
        // About one member per cell for points on a surface (roots on a scalp,
        // strands' centroids around a head): √n cells along the longest side.
        let along = (members.len() as f32).sqrt().ceil().clamp(1.0, 1024.0);
        let cell = extent.max_element() / along;
        let dims = [0, 1, 2].map(|a| (extent[a] / cell).floor() as i64 + 1);
        let mut grid = PointGrid { points, lo, cell, dims, cells: std::collections::HashMap::new() };
        let mut sorted = members.to_vec();
        sorted.sort_unstable();
        for s in sorted {
            let key = grid.key(points[s as usize]);
            grid.cells.entry(key).or_default().push(s);
        }
        grid
    }

    fn key(&self, p: Vec3) -> [i64; 3] {
        [0, 1, 2].map(|a| (((p[a] - self.lo[a]) / self.cell).floor() as i64).clamp(0, self.dims[a] - 1))
    }

    /// The member nearest `p` (the lowest-numbered of equals): rings of cells
    /// around p's cell until no unvisited cell can hold a nearer one.
    fn nearest(&self, p: Vec3) -> u32 {
        let c = self.key(p);
        let mut best: Option<(f32, u32)> = None;
        let most = self.dims.iter().copied().max().unwrap_or(1);
        // The offsets of a ring along axis a that stay inside the grid.
        let span = |a: usize, ring: i64| (-ring).max(-c[a])..=ring.min(self.dims[a] - 1 - c[a]);
        for ring in 0..=most {
            for dz in span(2, ring) {
                for dy in span(1, ring) {
                    for dx in span(0, ring) {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != ring {
                            continue;
                        }
                        let Some(hairs) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                            continue;
                        };
                        for &s in hairs {
                            let d = self.points[s as usize].distance_squared(p);
                            if best.is_none_or(|(bd, bs)| d < bd || (d == bd && s < bs)) {
                                best = Some((d, s));
                            }
                        }
                    }
                }
            }
            // Every cell beyond this ring is at least `ring` cells away.
            if let Some((d, s)) = best {
                let reach = ring as f32 * self.cell;
                if d.sqrt() <= reach {
                    return s;
                }
            }
        }
        best.map_or(0, |(_, s)| s)
    }
}

/// The level of detail a simulation runs at: how many key hairs it simulates
/// (the first of [`LodOrder::order`]) and every key hair's guide.
#[derive(Debug, Clone)]
pub(crate) struct SimLod {
    pub order: LodOrder,
    /// Key hairs simulated (all of them by default).
    pub simulated: usize,
    /// Each key hair's guide at this level (itself when simulated).
    pub guides: Vec<u32>,
    /// Whether each key hair is simulated.
    active: Vec<bool>,
}

impl SimLod {
    /// Every key hair of `state` simulated.
    pub(crate) fn new(state: &SimState) -> Self {
        let order = LodOrder::new(state);
        let strands = order.order.len();
        SimLod { guides: order.guides(strands), order, simulated: strands, active: vec![true; strands] }
    }

    /// Simulates the first `count` key hairs of the order from the next step on.
    pub(crate) fn set(&mut self, count: usize) -> Result<()> {
        let strands = self.order.order.len();
        if !(1..=strands).contains(&count) {
            return Err(Error::param("simulated key hairs", count, format!("1..={strands} (the key hairs)")));
        }
        self.simulated = count;
        self.guides = self.order.guides(count);
        self.active = self.order.rank.iter().map(|&r| (r as usize) < count).collect();
        Ok(())
    }

    /// Which key hairs are simulated, when not all are.
    pub(crate) fn active(&self) -> Option<&[bool]> {
        (self.simulated < self.order.order.len()).then_some(&self.active[..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groom::Groom;
    use crate::sim::{RigidTransform, SimParams};

    fn state_of(roots: &[Vec3]) -> SimState {
        let strands: Vec<Vec<Vec3>> = roots.iter().map(|&r| vec![r, r + Vec3::new(0.0, -0.1, 0.0)]).collect();
        let groom = Groom::from_strands(&strands).expect("groom");
        SimState::from_groom(&groom, &SimParams::default(), &RigidTransform::default()).expect("state")
    }

    #[test]
    fn the_order_is_a_permutation_whose_prefixes_spread() {
        // A 20 × 20 grid of roots, 1 cm apart.
        let roots: Vec<Vec3> =
            (0..400).map(|i| Vec3::new((i % 20) as f32 * 0.01, 0.0, (i / 20) as f32 * 0.01)).collect();
        let lod = LodOrder::new(&state_of(&roots));
        let mut sorted = lod.order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..400).collect::<Vec<u32>>());
        for s in 0..400usize {
            assert_eq!(lod.order[lod.rank[s] as usize] as usize, s);
        }
        // The first 16 cover the square: every root lies within 6 cm of one of
        // them (the farthest root of a 4 × 4 tiling of 19 cm is 3.4 cm from its
        // tile's centre; the representative is a tile corner at worst).
        let first: Vec<Vec3> = lod.order[..16].iter().map(|&s| roots[s as usize]).collect();
        for r in &roots {
            let nearest = first.iter().map(|f| f.distance(*r)).fold(f32::MAX, f32::min);
            assert!(nearest < 0.06, "a root {nearest} m from the first 16");
        }
    }

    #[test]
    fn guides_are_the_nearest_simulated_hairs() {
        // Roots on a sphere's upper half, as a scalp.
        let roots: Vec<Vec3> = (0..500)
            .map(|i| {
                let (a, b) = (i as f32 * 2.399_963, (i as f32 / 500.0) * 1.4);
                Vec3::new(a.cos() * b.sin(), b.cos(), a.sin() * b.sin()) * 0.1
            })
            .collect();
        let lod = LodOrder::new(&state_of(&roots));
        for n in [1, 7, 50, 333, 499, 500] {
            let guides = lod.guides(n);
            let simulated = &lod.order[..n];
            for (s, &g) in guides.iter().enumerate() {
                assert!((lod.rank[g as usize] as usize) < n, "n {n}: hair {s} follows an unsimulated hair");
                if (lod.rank[s] as usize) < n {
                    assert_eq!(g as usize, s, "n {n}: a simulated hair follows another");
                    continue;
                }
                // The nearest centroid (root and root + 10 cm down: the root
                // 5 cm down) by brute force, the lowest-numbered of equals.
                let centroid = |h: usize| roots[h] - Vec3::new(0.0, 0.05, 0.0);
                let nearest = simulated
                    .iter()
                    .copied()
                    .min_by(|&a, &b| {
                        let da = centroid(a as usize).distance_squared(centroid(s));
                        let db = centroid(b as usize).distance_squared(centroid(s));
                        da.total_cmp(&db).then(a.cmp(&b))
                    })
                    .expect("a simulated hair");
                assert_eq!(g, nearest, "n {n}: hair {s}");
            }
        }
    }

    #[test]
    fn roots_on_a_line_are_searched_quickly() {
        // 2,000 roots along x only: the grid is one cell thick, its rings
        // clipped to it (unclipped, a query visited ~10¹² empty cells).
        let roots: Vec<Vec3> = (0..2000).map(|i| Vec3::new(i as f32 * 1e-3, 1.7, 0.0)).collect();
        let lod = LodOrder::new(&state_of(&roots));
        let started = std::time::Instant::now();
        let guides = lod.guides(10);
        assert!(started.elapsed().as_secs_f32() < 5.0, "{:?}", started.elapsed());
        for (s, &g) in guides.iter().enumerate() {
            let d = (roots[s].x - roots[g as usize].x).abs();
            let best =
                lod.order[..10].iter().map(|&k| (roots[s].x - roots[k as usize].x).abs()).fold(f32::MAX, f32::min);
            assert_eq!(d, best, "hair {s}");
        }
    }

    #[test]
    fn coincident_roots_are_ordered_too() {
        let roots = vec![Vec3::ZERO; 5];
        let lod = LodOrder::new(&state_of(&roots));
        let mut sorted = lod.order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, vec![0, 1, 2, 3, 4]);
        assert_eq!(lod.guides(1), vec![0; 5]);
    }
}
