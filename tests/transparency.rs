//! Transparent hair (`RenderParams::transparency`) against the exact CPU
//! reference `render::reference::composite_strands`, under validation.
//!
//! The scenes are unlit (no lights, ambient 1), so a fragment's colour is the
//! albedo at its t along the hair and the reference needs no shading model: what
//! is compared is coverage and compositing.

use crate::common;
use glam::Vec3;
use vkhair::groom::scenes;
use vkhair::headless::{Offscreen, Submit};
use vkhair::render::reference::{composite_strands, linear_rgb, srgb_error, CompositeScene};
use vkhair::render::{Camera, HairMaterial, LodParams, Raster, RenderParams, Renderer, Transparency};
use vkhair::sim::{HairSim, RigidTransform, SimParams};
use vkhair::Groom;

use common::Gpu;

const W: u32 = 160;
const H: u32 = 120;
const ROOT: Vec3 = Vec3::new(0.9, 0.2, 0.05);
const TIP: Vec3 = Vec3::new(0.1, 0.5, 0.9);
const BACKGROUND: Vec3 = Vec3::new(0.02, 0.02, 0.02);

/// The unlit material: albedo from ROOT to TIP, ambient 1, `width` metres wide.
fn material(width: f32, opacity: f32) -> HairMaterial {
    HairMaterial {
        root_color: ROOT,
        tip_color: TIP,
        ambient: 1.0,
        root_width: width,
        tip_width: width,
        opacity,
        ..HairMaterial::default()
    }
}

/// One hair per key hair, on the key hair itself (no clump offset), two smoothed
/// segments per key segment, no level of detail.
fn params(transparency: Transparency) -> RenderParams {
    RenderParams {
        hairs_per_key: 1,
        smoothing_level: 2,
        clump_width: 0.0,
        lod: LodParams { enabled: false, ..LodParams::default() },
        transparency,
        ..RenderParams::default()
    }
}

/// Both rasterisers of the exact mode.
const RASTERS: [Raster; 2] = [Raster::Hardware, Raster::Compute];

/// [`params`] in the exact mode, its strands rasterised by `raster`.
fn exact(raster: Raster) -> RenderParams {
    RenderParams { raster, ..params(Transparency::Exact) }
}

/// The camera of the small scenes: the thesis head from the front, 0.9 m away.
fn camera() -> Camera {
    common::front_camera(0.9, (W, H))
}

struct Scene {
    sim: HairSim,
    renderer: Renderer,
    offscreen: Offscreen,
    camera: Camera,
}

fn scene(gpu: &Gpu, groom: &Groom, params: &RenderParams, material: &HairMaterial) -> Scene {
    let sim = HairSim::new(gpu.ctx(), groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let mut renderer = Renderer::new(gpu.ctx(), &sim, params).expect("renderer");
    renderer.set_material(material).expect("material");
    Scene { sim, renderer, offscreen: Offscreen::new(gpu.ctx(), W, H).expect("offscreen"), camera: camera() }
}

/// Draws the hair over BACKGROUND; returns linear RGB per pixel.
fn draw(gpu: &Gpu, s: &mut Scene) -> Vec<Vec3> {
    draw_then(gpu, s, BACKGROUND, None)
}

/// The exact image of the hairs the renderer drew (read back), by the CPU reference.
fn reference(s: &Scene, width: f32, opacity: f32) -> Vec<Vec3> {
    rgb(&reference_bands(s, width, 1.0, s.renderer.strand_spacing(), opacity))
}

/// The CPU reference's image of the hairs the renderer drew (read back), each
/// a band standing for `n` hairs `width` m wide whose drawn strands lie
/// `band_spacing` apart (root, tip): linear RGB over BACKGROUND and hair alpha.
fn reference_bands(s: &Scene, width: f32, n: f32, band_spacing: (f32, f32), opacity: f32) -> Vec<glam::Vec4> {
    let strands = s.renderer.read_strands().expect("hairs");
    let color = |t: f32| ROOT.lerp(TIP, t);
    composite_strands(&CompositeScene {
        hairs: &strands,
        view_proj: s.camera.projection * s.camera.view,
        camera: s.camera.position(),
        extent: (W, H),
        widths: (width, width),
        represented_hairs: n,
        band_spacing,
        opacity,
        color: &color,
        background: BACKGROUND,
    })
}

/// Real hairs each strand of [`sparse_band_scene`] stands for.
const SPARSE_HAIRS: f32 = 6.0;

/// Sparse strands standing for [`SPARSE_HAIRS`] hairs `width` wide each: 300
/// key hairs grown on the thesis scalp, 4 strands a key hair in clumps 0.1
/// wide, in the exact mode with K = 32; the scene and its parameters.
fn sparse_band_scene(gpu: &Gpu, width: f32) -> (Scene, RenderParams) {
    let groom = common::grown_groom(300, 8, 5);
    let m = HairMaterial { represented_hairs: SPARSE_HAIRS, ..material(width, OPACITY) };
    let mut p = RenderParams { hairs_per_key: 4, clump_width: 0.1, ..params(Transparency::Exact) };
    p.oit.sorted_fragments = 32;
    (scene(gpu, &groom, &p, &m), p)
}

/// The colour of each pixel of a reference image, without its alpha.
fn rgb(image: &[glam::Vec4]) -> Vec<Vec3> {
    image.iter().map(|p| p.truncate()).collect()
}

/// Mean absolute error in 8-bit sRGB steps over the pixels where either image has hair.
fn mae(image: &[Vec3], reference: &[Vec3]) -> f64 {
    let (error, count) = srgb_error(image, reference, BACKGROUND).expect("images of one size with hair");
    assert!(count > 100, "only {count} hair pixels: the scene shows no hair");
    error
}

/// A pixel-wide scene: 300 key hairs grown on the thesis scalp, 0.8 mm wide
/// (about a third of a pixel at this distance), opacity 0.8.
const WIDTH: f32 = 0.0008;
const OPACITY: f32 = 0.8;

#[test]
fn each_mode_against_the_exact_reference() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let m = material(WIDTH, OPACITY);
    let mut errors = Vec::new();
    let modes = [
        params(Transparency::Off),
        params(Transparency::Fast),
        exact(Raster::Hardware),
        exact(Raster::Compute),
        exact(Raster::Tiles),
    ];
    for p in modes {
        let mode = (p.transparency, p.raster);
        let mut s = scene(&gpu, &groom, &p, &m);
        let image = draw(&gpu, &mut s);
        let truth = reference(&s, WIDTH, OPACITY);
        let e = mae(&image, &truth);
        let ink = |img: &[Vec3]| img.iter().map(|c| (*c - BACKGROUND).element_sum()).sum::<f32>();
        println!("{mode:?}: ink {:.1}, reference ink {:.1}", ink(&image), ink(&truth));
        println!("{mode:?}: mean absolute error against the reference {e:.2} (8-bit sRGB steps)");
        errors.push(e);
    }
    let [off, fast, hardware, compute, tiles] = [errors[0], errors[1], errors[2], errors[3], errors[4]];
    for (raster, exact) in [("hardware", hardware), ("compute", compute), ("tiles", tiles)] {
        assert!(exact <= 0.5 * off, "exact's error ({raster}) {exact:.2} is not at most half of off's {off:.2}");
    }
    assert!(fast < off, "fast's error {fast:.2} is not below off's {off:.2}");
}

