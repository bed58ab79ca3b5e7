//! CPU references of the render passes (test oracles).

use glam::Vec3;

pub use super::motion_reference::{hair_motion, hair_motions_at, MotionPick, MotionScene};
pub use super::strand_frames::{key_frame, rest_plane_normals, smooth_strand, strand_spread};

/// The key points drawn at `alpha` between the state before the latest step and
/// the latest one ([`crate::sim::KeyHairs::blended`]): `before + (latest −
/// before)·alpha` per point, exactly `before` at 0 and `latest` at 1.
pub fn blend_key_points(before: &[glam::Vec4], latest: &[glam::Vec4], alpha: f32) -> Vec<Vec3> {
    before
        .iter()
        .zip(latest)
        .map(|(b, l)| match alpha {
            a if a >= 1.0 => l.truncate(),
            a if a <= 0.0 => b.truncate(),
            a => b.truncate() + (l.truncate() - b.truncate()) * a,
        })
        .collect()
}

/// The stable clump coordinate of interpolated hair `hair` of key hair `key`,
/// uniform in the unit disk (as `clump_coordinate` in `render.glsl`).
pub fn clump_coordinate(key: u32, hair: u32) -> glam::Vec2 {
    let seed = key.wrapping_mul(crate::codes::interpolate::MAX_HAIRS_PER_KEY).wrapping_add(hair);
    let r = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x9e37_79b9)).sqrt();
    let a = std::f32::consts::TAU * crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x7f4a_7c15));
    glam::Vec2::new(r * a.cos(), r * a.sin())
}

/// Barycentric weights of hair `hair` of scalp triangle `tri`, as
/// `barycentric_weights` in `render.glsl`.
pub fn barycentric_weights(tri: u32, hair: u32) -> Vec3 {
    let seed = tri.wrapping_mul(crate::codes::interpolate::MAX_HAIRS_PER_KEY).wrapping_add(hair);
    let r1 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x51ed_270b)).sqrt();
    let r2 = crate::hash::hash_unit(seed.wrapping_mul(2).wrapping_add(0x2545_f491));
    let u = 1.0 - r1;
    let v = r1 * (1.0 - r2);
    Vec3::new(u, v, 1.0 - u - v)
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
    /// [`super::Renderer::strand_hairs`]).
    pub represented_hairs: f32,
    /// Spacing of the drawn strands at the root and at the tip, meters, which
    /// the bands spread over ([`strand_band`], [`super::Renderer::strand_spacing`];
    /// 0 for none).
    pub band_spacing: (f32, f32),
    /// Opacity of a strand where it covers a sample.
    pub opacity: f32,
    /// Linear colour of the hair at t.
    pub color: &'a (dyn Fn(f32) -> Vec3 + Sync),
    /// Linear background colour.
    pub background: Vec3,
}

/// The band a transparent strand standing for `n` hairs of width `hair_width`
/// is drawn as, where the drawn strands lie `spacing` apart (meters): its width,
/// `max(n · hair_width, min((1 − 1/n) · spacing, 2 · n · hair_width))` (the
/// hairs spread over the space between the drawn strands, up to twice as wide
/// as side by side, `codes::band::MAX_SPREAD`; one hair stays one hair), and
/// its density, the fraction of it `n` hairs placed at random across it cover,
/// `1 − (1 − hair_width / width)^n` (as `ribbon.vert`).
pub fn strand_band(hair_width: f32, n: f32, spacing: f32) -> (f32, f32) {
    let n = n.max(1.0);
    let most = crate::codes::band::MAX_SPREAD as f32 * n * hair_width;
    let width = (n * hair_width).max(strand_spread(n, spacing).min(most));
    let density = if width > 0.0 { 1.0 - (1.0 - hair_width / width).max(0.0).powf(n) } else { 0.0 };
    (width, density)
}

/// Sub-samples per pixel side of [`composite_strands`] (16 per pixel).
pub const COMPOSITE_SAMPLES: u32 = 4;

/// Pixel rows of one band of [`composite_strands`]: its memory holds one band's
/// sample fragments per thread, not the whole image's.
const BAND_ROWS: u32 = 8;

