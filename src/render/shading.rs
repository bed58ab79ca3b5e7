//! The look of the hair: camera, lights and material, and the noise texture
//! the shading samples.

use glam::{Mat4, Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::codes::{light_kind, shading};
use crate::error::{Error, Result};
use crate::gpu_types::GpuLight;

/// Most lights the draw pass shades with.
pub const MAX_LIGHTS: usize = crate::limits::MAX_LIGHTS as usize;

/// A perspective camera (Vulkan clip space: y down, depth 0..1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// World → view.
    pub view: Mat4,
    /// View → clip.
    pub projection: Mat4,
    /// Vertical field of view, radians (for pixel-size estimates).
    pub fov_y: f32,
    /// This frame's sub-pixel jitter, in pixels of the render target: +x to
    /// the right, +y down the rows (each within ±1). The hair is drawn with
    /// `projection` moved by it in clip space ([`Camera::jittered_projection`]),
    /// as a TAA or upscaling host jitters its own geometry; `projection`
    /// itself stays unjittered. Default (from [`Camera::look_at`]): zero.
    pub jitter: Vec2,
    /// How the host's depth buffer orders depth: the hair's depth test and
    /// the depth it writes follow it ([`Camera::depth_reversed`]). Default:
    /// [`DepthConvention::Auto`], read from `projection`.
    pub depth: DepthConvention,
}

/// Which way a host's depth buffer runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// Read from the projection: reversed when a point farther along the view
    /// axis gets a smaller depth ([`Camera::depth_reversed`]).
    #[default]
    Auto,
    /// Near 0, far 1: the nearer fragment has the smaller depth, the buffer is
    /// cleared to 1 (`LESS_OR_EQUAL`).
    Forward,
    /// Reverse-Z: near 1, far 0 (or an infinite far plane at 0), the buffer
    /// cleared to 0 (`GREATER_OR_EQUAL`).
    Reverse,
}

impl Camera {
    /// A camera at `eye` looking at `target` with +Y up.
    pub fn look_at(eye: Vec3, target: Vec3, fov_y: f32, aspect: f32, near: f32, far: f32) -> Result<Camera> {
        let finite = eye.is_finite() && target.is_finite() && fov_y.is_finite() && aspect.is_finite();
        if !finite
            || (eye - target).length() < 1e-6
            || !(0.01..3.1).contains(&fov_y)
            || aspect <= 0.0
            || !(0.0 < near && near < far)
        {
            return Err(Error::param(
                "camera",
                format!("eye {eye}, target {target}, fov {fov_y}, aspect {aspect}, near {near}, far {far}"),
                "finite, eye ≠ target, fov in 0.01..3.1, aspect > 0, 0 < near < far",
            ));
        }
        Ok(Camera {
            view: glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y),
            projection: glam::camera::rh::proj::vulkan::perspective(fov_y, aspect, near, far),
            fov_y,
            jitter: Vec2::ZERO,
            depth: DepthConvention::Auto,
        })
    }

    /// A reverse-Z camera with an infinite far plane (near maps to depth 1,
    /// infinity to 0), as many modern hosts draw: otherwise as
    /// [`Camera::look_at`], whose checks it shares.
    pub fn look_at_reverse_z(eye: Vec3, target: Vec3, fov_y: f32, aspect: f32, near: f32) -> Result<Camera> {
        let camera = Camera::look_at(eye, target, fov_y, aspect, near, near * 2.0)?;
        Ok(Camera {
            projection: glam::camera::rh::proj::vulkan::perspective_infinite_reverse(fov_y, aspect, near),
            ..camera
        })
    }

    /// Whether the host's depth is reversed: [`Camera::depth`], with
    /// [`DepthConvention::Auto`] read from `projection` — reversed when a
    /// point two units along the view axis gets a smaller depth than one at
    /// one unit (a projective depth runs one way over the whole view axis).
    /// A projection that gives both the same depth (or a non-finite one) is
    /// taken as forward.
    pub fn depth_reversed(&self) -> bool {
        match self.depth {
            DepthConvention::Forward => false,
            DepthConvention::Reverse => true,
            DepthConvention::Auto => {
                let depth = |v: f32| {
                    let c = self.projection * glam::Vec4::new(0.0, 0.0, -v, 1.0);
                    c.z / c.w
                };
                depth(2.0) < depth(1.0)
            }
        }
    }

    /// The same camera with `jitter` (pixels, see [`Camera::jitter`]);
    /// refused unless finite and within ±1 pixel on each axis.
    pub fn with_jitter(self, jitter: Vec2) -> Result<Camera> {
        if !jitter.is_finite() || jitter.abs().max_element() > 1.0 {
            return Err(Error::param("camera jitter", jitter, "finite, within ±1 pixel on each axis"));
        }
        Ok(Camera { jitter, ..self })
    }

    /// `projection` moved by [`Camera::jitter`] for a target of `width` ×
    /// `height` pixels: clip x and y gain 2·jitter/size · w, so every point
    /// lands `jitter` pixels away from where `projection` puts it.
    pub fn jittered_projection(&self, (width, height): (u32, u32)) -> Mat4 {
        let shift = 2.0 * self.jitter / Vec2::new(width.max(1) as f32, height.max(1) as f32);
        let mut clip = Mat4::IDENTITY;
        clip.w_axis.x = shift.x;
        clip.w_axis.y = shift.y;
        clip * self.projection
    }

    /// The camera's world position.
    pub fn position(&self) -> Vec3 {
        self.view.inverse().w_axis.truncate()
    }
}

