//! What the renderer draws: counts, widths, level of detail, supersampling,
//! interpolation mode and primitive.

use crate::error::{Error, Result};

/// Most smoothed segments per key segment (the tessellation level limit vkhair uses).
pub const MAX_SMOOTHING_LEVEL: u32 = 64;

/// Most hairs grown around (or between) key hairs.
pub const MAX_HAIRS_PER_KEY: u32 = crate::codes::interpolate::MAX_HAIRS_PER_KEY;

/// Rendering parameters.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderParams {
    /// Smoothed segments per key segment (1..=64). Default: 4 (a 6-point key hair
    /// becomes 20 segments, as in the thesis scene).
    pub smoothing_level: u32,
    /// Hairs grown around each key hair (1..=1024, [`MAX_HAIRS_PER_KEY`]). Default: 16 (1750 key hairs give
    /// 28,000 hairs, as in the thesis scene).
    pub hairs_per_key: u32,
    /// Radius of a clump around its key hair, meters (≥ 0). Default: 0.012.
    pub clump_width: f32,
    /// Fraction of `clump_width` at the root (≥ 0). Default: 0.3.
    pub root_width: f32,
    /// Fraction of `clump_width` at the tip (≥ 0). Default: 1.0.
    pub tip_width: f32,
    /// Level of detail by camera distance.
    pub lod: LodParams,
    /// Draw at twice the target's width and height and resolve with a 5-tap filter
    /// (thesis 3.5). Default: false (a host may use MSAA targets instead).
    pub supersampling: bool,
    /// How hairs are grown from key hairs. Default: [`InterpolationMode::SingleStrand`].
    pub interpolation: InterpolationMode,
    /// What each hair segment is drawn as. Default: [`Primitive::Ribbons`].
    pub primitive: Primitive,
    /// How hair is blended. Default: [`Transparency::Off`] (opaque ribbons).
    pub transparency: Transparency,
    /// The transparent modes' sizes.
    pub oit: OitParams,
    /// Who rasterises the strands of [`Transparency::Exact`] and of the deep
    /// opacity maps: the hardware raster pipeline or vkhair's compute
    /// rasteriser. Default: [`Raster::Auto`] (compute on GPUs, see
    /// [`Raster::Auto`] for CPU devices).
    pub raster: Raster,
    /// Who grows the drawn hairs from the smoothed key hairs: the tessellation
    /// isoline stages or a compute dispatch (the same vertices either way).
    /// Default: [`Interpolator::Auto`] (compute on GPUs, see
    /// [`Interpolator::Auto`] for CPU devices).
    pub interpolator: Interpolator,
    /// Frames the host has in flight (1..=16): images a new target size makes
    /// obsolete are freed this many frames after their last use. Default: 2.
    pub frames_in_flight: u32,
    /// How motion vectors are written into a target's velocity image
    /// ([`super::RenderTarget::velocity`]): which hair a pixel follows, the
    /// units and the sign.
    pub motion: MotionParams,
}

/// How the hair's motion vectors are written ([`super::RenderTarget::velocity`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotionParams {
    /// The opacity, accumulated front to back, at which a pixel's motion takes
    /// its hair (0 < threshold ≤ 1): in [`Transparency::Exact`] the motion is
    /// that of the hair whose fragment brings the pixel's sorted fragments to
    /// this opacity (a pixel whose nearest [`OitParams::sorted_fragments`]
    /// never reach it gets none). [`Transparency::Fast`], which keeps no
    /// order, follows the nearest fragment at least half opaque, whatever
    /// this is. Default: 0.5.
    pub threshold: f32,
    /// The units of a motion vector. Default: [`MotionUnits::Pixels`].
    pub units: MotionUnits,
    /// Which way a motion vector points. Default:
    /// [`MotionDirection::CurrentMinusPrevious`].
    pub direction: MotionDirection,
}

impl Default for MotionParams {
    fn default() -> Self {
        MotionParams { threshold: 0.5, units: MotionUnits::Pixels, direction: MotionDirection::CurrentMinusPrevious }
    }
}

/// The units of a motion vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionUnits {
    /// Pixels of the host's target (not of the supersampled images), +x to
    /// the right, +y down the rows.
    #[default]
    Pixels,
    /// Vulkan normalised device coordinates: the same axes, 2 across the
    /// target's width and height.
    Ndc,
}

/// Which way a motion vector points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionDirection {
    /// Where the pixel's hair is in this frame minus where it was in the
    /// previous one (a TAA resolve subtracts it to find the history).
    #[default]
    CurrentMinusPrevious,
    /// Where it was minus where it is (the history's offset from the pixel).
    PreviousMinusCurrent,
}