/// One triangle of a ribbon quad in screen space: per corner the pixel
/// position, depth, clip w, t along the hair and the band's density there.
#[derive(Clone, Copy)]
struct ScreenTriangle {
    corners: [(glam::Vec2, f32, f32, f32, f32); 3],
    /// Twice the signed area.
    area: f32,
    /// The quad's second triangle (half-open on the shared diagonal).
    second: bool,
    /// Sample rows covered, inclusive.
    rows: (u32, u32),
    /// Sample columns covered, inclusive.
    columns: (u32, u32),
}

/// Width and density of `scene`'s bands at `t` along the hair ([`strand_band`]).
fn band_at(scene: &CompositeScene<'_>, t: f32) -> (f32, f32) {
    let hair_width = scene.widths.0 + (scene.widths.1 - scene.widths.0) * t;
    let spacing = scene.band_spacing.0 + (scene.band_spacing.1 - scene.band_spacing.0) * t;
    strand_band(hair_width, scene.represented_hairs, spacing)
}

/// The ribbon triangles of `scene` (the draw pass's camera-facing quads).
fn screen_triangles(scene: &CompositeScene<'_>) -> Vec<ScreenTriangle> {
    let (w, h) = scene.extent;
    let n = COMPOSITE_SAMPLES as f32;
    let project = |p: Vec3| {
        let c = scene.view_proj * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        (glam::Vec2::new((ndc.x * 0.5 + 0.5) * w as f32, (ndc.y * 0.5 + 0.5) * h as f32), ndc.z, c.w)
    };
    let mut triangles = Vec::new();
    for hair in scene.hairs {
        for seg in hair.windows(2) {
            let (p0, p1) = (seg[0].truncate(), seg[1].truncate());
            let Some(dir) = (p1 - p0).try_normalize() else { continue };
            let mut corners = [(glam::Vec2::ZERO, 0.0, 0.0, 0.0, 0.0); 4];
            for (i, v) in [seg[0], seg[1]].into_iter().enumerate() {
                let p = v.truncate();
                let side = dir.cross(scene.camera - p).try_normalize().unwrap_or(Vec3::X);
                let (band, density) = band_at(scene, v.w);
                let half = 0.5 * band;
                for (k, s) in [-1.0, 1.0].into_iter().enumerate() {
                    let (xy, z, cw) = project(p + side * half * s);
                    corners[2 * i + k] = (xy, z, cw, v.w, density);
                }
            }
            if corners.iter().any(|c| c.2.is_nan() || c.2 <= 0.0) {
                continue;
            }
            for (second, tri) in [(false, [0, 1, 2]), (true, [1, 2, 3])] {
                let t = tri.map(|i| corners[i]);
                let lo = t.iter().fold(glam::Vec2::splat(f32::MAX), |a, c| a.min(c.0));
                let hi = t.iter().fold(glam::Vec2::splat(f32::MIN), |a, c| a.max(c.0));
                let area = (t[1].0 - t[0].0).perp_dot(t[2].0 - t[0].0);
                if area.abs() < 1e-12 || !(lo.is_finite() && hi.is_finite()) {
                    continue;
                }
                let first = |v: f32| (v * n - 0.5).ceil().max(0.0);
                let last = |v: f32, size: u32| (v * n - 0.5).floor().min(size as f32 * n - 1.0);
                let (x0, y0, x1, y1) = (first(lo.x), first(lo.y), last(hi.x, w), last(hi.y, h));
                if x1 < x0 || y1 < y0 {
                    continue;
                }
                triangles.push(ScreenTriangle {
                    corners: t,
                    area,
                    second,
                    rows: (y0 as u32, y1 as u32),
                    columns: (x0 as u32, x1 as u32),
                });
            }
        }
    }
    triangles
}