/// A light.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Light {
    /// Parallel light travelling along `direction`.
    Directional {
        /// Direction of travel (finite, non-zero).
        direction: Vec3,
        /// Linear RGB radiance (each 0..=1e6).
        color: Vec3,
    },
    /// A point light; radiance falls off with the squared distance.
    Point {
        /// Position, meters (each within ±1e6).
        position: Vec3,
        /// Linear RGB intensity (radiance at 1 m; each 0..=1e9).
        color: Vec3,
    },
    /// A spot light: a point light within a cone.
    Spot {
        /// Position, meters (each within ±1e6).
        position: Vec3,
        /// Direction the cone points (finite, non-zero).
        direction: Vec3,
        /// Half-angle where the cone ends, radians (< π).
        outer_angle: f32,
        /// Half-angle of full intensity, radians (0..=outer_angle).
        inner_angle: f32,
        /// Linear RGB intensity (radiance at 1 m; each 0..=1e9: a light
        /// 10 km away lighting a scene as one 1 m away does needs 1e8 times
        /// its intensity).
        color: Vec3,
    },
}

impl Light {
    /// The thesis scene's three lights around a head of hair of bounding
    /// radius `radius` centred at `center`: a key spot (light 0) and a fill spot
    /// (light 1), the two that cast shadows in the thesis' setup, and a dim
    /// directional rim light. At the thesis' own size
    /// ([`crate::groom::scenes::THESIS_BOUNDING_RADIUS`]) the spots sit at its
    /// offsets from the centre; for another size the offsets scale with the
    /// radius and the spots' radiance with its square, so that the same light
    /// reaches the hair.
    pub fn thesis_rig(center: Vec3, radius: f32) -> [Light; 3] {
        let k = radius / crate::groom::scenes::THESIS_BOUNDING_RADIUS;
        let spot = |offset: Vec3, color: Vec3| Light::Spot {
            position: center + k * offset,
            direction: -offset,
            outer_angle: 0.6,
            inner_angle: 0.4,
            color: color * k * k,
        };
        [
            spot(Vec3::new(-0.6, 0.5, 0.8), Vec3::splat(1.1)),
            spot(Vec3::new(0.9, 0.1, 0.4), Vec3::new(0.25, 0.27, 0.33)),
            Light::Directional { direction: Vec3::new(0.2, -0.3, 1.0), color: Vec3::new(0.25, 0.22, 0.2) },
        ]
    }

