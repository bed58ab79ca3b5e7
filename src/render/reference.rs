//! CPU references of the render passes (test oracles).

use glam::Vec3;

/// The key point `idx` of a strand, mirrored beyond root and tip as the
/// smoothing pass does.
fn control_point(points: &[Vec3], idx: isize) -> Vec3 {
    let n = points.len() as isize;
    if idx < 0 {
        2.0 * points[0] - points[1]
    } else if idx >= n {
        2.0 * points[(n - 1) as usize] - points[(n - 2) as usize]
    } else {
        points[idx as usize]
    }
}

/// Smoothed vertices (position, unit tangent) of one key hair with `level`
/// segments per key segment: (points − 1)·level + 1 of them, root to tip.
pub fn smooth_strand(points: &[Vec3], level: u32) -> Vec<(Vec3, Vec3)> {
    let segs = points.len() - 1;
    let mut out = Vec::with_capacity(segs * level as usize + 1);
    for seg in 0..segs {
        let c: Vec<Vec3> = (0..4).map(|k| control_point(points, seg as isize - 1 + k)).collect();
        let last = if seg + 1 == segs { level } else { level - 1 };
        for j in 0..=last {
            let u = j as f32 / level as f32;
            let v = 1.0 - u;
            let (u2, u3) = (u * u, u * u * u);
            let b = [v * v * v, 3.0 * u3 - 6.0 * u2 + 4.0, -3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0, u3].map(|x| x / 6.0);
            let db = [-v * v, 3.0 * u2 - 4.0 * u, -3.0 * u2 + 2.0 * u + 1.0, u2].map(|x| x * 0.5);
            let p = c[0] * b[0] + c[1] * b[1] + c[2] * b[2] + c[3] * b[3];
            let d = c[0] * db[0] + c[1] * db[1] + c[2] * db[2] + c[3] * db[3];
            out.push((p, d.try_normalize().unwrap_or(Vec3::NEG_Y)));
        }
    }
    out
}

/// The stable clump coordinate of interpolated hair `hair` of key hair `key`,
/// uniform in the unit disk (as `clump_coordinate` in `render.glsl`).
pub fn clump_coordinate(key: u32, hair: u32) -> glam::Vec2 {
    let seed = key.wrapping_mul(64).wrapping_add(hair);
    let r = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x9e37_79b9)).sqrt();
    let a = std::f32::consts::TAU * crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x7f4a_7c15));
    glam::Vec2::new(r * a.cos(), r * a.sin())
}

/// Barycentric weights of hair `hair` of scalp triangle `tri`, as
/// `barycentric_weights` in `render.glsl`.
pub fn barycentric_weights(tri: u32, hair: u32) -> Vec3 {
    let seed = tri.wrapping_mul(64).wrapping_add(hair);
    let r1 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x51ed_270b)).sqrt();
    let r2 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x2545_f491));
    let u = 1.0 - r1;
    let v = r1 * (1.0 - r2);
    Vec3::new(u, v, 1.0 - u - v)
}

/// The offset frame (B1, B2) of a key vertex with unit tangent `t` and reference
/// vector `reference` (world), as `key_frame` in `render.glsl`.
pub fn key_frame(t: Vec3, reference: Vec3) -> (Vec3, Vec3) {
    let mut r = reference - reference.dot(t) * t;
    if r.length() < 1e-4 {
        let any = if t.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        r = any - any.dot(t) * t;
    }
    let b1 = r.normalize();
    (b1, t.cross(b1))
}