/// Strands standing for several hairs, sparser than the hairs they stand for:
/// each is drawn as a band spread over the space to its neighbours
/// (`Renderer::strand_spacing`, `reference::strand_band`), and the exact mode
/// matches the CPU reference of those bands, not of bands n hair widths wide.
#[test]
fn sparse_strands_are_drawn_as_bands_spread_to_their_neighbours() {
    let gpu = Gpu::new();
    // Bands over two pixels wide (a pixel is about 5.5 mm here), so that the
    // exact mode's coverage is exact.
    let (width, n) = (0.001, SPARSE_HAIRS);
    let (mut s, p) = sparse_band_scene(&gpu, width);
    let image = draw(&gpu, &mut s);
    let spacing = s.renderer.strand_spacing();
    let root_share = (std::f32::consts::PI / 4.0).sqrt() * 0.1;
    assert!(
        (spacing.0 - root_share * p.root_width).abs() < 1e-7 && (spacing.1 - root_share * p.tip_width).abs() < 1e-7
    );
    let (band, density) = vkhair::render::reference::strand_band(width, n, spacing.0);
    assert!(band > n * width, "the spread is wider than the hairs side by side: {band} vs {}", n * width);
    assert!((density - (1.0 - (1.0 - width / band).powf(n))).abs() < 1e-6);
    let reference_with = |band_spacing: (f32, f32)| rgb(&reference_bands(&s, width, n, band_spacing, OPACITY));
    let spread = mae(&image, &reference_with(spacing));
    let unspread = mae(&image, &reference_with((0.0, 0.0)));
    println!("error against the spread bands {spread:.2}, against bands n hairs wide {unspread:.2} (8-bit sRGB steps)");
    // lavapipe: 2.5 to 3.0 against 11.2 to 11.4 (the ribbons' joints overlap
    // where the reference's quads meet edge to edge, and beyond K = 32 the
    // tail's order follows the atomics).
    assert!(spread < 4.0, "{spread:.2}");
    assert!(unspread > 2.5 * spread, "{unspread:.2} vs {spread:.2}");
}

#[test]
fn the_exact_image_does_not_depend_on_strand_order() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(200, 8, 9);
    // Every strand, in another order: the last first, odd before even.
    let order: Vec<usize> = (0..groom.strand_count())
        .rev()
        .filter(|i| i % 2 == 1)
        .chain((0..groom.strand_count()).filter(|i| i % 2 == 0))
        .collect();
    let shuffled = groom.select(&order).expect("shuffle");
    for raster in RASTERS {
        // K large enough to cover the depth complexity of this sparse scene.
        let mut p = exact(raster);
        p.oit.sorted_fragments = 32;
        let m = material(WIDTH, OPACITY);
        let mut a = scene(&gpu, &groom, &p, &m);
        let mut b = scene(&gpu, &shuffled, &p, &m);
        let (first, second) = (draw(&gpu, &mut a), draw(&gpu, &mut b));
        order_independent(&first, &second, raster);
    }
}

/// Two images of the same strands drawn in two orders differ by at most one
/// 8-bit step anywhere, and show hair.
fn order_independent(first: &[Vec3], second: &[Vec3], raster: Raster) {
    let differing = first.iter().zip(second).filter(|(x, y)| (**x - **y).abs().max_element() > 0.0).count();
    let worst = first
        .iter()
        .zip(second)
        .map(|(x, y)| {
            let to8 = |c: Vec3| c.to_array().map(|v| (v.powf(1.0 / 2.2) * 255.0).round());
            let (x, y) = (to8(*x), to8(*y));
            (0..3).map(|i| (x[i] - y[i]).abs()).fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max);
    println!("{raster:?}: shuffled strands: {differing} pixels differ, by at most {worst} steps");
    assert!(worst <= 1.0, "{raster:?}: shuffling the strands changed a pixel by {worst} steps of 255");
    assert!(first.iter().filter(|c| (**c - BACKGROUND).abs().max_element() > 0.01).count() > 100, "no hair drawn");
}

#[test]
fn an_overflowing_pool_blends_the_rest_unsorted_and_says_so() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let m = material(WIDTH, OPACITY);
    for raster in RASTERS {
        let mut s = scene(&gpu, &groom, &exact(raster), &m);
        assert_eq!(s.renderer.transparency_stats(), None, "stats before any frame");
        let full = draw(&gpu, &mut s);
        let needed = s.renderer.transparency_stats().expect("stats of an exact frame");
        assert_eq!(needed.overflowed, 0, "{raster:?}: the default pool overflowed: {needed:?}");
        assert!(needed.fragments > 1000, "{raster:?}: too few fragments to test with: {needed:?}");
        // A pool of about 1 % of the fragments the scene needs (the least pool allowed).
        let mut p = exact(raster);
        p.oit.fragments_per_pixel = (0.01 * needed.fragments as f32 / (W * H) as f32).max(0.01);
        s.renderer.set_params(&p).expect("params");
        let starved = draw(&gpu, &mut s);
        let stats = s.renderer.transparency_stats().expect("stats");
        println!("{raster:?}: pool of {} for {} fragments: {stats:?}", stats.capacity, needed.fragments);
        assert!(stats.capacity * 50 < needed.fragments, "{raster:?}: the pool is not starved: {stats:?}");
        assert_eq!(stats.fragments, needed.fragments, "{raster:?}: the same fragments are offered");
        assert_eq!(stats.stored, stats.capacity, "{raster:?}: the pool is filled");
        assert_eq!(
            stats.overflowed,
            needed.fragments - stats.capacity,
            "{raster:?}: the rest is counted as overflowed"
        );
        assert!(starved.iter().all(|c| c.is_finite() && c.max_element() <= 1.0), "garbage in the starved image");
        // Nothing is lost: the fragments beyond the pool are blended unsorted, so
        // the starved image has the same hair pixels and stays near the reference.
        let hair = |img: &[Vec3]| img.iter().filter(|c| (**c - BACKGROUND).abs().max_element() > 0.01).count();
        let (full_hair, starved_hair) = (hair(&full), hair(&starved));
        let truth = reference(&s, WIDTH, OPACITY);
        let (full_error, starved_error) = (mae(&full, &truth), mae(&starved, &truth));
        println!(
            "{raster:?}: hair pixels: {full_hair} with the full pool, {starved_hair} with 1 %; error {full_error:.2} and {starved_error:.2} steps"
        );
        assert_eq!(starved_hair, full_hair, "{raster:?}: hair pixels lost to the full pool");
        assert!(
            starved_error < 1.5 * full_error,
            "{raster:?}: the starved image is far from the reference: {starved_error:.2} steps"
        );
        // A fast-mode frame keeps no lists: nothing to report.
        s.renderer.set_params(&params(Transparency::Fast)).expect("params");
        draw(&gpu, &mut s);
        assert_eq!(s.renderer.transparency_stats(), None, "stats after a fast-mode frame");
    }
}

/// Darkening (sum over the image of background − pixel, linear) of one straight
/// black strand across a white background, `pixels` wide.
fn darkening(gpu: &Gpu, pixels: f32) -> f32 {
    let center = scenes::THESIS_HEAD_CENTER;
    let distance = 0.9;
    // A horizontal strand through the view's centre, at the camera's distance.
    let strand: Vec<Vec3> = (0..8).map(|i| center + Vec3::new(-0.15 + 0.3 * i as f32 / 7.0, 0.0, 0.0)).collect();
    let groom = Groom::from_strands(&[strand]).expect("strand");
    let camera = Camera::look_at(center + Vec3::new(0.0, 0.0, distance), center, 0.7, W as f32 / H as f32, 0.05, 10.0)
        .expect("camera");
    let pixel = 2.0 * (0.35f32).tan() * distance / H as f32;
    let m =
        HairMaterial { root_color: Vec3::ZERO, tip_color: Vec3::ZERO, opacity: 1.0, ..material(pixels * pixel, 1.0) };
    let mut s = scene(gpu, &groom, &params(Transparency::Exact), &m);
    s.camera = camera;
    draw_then(gpu, &mut s, Vec3::ONE, None).iter().map(|c| 1.0 - c.y).sum()
}

#[test]
fn a_quarter_pixel_strand_darkens_a_quarter_of_a_one_pixel_strand() {
    let gpu = Gpu::new();
    let (quarter, one) = (darkening(&gpu, 0.25), darkening(&gpu, 1.0));
    let ratio = quarter / one;
    println!("darkening: 0.25 px {quarter:.2}, 1 px {one:.2}, ratio {ratio:.3}");
    assert!(one > 40.0, "the 1-px strand darkens only {one}");
    assert!((ratio - 0.25).abs() <= 0.025, "a 0.25-px strand darkens {ratio:.3} of a 1-px one, not 0.25 ± 10 %");
}