    /// Checks the light: a colour of finite components in 0..=1e6 (a
    /// directional light's radiance; a point or spot light's intensity at
    /// 1 m in 0..=1e9, since it falls off with the squared distance), a position
    /// within 1e6 m of the origin on every axis, a finite non-zero direction,
    /// and 0 ≤ inner ≤ outer < π for a spot; the error names the field.
    pub fn validate(&self) -> Result<()> {
        let (color, most) = match *self {
            Light::Directional { color, .. } => (color, 1e6f32),
            Light::Point { color, .. } | Light::Spot { color, .. } => (color, 1e9),
        };
        if !(color.is_finite() && color.min_element() >= 0.0 && color.max_element() <= most) {
            return Err(Error::param("light color", color, format!("finite, each component 0..={most:e}")));
        }
        if let Light::Point { position, .. } | Light::Spot { position, .. } = *self {
            if !(position.is_finite() && position.abs().max_element() <= 1e6) {
                return Err(Error::param("light position", position, "finite, each component within ±1e6 m"));
            }
        }
        if let Light::Directional { direction, .. } | Light::Spot { direction, .. } = *self {
            if !(direction.is_finite() && direction.abs().max_element() <= 1e6) || direction.try_normalize().is_none() {
                return Err(Error::param("light direction", direction, "finite and non-zero"));
            }
        }
        if let Light::Spot { outer_angle, inner_angle, .. } = *self {
            let ordered = outer_angle.is_finite()
                && inner_angle.is_finite()
                && 0.0 <= inner_angle
                && inner_angle <= outer_angle
                && outer_angle < std::f32::consts::PI;
            if !ordered {
                return Err(Error::param(
                    "light inner_angle and outer_angle",
                    format!("{inner_angle} and {outer_angle}"),
                    "0 ≤ inner_angle ≤ outer_angle < π radians",
                ));
            }
        }
        Ok(())
    }

    pub(crate) fn to_gpu(self) -> Result<GpuLight> {
        self.validate()?;
        let normal = |d: Vec3| d.normalize();
        Ok(match self {
            Light::Directional { direction, color } => {
                let d = normal(direction);
                GpuLight {
                    position_kind: [0.0, 0.0, 0.0, light_kind::DIRECTIONAL as f32],
                    direction_cone: [d.x, d.y, d.z, 0.0],
                    color_range: color.extend(0.0).to_array(),
                }
            }
            Light::Point { position, color } => GpuLight {
                position_kind: position.extend(light_kind::POINT as f32).to_array(),
                direction_cone: [0.0, -1.0, 0.0, 0.0],
                color_range: color.extend(0.0).to_array(),
            },
            Light::Spot { position, direction, outer_angle, inner_angle, color } => {
                let d = normal(direction);
                GpuLight {
                    position_kind: position.extend(light_kind::SPOT as f32).to_array(),
                    direction_cone: [d.x, d.y, d.z, outer_angle.cos()],
                    color_range: color.extend(inner_angle.cos()).to_array(),
                }
            }
        })
    }
}

/// How hair is shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadingMode {
    /// Kajiya-Kay diffuse and two shifted highlights (Scheuermann; the thesis).
    #[default]
    KajiyaKay,
    /// Marschner R, TT and TRT through lookup tables (Nalu), with
    /// [`HairMaterial::marschner`] parameters.
    Marschner,
}

impl ShadingMode {
    /// The `SHADING_*` code the draw pass's shaders test.
    pub(crate) fn code(self) -> u32 {
        match self {
            ShadingMode::KajiyaKay => shading::KAJIYA_KAY,
            ShadingMode::Marschner => shading::MARSCHNER,
        }
    }
}