/// What the draw pass turns each hair segment into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Primitive {
    /// Camera-facing quads pulled by the vertex stage (two triangles per segment),
    /// [`super::HairMaterial`] widths.
    #[default]
    Ribbons,
    /// One-pixel lines (two vertices per segment; cheapest).
    Lines,
}

/// How the interpolation pass grows hairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InterpolationMode {
    /// `hairs_per_key` hairs around each key hair, offset in its frame (thesis 3.2).
    #[default]
    SingleStrand,
    /// `hairs_per_key` hairs inside each triangle of key-hair roots, blending the
    /// three key hairs with stable random barycentric weights (Nalu).
    Barycentric,
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams {
            smoothing_level: 4,
            hairs_per_key: 16,
            clump_width: 0.012,
            root_width: 0.3,
            tip_width: 1.0,
            lod: LodParams::default(),
            supersampling: false,
            interpolation: InterpolationMode::SingleStrand,
            primitive: Primitive::Ribbons,
            transparency: Transparency::Off,
            oit: OitParams::default(),
            raster: Raster::Auto,
            interpolator: Interpolator::Auto,
            frames_in_flight: 2,
            motion: MotionParams::default(),
        }
    }
}

/// How the draw pass blends hair into the target (with the `clap` feature, a
/// command-line value: `off`, `fast`, `exact`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Transparency {
    /// Opaque ribbons at least [`super::HairMaterial::least_pixel_width`] wide,
    /// nearest layer only (a depth pre-pass, then one shaded layer).
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Opaque ribbons at least a pixel wide, nearest layer only"))]
    Off,
    /// Weighted blended order-independent transparency (one pass, two
    /// accumulation images, no lists): every hair vertex shaded once and its
    /// colour carried along the ribbon, the fragments' colours averaged with
    /// weights falling with depth, the total opacity exact.
    #[cfg_attr(feature = "clap", value(help = "Weighted blended transparency: one pass, no lists"))]
    Fast,
    /// Per-pixel linked lists of every fragment (coloured by the hair's vertices,
    /// each shaded once per frame), the
    /// [`OitParams::sorted_fragments`] nearest sorted exactly per pixel and the rest
    /// blended as an order-independent tail.
    #[cfg_attr(feature = "clap", value(help = "Per-pixel lists, the nearest fragments sorted exactly"))]
    Exact,
}

/// Who rasterises the strands of [`Transparency::Exact`] and of the deep
/// opacity maps (with the `clap` feature, a command-line value: `auto`,
/// `hardware`, `compute`, `tiles`). The other transparency modes always draw
/// through the hardware raster pipeline.
///
/// For the exact mode the hardware and compute rasterisers feed the same
/// per-pixel lists and the same composite; they differ in how a segment
/// becomes fragments:
///
/// - the hardware raster pipeline draws each segment as a camera-facing ribbon
///   (two triangles) whose fragments compute their coverage;
/// - the compute rasteriser (`glsl/render/strand_raster.comp`) walks, per
///   segment, the pixels within its band's reach and gives each the analytic
///   coverage of the band's true width across the strand (no least width:
///   sub-pixel strands blend by coverage), without the 2×2 pixel quads and
///   tiny triangles that long thin strands cost a hardware rasteriser. It
///   reads the host's depth from [`super::RenderTarget::depth_image`], which
///   must then be given (created with `TRANSFER_SRC` usage).
///
/// For the deep opacity maps, the hardware draws the strands as lines into
/// the atlas (depth test and blending); the compute rasteriser walks each
/// segment as a one-texel line and keeps z0 and the layers' opacity with
/// integer atomics (each fragment's opacity rounded to 1/65,536), then writes
/// the same atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Raster {
    /// On GPUs (discrete, integrated, virtual) the compute rasteriser for the
    /// strands ([`Raster::Compute`], measured faster there than
    /// [`Raster::Tiles`]) and for the maps; on a CPU
    /// device (lavapipe) the one measured faster there, for the strands
    /// ([`Raster::resolve`]: the hardware) and for the maps
    /// ([`Raster::resolve_shadows`]: the compute rasteriser).
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Compute on GPUs; on a CPU device the faster one there"))]
    Auto,
    /// Ribbons through the hardware raster pipeline.
    #[cfg_attr(feature = "clap", value(help = "Ribbons through the hardware raster pipeline"))]
    Hardware,
    /// vkhair's compute rasteriser, one invocation a segment into per-pixel lists.
    #[cfg_attr(feature = "clap", value(help = "vkhair's compute rasteriser, per-pixel lists"))]
    Compute,
    /// vkhair's tiled compute rasteriser: the segments binned into screen
    /// tiles, each tile's fragments sorted in one workgroup's shared memory
    /// (`render/draw/tiles.rs`), no per-pixel lists. The same fragments as
    /// [`Raster::Compute`] (one definition, `glsl/include/strand_segment.glsl`)
    /// and the same K nearest and tail per pixel, every fragment sorted or in
    /// the tail (no pool to overflow). The deep opacity maps draw with
    /// [`Raster::Compute`].
    #[cfg_attr(feature = "clap", value(help = "vkhair's tiled compute rasteriser, no per-pixel lists"))]
    Tiles,
}