/// Fraction of the crown's pixels (within half the head's radius of its centre,
/// seen from above) where the reference image of `groom`'s hairs, drawn as
/// strands standing for `represented_hairs` hairs each, is at least half opaque.
fn crown_coverage(gpu: &Gpu, groom: &Groom, hairs_per_key: u32, represented_hairs: f32) -> f32 {
    let center = scenes::THESIS_HEAD_CENTER;
    let radius = scenes::THESIS_HEAD_RADIUS;
    let p = RenderParams { hairs_per_key, clump_width: 0.02, ..params(Transparency::Exact) };
    let m = HairMaterial::default();
    let mut s = scene(gpu, groom, &p, &m);
    // From above (a little in front, so +Y can stay the camera's up).
    s.camera = Camera::look_at(center + Vec3::new(0.0, 0.6, 0.06), center, 0.7, W as f32 / H as f32, 0.05, 10.0)
        .expect("camera");
    // Prepares the interpolated hairs for this camera.
    draw(gpu, &mut s);
    let strands = s.renderer.read_strands().expect("hairs");
    let image = composite_strands(&CompositeScene {
        hairs: &strands,
        view_proj: s.camera.projection * s.camera.view,
        camera: s.camera.position(),
        extent: (W, H),
        widths: (m.root_width, m.tip_width),
        represented_hairs,
        band_spacing: s.renderer.strand_spacing(),
        opacity: m.opacity,
        color: &|_| Vec3::ONE,
        background: Vec3::ZERO,
    });
    let project = |q: Vec3| {
        let c = s.camera.projection * s.camera.view * q.extend(1.0);
        ((c.truncate().truncate() / c.w) * 0.5 + 0.5) * glam::Vec2::new(W as f32, H as f32)
    };
    let (mid, edge) = (project(center), project(center + Vec3::new(0.5 * radius, 0.0, 0.0)));
    let crown = (edge - mid).length();
    let mut inside = 0usize;
    let mut covered = 0usize;
    for (i, px) in image.iter().enumerate() {
        let xy = glam::Vec2::new((i as u32 % W) as f32 + 0.5, (i as u32 / W) as f32 + 0.5);
        if (xy - mid).length() <= crown {
            inside += 1;
            covered += usize::from(px.w >= 0.5);
        }
    }
    assert!(inside > 50, "the crown covers only {inside} pixels");
    covered as f32 / inside as f32
}

#[test]
fn strands_standing_for_a_full_head_cover_the_scalp() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(400, 8, 3);
    let hairs_per_key = 4;
    // A full head of 100,000 hairs over the 1,600 strands drawn (the tool's default).
    let full = crown_coverage(&gpu, &groom, hairs_per_key, 100_000.0 / (400.0 * hairs_per_key as f32));
    let single = crown_coverage(&gpu, &groom, hairs_per_key, 1.0);
    println!(
        "crown pixels at least half covered: {:.1} % standing for a full head, {:.1} % one hair each",
        100.0 * full,
        100.0 * single
    );
    assert!(full >= 0.75, "strands standing for a full head cover only {:.1} % of the crown", 100.0 * full);
}

/// Draws the hair over `background`, then (if given) a green mesh the host draws
/// after it; returns linear RGB per pixel.
fn draw_then(gpu: &Gpu, s: &mut Scene, background: Vec3, after: Option<&vkhair::headless::MeshDrawer>) -> Vec<Vec3> {
    let host = common::HostFrame { clear: background, before: None, after };
    let rgba = common::draw_frame(gpu, (&s.sim, &mut s.renderer), &s.offscreen, &s.camera, &host);
    linear_rgb(&rgba)
}

/// Transparent hair writes the depth of its nearest half-opaque layer: a sphere
/// the host draws afterwards behind the hair is hidden where the hair is dense
/// and shows through elsewhere. Through the supersampling images the hair is
/// drawn too, and (as for opaque hair) the host's depth is left unwritten.
#[test]
fn later_host_geometry_behind_transparent_hair_is_hidden_where_the_hair_is_dense() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    // Dense strands (a band of 30 hairs) so that many pixels are more than half covered.
    let m = HairMaterial { represented_hairs: 30.0, ..material(WIDTH, 1.0) };
    let behind = scenes::THESIS_HEAD_CENTER - Vec3::new(0.0, 0.0, 1.0);
    let sphere = vkhair::groom::mesh::TriMesh::uv_sphere(behind, 0.8, 16, 24).expect("sphere");
    let mesh = vkhair::headless::MeshDrawer::new(gpu.ctx(), &sphere).expect("mesh");
    for (supersampling, raster) in [false, true].into_iter().flat_map(|ss| RASTERS.map(|r| (ss, r))) {
        let p = RenderParams { supersampling, ..exact(raster) };
        let mut s = scene(&gpu, &groom, &p, &m);
        let hair = draw_then(&gpu, &mut s, BACKGROUND, None);
        let with_sphere = draw_then(&gpu, &mut s, BACKGROUND, Some(&mesh));
        let green = |c: &Vec3| c.y > 0.05 && c.y > 4.0 * c.x;
        // Pixels well inside the sphere's outline (it spans about 75 px around its centre).
        let c = s.camera.projection * s.camera.view * behind.extend(1.0);
        let centre = ((c.truncate().truncate() / c.w) * 0.5 + 0.5) * glam::Vec2::new(W as f32, H as f32);
        let inside = |i: usize| {
            let xy = glam::Vec2::new((i as u32 % W) as f32 + 0.5, (i as u32 / W) as f32 + 0.5);
            (xy - centre).length() < 50.0
        };
        // Pixels the hair covers well (alpha ≳ 2/3: colours reach about 0.9), and hairless ones.
        let dense: Vec<usize> =
            (0..hair.len()).filter(|&i| inside(i) && (hair[i] - BACKGROUND).max_element() > 0.6).collect();
        let bare: Vec<usize> =
            (0..hair.len()).filter(|&i| inside(i) && (hair[i] - BACKGROUND).max_element() < 0.001).collect();
        let hidden = dense.iter().filter(|&&i| !green(&with_sphere[i])).count();
        let shown = bare.iter().filter(|&&i| green(&with_sphere[i])).count();
        println!(
            "{raster:?}, supersampling {supersampling}: {hidden} of {} dense hair pixels hide the sphere; it shows in {shown} of {} hairless pixels",
            dense.len(),
            bare.len()
        );
        assert!(dense.len() > 100, "too few dense hair pixels: {}", dense.len());
        if supersampling {
            // The supersampling resolve tests the host's depth but does not write it
            // (as for opaque hair): the sphere drawn afterwards covers the hair.
            assert_eq!(hidden, 0, "the supersampled hair wrote the host's depth");
            continue;
        }
        assert!(hidden * 10 >= dense.len() * 9, "the sphere shows through dense hair: {hidden} of {}", dense.len());
        assert!(shown == bare.len() && bare.len() > 100, "the sphere is hidden where there is no hair");
    }
}

/// Prepares and draws `s`'s hair into `target` (a target the test altered,
/// which the draw may refuse before recording anything with it); the draw's result.
fn draw_into(gpu: &Gpu, s: &mut Scene, target: &vkhair::render::RenderTarget) -> vkhair::Result<()> {
    let mut result = Ok(());
    gpu.ctx()
        .run_commands("an altered target", |cmd| {
            // SAFETY: a recording command buffer of the context's device; a target
            // the draw refuses is refused before anything is recorded with it.
            result = unsafe {
                s.renderer
                    .record_prepare(cmd, &s.sim, Some(&s.camera), None)
                    .and_then(|_| s.renderer.record_draw(cmd, common::next_frame(), target, &s.camera, None))
            };
        })
        .expect("submit");
    result
}