/// Bertails et al.'s light-oriented density map (2005), the CPU reference of
/// density-volume shadows: `particles` splatted into cubic cells of side `ds` in a
/// frame whose first axis is the light's direction of travel `light_dir`;
/// transmittance at each of `points` = exp(−σ · Σ N / ds²) over the cells of its
/// column strictly before its own cell along the light (N particles per cell, so
/// Σ N / ds² is the particles per area crossed, ∫ particle density ds). The counts
/// are box-filtered over (2·`filter` + 1)² neighbouring columns, the map's filtering
/// step, which hides where the particle lattice happens to fall on the cells.
pub fn light_oriented_transmittance(
    particles: &[Vec3],
    light_dir: Vec3,
    cross_section: f32,
    ds: f32,
    filter: i64,
    points: &[Vec3],
) -> Vec<f32> {
    let x = light_dir.normalize();
    let helper = if x.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let y = x.cross(helper).normalize();
    let z = x.cross(y);
    let cell = |p: Vec3| [p.dot(x), p.dot(y), p.dot(z)].map(|c| (c / ds).floor() as i64);
    let mut columns: std::collections::HashMap<(i64, i64), Vec<i64>> = std::collections::HashMap::new();
    for &p in particles {
        let [i, j, k] = cell(p);
        columns.entry((j, k)).or_default().push(i);
    }
    points
        .iter()
        .map(|&q| {
            let [i, j, k] = cell(q);
            let mut before = 0;
            for dj in -filter..=filter {
                for dk in -filter..=filter {
                    let column = columns.get(&(j + dj, k + dk));
                    before += column.map_or(0, |c| c.iter().filter(|&&ci| ci < i).count());
                }
            }
            let columns_averaged = ((2 * filter + 1) * (2 * filter + 1)) as f32;
            (-cross_section * before as f32 / columns_averaged / (ds * ds)).exp()
        })
        .collect()
}

/// What [`composite_strands`] draws: hairs as the draw pass's ribbons (true
/// width, no least width), coloured by `color(t)` along each hair, in one
/// uniform opacity, over a background.
pub struct CompositeScene<'a> {
    /// Each hair's vertices, root to tip: xyz position (m), w the parameter t
    /// along the hair (0 at the root, 1 at the tip).
    pub hairs: &'a [Vec<glam::Vec4>],
    /// World → clip.
    pub view_proj: glam::Mat4,
    /// Camera position (the ribbons face it).
    pub camera: Vec3,
    /// Image width and height, pixels.
    pub extent: (u32, u32),
    /// Hair width at the root and at the tip, meters.
    pub widths: (f32, f32),
    /// Real hairs each drawn strand stands for (as
    /// [`super::HairMaterial::represented_hairs`]).
    pub represented_hairs: f32,
    /// Opacity of a strand where it covers a sample.
    pub opacity: f32,
    /// Linear colour of the hair at t.
    pub color: &'a dyn Fn(f32) -> Vec3,
    /// Linear background colour.
    pub background: Vec3,
}

/// Sub-samples per pixel side of [`composite_strands`] (16 per pixel).
pub const COMPOSITE_SAMPLES: u32 = 4;

