//! The parameters and the renderer of a scene's flags.

use vkhair::config::Config;
use vkhair::render::{
    Followers, InterpolationMode, Light, Primitive, Renderer, ShadingMode, ShadowCaster, ShadowParams, Transparency,
    SCALP_DENSITY_RANGE,
};
use vkhair::sim::{KeyHairs, RigidTransform, SimParams, SimState, VolumeMode, VolumeParams};
use vkhair::GpuContext;

use super::{drawing_scale, Scene};
use crate::args::input::{strand_widths, Dense};
use crate::args::scene::SceneArgs;
use crate::say;
use crate::say_err;

/// The parameters: vkhair's defaults (an `--input` groom held in its authored
/// style, [`SimParams::styled`]; strands as wide as the groom file says when it
/// says something plausible), then the `--config` file, then the flags given;
/// the tool's lights when the file lists none. Checked before any GPU work.
pub fn parameters(a: &SceneArgs, s: &Scene) -> Result<Config, vkhair::Error> {
    let (center, radius) = (s.center, s.radius);
    let sim =
        if a.input.input.is_some() || a.input.gltf.is_some() { SimParams::styled() } else { SimParams::default() };
    let mut base = Config { sim, ..Config::default() };
    // The tool draws soft hair unless told otherwise (the library's default is opaque).
    base.render.transparency = Transparency::Exact;
    let k = drawing_scale(radius);
    let from_groom = strand_widths(s.thickness, k);
    if let Some((root, tip)) = from_groom {
        // In the units the scale below converts from, so that they come out as given.
        (base.material.root_width, base.material.tip_width) = (root / k, tip / k);
    }
    let base_widths = (base.material.root_width, base.material.tip_width);
    let mut config = match &a.config {
        Some(path) => base.load_over(path)?,
        None => base,
    };
    let r = &mut config.render;
    if let Some(level) = a.level {
        r.smoothing_level = level;
    }
    if let Some(hairs) = a.hairs_per_key {
        r.hairs_per_key = hairs;
    }
    r.supersampling |= a.ssaa;
    r.lod.enabled &= !a.no_lod;
    if a.barycentric {
        r.interpolation = InterpolationMode::Barycentric;
    }
    if a.lines {
        r.primitive = Primitive::Lines;
        r.transparency = Transparency::Off;
    }
    if let Some(k) = a.sorted_fragments {
        r.oit.sorted_fragments = k;
    }
    if let Some(f) = a.fragments_per_pixel {
        r.oit.fragments_per_pixel = f;
    }
    if let Some(t) = a.transparency {
        r.transparency = t;
    }
    if let Some(d) = a.density {
        config.scalp.density = d;
    }
    if let Some(raster) = a.raster {
        r.raster = raster;
    }
    if let Some(interpolator) = a.interpolator {
        r.interpolator = interpolator;
    }
    if a.marschner {
        config.material.shading = ShadingMode::Marschner;
    }
    a.sim.apply(&mut config.sim);
    if a.volume_shadows && config.sim.volume.mode == VolumeMode::Off {
        config.sim.volume = VolumeParams::flip([32, 32, 32]);
    }
    if config.lights.is_empty() {
        config.lights = Light::thesis_rig(center, radius).to_vec();
    }
    let m = &config.material;
    let source = match from_groom {
        _ if a.config.is_some() && (m.root_width, m.tip_width) != base_widths => "--config",
        Some(_) => "the groom's thickness",
        None => "vkhair's default",
    };
    say!("strand width: {:.1} µm at the root, {:.1} µm at the tip ({source})", m.root_width * 1e6, m.tip_width * 1e6);
    if k != 1.0 {
        say_err!(
            "vkhair: warning: the groom and mesh span {:.3} units around their centre, not the size of a \
             head of hair in meters (vkhair's unit); drawing clumps, hair widths and shadow layers {k:.3}× as wide to match \
             (give --scale to convert the groom itself: the simulation stays in meters)",
            radius
        );
        config.render.clump_width *= k;
        config.render.lod.full_detail_distance *= k;
        config.material.root_width *= k;
        config.material.tip_width *= k;
        // Hairs per cm² of a head in meters: the groom's own units count k² as
        // many, within the parameter's range (checked as given first).
        config.scalp.validate().map_err(crate::args::flag_error)?;
        let scaled = config.scalp.density / (k * k);
        config.scalp.density = scaled.clamp(*SCALP_DENSITY_RANGE.start(), *SCALP_DENSITY_RANGE.end());
        if config.scalp.density != scaled {
            say_err!(
                "vkhair: warning: {scaled} hairs per cm² of the groom's units is outside {}..={}; rooting {} per \
                 cm² (give --scale to convert the groom to meters)",
                SCALP_DENSITY_RANGE.start(),
                SCALP_DENSITY_RANGE.end(),
                config.scalp.density
            );
        }
    }
    config.validate().map_err(crate::args::flag_error)?;
    Ok(config)
}

