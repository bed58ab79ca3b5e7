//! Drawn hairs rooted over the whole scalp ([`Followers::over_scalp`]): a
//! full head from sparse guides, where growing drawn hairs around each guide
//! (single-strand interpolation) draws one clump a guide.
//!
//! 1. **Roots.** The scalp region is the guides' own root surface: the
//!    triangles between their roots (`render::scalp::root_triangles`, open
//!    regions such as the face left out). Each triangle gets its share of
//!    [`ScalpHairParams::density`] × its area (running totals rounded, so the
//!    count over the head is the density times the area), placed by a
//!    low-discrepancy sequence over the triangle (R2, Roberts 2018, started
//!    at a hash of the triangle): even, blue-noise-like, and the same on every
//!    run.
//! 2. **Shape.** Each hair blends its triangle's three guides by the
//!    barycentric weights of its root — never across a parting: a guide whose
//!    rest direction (root to tip) turns more than
//!    [`ScalpHairParams::parting_angle`] from that of the hair's nearest guide
//!    weighs nothing, the others share its weight. The hair starts at its own
//!    root and follows the blend of its guides' shapes from their roots; then
//!    the look: up to [`ScalpHairParams::length_variation`] shorter, and drawn
//!    toward its nearest guide by [`ScalpHairParams::clumping`], more toward
//!    the tip.
//! 3. **Binding.** Each hair is bound as a follower of those guides
//!    (`followers.rs`): offsets from their blend in the blend of their frames,
//!    so it keeps its place among them when they move. Hairs are drawn in a
//!    stable pseudo-random order, so level of detail drops them evenly over the
//!    scalp (a prefix is drawn) and a hair never jumps between frames or levels.

use glam::Vec3;

use super::followers::GuideShapes;
use super::scalp::triangle_area;
use super::Followers;
use crate::error::{Error, Result};
use crate::gpu_types::FollowerBinding;
use crate::hash::hash_u32;
use crate::sim::SimState;

/// Square centimetres per square metre.
pub(super) const CM2_PER_M2: f32 = 1e4;
/// Most points over all hairs [`Followers::over_scalp`] binds (2^26: 768 MiB
/// of offsets on the host), whatever `max_hairs` allows.
const MAX_SCALP_POINTS: u64 = 1 << 26;

/// How drawn hairs are rooted over the scalp and shaped from their guides
/// ([`Followers::over_scalp`]; the `[scalp]` table of a parameter file).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ScalpHairParams {
    /// Drawn hairs per square centimetre of the scalp region the guides'
    /// roots cover (0.01..=1000). Default: 150, a human scalp's order (100 to
    /// 200 per cm²).
    pub density: f32,
    /// Guides whose rest directions (root to tip) differ by more than this,
    /// degrees, do not blend: a hair between them follows those on its nearest
    /// guide's side (0..=180; 180 blends every triangle's three). Default: 60.
    pub parting_angle: f32,
    /// How far each hair is drawn toward its nearest guide, nothing at the
    /// root and this fraction at the tip (0..=1). Default: 0.
    pub clumping: f32,
    /// Each hair is shorter than its guides' blend by up to this fraction of
    /// its length, stable per hair (0..=0.9). Default: 0.1.
    pub length_variation: f32,
    /// Radius of each hair's own curl about its guides' blend, meters, reached
    /// a fifth of the way from the root (0..=0.05; 0 for straight). Default: 0.
    pub curl_radius: f32,
    /// Length of hair one turn of the curl takes, meters (1e-4..=10).
    /// Default: 0.02.
    pub curl_period: f32,
    /// How much each hair's curl radius and period differ from the set ones,
    /// as a fraction, stable per hair (0..=0.9; the phase is each hair's own
    /// always). Default: 0.3.
    pub curl_variation: f32,
    /// Most drawn hairs: a density over an area that asks for more is refused
    /// (1..=4,000,000). Default: 1,000,000.
    pub max_hairs: u32,
}

impl Default for ScalpHairParams {
    fn default() -> Self {
        ScalpHairParams {
            density: 150.0,
            parting_angle: 60.0,
            clumping: 0.0,
            length_variation: 0.1,
            curl_radius: 0.0,
            curl_period: 0.02,
            curl_variation: 0.3,
            max_hairs: 1_000_000,
        }
    }
}

