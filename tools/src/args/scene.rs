//! The rendered scene's flags, shared by `render` and the frames `bench`
//! measures: the image, the groom, the render and material knobs, the lights'
//! shadows and the simulation knobs.

use std::path::PathBuf;

use vkhair::render::{Interpolator, Raster, Transparency};

use super::input::InputArgs;
use super::sim::SimArgs;
use crate::output::{MAX_IMAGE_SIDE, MIN_IMAGE_SIDE};

#[derive(clap::Args, Clone, Debug)]
pub struct SceneArgs {
    /// Image width, pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height, pixels.
    #[arg(long, default_value_t = 480)]
    pub height: u32,
    #[command(flatten)]
    pub input: InputArgs,
    /// Parameter file (TOML, see `vkhair config`): simulation, rendering, lights and
    /// material; the flags below win over it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Hairs grown per key hair with --clumps (per triangle of key-hair roots
    /// with --barycentric), or the share of followers drawn with --guides; over
    /// the scalp the count follows --density instead, and this is refused
    /// [default: 16].
    #[arg(long)]
    pub hairs_per_key: Option<u32>,
    /// Smoothed segments per key segment [default: 4].
    #[arg(long)]
    pub level: Option<u32>,
    /// Camera distance from the centre of the groom and mesh, in their units
    /// [default: framed to their bounds].
    #[arg(long)]
    pub distance: Option<f32>,
    /// Supersample 2× and resolve with the 5-tap filter.
    #[arg(long)]
    pub ssaa: bool,
    /// Turn level of detail off (always full detail).
    #[arg(long)]
    pub no_lod: bool,
    /// Grow hairs inside triangles of key-hair roots (barycentric, a set count
    /// per triangle) instead of rooting them over the scalp.
    #[arg(long, conflicts_with = "clumps")]
    pub barycentric: bool,
    /// Grow hairs in clumps around each key hair (single-strand interpolation,
    /// --hairs-per-key a key hair) instead of rooting them over the scalp.
    #[arg(long)]
    pub clumps: bool,
    /// Drawn hairs per cm² of the scalp the key hairs' roots cover, each
    /// blended from its nearest key hairs [default: the --config file's
    /// [scalp] density, else 150].
    #[arg(long)]
    pub density: Option<f32>,
    /// Shade with Marschner lookup tables instead of Kajiya-Kay.
    #[arg(long)]
    pub marschner: bool,
    /// Draw one-pixel lines instead of ribbons (opaque: turns transparency off
    /// unless --transparency is given).
    #[arg(long)]
    pub lines: bool,
    /// How hair is blended: opaque ribbons, weighted blended transparency or
    /// per-pixel sorted lists [default: the --config file's, else exact].
    #[arg(long, value_enum)]
    pub transparency: Option<Transparency>,
    /// Who rasterises the strands of --transparency exact: the compute
    /// rasteriser (per-pixel lists), the tiled one (no per-pixel lists, the
    /// least memory) or the hardware raster pipeline [default: the --config
    /// file's, else auto: compute on GPUs, on a CPU device the faster one there].
    #[arg(long, value_enum)]
    pub raster: Option<Raster>,
    /// Who grows the drawn hairs from the smoothed key hairs: a compute
    /// dispatch or the tessellation stages [default: the --config file's,
    /// else auto: compute on GPUs, on a CPU device the faster one there].
    #[arg(long, value_enum)]
    pub interpolator: Option<Interpolator>,
    /// Fragments sorted exactly per pixel by --transparency exact (1..=32) [default: 8].
    #[arg(long)]
    pub sorted_fragments: Option<u32>,
    /// Fragment pool of --transparency exact, fragments per pixel (0.01..=256;
    /// fragments beyond it are blended unsorted) [default: 8].
    #[arg(long)]
    pub fragments_per_pixel: Option<f32>,
    /// No self-shadowing (by default the two spot lights cast deep opacity maps).
    #[arg(long)]
    pub no_shadows: bool,
    /// Side of each light's opacity map, texels.
    #[arg(long, default_value_t = 512)]
    pub shadow_resolution: u32,
    /// Shadow the spot lights through the simulation's density volume instead of
    /// opacity maps (turns the simulation's FLIP volume stage on).
    #[arg(long)]
    pub volume_shadows: bool,
    #[command(flatten)]
    pub sim: SimArgs,
}

impl SceneArgs {
    /// Options that mean something only with others, and values out of range: an
    /// error saying what the option needs, before any file is read or GPU work done.
    pub fn check(&self) -> Result<(), String> {
        let sides = MIN_IMAGE_SIDE..=MAX_IMAGE_SIDE;
        if !sides.contains(&self.width) || !sides.contains(&self.height) {
            return Err(format!(
                "--width and --height must be {MIN_IMAGE_SIDE}..={MAX_IMAGE_SIDE} pixels (got {}×{})",
                self.width, self.height
            ));
        }
        if !(16..=4096).contains(&self.shadow_resolution) {
            return Err(format!("--shadow-resolution must be 16..=4096 texels (got {})", self.shadow_resolution));
        }
        self.input.check()?;
        if self.volume_shadows && self.sim.volume == Some(vkhair::sim::VolumeMode::Off) {
            return Err("--volume-shadows needs the simulation's volume stage (--volume off turns it off)".into());
        }
        if let Some(d) = self.distance {
            if !(d.is_finite() && d > 0.0) {
                return Err(format!("--distance must be a finite number above 0 (got {d})"));
            }
            if d > 1e6 {
                return Err(format!("--distance must be at most 1e6 (in the groom's units; got {d:e})"));
            }
            // Closer, the camera's matrices are no longer finite (1e-9 made them so).
            if d < 1e-6 {
                return Err(format!("--distance must be at least 1e-6 (in the groom's units; got {d:e})"));
            }
        }
        Ok(())
    }
}