/// Hair behind what the host drew before it is hidden, fragment by fragment,
/// by both rasterisers (the compute one reads the host's depth through
/// `RenderTarget::depth_image`): a sphere in front of the head's lower half
/// hides the hair there and leaves the rest as drawn without it. A compute
/// frame on a target whose depth image is not given, or of a depth-stencil
/// format, is refused before it records.
#[test]
fn hair_behind_host_geometry_drawn_first_is_hidden_by_both_rasterisers() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let m = HairMaterial { represented_hairs: 4.0, ..material(WIDTH, OPACITY) };
    // A sphere between the camera and the lower half of the head.
    let front = scenes::THESIS_HEAD_CENTER + Vec3::new(0.0, -0.12, 0.45);
    let sphere = vkhair::groom::mesh::TriMesh::uv_sphere(front, 0.1, 16, 24).expect("sphere");
    let mesh = vkhair::headless::MeshDrawer::new(gpu.ctx(), &sphere).expect("mesh");
    let green = |c: &Vec3| c.y > 0.05 && c.y > 4.0 * c.x && c.y > 4.0 * c.z;
    for raster in [Raster::Hardware, Raster::Compute, Raster::Tiles] {
        let mut s = scene(&gpu, &groom, &exact(raster), &m);
        let alone = draw(&gpu, &mut s);
        let host = common::HostFrame { clear: BACKGROUND, before: Some(&mesh), after: None };
        let rgba = common::draw_frame(&gpu, (&s.sim, &mut s.renderer), &s.offscreen, &s.camera, &host);
        let occluded = linear_rgb(&rgba);
        let hair = |c: &Vec3| (*c - BACKGROUND).abs().max_element() > 0.02;
        let sphere_pixels: Vec<usize> = (0..occluded.len()).filter(|&i| green(&occluded[i])).collect();
        let behind = sphere_pixels.iter().filter(|&&i| hair(&alone[i])).count();
        // Where the sphere shows, it is pure: no hair blended over it.
        let tinted = sphere_pixels.iter().filter(|&&i| occluded[i].x > 0.01 || occluded[i].z > 0.01).count();
        let elsewhere: Vec<usize> = (0..occluded.len()).filter(|&i| !green(&occluded[i]) && hair(&alone[i])).collect();
        let changed = elsewhere.iter().filter(|&&i| (occluded[i] - alone[i]).abs().max_element() > 0.02).count();
        println!(
            "{raster:?}: the sphere covers {} pixels, {behind} with hair behind it; {tinted} tinted; {changed} of {} other hair pixels changed",
            sphere_pixels.len(),
            elsewhere.len()
        );
        assert!(behind > 300, "{raster:?}: too little hair behind the sphere to test with: {behind}");
        assert_eq!(tinted, 0, "{raster:?}: hair behind the sphere was drawn over it");
        // Pixels beside the sphere's outline share it: a few change.
        assert!(changed * 50 < elsewhere.len(), "{raster:?}: {changed} hair pixels away from the sphere changed");
    }
    // The compute rasteriser needs the depth image behind the depth view.
    let mut s = scene(&gpu, &groom, &exact(Raster::Compute), &m);
    let mut target = s.offscreen.target();
    target.depth_image = vkhair::ash::vk::Image::null();
    match draw_into(&gpu, &mut s, &target) {
        Err(vkhair::Error::Incompatible { what: "render target", reason }) => {
            assert!(reason.contains("depth_image"), "the error does not name the field: {reason}")
        }
        other => panic!("a compute frame without the depth image was not refused: {other:?}"),
    }
    // A depth-stencil target is refused before anything is recorded, naming
    // the rasteriser that draws it.
    let mut target = s.offscreen.target();
    target.depth_format = vkhair::ash::vk::Format::D24_UNORM_S8_UINT;
    match draw_into(&gpu, &mut s, &target) {
        Err(vkhair::Error::Incompatible { what: "render target", reason }) => {
            assert!(reason.contains("Raster::Hardware"), "the error names no way out: {reason}")
        }
        other => panic!("a depth-stencil target was not refused: {other:?}"),
    }
}

/// The compute rasteriser draws what the hardware one draws: against the CPU
/// reference, within 1.25 × the hardware's error plus 0.5 of an 8-bit step,
/// and within 3 steps of the hardware's image on average over hair pixels
/// (the two differ at the strands' fringes, where the compute rasteriser's
/// coverage is that of the band's projected width and the ribbon's is
/// interpolated across it); from a camera among the strands whose near plane
/// they cross, within the same bound of the hardware's error against the
/// reference (both clip to the depth range); the raster the renderer reports
/// follows the parameters
/// (and the mode: only the exact mode has a compute rasteriser).
#[test]
fn the_compute_rasteriser_draws_what_the_hardware_one_draws() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let mut images = Vec::new();
    for (width, n) in [(WIDTH, 1.0), (0.002, 6.0)] {
        let m = HairMaterial { represented_hairs: n, ..material(width, OPACITY) };
        let mut errors = Vec::new();
        for raster in RASTERS {
            let mut p = exact(raster);
            // A pool the scene does not overflow (the tail's order follows the atomics).
            p.oit.fragments_per_pixel = 32.0;
            p.oit.sorted_fragments = 32;
            let mut s = scene(&gpu, &groom, &p, &m);
            assert_eq!(s.renderer.raster(), raster);
            let image = draw(&gpu, &mut s);
            let stats = s.renderer.transparency_stats().expect("stats");
            assert_eq!(stats.overflowed, 0, "{stats:?}");
            let truth = rgb(&reference_bands(&s, width, n, s.renderer.strand_spacing(), OPACITY));
            errors.push(mae(&image, &truth));
            images.push(image);
        }
        let between = mae(&images[images.len() - 1], &images[images.len() - 2]);
        println!(
            "{n} hair(s) {width} m wide: error against the reference {:.2} (hardware), {:.2} (compute); {between:.2} between them",
            errors[0], errors[1]
        );
        assert!(errors[1] <= 1.25 * errors[0] + 0.5, "compute {:.2} against hardware {:.2}", errors[1], errors[0]);
        assert!(between < 3.0, "the rasterisers' images differ by {between:.2} steps");
    }
    // A camera among the strands, a near plane of 5 cm: segments cross it and
    // reach behind the camera, and both rasterisers clip them to the depth range.
    let m = material(0.002, OPACITY);
    let mut close = Vec::new();
    for raster in RASTERS {
        let mut p = exact(raster);
        p.oit.fragments_per_pixel = 32.0;
        let mut s = scene(&gpu, &groom, &p, &m);
        let eye = scenes::THESIS_HEAD_CENTER + Vec3::new(0.05, 0.0, 0.2);
        let target = scenes::THESIS_HEAD_CENTER - Vec3::new(0.0, 0.0, 0.2);
        s.camera = Camera::look_at(eye, target, 1.2, W as f32 / H as f32, 0.05, 10.0).expect("camera");
        let image = draw(&gpu, &mut s);
        let stats = s.renderer.transparency_stats().expect("stats");
        assert_eq!(stats.overflowed, 0, "{stats:?}");
        let truth = rgb(&reference_bands(&s, 0.002, 1.0, s.renderer.strand_spacing(), OPACITY));
        close.push(mae(&image, &truth));
    }
    println!(
        "a camera among the strands: error against the reference {:.2} (hardware), {:.2} (compute)",
        close[0], close[1]
    );
    // lavapipe: 11.43 and 7.28 (at a 1.2 rad field of view the ribbons'
    // interpolated coverage strays from the band's projected width).
    assert!(close[1] <= 1.25 * close[0] + 0.5, "compute {:.2} against hardware {:.2}", close[1], close[0]);
    let gpu_ctx = gpu.ctx();
    let sim = HairSim::new(gpu_ctx, &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    for (p, drawn) in [
        (params(Transparency::Fast), Raster::Hardware),
        (RenderParams { raster: Raster::Compute, ..params(Transparency::Off) }, Raster::Hardware),
        (exact(Raster::Hardware), Raster::Hardware),
        (exact(Raster::Compute), Raster::Compute),
        (exact(Raster::Tiles), Raster::Tiles),
        (RenderParams { raster: Raster::Tiles, ..params(Transparency::Fast) }, Raster::Hardware),
    ] {
        let renderer = Renderer::new(gpu_ctx, &sim, &p).expect("renderer");
        assert_eq!(renderer.raster(), drawn, "{:?} with {:?}", p.transparency, p.raster);
    }
    // Auto: compute on GPUs; on a CPU device (lavapipe) the hardware raster pipeline, faster there.
    let auto = Renderer::new(gpu_ctx, &sim, &exact(Raster::Auto)).expect("renderer");
    let cpu = gpu_ctx.info().device_type == vkhair::ash::vk::PhysicalDeviceType::CPU;
    let expected = if cpu { Raster::Hardware } else { Raster::Compute };
    assert_eq!(auto.raster(), expected);
}