/// The renderer `render` draws with: parameters, lights, the two spot lights'
/// shadows and the material of `config`.
pub fn make_renderer(
    a: &SceneArgs,
    ctx: &GpuContext,
    config: &Config,
    key_hairs: KeyHairs<'_>,
    s: &Scene,
) -> Result<Renderer, vkhair::Error> {
    let radius = s.radius;
    // Hairs rooted over the scalp: not a dense groom's followers, not clumps
    // or barycentric hairs.
    let over_scalp = s.dense.is_none() && !a.clumps && config.render.interpolation == InterpolationMode::SingleStrand;
    if let (Some(density), false) = (a.density, over_scalp) {
        return Err(vkhair::Error::InvalidParameter {
            name: "--density",
            value: density.to_string(),
            allowed: "only with hairs rooted over the scalp: with --clumps, --barycentric or followers (--guides) \
                      the count follows --hairs-per-key"
                .into(),
        });
    }
    let scalp = if over_scalp { scalp_followers(&s.groom, config, ctx)? } else { None };
    let mut renderer = match (&s.dense, scalp) {
        (None, Some(followers)) => {
            if let Some(hairs) = a.hairs_per_key {
                return Err(vkhair::Error::InvalidParameter {
                    name: "--hairs-per-key",
                    value: hairs.to_string(),
                    allowed: format!(
                        "only with --clumps, --barycentric or followers (--guides): over the scalp the count \
                         follows --density, {} hairs here",
                        followers.count()
                    ),
                });
            }
            let mut render = config.render.clone();
            // Full detail while the roots lie at least SCALP_LOD_PIXELS apart on
            // screen; farther, fewer hairs, each standing for more (level of detail).
            let pixel_at_1m = 2.0 * (0.5 * super::FOV_Y).tan() / a.height as f32;
            let apart = followers.root_spacing() / (SCALP_LOD_PIXELS * pixel_at_1m);
            let lod = &mut render.lod;
            lod.full_detail_distance = lod.full_detail_distance.min(apart).max(1e-4);
            // Followers are drawn in shares of hairs_per_key: the finest steps,
            // down to 1/64 of the hairs (a small or distant head).
            (render.hairs_per_key, lod.min_hairs_per_key) = (SCALP_LOD_STEPS, 1);
            Renderer::with_followers(ctx, key_hairs, &render, &followers)?
        }
        (None, None) => Renderer::new(ctx, key_hairs, &config.render)?,
        (Some(d), _) => {
            let followers = bind_followers(d, &s.groom, config)?;
            say!(
                "followers: {} strands drawn as followers of {} guides ({}), {} points each, {:.1} MiB of bindings, \
                 {} colours",
                followers.count(),
                d.guides.len(),
                d.chosen_by,
                followers.points(),
                followers.gpu_bytes() as f64 / (1 << 20) as f64,
                d.colors_from
            );
            Renderer::with_followers(ctx, key_hairs, &config.render, &followers)?
        }
    };
    renderer.set_lights(&config.lights)?;
    if !a.no_shadows {
        // The thesis' setup: both spot lights cast shadows through their own maps.
        let casters = if a.volume_shadows {
            vec![ShadowCaster::density_volume(0), ShadowCaster::density_volume(1)]
        } else {
            vec![0.into(), 1.into()]
        };
        let layers = ShadowParams::default().layers.map(|l| l * drawing_scale(radius));
        let shadows = ShadowParams { casters, resolution: a.shadow_resolution, layers, ..ShadowParams::default() };
        renderer.set_shadows(key_hairs, &shadows).map_err(|e| match e {
            vkhair::Error::UnsupportedFeature { .. } => vkhair::Error::UnsupportedFeature {
                what: "shadows of a point light",
                reason: "the --config file makes light 0 or 1, the two that cast shadows, a point light, which \
                         has no deep opacity map; render with --volume-shadows or --no-shadows, or make it a spot \
                         or directional light"
                    .into(),
            },
            e => e,
        })?;
    }
    let mut material = config.material.clone();
    if material.represented_hairs == 1.0 {
        material.represented_hairs = represented_hairs(renderer.hair_counts().0);
    }
    renderer.set_material(&material)?;
    let extent = vkhair::ash::vk::Extent2D { width: a.width, height: a.height };
    if let Some(pool) = renderer.transparency_pool(extent).filter(|p| p.is_capped()) {
        say_err!(
            "vkhair: warning: at {}×{} this device holds {:.2} of the {} fragments per pixel oit.fragments_per_pixel \
             asks for ({} of {} MiB in {} buffers); the fragments beyond the pool join the order-independent tail",
            a.width,
            a.height,
            pool.fragments_per_pixel(),
            config.render.oit.fragments_per_pixel,
            pool.bytes() >> 20,
            pool.requested_bytes() >> 20,
            pool.buffers
        );
    }
    Ok(renderer)
}

