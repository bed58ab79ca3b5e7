//! The CPU reference of the hair's motion vectors ([`hair_motion`]), re-exported
//! by [`super::reference`].

use glam::{Mat4, Vec2, Vec3, Vec4};

/// What [`hair_motion`] draws: the drawn hairs of two frames, their width and
/// opacity, and the two frames' cameras.
pub struct MotionScene<'a> {
    /// This frame's drawn hairs: per hair its vertices root to tip, xyz the
    /// position (m) and w the hair's width factor (as
    /// [`super::Renderer::read_hairs`] reads them).
    pub now: &'a [Vec<Vec4>],
    /// The same hairs' vertices in the previous frame (xyz; as many).
    pub before: &'a [Vec<Vec4>],
    /// Each vertex's t along its hair (0 at the root, 1 at the tip).
    pub along: &'a [Vec<f32>],
    /// World → clip of this frame as drawn, its jitter included: which pixels a
    /// hair covers.
    pub drawn: Mat4,
    /// World → clip of this frame and of the previous one, without jitter.
    pub now_view_proj: Mat4,
    /// See `now_view_proj`.
    pub before_view_proj: Mat4,
    /// World size of one target pixel at distance 1: 2 tan(fov_y / 2) / height.
    pub pixel: f32,
    /// The target's width and height, pixels.
    pub extent: (u32, u32),
    /// Drawn pixels per target pixel along each axis: 1, or 2 supersampled
    /// (a target pixel takes the motion of its drawn pixel whose picked hair
    /// is nearest).
    pub samples: u32,
    /// Width of one hair at the root and at the tip, meters (each drawn
    /// strand one hair).
    pub widths: (f32, f32),
    /// Opacity of a strand where it covers a whole pixel.
    pub opacity: f32,
    /// Which fragment a pixel's motion follows.
    pub pick: MotionPick,
}

/// Which fragment of a pixel its motion follows.
#[derive(Debug, Clone, Copy)]
pub enum MotionPick {
    /// The one at which the fragments, composited front to back, first reach
    /// this opacity ([`super::Transparency::Exact`]).
    Accumulated(f32),
    /// The nearest of at least this alpha ([`super::Transparency::Fast`]: 0.5).
    NearestAtLeast(f32),
    /// The nearest whose ribbon covers the pixel's centre, a ribbon being at
    /// least this many pixels wide ([`super::Transparency::Off`]:
    /// [`super::HairMaterial::least_pixel_width`]).
    NearestRibbon(f32),
}

/// One fragment: forward depth, alpha, motion, and where the pixel's centre
/// lies: 0 within the segment's true half width, else its distance from the
/// centre line, pixels.
type Fragment = (f32, f32, Vec2, f32);

/// The motion of each pixel's hair, rows from the top, in pixels, this frame
/// minus the previous one, by the definition the renderer follows
/// ([`super::MotionParams`]): every segment covers the pixels whose centre
/// projects onto its screen span (half-open) within its half width plus half
/// a pixel, with alpha `opacity` × the length of its cross-section inside
/// the pixel; a pixel's fragments sorted by depth and composited front to
/// back, the first to bring the opacity to `threshold` gives the motion of
/// its point — this frame's position at the pixel against the same point of
/// the hair before, each projected by its frame's camera. `None` where the
/// fragments never reach the threshold. Segments reaching behind the camera
/// are left out (test scenes keep in front of it).
///
/// # Panics
/// Where `before` and `along` do not have `now`'s hairs and vertices.
pub fn hair_motion(scene: &MotionScene<'_>) -> Vec<Option<Vec2>> {
    let (fragments, (w, _)) = fragments_of(scene);
    let picked: Vec<Option<(f32, Vec2)>> = fragments
        .into_iter()
        .map(|mut f| {
            f.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut transmittance = 1.0;
            f.into_iter().find_map(|(z, alpha, motion, outside)| {
                transmittance *= 1.0 - alpha;
                let opaque = match scene.pick {
                    MotionPick::Accumulated(threshold) => 1.0 - transmittance >= threshold,
                    MotionPick::NearestAtLeast(least) => alpha >= least,
                    MotionPick::NearestRibbon(least) => outside <= least * 0.5,
                };
                opaque.then_some((z, motion))
            })
        })
        .collect();
    let n = scene.samples.max(1);
    (0..scene.extent.0 * scene.extent.1)
        .map(|i| {
            let (x, y) = (i % scene.extent.0, i / scene.extent.0);
            let samples = (0..n * n).filter_map(|k| picked[((y * n + k / n) * w + x * n + k % n) as usize]);
            samples.min_by(|a, b| a.0.total_cmp(&b.0)).map(|(_, motion)| motion)
        })
        .collect()
}