/// Out-of-range transparency parameters are refused, naming the field; a
/// multisampled target is refused by the transparent draw before it records.
#[test]
fn bad_transparency_parameters_and_targets_are_refused() {
    let field = |r: vkhair::Result<()>| match r {
        Err(vkhair::Error::InvalidParameter { name, .. }) => name,
        other => panic!("not refused as a parameter: {other:?}"),
    };
    let mut p = params(Transparency::Exact);
    for (k, f) in [(0, 8.0), (33, 8.0), (8, 0.0), (8, f32::NAN), (8, 300.0)] {
        p.oit.sorted_fragments = k;
        p.oit.fragments_per_pixel = f;
        let name = field(p.validate());
        assert!(name.starts_with("oit."), "K {k}, fragments {f}: refused as {name}");
    }
    // A pool buffer of 0 (the device's limits) or at least 64 KiB.
    let mut p = params(Transparency::Exact);
    for (bytes, refused) in [(1, true), (65_535, true), (65_536, false), (0, false), (u32::MAX, false)] {
        p.oit.max_buffer_bytes = bytes;
        match refused {
            true => assert_eq!(field(p.validate()), "oit.max_buffer_bytes", "{bytes} bytes"),
            false => assert!(p.validate().is_ok(), "{bytes} bytes refused"),
        }
    }
    let lines = RenderParams { primitive: vkhair::render::Primitive::Lines, ..params(Transparency::Fast) };
    assert_eq!(field(lines.validate()), "transparency");
    assert!(RenderParams { primitive: vkhair::render::Primitive::Lines, ..params(Transparency::Off) }
        .validate()
        .is_ok());
    for (m, expected) in [
        (HairMaterial { opacity: 1.5, ..HairMaterial::default() }, "opacity"),
        (HairMaterial { opacity: f32::NAN, ..HairMaterial::default() }, "opacity"),
        (HairMaterial { represented_hairs: 0.5, ..HairMaterial::default() }, "represented_hairs"),
        (HairMaterial { represented_hairs: f32::INFINITY, ..HairMaterial::default() }, "represented_hairs"),
    ] {
        assert_eq!(field(m.validate()), expected);
    }

    let gpu = Gpu::new();
    let groom = common::grown_groom(20, 8, 1);
    let mut s = scene(&gpu, &groom, &params(Transparency::Exact), &material(WIDTH, OPACITY));
    let mut target = s.offscreen.target();
    target.samples = vkhair::ash::vk::SampleCountFlags::TYPE_4;
    let result = draw_into(&gpu, &mut s, &target);
    assert!(
        matches!(result, Err(vkhair::Error::Incompatible { what: "render target", .. })),
        "a multisampled target was not refused: {result:?}"
    );
}

/// The pool split over several buffers (a small `max_buffer_bytes` forces
/// eight) stores what one buffer stores and draws the same image; a request
/// beyond eight buffers is capped, reported, and the rest joins the tail.
#[test]
fn a_pool_split_over_buffers_draws_what_one_buffer_draws() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let m = material(WIDTH, OPACITY);
    let extent = vkhair::ash::vk::Extent2D { width: W, height: H };
    for raster in RASTERS {
        let mut p = exact(raster);
        // 28,800 nodes: in one buffer by default, in eight of 3,600 at 64 KiB each.
        p.oit.fragments_per_pixel = 1.5;
        let mut s = scene(&gpu, &groom, &p, &m);
        let one = draw(&gpu, &mut s);
        let whole = s.renderer.transparency_stats().expect("stats");
        let pool = s.renderer.transparency_pool(extent).expect("an exact pool");
        assert_eq!((pool.buffers, pool.capacity, pool.requested), (1, 28_800, 28_800), "{pool:?}");

        p.oit.max_buffer_bytes = 65_536;
        s.renderer.set_params(&p).expect("params");
        let split = draw(&gpu, &mut s);
        let stats = s.renderer.transparency_stats().expect("stats");
        let pool = s.renderer.transparency_pool(extent).expect("an exact pool");
        println!("{raster:?}: one buffer: {whole:?}; split: {pool:?}, {stats:?}");
        assert_eq!((pool.buffers, pool.nodes_per_buffer, pool.capacity), (8, 3_600, 28_800), "{pool:?}");
        assert_eq!(stats, whole, "the split pool stored other fragments");
        assert_eq!(stats.overflowed, 0, "the pool overflowed: {stats:?}");
        assert!(stats.stored > 2 * pool.nodes_per_buffer, "too few fragments to reach the third buffer: {stats:?}");
        let worst = one.iter().zip(&split).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0f32, f32::max);
        println!("largest difference between the two images: {worst} (linear)");
        assert!(worst <= 2.0 / 255.0, "the split pool draws another image: a difference of {worst}");

        // Eight buffers of 64 KiB hold 32,768 of the 153,600 nodes 8 per pixel asks for.
        p.oit.fragments_per_pixel = 8.0;
        s.renderer.set_params(&p).expect("params");
        let capped = draw(&gpu, &mut s);
        let stats = s.renderer.transparency_stats().expect("stats");
        let pool = s.renderer.transparency_pool(extent).expect("an exact pool");
        println!("capped: {pool:?}, {stats:?}");
        assert!(pool.is_capped(), "{pool:?}");
        assert_eq!((pool.buffers, pool.capacity, pool.requested), (8, 32_768, 153_600), "{pool:?}");
        assert_eq!((stats.capacity, stats.requested), (32_768, 153_600), "{stats:?}");
        let truth = reference(&s, WIDTH, OPACITY);
        let (e_one, e_capped) = (mae(&one, &truth), mae(&capped, &truth));
        println!("{raster:?}: error against the reference: {e_one:.2} with one buffer, {e_capped:.2} capped");
        assert!(e_capped <= e_one * 1.05 + 0.05, "the capped pool drew worse: {e_capped:.2} against {e_one:.2}");
    }
}