/// The densities [`ScalpHairParams::density`] takes, hairs per cm²: from
/// the sparsest rooting to ten times a human scalp's.
pub const SCALP_DENSITY_RANGE: std::ops::RangeInclusive<f32> = 0.01..=1000.0;

impl ScalpHairParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        let ranges = [
            ("scalp.density", self.density, *SCALP_DENSITY_RANGE.start(), *SCALP_DENSITY_RANGE.end()),
            ("scalp.parting_angle", self.parting_angle, 0.0, 180.0),
            ("scalp.clumping", self.clumping, 0.0, 1.0),
            ("scalp.length_variation", self.length_variation, 0.0, 0.9),
            ("scalp.curl_radius", self.curl_radius, 0.0, 0.05),
            ("scalp.curl_period", self.curl_period, 1e-4, 10.0),
            ("scalp.curl_variation", self.curl_variation, 0.0, 0.9),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(Error::param(name, v, format!("{lo}..={hi}")));
            }
        }
        if !(1..=4_000_000).contains(&self.max_hairs) {
            return Err(Error::param("scalp.max_hairs", self.max_hairs, "1..=4000000"));
        }
        Ok(())
    }
}

/// The area of the scalp region the guides of `rest` cover (the triangles
/// between their roots), cm²: a density times it is the count
/// [`Followers::over_scalp`] roots (0 where the roots make no triangle).
pub fn scalp_area_cm2(rest: &SimState) -> f32 {
    let roots = rest.rest_roots();
    let area: f32 = super::scalp::root_triangles(rest).iter().map(|t| triangle_area(&roots, t)).sum();
    area * CM2_PER_M2
}

/// Drawn hairs over the scalp: a root and its guides' weights each.
struct Roots {
    /// Per hair: its root (head frame), its triangle's guides and its
    /// barycentric weights there.
    hairs: Vec<(Vec3, [u32; 3], [f32; 3])>,
    /// The scalp region's area, m².
    area: f32,
}

/// The roots of `params.density` hairs per cm² over `triangles` of `roots`.
fn scalp_roots(roots: &[Vec3], triangles: &[[u32; 3]], params: &ScalpHairParams) -> Result<Roots> {
    let area_of = |t: &[u32; 3]| triangle_area(roots, t);
    let area: f32 = triangles.iter().map(area_of).sum();
    let wanted = f64::from(area) * f64::from(CM2_PER_M2) * f64::from(params.density);
    if wanted > f64::from(params.max_hairs) {
        return Err(Error::param(
            "scalp.density",
            params.density,
            format!(
                "at most {:.1} hairs per cm² over this scalp region of {:.1} cm² (scalp.max_hairs {})",
                f64::from(params.max_hairs) / (f64::from(area) * f64::from(CM2_PER_M2)),
                area * CM2_PER_M2,
                params.max_hairs
            ),
        ));
    }
    // R2: the plastic number's reciprocals.
    let (a1, a2) = (0.754_877_7_f64, 0.569_840_3_f64);
    let unit = |x: u32| f64::from(x) / 4_294_967_296.0;
    let mut hairs = Vec::with_capacity(wanted as usize + 1);
    let mut total = 0.0f64;
    for (k, t) in triangles.iter().enumerate() {
        let before = total.round();
        total += f64::from(area_of(t)) * f64::from(CM2_PER_M2) * f64::from(params.density);
        let count = (total.round() - before) as u32;
        let (h1, h2) = (unit(hash_u32(k as u32 ^ 0x85eb_ca6b)), unit(hash_u32(k as u32 ^ 0xc2b2_ae35)));
        let [a, b, c] = t.map(|i| roots[i as usize]);
        for i in 0..count {
            let (mut u, mut v) = ((h1 + f64::from(i) * a1).fract(), (h2 + f64::from(i) * a2).fract());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let w = [(1.0 - u - v) as f32, u as f32, v as f32];
            hairs.push((w[0] * a + w[1] * b + w[2] * c, *t, w));
        }
    }
    Ok(Roots { hairs, area })
}