/// Per pixel of the target (rows from the top) the motion of every fragment
/// [`hair_motion`] composites there (of each of its drawn pixels when
/// supersampled), in no set order: what any choice among a pixel's hairs
/// could give.
///
/// # Panics
/// As [`hair_motion`].
pub fn hair_motions_at(scene: &MotionScene<'_>) -> Vec<Vec<Vec2>> {
    let (fragments, (w, _)) = fragments_of(scene);
    let n = scene.samples.max(1);
    (0..scene.extent.0 * scene.extent.1)
        .map(|i| {
            let (x, y) = (i % scene.extent.0, i / scene.extent.0);
            (0..n * n)
                .flat_map(|k| fragments[((y * n + k / n) * w + x * n + k % n) as usize].iter().map(|f| f.2))
                .collect()
        })
        .collect()
}

/// Every drawn pixel's fragments (rows from the top) and the drawn extent.
fn fragments_of(scene: &MotionScene<'_>) -> (Vec<Vec<Fragment>>, (u32, u32)) {
    let n = scene.samples.max(1);
    let (w, h) = (scene.extent.0 * n, scene.extent.1 * n);
    let mut fragments: Vec<Vec<Fragment>> = vec![Vec::new(); (w * h) as usize];
    for (hair, now) in scene.now.iter().enumerate() {
        for i in 0..now.len().saturating_sub(1) {
            segment(scene, (w, h), (hair, i), &mut fragments);
        }
    }
    (fragments, (w, h))
}

/// Adds the fragments of segment `i` of hair `hair`, drawn into `w` × `h`
/// pixels, to `out`.
fn segment(scene: &MotionScene<'_>, (w, h): (u32, u32), (hair, i): (usize, usize), out: &mut [Vec<Fragment>]) {
    let pixel = scene.pixel * scene.extent.1 as f32 / h as f32;
    let size = Vec2::new(w as f32, h as f32);
    let now = &scene.now[hair];
    let last = i + 2 == now.len();
    let ends = [now[i], now[i + 1]];
    let clip = ends.map(|p| scene.drawn * p.truncate().extend(1.0));
    if clip.iter().any(|c| !(c.w > 1e-6 && c.z >= 0.0 && c.z <= c.w)) {
        return;
    }
    let screen = clip.map(|c| (Vec2::new(c.x, c.y) / c.w * 0.5 + 0.5) * size);
    let depth = clip.map(|c| c.z / c.w);
    // Half the true width, m.
    let half = [0, 1].map(|k| {
        let t = scene.along[hair][i + k];
        0.5 * (scene.widths.0 + (scene.widths.1 - scene.widths.0) * t) * ends[k].w
    });
    let along = screen[1] - screen[0];
    let len = along.length();
    if len.is_nan() || len <= 1e-4 {
        return;
    }
    let dir = along / len;
    let normal = Vec2::new(-dir.y, dir.x);
    // Half the true width in pixels at u: over the size of a pixel at that view depth.
    let half_px = |u: f32| (half[0] + (half[1] - half[0]) * u) / (pixel * (clip[0].w + (clip[1].w - clip[0].w) * u));
    let reach = half_px(0.0).max(half_px(1.0)) + 0.5;
    let lo = (screen[0].min(screen[1]) - Vec2::splat(reach)).floor().max(Vec2::ZERO);
    let hi = (screen[0].max(screen[1]) + Vec2::splat(reach)).ceil().min(size);
    for y in lo.y as u32..hi.y as u32 {
        for x in lo.x as u32..hi.x as u32 {
            let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let s = (q - screen[0]).dot(dir) / len;
            if !(0.0..=1.0).contains(&s) || (s == 1.0 && !last) {
                continue;
            }
            let inv_w = 1.0 / clip[0].w + (1.0 / clip[1].w - 1.0 / clip[0].w) * s;
            let u = s / clip[1].w / inv_w;
            let half_width = half_px(u);
            let d = (q - screen[0]).dot(normal).abs();
            let cover = ((d + 0.5).min(half_width) - (d - 0.5).max(-half_width)).clamp(0.0, 1.0);
            let alpha = scene.opacity * cover;
            if alpha < 1.0 / 1024.0 {
                continue;
            }
            let z = depth[0] + (depth[1] - depth[0]) * s;
            // Outside the ribbon by d − its half width; inside a least width w
            // where d ≤ w / 2 (NearestRibbon compares with that).
            let outside = if d <= half_width { 0.0 } else { d };
            out[(y * w + x) as usize].push((z, alpha, motion(scene, hair, i, u), outside));
        }
    }
}

/// The motion in pixels of the point at `u` along segment `i` of hair `hair`.
fn motion(scene: &MotionScene<'_>, hair: usize, i: usize, u: f32) -> Vec2 {
    let at = |points: &[Vec4]| points[i].truncate().lerp(points[i + 1].truncate(), u);
    let ndc = |m: Mat4, p: Vec3| {
        let c = m * p.extend(1.0);
        Vec2::new(c.x, c.y) / c.w
    };
    let now = ndc(scene.now_view_proj, at(&scene.now[hair]));
    let before = ndc(scene.before_view_proj, at(&scene.before[hair]));
    (now - before) * 0.5 * Vec2::new(scene.extent.0 as f32, scene.extent.1 as f32)
}