/// Hair material (Kajiya-Kay diffuse and two shifted specular highlights).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HairMaterial {
    /// Albedo at the root, linear RGB (each 0..=1000). Default: dark brown (0.10, 0.05, 0.02).
    pub root_color: Vec3,
    /// Albedo at the tip, linear RGB (each 0..=1000). Default: (0.25, 0.14, 0.06).
    pub tip_color: Vec3,
    /// Ambient fraction of the albedo (0..=1). Default: 0.08.
    pub ambient: f32,
    /// How far diffuse light wraps around to the side away from the light
    /// (0 = none, 1 = half way). Default: 0.3.
    pub diffuse_wrap: f32,
    /// Primary highlight color, linear RGB (each 0..=1000). Default: (0.35, 0.33, 0.30).
    pub primary_color: Vec3,
    /// Primary highlight exponent (≥ 1). Default: 80.
    pub primary_exponent: f32,
    /// Primary tangent shift along the strand normal (−1..=1). Default: −0.1 (toward the tip).
    pub primary_shift: f32,
    /// Secondary highlight color (multiplied by the albedo; each 0..=1000). Default: (1.0, 0.8, 0.6).
    pub secondary_color: Vec3,
    /// Secondary highlight exponent (≥ 1). Default: 12.
    pub secondary_exponent: f32,
    /// Secondary tangent shift (−1..=1). Default: 0.15.
    pub secondary_shift: f32,
    /// Per-hair random shift added to both shifts, amplitude (0..=1). Default: 0.15.
    pub shift_jitter: f32,
    /// How much noise breaks up the secondary highlight (0..=1). Default: 0.7.
    pub highlight_breakup: f32,
    /// Ribbon width at the root, meters (0..=1). Default: 0.00012.
    pub root_width: f32,
    /// Ribbon width at the tip, meters (0..=1). Default: 0.00005.
    pub tip_width: f32,
    /// Least ribbon width on screen, pixels (0 = none), for opaque hair only
    /// ([`super::Transparency::Off`]); transparent strands keep their true width
    /// and are drawn with their coverage instead. Default: 1.
    pub least_pixel_width: f32,
    /// Opacity of one strand where it covers a whole pixel, for transparent hair
    /// (0..=1). Default: 0.8.
    pub opacity: f32,
    /// Real hairs each drawn strand stands for (1..=10,000; more where level of
    /// detail draws fewer strands, [`super::Renderer::strand_hairs`]). In every
    /// mode a strand's opacity-map fragments add n hairs' opacity
    /// ([`super::ShadowParams::opacity`]). For transparent hair the strand is
    /// drawn as a band n hair widths wide, or (1 − 1/n) × the drawn strands'
    /// spacing where that is wider ([`super::Renderer::strand_spacing`]), up to
    /// twice n hair widths, whose
    /// alpha where it covers fraction c of a pixel is `opacity · c · density`,
    /// the density being the part of the band n hairs placed at random cover
    /// ([`super::reference::strand_band`]). Default: 1.
    pub represented_hairs: f32,
    /// Shading model. Default: [`ShadingMode::KajiyaKay`].
    pub shading: ShadingMode,
    /// Marschner parameters (used in [`ShadingMode::Marschner`]; the lookup tables
    /// are rebuilt when they change).
    pub marschner: super::MarschnerParams,
}

impl Default for HairMaterial {
    fn default() -> Self {
        HairMaterial {
            root_color: Vec3::new(0.10, 0.05, 0.02),
            tip_color: Vec3::new(0.25, 0.14, 0.06),
            ambient: 0.08,
            diffuse_wrap: 0.3,
            primary_color: Vec3::new(0.35, 0.33, 0.30),
            primary_exponent: 80.0,
            primary_shift: -0.1,
            secondary_color: Vec3::new(1.0, 0.8, 0.6),
            secondary_exponent: 12.0,
            secondary_shift: 0.15,
            shift_jitter: 0.15,
            highlight_breakup: 0.7,
            root_width: 0.00012,
            tip_width: 0.00005,
            least_pixel_width: 1.0,
            opacity: 0.8,
            represented_hairs: 1.0,
            shading: ShadingMode::KajiyaKay,
            marschner: super::MarschnerParams::default(),
        }
    }
}