impl Raster {
    /// The rasteriser this choice names for the exact mode's strands on a
    /// device of type `device_type`: [`Raster::Hardware`],
    /// [`Raster::Compute`] or [`Raster::Tiles`], never [`Raster::Auto`].
    pub fn resolve(self, device_type: ash::vk::PhysicalDeviceType) -> Raster {
        match self {
            Raster::Auto if device_type == ash::vk::PhysicalDeviceType::CPU => CPU_DEVICE_STRANDS,
            Raster::Auto => GPU_STRANDS,
            chosen => chosen,
        }
    }

    /// The rasteriser this choice names for the deep opacity maps on a device
    /// of type `device_type`: [`Raster::Hardware`] or [`Raster::Compute`],
    /// never [`Raster::Auto`].
    pub fn resolve_shadows(self, device_type: ash::vk::PhysicalDeviceType) -> Raster {
        match self {
            Raster::Auto if device_type == ash::vk::PhysicalDeviceType::CPU => CPU_DEVICE_SHADOWS,
            Raster::Auto | Raster::Tiles => Raster::Compute,
            chosen => chosen,
        }
    }
}

/// What [`Raster::Auto`] picks on a GPU for the exact mode's strands: the
/// one faster there. Measured on an NVIDIA H100 (`tools/gpu-bench.sh`, the
/// hair passes' GPU ms, one run; README, "Raster"): the thesis at 1920×1080
/// 2.05 against 2.56 through the tiled rasteriser, Sintel at the peer's
/// geometry 0.50 against 0.88, its close-up 0.74 against 1.21, 1,001,000
/// strands 65.1 against 72.0 — the per-segment rasteriser's atomics on the
/// per-pixel lists cost that GPU less than a tile's workgroup sorting its
/// fragments in shared memory. The tiled one needs no per-pixel lists: at
/// 3840×2160 the thesis took 190 MiB against 1,360 MiB.
const GPU_STRANDS: Raster = Raster::Compute;

/// What [`Raster::Auto`] picks on a CPU device (lavapipe) for the exact
/// mode's strands: the one faster there. Measured on lavapipe (Mesa 22.3.6, 2
/// cores), Sintel at 1280×720, the draw's GPU scope: 130–134 ms through the
/// hardware raster pipeline against 194–218 ms through the compute rasteriser
/// (README, "Raster"): a CPU device's rasteriser is tuned C that bins
/// triangles in tiles, while an invocation a segment walks its pixels in
/// divergent SIMD lanes.
const CPU_DEVICE_STRANDS: Raster = Raster::Hardware;

/// What [`Raster::Auto`] picks on a CPU device for the deep opacity maps: the
/// one faster there. Same runs, the two shadow passes: 51–53 ms through the
/// hardware's lines against 23 ms through the compute rasteriser.
const CPU_DEVICE_SHADOWS: Raster = Raster::Compute;

/// Who grows the drawn hairs (pass 2, `render/interpolate.rs`; with the
/// `clap` feature, a command-line value: `auto`, `tessellation`, `compute`).
///
/// Both run the same per-vertex code (`glsl/include/grow_*.glsl`) and store
/// the same vertices at the same places; they differ in how the work reaches
/// the GPU. The tessellation stages (the design's isolines: one patch per key
/// segment, one isoline per grown hair) run where a GPU runs its geometry,
/// which on an NVIDIA H100 is a small part of the chip: measured there
/// (`tools/gpu-bench.sh`), 96,609 hairs over the thesis' scalp took 3.95 ms
/// and 1,001,000 clump hairs 31.6 ms — about 1 ns a vertex, wherever the
/// vertex's arithmetic was. A compute dispatch (one invocation per vertex)
/// runs on every unit and writes neighbouring vertices from neighbouring
/// invocations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Interpolator {
    /// A compute dispatch on GPUs (discrete, integrated, virtual); on a CPU
    /// device (lavapipe) the one measured faster there ([`Interpolator::resolve`]).
    #[default]
    #[cfg_attr(feature = "clap", value(help = "Compute on GPUs; on a CPU device the faster one there"))]
    Auto,
    /// The tessellation isoline stages.
    #[cfg_attr(feature = "clap", value(help = "The tessellation isoline stages"))]
    Tessellation,
    /// A compute dispatch, one invocation per grown vertex.
    #[cfg_attr(feature = "clap", value(help = "A compute dispatch, one invocation per vertex"))]
    Compute,
}