/// The exact transparent image of `scene` (the ground truth of the transparency
/// modes): every segment of every hair becomes the draw pass's camera-facing
/// quad of its band's width ([`strand_band`]), of opacity `opacity` times the
/// band's density at its ends interpolated as the draw interpolates it), every
/// quad is point-sampled at 4×4
/// samples per pixel with perspective-correct t, each sample's fragments are
/// sorted by depth and composited front to back over the background, and the
/// samples of a pixel are averaged. Linear RGB and hair alpha, rows from the top.
///
/// The image is built in bands of pixel rows on every core; the result does not
/// depend on the number of threads (each sample's fragments keep the order of
/// the hairs, so equal depths resolve the same way).
pub fn composite_strands(scene: &CompositeScene<'_>) -> Vec<glam::Vec4> {
    composite_on(scene, std::thread::available_parallelism().map_or(1, |t| t.get()))
}

/// [`composite_strands`] on at most `threads` threads.
fn composite_on(scene: &CompositeScene<'_>, threads: usize) -> Vec<glam::Vec4> {
    let (w, h) = scene.extent;
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let n = COMPOSITE_SAMPLES;
    let triangles = screen_triangles(scene);
    let band_samples = BAND_ROWS * n;
    let bands = h.div_ceil(BAND_ROWS).max(1);
    let mut in_band: Vec<Vec<u32>> = vec![Vec::new(); bands as usize];
    for (i, t) in triangles.iter().enumerate() {
        for band in t.rows.0 / band_samples..=t.rows.1 / band_samples {
            in_band[band as usize].push(i as u32);
        }
    }
    let mut image = vec![glam::Vec4::ZERO; (w * h) as usize];
    let work = std::sync::Mutex::new(image.chunks_mut((w * BAND_ROWS) as usize).zip(in_band.iter()).enumerate());
    let threads = threads.clamp(1, bands as usize);
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                let mut samples: Vec<Vec<Fragment>> = vec![Vec::new(); (w * n * band_samples) as usize];
                // The lock is released as soon as a band is taken (the guard is
                // consumed by the closure). A poisoned lock means another band
                // panicked; that panic is re-raised by the scope.
                let next_band = || work.lock().ok().and_then(|mut w| w.next());
                while let Some((band, (pixels, list))) = next_band() {
                    let top = band as u32 * band_samples;
                    for &i in list {
                        rasterize(&triangles[i as usize], top, top + band_samples - 1, w * n, scene, &mut samples);
                    }
                    resolve_band(&mut samples, pixels, w, scene.background);
                }
            });
        }
    });
    image
}

/// A sample's fragment: depth, linear colour, alpha.
type Fragment = (f32, Vec3, f32);

/// Adds the fragments of `t` in sample rows `top..=bottom` to `samples` (rows
/// from `top`, `row_len` samples each).
fn rasterize(
    t: &ScreenTriangle,
    top: u32,
    bottom: u32,
    row_len: u32,
    scene: &CompositeScene<'_>,
    samples: &mut [Vec<Fragment>],
) {
    let n = COMPOSITE_SAMPLES as f32;
    let c = &t.corners;
    for sy in t.rows.0.max(top)..=t.rows.1.min(bottom) {
        for sx in t.columns.0..=t.columns.1 {
            let q = glam::Vec2::new((sx as f32 + 0.5) / n, (sy as f32 + 0.5) / n);
            let b = [
                (c[2].0 - c[1].0).perp_dot(q - c[1].0) / t.area,
                (c[0].0 - c[2].0).perp_dot(q - c[2].0) / t.area,
                (c[1].0 - c[0].0).perp_dot(q - c[0].0) / t.area,
            ];
            // Half-open on the shared diagonal (corners 1–2): a sample on it
            // belongs to the first triangle only.
            let inside = b.iter().all(|&x| x >= 0.0) && !(t.second && b[0] == 0.0);
            if !inside {
                continue;
            }
            let depth = b[0] * c[0].1 + b[1] * c[1].1 + b[2] * c[2].1;
            let inv_w = b[0] / c[0].2 + b[1] / c[1].2 + b[2] / c[2].2;
            let along = (b[0] * c[0].3 / c[0].2 + b[1] * c[1].3 / c[1].2 + b[2] * c[2].3 / c[2].2) / inv_w;
            // The density at the segment's ends, interpolated as the draw's
            // vertex outputs are.
            let density = (b[0] * c[0].4 / c[0].2 + b[1] * c[1].4 / c[1].2 + b[2] * c[2].4 / c[2].2) / inv_w;
            if !(0.0..=1.0).contains(&depth) {
                continue;
            }
            let alpha = scene.opacity * density;
            samples[((sy - top) * row_len + sx) as usize].push((depth, (scene.color)(along), alpha));
        }
    }
}