/// 720p, 1080p and 4K in the exact mode with the default pool (8 fragments per
/// pixel): the pool is split over as many buffers as the device's buffer range
/// needs, nothing is capped where eight suffice, and the exact image covers the
/// pixels the fast mode's does.
#[test]
fn every_size_renders_in_the_exact_mode() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(120, 8, 3);
    let m = material(0.002, OPACITY);
    let info = gpu.ctx().info();
    let buffer_bytes = u64::from(info.max_storage_buffer_range).min(info.max_memory_allocation_size);
    println!("device: {} bytes per buffer", buffer_bytes);
    for (w, h) in [(1280u32, 720u32), (1920, 1080), (3840, 2160)] {
        let extent = vkhair::ash::vk::Extent2D { width: w, height: h };
        let sim = HairSim::new(gpu.ctx(), &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
        let offscreen = Offscreen::new(gpu.ctx(), w, h).expect("offscreen");
        let camera = common::front_camera(0.9, (w, h));
        let mut hair_pixels = Vec::new();
        for p in [params(Transparency::Fast), exact(Raster::Hardware), exact(Raster::Compute), exact(Raster::Tiles)] {
            let mode = p.transparency;
            let mut renderer = Renderer::new(gpu.ctx(), &sim, &p).expect("renderer");
            renderer.set_material(&m).expect("material");
            let host = common::HostFrame { clear: BACKGROUND, before: None, after: None };
            let rgba = common::draw_frame(&gpu, (&sim, &mut renderer), &offscreen, &camera, &host);
            let image = linear_rgb(&rgba);
            hair_pixels.push(image.iter().filter(|c| (**c - BACKGROUND).abs().max_element() > 0.01).count());
            if p.raster == Raster::Tiles {
                // No pool: every fragment is sorted or in the tail, and the bins held every entry.
                let stats = renderer.transparency_stats().expect("stats");
                println!("{w}×{h}, tiles: {stats:?}");
                assert_eq!(renderer.transparency_pool(extent), None);
                assert!(stats.tile_entries <= stats.tile_capacity && stats.tile_entries > 0, "{stats:?}");
                assert!(stats.stored > 1000, "too few fragments: {stats:?}");
            } else if mode == Transparency::Exact {
                let pool = renderer.transparency_pool(extent).expect("an exact pool");
                let stats = renderer.transparency_stats().expect("stats");
                println!("{w}×{h}: {pool:?}, {stats:?}");
                let bytes = u64::from(w) * u64::from(h) * 8 * 16;
                let needed = bytes.div_ceil(buffer_bytes);
                assert_eq!(pool.requested, u64::from(w) * u64::from(h) * 8, "{pool:?}");
                if needed <= 8 {
                    assert_eq!(u64::from(pool.buffers), needed, "{pool:?}");
                    assert!(!pool.is_capped(), "{pool:?}");
                } else {
                    println!(
                        "{w}×{h}: this device's buffers hold {:.2} fragments per pixel",
                        pool.fragments_per_pixel()
                    );
                }
                assert_eq!(stats.overflowed, 0, "{stats:?}");
                assert!(stats.stored > 1000, "too few fragments: {stats:?}");
            }
        }
        println!(
            "{w}×{h}: hair pixels fast {}, exact {} (hardware), {} (compute), {} (tiles)",
            hair_pixels[0], hair_pixels[1], hair_pixels[2], hair_pixels[3]
        );
        // The same fragments: a pixel at the 0.01 threshold may round either way.
        let (c, t) = (hair_pixels[2] as f64, hair_pixels[3] as f64);
        assert!((c - t).abs() <= 0.001 * c, "the tiled rasteriser covers other pixels than the compute one");
        assert!(hair_pixels[1] > 1000, "no hair at {w}×{h}");
        let (a, b, c) = (hair_pixels[0] as f64, hair_pixels[1] as f64, hair_pixels[2] as f64);
        assert!((a - b).abs() <= 0.01 * a, "the exact mode covers other pixels than the fast one at {w}×{h}");
        // The compute rasteriser's fringe follows the band's projected width,
        // the ribbons' their interpolated coverage: pixels of alpha ~1 % differ.
        assert!((a - c).abs() <= 0.05 * a, "the compute rasteriser covers other pixels than the ribbons at {w}×{h}");
    }
}

/// Lit transparent hair takes the shading of opaque hair: the transparent
/// modes shade each hair vertex once (`shade_points.comp`, in a compute
/// dispatch) and carry the colour along the ribbon, where the opaque draw
/// shades every pixel. With the thesis lights and their deep-opacity shadows,
/// where the exact image is fully covered (the same over black and over white)
/// it matches the opaque image within 7 8-bit steps on average.
#[test]
fn lit_transparent_hair_takes_the_shading_of_opaque_hair() {
    use vkhair::render::{Light, ShadowParams};
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    // Opaque, wide strands (about 3 pixels): many pixels fully covered.
    let m = HairMaterial {
        root_color: Vec3::new(0.35, 0.22, 0.12),
        tip_color: Vec3::new(0.6, 0.45, 0.3),
        root_width: 0.006,
        tip_width: 0.006,
        opacity: 1.0,
        ..HairMaterial::default()
    };
    let lights = Light::thesis_rig(scenes::THESIS_HEAD_CENTER, scenes::THESIS_BOUNDING_RADIUS);
    let mut images = Vec::new();
    for (mode, background) in
        [(Transparency::Off, Vec3::ZERO), (Transparency::Exact, Vec3::ZERO), (Transparency::Exact, Vec3::ONE)]
    {
        // Four smoothed segments per key segment, as by default (about 4 pixels each here).
        let mut s = scene(&gpu, &groom, &RenderParams { smoothing_level: 4, ..params(mode) }, &m);
        s.renderer.set_lights(&lights).expect("lights");
        let shadows = ShadowParams { casters: vec![0.into(), 1.into()], ..ShadowParams::default() };
        s.renderer.set_shadows(&s.sim, &shadows).expect("shadows");
        images.push(draw_then(&gpu, &mut s, background, None));
    }
    let to8 = |c: Vec3| c.to_array().map(|v| v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0);
    let (mut sum, mut count, mut lit) = (0.0f64, 0usize, 0usize);
    for ((o, b), w) in images[0].iter().zip(&images[1]).zip(&images[2]) {
        let (opaque, black, white) = (to8(*o), to8(*b), to8(*w));
        let covered = (0..3).all(|c| (black[c] - white[c]).abs() < 0.5);
        if !covered || o.max_element() <= 0.0 {
            continue;
        }
        count += 1;
        lit += usize::from(opaque.iter().any(|v| *v > 40.0));
        sum += (0..3).map(|c| f64::from((opaque[c] - black[c]).abs())).sum::<f64>() / 3.0;
    }
    let mean = sum / count.max(1) as f64;
    println!("{count} fully covered hair pixels ({lit} lit brighter than 40 of 255): mean difference {mean:.2} steps");
    assert!(count > 200 && lit > 50, "too few covered, lit hair pixels to compare: {count}, {lit}");
    // Measured on lavapipe: 6.4 steps (per-fragment shading of the transparent
    // build gave 3.0; every ribbon taking its first end's colour, 7.3).
    assert!(mean < 7.0, "transparent hair shaded {mean:.2} steps away from opaque hair");
}

/// The composite keeps K fragments in arrays sized by the smallest variant that
/// holds K (4, 8, 16 or 32): each K just past a variant's size sorts one more
/// fragment than the one before it, and a K below its variant's size sorts K,
/// not the variant's size (pixels more than an 8-bit step apart where pixels
/// hold that many), and the error against the reference falls from K = 4 to
/// K = 32, starting low: the order-independent tail keeps the rest.
#[test]
fn every_k_sorts_its_k_nearest_fragments() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(2000, 8, 5);
    // Strands 4 mm wide (about 3 pixels) and faint: many pixels hold more than 17 fragments.
    const WIDE: f32 = 0.004;
    let m = material(WIDE, 0.3);
    // Both rasterisers: the hardware build's composite resolves in its
    // fragment stage, the compute rasteriser's in a compute dispatch (each
    // with its variants by K).
    for raster in RASTERS {
        let mut s = scene(&gpu, &groom, &exact(raster), &m);
        let mut images = Vec::new();
        for k in [4u32, 5, 8, 9, 16, 17, 32] {
            let mut p = exact(raster);
            p.oit.sorted_fragments = k;
            // A pool that holds them all: which fragments overflow would vary from draw to draw.
            p.oit.fragments_per_pixel = 64.0;
            s.renderer.set_params(&p).expect("params");
            images.push((k, draw(&gpu, &mut s)));
            let stats = s.renderer.transparency_stats().expect("stats");
            assert_eq!(stats.overflowed, 0, "{stats:?}");
        }
        let truth = reference(&s, WIDE, 0.3);
        println!("{raster:?}: {:?}", s.renderer.transparency_stats());
        for pair in images.windows(2) {
            let ((a, x), (b, y)) = (&pair[0], &pair[1]);
            // More than one 8-bit step: the order in which fragments reach a list
            // (and so the tail's sums) varies by a step from draw to draw.
            let to8 = |c: Vec3| c.to_array().map(|v| v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0);
            let step = |p: Vec3, q: Vec3| (0..3).map(|i| (to8(p)[i] - to8(q)[i]).abs()).fold(0.0f32, f32::max);
            let differing = x.iter().zip(y).filter(|(p, q)| step(**p, **q) > 1.0).count();
            println!(
                "{raster:?}, K {a} → {b}: {differing} pixels differ; error {:.3} → {:.3}",
                mae(x, &truth),
                mae(y, &truth)
            );
            // K just past a variant's size keeps one more than the variant below;
            // K below a variant's size keeps K, not the variant's size.
            assert!(differing > 20, "{raster:?}: K = {b} drew what K = {a} drew: one of them keeps other than its K");
        }
        let (first, last) = (mae(&images[0].1, &truth), mae(&images[images.len() - 1].1, &truth));
        assert!(last < first, "{raster:?}: K = 32 is no nearer the reference than K = 4: {last:.3} against {first:.3}");
        // The tail stands in for the fragments beyond K: on lavapipe K = 4 is 4.3
        // steps from the reference (34 with the fragments beyond K dropped).
        assert!(first < 6.0, "{raster:?}: K = 4 is {first:.3} steps from the reference: the tail lost fragments");
    }
}