/// The exact transparent image of `scene` (the ground truth of the transparency
/// modes): every segment of every hair becomes the draw pass's camera-facing
/// quad of its true width (a band `represented_hairs` widths wide, of opacity
/// `opacity` times the band's density), every quad is point-sampled at 4×4
/// samples per pixel with perspective-correct t, each sample's fragments are
/// sorted by depth and composited front to back over the background, and the
/// samples of a pixel are averaged. Linear RGB and hair alpha, rows from the top.
pub fn composite_strands(scene: &CompositeScene<'_>) -> Vec<glam::Vec4> {
    let (w, h) = scene.extent;
    let n = COMPOSITE_SAMPLES;
    let n_hairs = scene.represented_hairs.max(1.0);
    let alpha = scene.opacity * (1.0 - (1.0 - 1.0 / n_hairs).powf(n_hairs));
    let mut samples: Vec<Vec<(f32, Vec3)>> = vec![Vec::new(); (w * h * n * n) as usize];
    let project = |p: Vec3| {
        let c = scene.view_proj * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        (glam::Vec2::new((ndc.x * 0.5 + 0.5) * w as f32, (ndc.y * 0.5 + 0.5) * h as f32), ndc.z, c.w)
    };
    for hair in scene.hairs {
        for seg in hair.windows(2) {
            let (p0, p1) = (seg[0].truncate(), seg[1].truncate());
            let Some(dir) = (p1 - p0).try_normalize() else { continue };
            let mut corners = Vec::with_capacity(4);
            for v in [seg[0], seg[1]] {
                let p = v.truncate();
                let side = dir.cross(scene.camera - p).try_normalize().unwrap_or(Vec3::X);
                let half = 0.5 * n_hairs * (scene.widths.0 + (scene.widths.1 - scene.widths.0) * v.w);
                for s in [-1.0, 1.0] {
                    let (xy, z, cw) = project(p + side * half * s);
                    corners.push((xy, z, cw, v.w));
                }
            }
            if corners.iter().any(|c| c.2.is_nan() || c.2 <= 0.0) {
                continue;
            }
            for tri in [[0, 1, 2], [1, 2, 3]] {
                let t = tri.map(|i| corners[i]);
                let lo = t.iter().fold(glam::Vec2::splat(f32::MAX), |a, c| a.min(c.0));
                let hi = t.iter().fold(glam::Vec2::splat(f32::MIN), |a, c| a.max(c.0));
                let area = (t[1].0 - t[0].0).perp_dot(t[2].0 - t[0].0);
                if area.abs() < 1e-12 {
                    continue;
                }
                let sx0 = ((lo.x * n as f32 - 0.5).ceil().max(0.0)) as u32;
                let sy0 = ((lo.y * n as f32 - 0.5).ceil().max(0.0)) as u32;
                let sx1 = ((hi.x * n as f32 - 0.5).floor().min((w * n) as f32 - 1.0)) as i64;
                let sy1 = ((hi.y * n as f32 - 0.5).floor().min((h * n) as f32 - 1.0)) as i64;
                for sy in sy0 as i64..=sy1 {
                    for sx in sx0 as i64..=sx1 {
                        let q = glam::Vec2::new((sx as f32 + 0.5) / n as f32, (sy as f32 + 0.5) / n as f32);
                        let b = [
                            (t[2].0 - t[1].0).perp_dot(q - t[1].0) / area,
                            (t[0].0 - t[2].0).perp_dot(q - t[2].0) / area,
                            (t[1].0 - t[0].0).perp_dot(q - t[0].0) / area,
                        ];
                        // Half-open on the shared diagonal (corners 1–2): a sample on it
                        // belongs to the first triangle only.
                        let inside = b.iter().all(|&x| x >= 0.0) && !(tri[0] == 1 && b[0] == 0.0);
                        if !inside {
                            continue;
                        }
                        let depth = b[0] * t[0].1 + b[1] * t[1].1 + b[2] * t[2].1;
                        let inv_w = b[0] / t[0].2 + b[1] / t[1].2 + b[2] / t[2].2;
                        let along = (b[0] * t[0].3 / t[0].2 + b[1] * t[1].3 / t[1].2 + b[2] * t[2].3 / t[2].2) / inv_w;
                        if !(0.0..=1.0).contains(&depth) {
                            continue;
                        }
                        samples[(sy as u32 * w * n + sx as u32) as usize].push((depth, (scene.color)(along)));
                    }
                }
            }
        }
    }
    let mut image = vec![glam::Vec4::ZERO; (w * h) as usize];
    for (index, fragments) in samples.iter_mut().enumerate() {
        fragments.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut sum = Vec3::ZERO;
        let mut transmittance = 1.0;
        for (_, c) in fragments.iter() {
            sum += transmittance * alpha * *c;
            transmittance *= 1.0 - alpha;
        }
        let (sx, sy) = (index as u32 % (w * n), index as u32 / (w * n));
        let pixel = &mut image[((sy / n) * w + sx / n) as usize];
        *pixel += (sum + transmittance * scene.background).extend(1.0 - transmittance) / (n * n) as f32;
    }
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_passes_through_root_and_tip_with_end_tangents() {
        let pts = [Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0), Vec3::new(1.0, -2.0, 0.0), Vec3::new(1.0, -3.0, 1.0)];
        let s = smooth_strand(&pts, 4);
        assert_eq!(s.len(), 13);
        assert!((s[0].0 - pts[0]).length() < 1e-6);
        assert!((s[12].0 - pts[3]).length() < 1e-6);
        assert!((s[0].1 - (pts[1] - pts[0]).normalize()).length() < 1e-6);
        assert!((s[12].1 - (pts[3] - pts[2]).normalize()).length() < 1e-6);
        // A straight strand stays straight and evenly spaced.
        let line: Vec<Vec3> = (0..5).map(|i| Vec3::X * i as f32).collect();
        let s = smooth_strand(&line, 3);
        for (k, (p, t)) in s.iter().enumerate() {
            assert!((*p - Vec3::X * (k as f32 / 3.0)).length() < 1e-5, "{k}: {p}");
            assert!((*t - Vec3::X).length() < 1e-6);
        }
    }
}