/// Sorts and composites each sample of a band and averages them into `pixels`
/// (the band's rows of the image), leaving `samples` empty for the next band.
fn resolve_band(samples: &mut [Vec<Fragment>], pixels: &mut [glam::Vec4], w: u32, background: Vec3) {
    let n = COMPOSITE_SAMPLES;
    let rows = pixels.len() as u32 / w;
    for (index, fragments) in samples.iter_mut().enumerate().take((rows * n * w * n) as usize) {
        fragments.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut sum = Vec3::ZERO;
        let mut transmittance = 1.0;
        for &(_, c, alpha) in fragments.iter() {
            sum += transmittance * alpha * c;
            transmittance *= 1.0 - alpha;
        }
        fragments.clear();
        let (sx, sy) = (index as u32 % (w * n), index as u32 / (w * n));
        let pixel = &mut pixels[((sy / n) * w + sx / n) as usize];
        *pixel += (sum + transmittance * background).extend(1.0 - transmittance) / (n * n) as f32;
    }
}

/// An sRGB-encoded RGBA8 image (as [`crate::headless::Offscreen::read_rgba8`]
/// reads it) as linear RGB per pixel.
pub fn linear_rgb(rgba8: &[u8]) -> Vec<Vec3> {
    let linear = |v: u8| {
        let c = f32::from(v) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    rgba8.chunks_exact(4).map(|p| Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))).collect()
}

/// Mean absolute difference of two linear RGB images in 8-bit sRGB steps, over
/// the pixels where either differs from `background` by more than one step
/// (the hair); and how many pixels that is. `None` when no pixel has hair or
/// the sizes differ.
pub fn srgb_error(image: &[Vec3], reference: &[Vec3], background: Vec3) -> Option<(f64, usize)> {
    srgb_error_stats(image, reference, background).map(|e| (e.mean, e.pixels))
}

/// How far an image is from a reference over its hair pixels ([`srgb_error_stats`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// Mean absolute difference per pixel (the mean of its three channels), 8-bit sRGB steps.
    pub mean: f64,
    /// The 95th percentile of the per-pixel differences (nearest rank), steps.
    pub p95: f64,
    /// Hair pixels compared.
    pub pixels: usize,
}