/// The composite runs over the rectangle of pixels the ribbons can reach
/// (`OitStats::composited`), not over the whole target: the rectangle holds
/// every pixel of the CPU reference's bands — wide ones here, strands standing
/// for six hairs 10 mm wide, over five pixels, so that a rectangle around the strands' centre
/// lines misses their outer edges — and reaches at most a few pixels beyond
/// them. Hair behind the camera, where a ribbon's projection is unbounded,
/// takes the whole target.
#[test]
fn the_composite_covers_every_ribbon_pixel_and_little_more() {
    let gpu = Gpu::new();
    let (width, n) = (0.01, SPARSE_HAIRS);
    for raster in [Raster::Compute, Raster::Hardware] {
        composite_covers_every_ribbon_pixel(&gpu, width, n, raster);
    }
}

/// [`the_composite_covers_every_ribbon_pixel_and_little_more`] with `raster`'s
/// fragments (the fast mode, drawn by the ribbons, compared where `raster` is
/// the hardware one).
fn composite_covers_every_ribbon_pixel(gpu: &Gpu, width: f32, n: f32, raster: Raster) {
    let (mut s, mut p) = sparse_band_scene(gpu, width);
    p.raster = raster;
    s.renderer.set_params(&p).expect("params");
    // About 11 mm a pixel: the bands are over five pixels wide, the head half the target.
    s.camera = common::front_camera(1.8, (W, H));
    let image = draw(gpu, &mut s);
    let stats = s.renderer.transparency_stats().expect("stats of an exact frame");
    let [x0, y0, x1, y1] = stats.composited.expect("a rectangle: hair was drawn");
    let truth = reference_bands(&s, width, n, s.renderer.strand_spacing(), OPACITY);
    // The reference's hair pixels and their bounds.
    let hair: Vec<(u32, u32)> = (0..W * H).filter(|&i| truth[i as usize].w > 0.0).map(|i| (i % W, i / W)).collect();
    assert!(hair.len() > 500, "only {} hair pixels", hair.len());
    let (lo, hi) = hair
        .iter()
        .fold(((W, H), (0, 0)), |(lo, hi), &(x, y)| ((lo.0.min(x), lo.1.min(y)), (hi.0.max(x + 1), hi.1.max(y + 1))));
    println!(
        "composited [{x0}, {y0}) × [{x1}, {y1}); the reference's hair spans [{}, {}) × [{}, {})",
        lo.0, lo.1, hi.0, hi.1
    );
    let outside: Vec<_> = hair.iter().filter(|&&(x, y)| x < x0 || x >= x1 || y < y0 || y >= y1).collect();
    assert!(
        outside.is_empty(),
        "{} of the reference's hair pixels outside the composite, e.g. {:?}",
        outside.len(),
        &outside[..outside.len().min(5)]
    );
    // Beyond a strand's end the cube around its last vertex reaches the drawn
    // half width (about 3.5 pixels), then two pixels and the rounding: at most 8.
    let beyond = [lo.0 - x0, lo.1 - y0, x1 - hi.0, y1 - hi.1];
    assert!(beyond.iter().all(|&b| b <= 8), "the composite reaches {beyond:?} pixels beyond the hair");
    assert!(u64::from((x1 - x0) * (y1 - y0)) < u64::from(W * H) * 3 / 4, "the composite covers most of the target");
    let error = mae(&image, &rgb(&truth));
    println!("{raster:?}: error against the reference {error:.2} (8-bit sRGB steps)");
    // lavapipe: 5.0 to 5.2, as when the composite ran over the whole target
    // (bands this wide overlap at the ribbons' joints, where the reference's
    // quads meet edge to edge).
    assert!(error < 6.5, "{error:.2}");
    // The fast mode composites over the same rectangle: hair shows wherever the
    // exact mode's ribbons do.
    if raster == Raster::Hardware {
        fast_shows_what_exact_shows(gpu, &mut s, &p, &image);
    }
}

/// The fast mode, over the same rectangle, shows hair wherever the exact
/// mode's ribbons (`exact`, drawn with `p`) do; then, with `p`, hair behind the
/// camera composites the whole target.
fn fast_shows_what_exact_shows(gpu: &Gpu, s: &mut Scene, p: &RenderParams, image: &[Vec3]) {
    s.renderer.set_params(&RenderParams { transparency: Transparency::Fast, ..p.clone() }).expect("fast mode");
    let fast = draw(gpu, s);
    let shows = |c: Vec3, least: f32| (c - BACKGROUND).abs().max_element() > least;
    let exact_hair = (0..image.len()).filter(|&i| shows(image[i], 0.02)).count();
    let missing = (0..image.len()).filter(|&i| shows(image[i], 0.02) && !shows(fast[i], 0.005)).count();
    assert!(
        exact_hair > 500 && missing == 0,
        "{missing} of the exact mode's {exact_hair} hair pixels are background in the fast mode"
    );
    s.renderer.set_params(p).expect("exact mode");
    // Well in front of the face looking away: all the hair is behind the
    // camera, where a projection is unbounded (conservatively the whole target:
    // a ribbon from there may cross into view).
    s.camera = vkhair::render::Camera::look_at(
        scenes::THESIS_HEAD_CENTER + Vec3::new(0.0, 0.0, 0.6),
        scenes::THESIS_HEAD_CENTER + Vec3::new(0.0, 0.0, 1.5),
        0.7,
        W as f32 / H as f32,
        0.01,
        10.0,
    )
    .expect("camera");
    draw(gpu, s);
    let stats = s.renderer.transparency_stats().expect("stats of an exact frame");
    assert_eq!(stats.composited, Some([0, 0, W, H]), "hair behind the camera composites the whole target");
}

