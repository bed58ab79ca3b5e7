//! Procedural growth of strands from a scalp (sphere/ellipsoid or triangle mesh).
//!
//! Roots are spread over the scalp region by area with a seeded generator
//! (same parameters and seed → the same groom, bit for bit). Each strand leaves
//! its root along the surface normal (tilted by a small random angle) and bends
//! toward the gravity direction as it grows (after an optional comb direction
//! is added to its root direction), by `droop` radians per unit of
//! normalised length, never past the gravity direction itself. Segments get
//! longer toward the tip: the last is `segment_growth` times the first.
//!
//! Given the direction the face looks ([`GrowParams::face`]), hair frames the
//! face: no strand leaves its root toward the face, and the strands rooted in
//! front of the scalp's middle are parted there and turned toward their own
//! side, the more the nearer the face, so they fall beside it, not over it.

use glam::{Quat, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::mesh::TriMesh;
use super::{Groom, MAX_POINTS, MAX_POINTS_PER_STRAND, MAX_STRANDS};
use crate::error::{Error, Result};

/// Where roots are placed.
#[derive(Debug, Clone, PartialEq)]
pub enum Scalp {
    /// Part of an ellipsoid surface.
    Ellipsoid {
        /// Centre, in the groom's length unit.
        center: Vec3,
        /// Semi-axes along x, y, z (all equal for a sphere).
        radii: Vec3,
        /// Unit direction of the crown.
        up: Vec3,
        /// Roots lie within this angle of `up`, radians (π covers everything).
        max_angle: f32,
        /// No roots within `face_angle` radians of this unit direction (the face);
        /// `None` for no exclusion.
        face: Option<(Vec3, f32)>,
    },
    /// Triangles of a mesh, selected by height and orientation.
    Mesh {
        /// The mesh.
        mesh: TriMesh,
        /// Unit up direction of the mesh.
        up: Vec3,
        /// Only triangles whose centroid lies above this fraction (0..=1) of the
        /// mesh's extent along `up`.
        min_height: f32,
        /// Only triangles whose normal has at least this dot product with `up` (-1..=1).
        min_up_dot: f32,
    },
}

impl Scalp {
    /// A whole-crown cap of a sphere: roots within `max_angle` of +Y, none on the face (+Z).
    pub fn sphere_cap(center: Vec3, radius: f32, max_angle: f32) -> Scalp {
        Scalp::Ellipsoid { center, radii: Vec3::splat(radius), up: Vec3::Y, max_angle, face: Some((Vec3::Z, 0.9)) }
    }
}

/// How strands grow. Lengths are in the scalp's unit.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GrowParams {
    /// Number of strands (1..=4,194,304). Default: 1000.
    pub strands: usize,
    /// Points per strand (2..=65,536). Default: 16.
    pub points_per_strand: usize,
    /// Strand length, scalp units (0 < length ≤ 1e6). Default: 0.3.
    pub length: f32,
    /// Random length variation as a fraction of `length` (0..1). Default: 0.1.
    pub length_jitter: f32,
    /// Bending toward gravity, radians per unit normalised length (0..=1000). Default: 2.5.
    pub droop: f32,
    /// Gravity direction (non-zero, each component within ±1e6; normalised). Default: −Y.
    pub gravity: Vec3,
    /// Random tilt of the root direction, radians (0..=π/2). Default: 0.15.
    pub direction_jitter: f32,
    /// Ratio of the last segment's length to the first (0 < ratio ≤ 1000). Default: 2.0.
    pub segment_growth: f32,
    /// Direction added to every root direction before the strand bends under
    /// gravity (combing: e.g. backward to keep hair off the face; length ≈ strength).
    /// Default: zero.
    pub comb: Vec3,
    /// Direction the face looks, in the scalp's frame (its length does not
    /// matter; each component within ±1e6), or zero for none. Hair is combed
    /// away from it: no strand leaves its root toward the face, and those
    /// rooted in front of the scalp's middle are parted at the middle (the
    /// plane of the face direction and gravity) and turned toward their side
    /// and back by up to [`PART_STRENGTH`], the more the nearer the face.
    /// Default: zero.
    pub face: Vec3,
    /// Seed of the random generator. Default: 1.
    pub seed: u64,
}

/// How far a strand rooted straight in front of the scalp's middle is turned
/// toward its side of the parting and back: the sideways direction and the
/// backward one, each at this length, are added to its root direction (unit
/// length).
pub const PART_STRENGTH: f32 = 1.5;

impl Default for GrowParams {
    fn default() -> Self {
        GrowParams {
            strands: 1000,
            points_per_strand: 16,
            length: 0.3,
            length_jitter: 0.1,
            droop: 2.5,
            gravity: Vec3::NEG_Y,
            direction_jitter: 0.15,
            segment_growth: 2.0,
            comb: Vec3::ZERO,
            face: Vec3::ZERO,
            seed: 1,
        }
    }
}