/// A hair's own curl ([`ScalpHairParams::curl_radius`]): a helix about its
/// guides' blend, its frame carried along the blend (parallel transport) so
/// that it turns smoothly.
struct Curl {
    /// Radius, meters.
    radius: f32,
    /// Radians of the turn per meter of hair.
    turn: f32,
    /// Phase at the root, radians.
    phase: f32,
    /// The frame's first axis at the previous point (unit, across the blend).
    across: Option<Vec3>,
    /// The blend at the previous point.
    previous: Option<Vec3>,
    /// Meters along the blend so far.
    run: f32,
}

impl Curl {
    /// The curl of hair `h` by `params` (radius and period varied per hair);
    /// none for straight hair.
    fn of(params: &ScalpHairParams, h: u32) -> Option<Curl> {
        if params.curl_radius == 0.0 {
            return None;
        }
        let unit = |salt: u32| hash_u32(h ^ salt) as f32 / u32::MAX as f32;
        let vary = |salt: u32| 1.0 + params.curl_variation * (2.0 * unit(salt) - 1.0);
        Some(Curl {
            radius: params.curl_radius * vary(0x243f_6a88),
            turn: std::f32::consts::TAU / (params.curl_period * vary(0x85a3_08d3)),
            phase: std::f32::consts::TAU * unit(0x1319_8a2e),
            across: None,
            previous: None,
            run: 0.0,
        })
    }

    /// The offset at the next point, `along` (0..=1) of the hair, where the
    /// blend is at `blend` and, a point further, at `ahead`: around the
    /// blend's direction, growing from nothing at the root to the full radius
    /// a fifth of the way along. Points are visited root to tip.
    fn next(&mut self, blend: Vec3, ahead: Vec3, along: f32) -> Vec3 {
        let previous = self.previous.replace(blend).unwrap_or(blend);
        self.run += blend.distance(previous);
        let Some(tangent) = (ahead - blend).try_normalize().or((blend - previous).try_normalize()) else {
            return Vec3::ZERO;
        };
        let previous = self.across.unwrap_or_else(|| tangent.any_orthonormal_vector());
        let across = (previous - tangent * previous.dot(tangent)).try_normalize().unwrap_or(previous);
        self.across = Some(across);
        let angle = self.phase + self.turn * self.run;
        let ramp = (5.0 * along).min(1.0);
        self.radius * ramp * (angle.cos() * across + angle.sin() * tangent.cross(across))
    }
}

/// The order hairs are drawn in: a stable pseudo-random permutation of
/// `0..count`, so a prefix (level of detail) spreads over the scalp.
fn drawing_order(count: usize) -> Vec<u32> {
    let mut order: Vec<u32> = (0..count as u32).collect();
    order.sort_by_key(|&h| (hash_u32(h ^ 0x6a09_e667), h));
    order
}

/// The hairs [`Followers::over_scalp`] roots over the scalp, as
/// [`drawn_roots`] finds them.
pub(super) struct DrawnRoots {
    /// Their roots (head frame, at rest), in drawing order: the first k are
    /// those a frame drawing k hairs draws.
    pub roots: Vec<Vec3>,
    /// The scalp region's area, m².
    pub area: f32,
    /// The guides' roots.
    pub guide_roots: Vec<Vec3>,
    /// The scalp region: triangles of guide roots.
    pub triangles: Vec<[u32; 3]>,
}

/// The hairs [`Followers::over_scalp`] roots over the scalp of `rest` by
/// `params` ([`DrawnRoots`]).
pub(super) fn drawn_roots(rest: &SimState, params: &ScalpHairParams) -> Result<DrawnRoots> {
    params.validate()?;
    let guide_roots = rest.rest_roots();
    let triangles = super::scalp::root_triangles(rest);
    let scalp = scalp_roots(&guide_roots, &triangles, params)?;
    let roots = drawing_order(scalp.hairs.len()).iter().map(|&h| scalp.hairs[h as usize].0).collect();
    Ok(DrawnRoots { roots, area: scalp.area, guide_roots, triangles })
}