/// The strands of `dense` bound to its guides, the key hairs `keys` (the
/// simulation's rest state), at the smoothing level of `config`.
pub fn bind_followers(dense: &Dense, keys: &vkhair::Groom, config: &Config) -> Result<Followers, vkhair::Error> {
    let rest = SimState::from_groom(keys, &config.sim, &RigidTransform::default())?;
    let followers = Followers::bind(&dense.groom, &dense.guides, &rest, config.render.smoothing_level, dense.points)?;
    let followers = match &dense.colors {
        Some(c) => followers.with_colors(c)?,
        None => followers,
    };
    match &dense.width_factors {
        Some(w) => followers.with_width_factors(w),
        None => Ok(followers),
    }
}

/// The fewest pixels between the roots of the hairs the tool draws over the
/// scalp: nearer than that, level of detail drops hairs (each survivor
/// standing for more, its band spread over the gap).
const SCALP_LOD_PIXELS: f32 = 2.0;

/// The steps of level of detail over the scalp's hairs: a frame draws k / 64
/// of them (k in 1..=64; `hairs_per_key` only sets the share followers draw).
const SCALP_LOD_STEPS: u32 = 64;

/// Most points the tool draws a hair rooted over the scalp with.
const SCALP_HAIR_POINTS: u32 = 32;