impl Interpolator {
    /// What this choice names on a device of type `device_type`:
    /// [`Interpolator::Tessellation`] or [`Interpolator::Compute`], never
    /// [`Interpolator::Auto`].
    pub fn resolve(self, device_type: ash::vk::PhysicalDeviceType) -> Interpolator {
        match self {
            Interpolator::Auto if device_type == ash::vk::PhysicalDeviceType::CPU => CPU_DEVICE_INTERPOLATOR,
            Interpolator::Auto => Interpolator::Compute,
            chosen => chosen,
        }
    }
}

/// What [`Interpolator::Auto`] picks on a CPU device (lavapipe): the one
/// faster there (README, "Interpolation").
const CPU_DEVICE_INTERPOLATOR: Interpolator = Interpolator::Compute;

/// Smallest [`OitParams::max_buffer_bytes`] other than 0 (64 KiB).
pub const MIN_POOL_BUFFER_BYTES: u32 = 65_536;

/// Sizes of the transparent modes ([`Transparency::Fast`], [`Transparency::Exact`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OitParams {
    /// Fragments sorted exactly per pixel in the exact mode, K (1..=32). Default: 8.
    pub sorted_fragments: u32,
    /// Fragment pool of the exact mode, in fragments per pixel of the drawn extent
    /// (0.01..=256; 16 bytes each): fragments beyond it are counted and
    /// composited unsorted, in the order-independent tail behind the sorted
    /// ones (none is lost; the order of those is approximate). The pool is
    /// split over up to 8 storage buffers, each within the device's
    /// `maxStorageBufferRange`; a device whose 8 buffers cannot hold the request
    /// gets the pool they can hold ([`super::OitPool`], [`super::OitStats::requested`]).
    /// Default: 8.
    pub fragments_per_pixel: f32,
    /// Largest buffer of the exact mode's pool, bytes: 0 for the device's limits,
    /// else 65,536..=4,294,967,295 (the device's limits still apply), e.g. to
    /// keep each buffer within a host allocator's block. Default: 0.
    pub max_buffer_bytes: u32,
    /// Entries of the tiled rasteriser's bins ([`Raster::Tiles`]) per hair
    /// vertex the renderer can draw (0.1..=256; 4 bytes each; at least 256 a
    /// tile of the target): a segment takes one entry for each screen tile of
    /// 16 × 16 pixels its band reaches. A frame whose segments ask for more
    /// draws the entries that fit and says so
    /// ([`super::OitStats::tile_entries`]); the bins of the frame
    /// `frames_in_flight` after it grow to what it asked for. Default: 4.
    pub tile_entries_per_vertex: f32,
}

impl Default for OitParams {
    fn default() -> Self {
        OitParams { sorted_fragments: 8, fragments_per_pixel: 8.0, max_buffer_bytes: 0, tile_entries_per_vertex: 4.0 }
    }
}

/// Level of detail by camera distance d (to the centre of the hair), stepped:
/// with d0 = `full_detail_distance`, hairs per key = round(full · (d0/d)²) (they
/// cover screen area) and segments per key segment = round(full · d0/d) (they
/// follow screen length), each clamped between its minimum and the full count of
/// [`RenderParams`]; ribbon width grows by √(full hairs / hairs) to keep coverage.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LodParams {
    /// Whether detail falls with distance. Default: true.
    pub enabled: bool,
    /// Distance up to which full detail is drawn, meters (1e-4..=1e6). Default: 0.6.
    pub full_detail_distance: f32,
    /// Fewest hairs per key hair (1..=1024). Default: 2.
    pub min_hairs_per_key: u32,
    /// Lowest smoothing level (1..=64). Default: 1.
    pub min_smoothing_level: u32,
}

impl Default for LodParams {
    fn default() -> Self {
        LodParams { enabled: true, full_detail_distance: 0.6, min_hairs_per_key: 2, min_smoothing_level: 1 }
    }
}

/// The detail actually drawn (see [`LodParams`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detail {
    /// Smoothed segments per key segment.
    pub smoothing_level: u32,
    /// Hairs per key hair.
    pub hairs_per_key: u32,
    /// Ribbon width factor.
    pub width_scale: f32,
}