/// The weights `w` of guides `g` with the guides across a parting from the
/// heaviest one (rest directions `dirs` more than `cos_parting` apart) weighing
/// nothing and the others sharing their weight.
fn without_parting(g: [u32; 3], w: [f32; 3], dirs: &[Vec3], cos_parting: f32) -> [f32; 3] {
    let near = (0..3).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
    let d = dirs[g[near] as usize];
    let kept: [f32; 3] = std::array::from_fn(|k| if dirs[g[k] as usize].dot(d) >= cos_parting { w[k] } else { 0.0 });
    let sum: f32 = kept.iter().sum();
    if sum > 0.0 {
        kept.map(|x| x / sum)
    } else {
        std::array::from_fn(|k| if k == near { 1.0 } else { 0.0 })
    }
}

impl Followers {
    /// Drawn hairs rooted over the scalp region the guides of `rest` cover,
    /// `params.density` per cm², each blended from its nearest guides and
    /// bound to them (see the module docs), drawn with `points` points
    /// against the guides smoothed at `level` (the renderer's).
    ///
    /// Refused: bad parameters (naming the field), fewer than three guides or
    /// guide roots that make no triangle, a count beyond
    /// [`ScalpHairParams::max_hairs`] or beyond 2^26 points over all hairs,
    /// `points` outside 2..=256.
    pub fn over_scalp(rest: &SimState, params: &ScalpHairParams, level: u32, points: usize) -> Result<Self> {
        params.validate()?;
        if !(2..=super::followers::MAX_FOLLOWER_POINTS).contains(&points) {
            return Err(Error::param(
                "follower points",
                points,
                format!("2..={}", super::followers::MAX_FOLLOWER_POINTS),
            ));
        }
        if level == 0 {
            return Err(Error::param("smoothing level", level, "at least 1"));
        }
        let roots = rest.rest_roots();
        let triangles = super::scalp::root_triangles(rest);
        if triangles.is_empty() {
            return Err(Error::incompatible(
                "guides",
                format!("{} guide roots make no scalp triangle to root hairs in (at least 3 needed)", roots.len()),
            ));
        }
        let most = (MAX_SCALP_POINTS / points as u64).min(u64::from(params.max_hairs)) as u32;
        let scalp = scalp_roots(&roots, &triangles, &ScalpHairParams { max_hairs: most, ..params.clone() })?;
        if scalp.hairs.is_empty() {
            return Err(Error::param(
                "scalp.density",
                params.density,
                format!("at least one hair over the scalp region of {:.3} cm²", scalp.area * CM2_PER_M2),
            ));
        }
        let shapes = GuideShapes::of(rest, level);
        let dirs: Vec<Vec3> = (0..rest.strands)
            .map(|g| {
                let strand = &rest.rest[g * rest.points..(g + 1) * rest.points];
                (strand[rest.points - 1] - strand[0]).truncate().normalize_or(Vec3::Y)
            })
            .collect();
        // At 180° every guide blends (a dot product of opposite directions may
        // round below −1).
        let cos_parting = if params.parting_angle >= 180.0 { -2.0 } else { params.parting_angle.to_radians().cos() };
        let order = drawing_order(scalp.hairs.len());
        // Each hair is bound on its own: chunks of the drawing order on every
        // core, joined in order (the result does not depend on the threads).
        let bind = |hairs: &[u32]| -> (Vec<FollowerBinding>, Vec<f32>) {
            let mut bindings = Vec::with_capacity(hairs.len());
            let mut offsets = Vec::with_capacity(hairs.len() * points * 3);
            let mut strand = vec![Vec3::ZERO; points];
            for &h in hairs {
                let (root, g, w) = scalp.hairs[h as usize];
                let w = without_parting(g, w, &dirs, cos_parting);
                let near = (0..3).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
                let alone = ([g[near]; 3], [1.0, 0.0, 0.0]);
                let seed = hash_u32(h ^ 0x1b87_3593);
                let length = 1.0 - params.length_variation * (seed as f32 / u32::MAX as f32);
                let origin = shapes.position_at((g, w), 0.0);
                let mut curl = Curl::of(params, h);
                for (i, x) in strand.iter_mut().enumerate() {
                    let along = i as f32 / (points - 1) as f32;
                    let s = length * along;
                    let blend = shapes.position_at((g, w), s);
                    let mut own = root + (blend - origin);
                    if let Some(curl) = &mut curl {
                        let ahead = shapes.position_at((g, w), (s + 1.0 / (points - 1) as f32).min(1.0));
                        own += curl.next(blend, ahead, along);
                    }
                    // Without clumping the lerp keeps `own`: the clump's
                    // position is not even looked up.
                    *x = if params.clumping == 0.0 {
                        own
                    } else {
                        own.lerp(shapes.position_at(alone, s), params.clumping * along)
                    };
                }
                let ((g, w), point_offsets) = shapes.bind_strand(&strand, (g, w));
                offsets.extend(point_offsets.iter().flat_map(|o| o.to_array()));
                bindings.push(FollowerBinding { guides: [g[0], g[1], g[2], 0], weights: [w[0], w[1], w[2], 0.0] });
            }
            (bindings, offsets)
        };
        let threads = std::thread::available_parallelism().map_or(1, |t| t.get()).clamp(1, 16);
        let chunk = order.len().div_ceil(threads).max(1);
        let parts: Vec<(Vec<FollowerBinding>, Vec<f32>)> = std::thread::scope(|scope| {
            let handles: Vec<_> = order.chunks(chunk).map(|c| scope.spawn(move || bind(c))).collect();
            handles.into_iter().map(|h| h.join()).collect::<std::result::Result<_, _>>()
        })
        .map_err(|_| Error::incompatible("scalp hairs", "a binding thread panicked"))?;
        let mut bindings = Vec::with_capacity(order.len());
        let mut offsets = Vec::with_capacity(order.len() * points * 3);
        for (b, o) in parts {
            bindings.extend(b);
            offsets.extend(o);
        }
        let spacing = (scalp.area / order.len() as f32).sqrt().max(1e-6);
        Ok(Followers::from_parts(points, level, (bindings, offsets), order, spacing))
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::groom::grow::{grow, GrowParams};
    use crate::groom::{scenes, Groom};
    use crate::render::reference::{rest_plane_normals, smooth_strand};
    use crate::sim::{RigidTransform, SimParams};

    /// The rest state of `strands` guides of 8 points grown on the thesis scalp.
    fn guides(strands: usize) -> SimState {
        let groom = grow(&scenes::thesis_scalp(), &GrowParams { strands, points_per_strand: 8, ..Default::default() })
            .expect("groom");
        SimState::from_groom(&groom, &SimParams::default(), &RigidTransform::default()).expect("rest")
    }

    /// The first point of each of the first `drawn` followers, at rest.
    fn roots_of(f: &Followers, rest: &SimState, drawn: usize) -> Vec<Vec3> {
        let smoothed: Vec<Vec<(Vec3, Vec3)>> = (0..rest.strands)
            .map(|g| {
                let keys: Vec<Vec3> = (0..rest.points).map(|i| rest.rest[g * rest.points + i].truncate()).collect();
                smooth_strand(&keys, f.level())
            })
            .collect();
        let points = f.evaluate(&smoothed, &rest_plane_normals(rest), Quat::IDENTITY, drawn).expect("evaluate");
        points.chunks(f.points()).map(|h| h[0]).collect()
    }

    /// The count is the density times the scalp's area (to one hair), the
    /// roots cover the scalp evenly (no root-free disk wider than 3 × the
    /// mean root spacing), and binding is the same on every run.
    #[test]
    fn hairs_cover_the_scalp_at_the_density_asked_for() {
        let rest = guides(300);
        let area = scalp_area_cm2(&rest);
        let params = ScalpHairParams { density: 20.0, ..ScalpHairParams::default() };
        let f = Followers::over_scalp(&rest, &params, 2, 8).expect("followers");
        let expected = area * params.density;
        println!("{} hairs over {area:.1} cm² at {} per cm² ({expected:.1} asked)", f.count(), params.density);
        assert!((f.count() as f32 - expected).abs() <= 1.0, "{} hairs for {expected}", f.count());
        let spacing = (area / CM2_PER_M2 / f.count() as f32).sqrt();
        assert!((f.root_spacing() - spacing).abs() < 1e-6 * spacing.max(1.0));
        // The roots the coverage measures are those the followers are drawn from.
        let roots = roots_of(&f, &rest, f.count());
        let scalp = drawn_roots(&rest, &params).expect("roots");
        let measured = &scalp.roots;
        assert_eq!(roots.len(), measured.len());
        for (drawn, measured) in roots.iter().zip(measured) {
            assert!(drawn.distance(*measured) < 1e-5, "a follower rooted at {drawn}, measured at {measured}");
        }
        let cov = crate::render::scalp_coverage(&rest, &params, 1.0).expect("coverage");
        assert_eq!(cov.hairs as usize, f.count());
        assert!((cov.spacing - spacing).abs() < 1e-6);
        let gap = cov.largest_gap;
        println!("largest root-free disk: radius {:.2} mm, {:.2} × the mean spacing", gap * 1e3, cov.gap_ratio());
        assert!(gap <= 3.0 * spacing, "a root-free disk of radius {gap} against a spacing of {spacing}");
        // The measure sees a hole: without the hairs of one region, the
        // largest gap grows past 3 × the spacing.
        let holed: Vec<Vec3> = measured.iter().copied().filter(|r| r.distance(measured[0]) > 8.0 * spacing).collect();
        let hole =
            super::super::scalp_coverage::largest_gap(&scalp.guide_roots, &scalp.triangles, &holed, 0.5 * spacing);
        assert!(hole > 3.0 * spacing, "a hole of radius 8 spacings measured as {hole}");
        assert_eq!(Followers::over_scalp(&rest, &params, 2, 8).expect("again"), f, "not the same on a second run");
    }

    /// Curl: each hair winds about where it would lie straight, at its own
    /// radius (the set one ± the variation), its own phase, none at the root;
    /// the roots stay where they were.
    #[test]
    fn curled_hairs_wind_about_their_straight_selves() {
        let rest = guides(300);
        let straight = ScalpHairParams { density: 5.0, ..ScalpHairParams::default() };
        let radius = 0.004;
        let curled = ScalpHairParams { curl_radius: radius, curl_period: 0.03, ..straight.clone() };
        let points = |p: &ScalpHairParams| {
            let f = Followers::over_scalp(&rest, p, 2, 24).expect("followers");
            let smoothed: Vec<Vec<(Vec3, Vec3)>> = (0..rest.strands)
                .map(|g| {
                    let keys: Vec<Vec3> = (0..rest.points).map(|i| rest.rest[g * rest.points + i].truncate()).collect();
                    smooth_strand(&keys, 2)
                })
                .collect();
            f.evaluate(&smoothed, &rest_plane_normals(&rest), Quat::IDENTITY, f.count()).expect("evaluate")
        };
        let (a, b) = (points(&straight), points(&curled));
        assert_eq!(a.len(), b.len());
        let (lo, hi) = (radius * (1.0 - curled.curl_variation), radius * (1.0 + curled.curl_variation));
        let mut directions = Vec::new();
        for (h, (x, y)) in a.chunks(24).zip(b.chunks(24)).enumerate() {
            assert!(x[0].distance(y[0]) < 1e-6, "hair {h}'s root moved");
            for (i, (p, q)) in x.iter().zip(y).enumerate().skip(6) {
                let d = p.distance(*q);
                assert!(d >= 0.9 * lo && d <= 1.1 * hi, "hair {h} point {i}: {d} m from straight, not {lo}..{hi}");
            }
            directions.push((y[12] - x[12]).normalize());
        }
        // Phases differ: the offsets at the same point of the hairs point every way.
        let mean = directions.iter().copied().sum::<Vec3>() / directions.len() as f32;
        println!("{} hairs; mean offset direction {mean}", directions.len());
        assert!(mean.length() < 0.2, "the hairs curl in step: mean direction {mean}");
    }

    /// Level of detail draws a prefix of the drawing order: a hair drawn at a
    /// lower detail is the same hair at a higher one (none jumps), and the
    /// prefix spreads over the scalp (a tenth of the hairs still leaves no
    /// root-free disk wider than 3 × its own mean spacing).
    #[test]
    fn fewer_hairs_are_a_prefix_spread_over_the_scalp() {
        let rest = guides(300);
        let params = ScalpHairParams { density: 20.0, ..ScalpHairParams::default() };
        let f = Followers::over_scalp(&rest, &params, 2, 8).expect("followers");
        let all = roots_of(&f, &rest, f.count());
        let tenth = roots_of(&f, &rest, (f.count() as f32 * 0.1).round() as usize);
        assert_eq!(&all[..tenth.len()], &tenth[..], "a hair moved when fewer were drawn");
        let cov = crate::render::scalp_coverage(&rest, &params, 0.1).expect("coverage");
        assert_eq!(cov.hairs as usize, tenth.len());
        println!("a tenth: largest root-free disk {:.2} × its mean spacing", cov.gap_ratio());
        assert!(cov.gap_ratio() <= 3.0, "a tenth of the hairs leaves a gap {:.2} × its spacing", cov.gap_ratio());
    }

    /// Two groups of guides combed apart (a parting down the middle: the left
    /// half's tips point left, the right half's right) never blend across it,
    /// however the root triangles straddle it; with the parting angle at 180°
    /// the straddling triangles blend both sides.
    #[test]
    fn hairs_never_blend_across_a_parting() {
        let rest = guides(300);
        let side = |g: usize| rest.rest[g * rest.points].x >= 0.0;
        let strands: Vec<Vec<Vec3>> = (0..rest.strands)
            .map(|g| {
                let root = rest.rest[g * rest.points].truncate();
                let out = if side(g) { Vec3::X } else { -Vec3::X };
                (0..8).map(|i| root + (out - 0.5 * Vec3::Y) * (0.03 * i as f32)).collect()
            })
            .collect();
        let parted = Groom::from_strands(&strands).expect("groom");
        let rest = SimState::from_groom(&parted, &SimParams::default(), &RigidTransform::default()).expect("rest");
        let mixed = |f: &Followers| {
            (0..f.count())
                .filter(|&s| {
                    let g = f.guides_of(s).expect("bound");
                    let sides: Vec<bool> = g.iter().filter(|(_, w)| *w > 0.0).map(|&(g, _)| side(g as usize)).collect();
                    sides.iter().any(|&x| x) && sides.iter().any(|&x| !x)
                })
                .count()
        };
        let params = ScalpHairParams { density: 20.0, ..ScalpHairParams::default() };
        let parted_hairs = Followers::over_scalp(&rest, &params, 2, 8).expect("followers");
        let blended =
            Followers::over_scalp(&rest, &ScalpHairParams { parting_angle: 180.0, ..params }, 2, 8).expect("followers");
        println!("hairs across the parting: {} at 60°, {} at 180°", mixed(&parted_hairs), mixed(&blended));
        assert_eq!(mixed(&parted_hairs), 0, "hairs blend guides from both sides of the parting");
        assert!(mixed(&blended) > 20, "too few straddling hairs to test with: {}", mixed(&blended));
    }

    /// Bad parameters are refused naming the field; a density beyond the
    /// largest count, and guides whose roots make no triangle, are refused
    /// saying so.
    #[test]
    fn bad_scalp_parameters_are_refused() {
        let rest = guides(300);
        let name = |p: ScalpHairParams| match Followers::over_scalp(&rest, &p, 2, 8) {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("not refused as a parameter: {other:?}"),
        };
        let d = ScalpHairParams::default();
        for (p, field) in [
            (ScalpHairParams { density: 0.0, ..d.clone() }, "scalp.density"),
            (ScalpHairParams { density: f32::NAN, ..d.clone() }, "scalp.density"),
            (ScalpHairParams { parting_angle: -1.0, ..d.clone() }, "scalp.parting_angle"),
            (ScalpHairParams { clumping: 1.5, ..d.clone() }, "scalp.clumping"),
            (ScalpHairParams { length_variation: f32::INFINITY, ..d.clone() }, "scalp.length_variation"),
            (ScalpHairParams { max_hairs: 0, ..d.clone() }, "scalp.max_hairs"),
            (ScalpHairParams { density: 1000.0, max_hairs: 100, ..d.clone() }, "scalp.density"),
        ] {
            assert_eq!(name(p), field);
        }
        let line: Vec<Vec<Vec3>> =
            (0..10).map(|i| vec![Vec3::new(0.01 * i as f32, 1.6, 0.0), Vec3::new(0.01 * i as f32, 1.5, 0.0)]).collect();
        let line = Groom::from_strands(&line).expect("groom");
        let rest = SimState::from_groom(&line, &SimParams::default(), &RigidTransform::default()).expect("rest");
        assert!(matches!(Followers::over_scalp(&rest, &d, 2, 8), Err(Error::Incompatible { what: "guides", .. })));
    }
}