/// Hairs rooted over the scalp the key hairs `keys` cover
/// ([`Followers::over_scalp`], `config.scalp`), each drawn with the smoothed
/// key hair's points (at most [`SCALP_HAIR_POINTS`]); `None`, saying why,
/// where the key hairs' roots make no scalp (too few, or in a line): those
/// hairs grow in clumps around each key hair instead.
pub fn scalp_followers(
    keys: &vkhair::Groom,
    config: &Config,
    ctx: &GpuContext,
) -> Result<Option<Followers>, vkhair::Error> {
    let rest = SimState::from_groom(keys, &config.sim, &RigidTransform::default())?;
    let level = config.render.smoothing_level;
    let points = ((rest.points as u32 - 1) * level + 1).clamp(2, SCALP_HAIR_POINTS) as usize;
    // The most hairs of `points` points the device's storage range holds.
    let most = (u64::from(ctx.info().max_storage_buffer_range) / (16 * points as u64)).min(u64::from(u32::MAX)) as u32;
    let mut params = config.scalp.clone();
    params.max_hairs = params.max_hairs.min(most);
    let area = vkhair::render::scalp_area_cm2(&rest);
    if area.is_nan() || area <= 0.0 {
        say!(
            "scalp: the {} key hairs' roots make no scalp to root hairs over (too few, or in a line); growing \
             hairs in clumps around each key hair instead",
            rest.strands
        );
        return Ok(None);
    }
    if f64::from(area) * f64::from(params.density) < 1.0 {
        say!(
            "scalp: {} per cm² over the {area:.3} cm² the key hairs' roots cover roots no hair; growing hairs in \
             clumps around each key hair instead",
            params.density
        );
        return Ok(None);
    }
    if f64::from(area) * f64::from(params.density) > f64::from(params.max_hairs) {
        let density = 0.999 * params.max_hairs as f32 / area;
        let sparsest = *SCALP_DENSITY_RANGE.start();
        if density < sparsest {
            // Even the sparsest rooting is more than the device holds: a groom
            // far larger than a head (its units read as meters).
            say_err!(
                "vkhair: warning: the key hairs' roots cover {area:.0} cm² (the groom's units read as meters: give \
                 --scale to convert them); even {sparsest} hairs per cm² would be more than the {} hairs \
                 of {points} points this device holds; growing hairs in clumps around each key hair instead",
                params.max_hairs
            );
            return Ok(None);
        }
        say_err!(
            "vkhair: warning: {} hairs per cm² over the {area:.0} cm² the key hairs' roots cover would be more \
             than the {} hairs of {points} points this device holds; drawing {density:.2} per cm²",
            params.density,
            params.max_hairs
        );
        params.density = density;
    }
    let followers = bound_over_scalp(&rest, &params, level, points)?;
    say!(
        "scalp: {} hairs rooted over the scalp the {} key hairs' roots cover ({} per cm², a root every {:.2} mm), \
         each blended from its nearest key hairs, {} points each, {:.1} MiB of bindings",
        followers.count(),
        rest.strands,
        params.density,
        followers.root_spacing() * 1e3,
        points,
        followers.gpu_bytes() as f64 / (1 << 20) as f64
    );
    Ok(Some(followers))
}

/// The last scalp binding made, by a hash of what it was made from: `bench`
/// draws one groom in several modes, and binding a full head (96,609 hairs
/// on the thesis scalp) was the largest fixed cost of each.
static LAST_SCALP_BINDING: std::sync::Mutex<Option<(u64, Followers)>> = std::sync::Mutex::new(None);

/// [`Followers::over_scalp`], or a copy of the last one where its inputs
/// were the same.
fn bound_over_scalp(
    rest: &SimState,
    params: &vkhair::render::ScalpHairParams,
    level: u32,
    points: usize,
) -> Result<Followers, vkhair::Error> {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    rest.rest.iter().for_each(|p| p.to_array().map(f32::to_bits).hash(&mut hasher));
    (rest.strands, rest.points, format!("{params:?}"), level, points).hash(&mut hasher);
    let key = hasher.finish();
    let mut last = LAST_SCALP_BINDING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, followers)) = last.as_ref().filter(|(k, _)| *k == key) {
        return Ok(followers.clone());
    }
    let followers = Followers::over_scalp(rest, params, level, points)?;
    *last = Some((key, followers.clone()));
    Ok(followers)
}

/// Hairs on a full head of real hair, for the tool's default of
/// [`vkhair::render::HairMaterial::represented_hairs`].
pub const FULL_HEAD_HAIRS: f32 = 100_000.0;

/// The tool's default hairs per drawn strand for `drawn` strands: a full head
/// ([`FULL_HEAD_HAIRS`]) over the strands drawn at full detail, at least 1
/// (`material.represented_hairs` in a `--config` file other than 1 wins).
pub fn represented_hairs(drawn: u32) -> f32 {
    (FULL_HEAD_HAIRS / drawn.max(1) as f32).clamp(1.0, 10_000.0)
}
