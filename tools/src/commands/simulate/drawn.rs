//! `simulate --drawn-out`: the strands as the renderer draws them after the
//! last step, evaluated on the GPU by the renderer's interpolation stage.

use std::path::Path;

use glam::Vec3;
use vkhair::config::Config;
use vkhair::groom::cyhair::HairFile;
use vkhair::render::Renderer;
use vkhair::sim::HairSim;
use vkhair::{GpuContext, Groom};

use crate::args::input::Dense;
use crate::output::CliResult;
use crate::say;
use crate::scene::bind_followers;

/// Writes to `path` the strands drawn for `sim`'s latest state (world, meters):
/// a dense groom's followers in the input's strand order (before the
/// tessellation smooths them: each at its follower points), else the hairs
/// grown from the key hairs in drawing order; at full detail.
pub fn write_drawn(
    path: &Path,
    ctx: &GpuContext,
    sim: &HairSim,
    keys: &Groom,
    dense: Option<&Dense>,
    config: &Config,
) -> CliResult {
    let followers = dense.map(|d| bind_followers(d, keys, config)).transpose()?;
    let mut renderer = match &followers {
        Some(f) => Renderer::with_followers(ctx, sim, &config.render, f)?,
        None => Renderer::new(ctx, sim, &config.render)?,
    };
    renderer.prepare_now(sim, None)?;
    let (positions, _) = renderer.read_hairs()?;
    let (hairs, per_hair) = renderer.hair_counts();
    let strands: Vec<Vec<Vec3>> = match &followers {
        Some(f) => f.to_input_order(&positions)?.into_iter().map(|(_, strand)| strand).collect(),
        None => positions.chunks_exact(per_hair as usize).map(|h| h.iter().map(|p| p.truncate()).collect()).collect(),
    };
    let groom = Groom::from_strands(&strands)?;
    HairFile::new(groom, "vkhair simulate: strands as drawn after the last step").save(path)?;
    say!("wrote {}: {hairs} drawn strands × {per_hair} points", path.display());
    Ok(())
}