impl HairMaterial {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        let colors = [
            ("root_color", self.root_color),
            ("tip_color", self.tip_color),
            ("primary_color", self.primary_color),
            ("secondary_color", self.secondary_color),
        ];
        for (name, c) in colors {
            if !c.is_finite() || c.min_element() < 0.0 || c.max_element() > 1000.0 {
                return Err(Error::param(name, c, "finite, each component 0..=1000"));
            }
        }
        let ranges = [
            ("ambient", self.ambient, 0.0, 1.0),
            ("diffuse_wrap", self.diffuse_wrap, 0.0, 1.0),
            ("primary_exponent", self.primary_exponent, 1.0, 10_000.0),
            ("secondary_exponent", self.secondary_exponent, 1.0, 10_000.0),
            ("primary_shift", self.primary_shift, -1.0, 1.0),
            ("secondary_shift", self.secondary_shift, -1.0, 1.0),
            ("shift_jitter", self.shift_jitter, 0.0, 1.0),
            ("highlight_breakup", self.highlight_breakup, 0.0, 1.0),
            ("root_width", self.root_width, 0.0, 1.0),
            ("tip_width", self.tip_width, 0.0, 1.0),
            ("least_pixel_width", self.least_pixel_width, 0.0, 64.0),
            ("opacity", self.opacity, 0.0, 1.0),
            ("represented_hairs", self.represented_hairs, 1.0, 10_000.0),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(Error::param(name, v, format!("{lo}..={hi}")));
            }
        }
        self.marschner.validate()
    }
}

/// Side of the square noise texture, texels.
pub(crate) const NOISE_SIZE: u32 = 128;

/// The RG8 noise texture: R breaks up the secondary highlight, G jitters the
/// shift. Smoothed white noise (a 3×3 box of random texels), deterministic.
pub(crate) fn noise_texels() -> Vec<u8> {
    let n = NOISE_SIZE as usize;
    let mut rng = Pcg64Mcg::seed_from_u64(0x5eed_4a1e);
    let raw: Vec<[f32; 2]> = (0..n * n).map(|_| [rng.random::<f32>(), rng.random::<f32>()]).collect();
    let mut out = Vec::with_capacity(n * n * 2);
    for y in 0..n {
        for x in 0..n {
            let mut sum = [0.0f32; 2];
            for dy in [n - 1, 0, 1] {
                for dx in [n - 1, 0, 1] {
                    let v = raw[((y + dy) % n) * n + (x + dx) % n];
                    sum[0] += v[0];
                    sum[1] += v[1];
                }
            }
            // The mean of 9 uniforms has std 0.096: stretch it back to about 0..1.
            for s in sum {
                out.push(((s / 9.0 - 0.5) * 3.0 + 0.5).clamp(0.0, 1.0).mul_add(255.0, 0.5) as u8);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::Light;
    use crate::groom::scenes::THESIS_BOUNDING_RADIUS;

    /// At the thesis' size the key spot sits at the thesis' offset; at twice the
    /// size twice as far and four times as bright, pointing at the same centre.
    #[test]
    fn the_thesis_rig_scales_with_the_head_of_hair() {
        let center = Vec3::new(0.0, 1.6, 0.0);
        let [key, fill, rim] = Light::thesis_rig(center, THESIS_BOUNDING_RADIUS);
        let Light::Spot { position, direction, color, .. } = key else { panic!("the key light is a spot") };
        assert_eq!(position, center + Vec3::new(-0.6, 0.5, 0.8));
        assert_eq!((direction, color), (Vec3::new(0.6, -0.5, -0.8), Vec3::splat(1.1)));
        assert!(matches!(fill, Light::Spot { .. }) && matches!(rim, Light::Directional { .. }));
        let [big, ..] = Light::thesis_rig(center, 2.0 * THESIS_BOUNDING_RADIUS);
        let Light::Spot { position, direction, color, .. } = big else { panic!("the key light is a spot") };
        assert!((position - (center + 2.0 * Vec3::new(-0.6, 0.5, 0.8))).length() < 1e-6);
        assert_eq!(direction, Vec3::new(0.6, -0.5, -0.8));
        assert!((color - Vec3::splat(4.4)).length() < 1e-5);
        // The rig of the largest scene the tool draws (1e4 m from its centre) is valid.
        for light in Light::thesis_rig(center, 1e4) {
            light.validate().expect("a valid light");
        }
    }
}