/// The per-pixel absolute difference of two linear RGB images in 8-bit sRGB
/// steps (the mean over the three channels), over the pixels where either
/// differs from `background` by more than one step (the hair): its mean and
/// 95th percentile. `None` when no pixel has hair or the sizes differ.
pub fn srgb_error_stats(image: &[Vec3], reference: &[Vec3], background: Vec3) -> Option<ImageError> {
    if image.len() != reference.len() {
        return None;
    }
    let srgb = |c: f32| if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 } * 255.0;
    let background = background.to_array().map(srgb);
    let mut errors = Vec::new();
    for (a, b) in image.iter().zip(reference) {
        let (a, b) = (a.to_array().map(srgb), b.to_array().map(srgb));
        let hair = (0..3).any(|i| (a[i] - background[i]).abs() > 1.0 || (b[i] - background[i]).abs() > 1.0);
        if hair {
            errors.push((0..3).map(|i| f64::from((a[i] - b[i]).abs())).sum::<f64>() / 3.0);
        }
    }
    if errors.is_empty() {
        return None;
    }
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    errors.sort_by(f64::total_cmp);
    // Nearest rank: the smallest difference at least 95 % of the pixels do not exceed.
    let rank = ((0.95 * errors.len() as f64).ceil() as usize).clamp(1, errors.len());
    Some(ImageError { mean, p95: errors[rank - 1], pixels: errors.len() })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A band's width and density: one hair stays one hair, no spacing leaves
    /// n widths, a wide spacing spreads to the bound (MAX_SPREAD × n widths).
    #[test]
    fn strand_bands_spread_within_their_bound() {
        let w = 1e-4;
        assert_eq!(strand_band(w, 1.0, 0.5), (w, 1.0), "one hair");
        let (width, density) = strand_band(w, 4.0, 0.0);
        assert!((width - 4.0 * w).abs() < 1e-9 && (density - (1.0 - 0.75f32.powi(4))).abs() < 1e-6);
        let (width, density) = strand_band(w, 4.0, 1.0);
        let most = crate::codes::band::MAX_SPREAD as f32 * 4.0 * w;
        assert!((width - most).abs() < 1e-9, "{width} vs {most}");
        assert!((density - (1.0 - (1.0 - w / most).powi(4))).abs() < 1e-6);
        let (width, _) = strand_band(w, 4.0, 6.0 * w);
        assert!((width - 4.5 * w).abs() < 1e-9, "(1 − 1/4) × 6 widths: {width}");
        assert_eq!(strand_band(0.0, 4.0, 0.0), (0.0, 0.0), "no width, no band");
    }

    /// The error's figures over hair pixels only: 20 hair pixels differing by
    /// 0..=19 steps (sRGB-exact values), background pixels equal in both left out.
    #[test]
    fn image_error_counts_hair_pixels_with_mean_and_p95() {
        let linear = |v: f32| {
            let c = v / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let background = Vec3::splat(linear(10.0));
        let mut image = vec![background; 30];
        let mut reference = vec![background; 30];
        for i in 0..20 {
            reference[i] = Vec3::splat(linear(100.0));
            image[i] = Vec3::splat(linear(100.0 + i as f32));
        }
        let e = srgb_error_stats(&image, &reference, background).expect("hair");
        assert_eq!(e.pixels, 20);
        assert!((e.mean - 9.5).abs() < 1e-3, "{e:?}");
        assert!((e.p95 - 18.0).abs() < 1e-3, "19 of 20 differ by at most 18: {e:?}");
        assert_eq!(srgb_error(&image, &reference, background).map(|e| e.1), Some(20));
        assert!(srgb_error_stats(&[background], &[background], background).is_none(), "no hair");
        assert!(srgb_error_stats(&image, &reference[1..], background).is_none(), "sizes differ");
    }

    /// Crossing hairs over several bands: one thread and three give the same
    /// image to the bit, and every band has hair in it.
    #[test]
    fn the_composite_does_not_depend_on_the_thread_count() {
        let hairs: Vec<Vec<glam::Vec4>> = (0..12)
            .map(|i| {
                let x = -0.5 + i as f32 / 11.0;
                (0..9)
                    .map(|k| {
                        glam::Vec4::new(
                            x + 0.05 * k as f32 * (i % 3) as f32,
                            0.6 - 0.15 * k as f32,
                            0.01 * i as f32,
                            k as f32 / 8.0,
                        )
                    })
                    .collect()
            })
            .collect();
        let camera = crate::render::Camera::look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, 0.8, 4.0 / 3.0, 0.1, 10.0)
            .expect("camera");
        let view_proj = camera.projection * camera.view;
        let color = |t: f32| Vec3::new(1.0 - t, 0.5, t);
        let scene = CompositeScene {
            hairs: &hairs,
            view_proj,
            camera: Vec3::new(0.0, 0.0, 2.0),
            extent: (40, 30),
            widths: (0.01, 0.004),
            represented_hairs: 3.0,
            band_spacing: (0.02, 0.05),
            opacity: 0.7,
            color: &color,
            background: Vec3::splat(0.1),
        };
        let one = composite_on(&scene, 1);
        let three = composite_on(&scene, 3);
        assert!(one.iter().zip(&three).all(|(a, b)| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)));
        for band in one.chunks(40 * BAND_ROWS as usize) {
            assert!(band.iter().any(|p| p.w > 0.0), "a band without hair: the scene does not test the bands");
        }
        // An empty extent is an empty image, not a panic.
        for extent in [(0, 30), (40, 0)] {
            assert!(composite_on(&CompositeScene { extent, ..scene }, 2).is_empty(), "{extent:?}");
        }
    }

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