/// Level of detail over hairs rooted over the scalp keeps the head's optical
/// density: drawing a quarter and a sixteenth of the hairs (each standing for
/// 4× and 16× as many, spread over the gap to its neighbours), black hair over
/// white darkens the picture within 10 % of what every hair darkens, with
/// either rasteriser. (Were the survivors to stand for no more hairs than at
/// full detail, a quarter of the hairs would darken 0.62 as much.)
#[test]
fn level_of_detail_keeps_the_optical_density_of_hair_over_the_scalp() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(300, 8, 5);
    let sim = HairSim::new(gpu.ctx(), &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let rest =
        vkhair::sim::SimState::from_groom(&groom, &SimParams::default(), &RigidTransform::default()).expect("rest");
    let density = 20.0;
    let scalp = vkhair::render::ScalpHairParams { density, ..Default::default() };
    let followers = vkhair::render::Followers::over_scalp(&rest, &scalp, 2, 15).expect("hairs over the scalp");
    // A head of 150 hairs per cm²: each drawn hair stands for 7.5 at full detail.
    let m = HairMaterial {
        root_color: Vec3::ZERO,
        tip_color: Vec3::ZERO,
        represented_hairs: 150.0 / density,
        ..material(70e-6, 0.8)
    };
    let offscreen = Offscreen::new(gpu.ctx(), W, H).expect("offscreen");
    let camera = camera();
    let darkening = |raster: Raster, lod: LodParams| -> (f32, u32) {
        let p = RenderParams { hairs_per_key: 64, lod, raster, ..params(Transparency::Exact) };
        let mut renderer = Renderer::with_followers(gpu.ctx(), &sim, &p, &followers).expect("renderer");
        renderer.set_material(&m).expect("material");
        let host = common::HostFrame { clear: Vec3::ONE, before: None, after: None };
        let rgba = common::draw_frame(&gpu, (&sim, &mut renderer), &offscreen, &camera, &host);
        (linear_rgb(&rgba).iter().map(|c| 1.0 - c.y).sum(), renderer.hair_counts().0)
    };
    for raster in RASTERS {
        let (full, all) = darkening(raster, LodParams { enabled: false, ..LodParams::default() });
        assert!(full > 200.0, "{raster:?}: every hair darkens only {full}");
        for (step, share) in [(2.0, 0.25), (4.0, 0.0625)] {
            let lod = LodParams { full_detail_distance: 0.9 / step, min_hairs_per_key: 1, ..LodParams::default() };
            let (fewer, drawn) = darkening(raster, lod);
            let (kept, ratio) = (drawn as f32 / all as f32, fewer / full);
            println!("{raster:?}: {drawn} of {all} hairs ({kept:.3}) darken {ratio:.3} of what all darken");
            assert!((kept - share).abs() < 0.25 * share, "{raster:?}: level of detail kept {kept} of the hairs");
            assert!((ratio - 1.0).abs() <= 0.1, "{raster:?}: {kept:.3} of the hairs darken {ratio:.3} as much");
        }
    }
}

/// The tiled rasteriser (`Raster::Tiles`) keeps the fragments the per-segment
/// compute rasteriser keeps — the same count, every pixel within one 8-bit
/// step, on average within a hundredth of one (they differ only where
/// fragments at one depth, or the tail's float sums, meet in another order) —
/// for each K-buffer variant (K = 4, 8, 16 and 32), on a target whose sides
/// are not multiples of the tile (partial tiles at the right and bottom), with
/// more fragments than a tile's shared buffer holds at once (so tiles take
/// several rounds), and against the host's depth (a sphere drawn first).
#[test]
fn the_tiled_rasteriser_keeps_the_fragments_of_the_per_segment_one() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(2000, 8, 5);
    // Wide faint strands: deep pixels, several rounds a tile.
    let m = material(0.004, 0.3);
    let (w, h) = (157u32, 93u32);
    let offscreen = Offscreen::new(gpu.ctx(), w, h).expect("offscreen");
    let camera = common::front_camera(0.9, (w, h));
    let front = scenes::THESIS_HEAD_CENTER + Vec3::new(0.0, -0.12, 0.45);
    let sphere = vkhair::groom::mesh::TriMesh::uv_sphere(front, 0.1, 16, 24).expect("sphere");
    let mesh = vkhair::headless::MeshDrawer::new(gpu.ctx(), &sphere).expect("mesh");
    let sim = HairSim::new(gpu.ctx(), &groom, &SimParams::default(), &RigidTransform::default()).expect("sim");
    let to8 = |c: Vec3| c.to_array().map(|v| v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0);
    let tiles = u64::from(w.div_ceil(16)) * u64::from(h.div_ceil(16));
    // One renderer a rasteriser, its K changed between frames.
    let mut renderers: Vec<Renderer> = [Raster::Compute, Raster::Tiles]
        .into_iter()
        .map(|raster| {
            let mut renderer = Renderer::new(gpu.ctx(), &sim, &exact(raster)).expect("renderer");
            renderer.set_material(&m).expect("material");
            renderer
        })
        .collect();
    for (k, before) in [(4u32, None), (8, Some(&mesh)), (16, None), (32, Some(&mesh))] {
        let mut images = Vec::new();
        let mut fragments = Vec::new();
        for (raster, renderer) in [Raster::Compute, Raster::Tiles].into_iter().zip(renderers.iter_mut()) {
            let mut p = exact(raster);
            p.oit.sorted_fragments = k;
            // A pool that holds them all.
            p.oit.fragments_per_pixel = 64.0;
            renderer.set_params(&p).expect("params");
            let host = common::HostFrame { clear: BACKGROUND, before, after: None };
            let rgba = common::draw_frame(&gpu, (&sim, renderer), &offscreen, &camera, &host);
            let stats = renderer.transparency_stats().expect("stats");
            assert_eq!(stats.overflowed, 0, "{stats:?}");
            fragments.push(stats.fragments);
            images.push(linear_rgb(&rgba));
            if raster == Raster::Tiles {
                assert!(stats.tile_entries > 0 && stats.tile_entries <= stats.tile_capacity, "{stats:?}");
                // More fragments than every tile's buffer holds at once: some tile took rounds.
                assert!(stats.fragments > tiles * 1024, "too few fragments for rounds: {stats:?}");
            }
        }
        let steps: Vec<f32> = images[0]
            .iter()
            .zip(&images[1])
            .map(|(a, b)| (0..3).map(|i| (to8(*a)[i] - to8(*b)[i]).abs()).fold(0.0f32, f32::max))
            .collect();
        let worst = steps.iter().copied().fold(0.0f32, f32::max);
        let mean = steps.iter().sum::<f32>() / steps.len() as f32;
        println!("K {k}, sphere {}: fragments {fragments:?}; worst {worst:.3}, mean {mean:.5} steps", before.is_some());
        assert_eq!(fragments[0], fragments[1], "K {k}: the rasterisers kept other fragments");
        assert!(fragments[0] > 10_000, "too few fragments to compare: {fragments:?}");
        assert!(worst <= 1.0 && mean < 0.01, "K {k}: the tiled image differs: worst {worst}, mean {mean}");
    }
}

/// Bins too small for a frame's segments (`OitParams::tile_entries_per_vertex`
/// at its least, wide strands reaching more than the bins' least 256 entries a
/// tile) draw the entries that fit and say so (`OitStats::tile_entries` beyond
/// `tile_capacity`); the bins of the frame `frames_in_flight` (here 1) after
/// it hold them all and it draws what the per-segment rasteriser draws.
#[test]
fn bins_too_small_draw_what_fits_say_so_and_grow() {
    let gpu = Gpu::new();
    let groom = common::grown_groom(2000, 8, 5);
    let m = material(0.004, OPACITY);
    let mut p = exact(Raster::Compute);
    p.oit.fragments_per_pixel = 32.0;
    let mut s = scene(&gpu, &groom, &p, &m);
    let whole = draw(&gpu, &mut s);
    let all = s.renderer.transparency_stats().expect("stats").fragments;
    let mut p = exact(Raster::Tiles);
    p.oit.tile_entries_per_vertex = 0.1;
    // The host waits for each frame: the next one reads what this one asked for.
    p.frames_in_flight = 1;
    s.renderer.set_params(&p).expect("params");
    let first = draw(&gpu, &mut s);
    let short = s.renderer.transparency_stats().expect("stats");
    println!("too small: {short:?}; all {all}");
    assert!(short.tile_entries > short.tile_capacity, "the bins held every entry: {short:?}");
    assert!(short.fragments < all, "fragments of entries past the bins were kept: {short:?}");
    assert!(mae(&first, &whole) > 0.5, "a frame missing entries looks whole");
    let second = draw(&gpu, &mut s);
    let grown = s.renderer.transparency_stats().expect("stats");
    println!("grown: {grown:?}");
    assert!(grown.tile_entries <= grown.tile_capacity, "the bins did not grow: {grown:?}");
    assert_eq!(grown.fragments, all, "{grown:?}");
    assert!(mae(&second, &whole) < 0.05, "the grown bins draw other hair: {:.3}", mae(&second, &whole));
}
