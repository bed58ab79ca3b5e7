//! How evenly the hairs rooted over the scalp ([`super::Followers::over_scalp`])
//! cover it: the largest disk on the scalp region with no drawn root in it,
//! against the mean spacing of the roots ([`scalp_coverage`]). What the
//! tests hold and `vkhair inspect --drawn` reports.

use std::collections::HashMap;

use glam::Vec3;

use super::scalp_hair::{drawn_roots, ScalpHairParams, CM2_PER_M2};
use crate::error::{Error, Result};
use crate::sim::SimState;

/// Most probes [`scalp_coverage`] places over the scalp region.
pub const MAX_COVERAGE_PROBES: u64 = 50_000_000;

/// How the drawn roots cover the scalp region ([`scalp_coverage`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalpCoverage {
    /// Hairs drawn (the share of the scalp's hairs asked for).
    pub hairs: u32,
    /// Every hair over the scalp at full detail.
    pub full_hairs: u32,
    /// The scalp region's area, cm².
    pub area_cm2: f32,
    /// Mean spacing of the drawn roots, √(area / hairs), meters.
    pub spacing: f32,
    /// Radius of the largest disk on the scalp region with no drawn root in
    /// it, meters (probed on a grid of half the spacing over each triangle).
    pub largest_gap: f32,
}

impl ScalpCoverage {
    /// The largest root-free disk's radius over the mean spacing.
    pub fn gap_ratio(&self) -> f32 {
        self.largest_gap / self.spacing
    }
}

/// How the first `share` (0 < share ≤ 1) of the hairs rooted over the scalp
/// of `rest` by `params` — those a frame at that level of detail draws —
/// cover the scalp region. Refused: a share outside (0, 1], parameters
/// [`super::Followers::over_scalp`] refuses, a region that would need more
/// than [`MAX_COVERAGE_PROBES`] probes.
pub fn scalp_coverage(rest: &SimState, params: &ScalpHairParams, share: f32) -> Result<ScalpCoverage> {
    if !(share.is_finite() && share > 0.0 && share <= 1.0) {
        return Err(Error::param("drawn share", share, "(0, 1]"));
    }
    let scalp = drawn_roots(rest, params)?;
    let (roots, area) = (&scalp.roots, scalp.area);
    let full_hairs = roots.len() as u32;
    let drawn = ((roots.len() as f32 * share).round() as usize).clamp(1, roots.len().max(1));
    let roots = roots.get(..drawn).ok_or_else(|| Error::incompatible("scalp", "no hair is rooted over it"))?;
    let spacing = (area / drawn as f32).sqrt();
    let probes = f64::from(area) / f64::from(0.5 * spacing).powi(2);
    if probes > MAX_COVERAGE_PROBES as f64 {
        return Err(Error::param(
            "drawn share",
            share,
            format!("few enough hairs to probe their scalp in at most {MAX_COVERAGE_PROBES} points"),
        ));
    }
    Ok(ScalpCoverage {
        hairs: drawn as u32,
        full_hairs,
        area_cm2: area * CM2_PER_M2,
        spacing,
        largest_gap: largest_gap(&scalp.guide_roots, &scalp.triangles, roots, 0.5 * spacing),
    })
}

/// The radius of the largest disk on `triangles` of `guide_roots` with no
/// point of `drawn` in it, probed on a grid of `step` over each triangle.
pub(super) fn largest_gap(guide_roots: &[Vec3], triangles: &[[u32; 3]], drawn: &[Vec3], step: f32) -> f32 {
    let cell = 4.0 * step;
    let mut grid: HashMap<[i32; 3], Vec<Vec3>> = HashMap::new();
    let key = |p: Vec3| (p / cell).floor().to_array().map(|x| x as i32);
    for &r in drawn {
        grid.entry(key(r)).or_default().push(r);
    }
    // The nearest drawn root: rings of cells outward until the nearest found
    // lies within the rings searched.
    let nearest = |p: Vec3| {
        let [x, y, z] = key(p);
        let mut best = f32::MAX;
        for reach in 0i32..64 {
            for dx in -reach..=reach {
                for dy in -reach..=reach {
                    for dz in -reach..=reach {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != reach {
                            continue;
                        }
                        for r in grid.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                            best = best.min(r.distance(p));
                        }
                    }
                }
            }
            if best <= reach as f32 * cell {
                return best;
            }
        }
        best
    };
    let mut worst = 0.0f32;
    for t in triangles {
        let [a, b, c] = t.map(|i| guide_roots[i as usize]);
        let n = ((b - a).length().max((c - a).length()) / step).ceil().max(1.0) as usize;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                worst = worst.max(nearest(a + u * (b - a) + v * (c - a)));
            }
        }
    }
    worst
}