impl GrowParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_STRANDS).contains(&self.strands) {
            return Err(Error::param("strands", self.strands, format!("1..={MAX_STRANDS}")));
        }
        if !(2..=MAX_POINTS_PER_STRAND).contains(&self.points_per_strand) {
            return Err(Error::param(
                "points_per_strand",
                self.points_per_strand,
                format!("2..={MAX_POINTS_PER_STRAND}"),
            ));
        }
        if self.strands.saturating_mul(self.points_per_strand) > MAX_POINTS {
            return Err(Error::TooManyPoints {
                count: (self.strands as u64) * self.points_per_strand as u64,
                max: MAX_POINTS as u64,
            });
        }
        let positive = |name, v: f32, max: f32| {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(Error::param(name, v, format!("(0, {max}]")))
            }
        };
        positive("length", self.length, 1e6)?;
        positive("segment_growth", self.segment_growth, 1e3)?;
        if !(self.length_jitter.is_finite() && (0.0..1.0).contains(&self.length_jitter)) {
            return Err(Error::param("length_jitter", self.length_jitter, "0..1"));
        }
        if !(self.droop.is_finite() && (0.0..=1e3).contains(&self.droop)) {
            return Err(Error::param("droop", self.droop, "0..=1000"));
        }
        if !(self.direction_jitter.is_finite() && (0.0..=std::f32::consts::FRAC_PI_2).contains(&self.direction_jitter))
        {
            return Err(Error::param("direction_jitter", self.direction_jitter, "0..=π/2"));
        }
        if !self.comb.is_finite() || self.comb.length() > 100.0 {
            return Err(Error::param("comb", self.comb, "finite and at most 100 long"));
        }
        if !self.face.is_finite() || self.face.abs().max_element() > 1e6 {
            return Err(Error::param("face", self.face, "finite, each component within ±1e6 (zero for none)"));
        }
        if !self.gravity.is_finite() || self.gravity.abs().max_element() > 1e6 || self.gravity.length_squared() < 1e-12
        {
            return Err(Error::param("gravity", self.gravity, "finite, non-zero, each component within ±1e6"));
        }
        Ok(())
    }
}

fn unit(name: &'static str, v: Vec3) -> Result<Vec3> {
    v.try_normalize().filter(|n| n.is_finite()).ok_or_else(|| Error::param(name, v, "a direction"))
}

/// Root positions and normals on the scalp.
fn roots(scalp: &Scalp, count: usize, rng: &mut Pcg64Mcg) -> Result<Vec<(Vec3, Vec3)>> {
    match scalp {
        Scalp::Ellipsoid { center, radii, up, max_angle, face } => {
            if !center.is_finite() || !radii.is_finite() || radii.min_element() <= 0.0 {
                return Err(Error::BadScalp(format!(
                    "ellipsoid centre {center} / radii {radii} must be finite and positive"
                )));
            }
            if !(max_angle.is_finite() && *max_angle > 0.0) {
                return Err(Error::param("max_angle", max_angle, "> 0"));
            }
            let up = unit("up", *up)?;
            let face = match face {
                Some((dir, angle)) => Some((unit("face direction", *dir)?, angle.cos())),
                None => None,
            };
            let to_world = Quat::from_rotation_arc(Vec3::Y, up);
            let cos_max = max_angle.min(std::f32::consts::PI).cos();
            let mut out = Vec::with_capacity(count);
            let budget = count.saturating_mul(200).max(10_000);
            for _ in 0..budget {
                if out.len() == count {
                    break;
                }
                // Uniform on the spherical cap around +Y, then rotated to `up`.
                let y = cos_max + (1.0 - cos_max) * rng.random::<f32>();
                let phi = std::f32::consts::TAU * rng.random::<f32>();
                let r = (1.0 - y * y).max(0.0).sqrt();
                let d = to_world * Vec3::new(r * phi.cos(), y, r * phi.sin());
                if face.is_some_and(|(f, cos_face)| d.dot(f) > cos_face) {
                    continue;
                }
                let position = *center + *radii * d;
                let normal = (d / *radii).normalize();
                out.push((position, normal));
            }
            if out.len() < count {
                return Err(Error::BadScalp("the face exclusion leaves almost no room on the cap".into()));
            }
            Ok(out)
        }
        Scalp::Mesh { mesh, up, min_height, min_up_dot } => {
            let up = unit("up", *up)?;
            if !(min_height.is_finite() && (0.0..=1.0).contains(min_height)) {
                return Err(Error::param("min_height", min_height, "0..=1"));
            }
            if !(min_up_dot.is_finite() && (-1.0..=1.0).contains(min_up_dot)) {
                return Err(Error::param("min_up_dot", min_up_dot, "-1..=1"));
            }
            let heights = mesh.positions.iter().map(|p| p.dot(up));
            let (lo, hi) = heights.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), h| (a.min(h), b.max(h)));
            let threshold = lo + (hi - lo) * min_height;
            let mut cumulative = Vec::new();
            let mut selected = Vec::new();
            let mut total = 0.0f64;
            for i in 0..mesh.triangles.len() {
                let n = mesh.scaled_normal(i);
                let area = 0.5 * n.length();
                let [a, b, c] = mesh.corners(i);
                let centroid = (a + b + c) / 3.0;
                if area > 0.0 && centroid.dot(up) >= threshold && n.normalize().dot(up) >= *min_up_dot {
                    total += f64::from(area);
                    cumulative.push(total);
                    selected.push(i);
                }
            }
            if selected.is_empty() {
                return Err(Error::BadScalp(format!(
                    "no triangle lies above height fraction {min_height} facing up by at least {min_up_dot}"
                )));
            }
            let mut out = Vec::with_capacity(count);
            for _ in 0..count {
                let pick = rng.random::<f64>() * total;
                let k = cumulative.partition_point(|&c| c < pick).min(selected.len() - 1);
                let tri = selected[k];
                let [a, b, c] = mesh.corners(tri);
                let (u, v) = (rng.random::<f32>(), rng.random::<f32>());
                let su = u.sqrt();
                let p = a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v);
                out.push((p, mesh.scaled_normal(tri).normalize()));
            }
            Ok(out)
        }
    }
}