impl RenderParams {
    /// The detail at camera distance `distance` (full detail when LOD is off).
    pub fn detail_at(&self, distance: f32) -> Detail {
        let full =
            Detail { smoothing_level: self.smoothing_level, hairs_per_key: self.hairs_per_key, width_scale: 1.0 };
        if !self.lod.enabled || !distance.is_finite() || distance <= self.lod.full_detail_distance {
            return full;
        }
        let ratio = self.lod.full_detail_distance / distance;
        let hairs = ((self.hairs_per_key as f32 * ratio * ratio).round() as u32)
            .clamp(self.lod.min_hairs_per_key.min(self.hairs_per_key), self.hairs_per_key);
        let level = ((self.smoothing_level as f32 * ratio).round() as u32)
            .clamp(self.lod.min_smoothing_level.min(self.smoothing_level), self.smoothing_level);
        Detail {
            smoothing_level: level,
            hairs_per_key: hairs,
            width_scale: (self.hairs_per_key as f32 / hairs as f32).sqrt(),
        }
    }
}

impl RenderParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_SMOOTHING_LEVEL).contains(&self.smoothing_level) {
            return Err(Error::param("smoothing_level", self.smoothing_level, format!("1..={MAX_SMOOTHING_LEVEL}")));
        }
        if !(1..=MAX_HAIRS_PER_KEY).contains(&self.hairs_per_key) {
            return Err(Error::param("hairs_per_key", self.hairs_per_key, format!("1..={MAX_HAIRS_PER_KEY}")));
        }
        for (name, v) in
            [("clump_width", self.clump_width), ("root_width", self.root_width), ("tip_width", self.tip_width)]
        {
            if !(v.is_finite() && (0.0..=1e3).contains(&v)) {
                return Err(Error::param(name, v, "0..=1000"));
            }
        }
        let k = self.oit.sorted_fragments;
        if !(1..=crate::limits::OIT_MAX_SORTED).contains(&k) {
            return Err(Error::param("oit.sorted_fragments", k, format!("1..={}", crate::limits::OIT_MAX_SORTED)));
        }
        let f = self.oit.fragments_per_pixel;
        if !(f.is_finite() && (0.01..=256.0).contains(&f)) {
            return Err(Error::param("oit.fragments_per_pixel", f, "0.01..=256"));
        }
        let b = self.oit.max_buffer_bytes;
        if b != 0 && b < MIN_POOL_BUFFER_BYTES {
            return Err(Error::param("oit.max_buffer_bytes", b, format!("0 or {MIN_POOL_BUFFER_BYTES}..=4294967295")));
        }
        let t = self.motion.threshold;
        if !(t.is_finite() && t > 0.0 && t <= 1.0) {
            return Err(Error::param("motion.threshold", t, "greater than 0, at most 1"));
        }
        let e = self.oit.tile_entries_per_vertex;
        if !(e.is_finite() && (0.1..=256.0).contains(&e)) {
            return Err(Error::param("oit.tile_entries_per_vertex", e, "0.1..=256"));
        }
        let lod = &self.lod;
        let d = lod.full_detail_distance;
        if !(d.is_finite() && (1e-4..=1e6).contains(&d)) {
            return Err(Error::param("lod.full_detail_distance", d, "1e-4..=1e6 meters"));
        }
        if !(1..=MAX_HAIRS_PER_KEY).contains(&lod.min_hairs_per_key) {
            return Err(Error::param(
                "lod.min_hairs_per_key",
                lod.min_hairs_per_key,
                format!("1..={MAX_HAIRS_PER_KEY}"),
            ));
        }
        if !(1..=MAX_SMOOTHING_LEVEL).contains(&lod.min_smoothing_level) {
            return Err(Error::param(
                "lod.min_smoothing_level",
                lod.min_smoothing_level,
                format!("1..={MAX_SMOOTHING_LEVEL}"),
            ));
        }
        if !(1..=16).contains(&self.frames_in_flight) {
            return Err(Error::param("frames_in_flight", self.frames_in_flight, "1..=16"));
        }
        if self.transparency != Transparency::Off && self.primitive == Primitive::Lines {
            return Err(Error::param(
                "transparency",
                format!("{:?} with lines", self.transparency),
                "off with lines (transparent strands need ribbons for their coverage)",
            ));
        }
        Ok(())
    }
}

impl Detail {
    /// This detail, lowered where `params` allows less.
    pub(super) fn min_with(self, params: &RenderParams) -> Detail {
        Detail {
            smoothing_level: self.smoothing_level.min(params.smoothing_level),
            hairs_per_key: self.hairs_per_key.min(params.hairs_per_key),
            width_scale: self.width_scale,
        }
    }
}