/// The face a groom frames ([`GrowParams::face`]).
struct FaceFraming {
    /// Unit direction the face looks.
    face: Vec3,
    /// Unit direction across the parting (face × up).
    across: Vec3,
    /// The roots' mean.
    middle: Vec3,
}

impl FaceFraming {
    /// The framing of `face` (none for zero) over `roots` under `gravity` (unit).
    fn new(face: Vec3, gravity: Vec3, roots: &[(Vec3, Vec3)]) -> Option<Self> {
        let face = face.try_normalize()?;
        let middle = roots.iter().map(|r| r.0).sum::<Vec3>() / roots.len().max(1) as f32;
        // A face looking along gravity has no sides: no parting then.
        let across = face.cross(-gravity).try_normalize().unwrap_or(Vec3::ZERO);
        Some(FaceFraming { face, across, middle })
    }

    /// The root direction `start` (unit) of a strand rooted at `root`, combed
    /// away from the face (unit).
    fn comb(&self, root: Vec3, start: Vec3) -> Vec3 {
        let from_middle = (root - self.middle).normalize_or_zero();
        let front = from_middle.dot(self.face).max(0.0);
        let side = if from_middle.dot(self.across) < 0.0 { -1.0 } else { 1.0 };
        let parted = start + (self.across * side - self.face) * (PART_STRENGTH * front);
        let toward_face = parted.dot(self.face).max(0.0);
        (parted - self.face * toward_face).try_normalize().unwrap_or(start)
    }
}

/// Grows strands on `scalp`.
pub fn grow(scalp: &Scalp, params: &GrowParams) -> Result<Groom> {
    params.validate()?;
    let mut rng = Pcg64Mcg::seed_from_u64(params.seed);
    let roots = roots(scalp, params.strands, &mut rng)?;
    let gravity = params.gravity.normalize();
    let segments = params.points_per_strand - 1;
    let ratio = if segments > 1 { params.segment_growth.powf(1.0 / (segments - 1) as f32) } else { 1.0 };
    let weights: Vec<f32> = (0..segments).map(|i| ratio.powi(i as i32)).collect();
    let weight_sum: f32 = weights.iter().sum();
    let framing = FaceFraming::new(params.face, gravity, &roots);
    let mut positions = Vec::with_capacity(params.strands * params.points_per_strand);
    for (root, normal) in roots {
        // Tilt the growth direction a little, around a random axis perpendicular to the normal.
        let spin = std::f32::consts::TAU * rng.random::<f32>();
        let tilt_axis = Quat::from_axis_angle(normal, spin) * normal.any_orthonormal_vector();
        let tilt = params.direction_jitter * rng.random::<f32>();
        let tilted = Quat::from_axis_angle(tilt_axis, tilt) * normal;
        let start = (tilted + params.comb).try_normalize().unwrap_or(tilted);
        let start = framing.as_ref().map_or(start, |f| f.comb(root, start));
        // Bend in the plane of start and gravity; straight up/down uses the tilt axis.
        let axis = start.cross(gravity).try_normalize().unwrap_or(tilt_axis);
        let max_bend = start.angle_between(gravity);
        let length = params.length * (1.0 + params.length_jitter * (2.0 * rng.random::<f32>() - 1.0));
        let mut p = root;
        positions.push(p);
        let mut travelled = 0.0f32;
        for w in &weights {
            let segment = length * w / weight_sum;
            let t = (travelled + 0.5 * segment) / length;
            let bend = (params.droop * t).min(max_bend);
            p += Quat::from_axis_angle(axis, bend) * start * segment;
            travelled += segment;
            positions.push(p);
        }
    }
    Groom::new(positions, &vec![params.points_per_strand as u32; params.strands])
}
