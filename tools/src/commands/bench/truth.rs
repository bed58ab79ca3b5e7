//! Sintel's default frame against its ground truth: every hair of the
//! full-density scalp distribution (the tool's default, `[scalp]` density
//! over the scalp the key hairs' roots cover: about 107,000 hairs for Sintel),
//! each one hair at its physical width, level of detail off, K = 32 and a pool
//! of 24 fragments per pixel, the same simulated state and camera. The figure
//! is the error of the default frame over hair pixels, as
//! `render::reference::srgb_error_stats`.

use vkhair::render::reference::{srgb_error_stats, ImageError};

use super::frames::{bench_frames, Keep, LIT_BACKGROUND};
use super::Bench;
use crate::output::Error;

/// The default frame of `args` (a render scene's flags) against its ground
/// truth, and the strands each draws at full detail.
pub struct TruthFigures {
    pub error: ImageError,
    pub default_strands: u64,
    pub truth_strands: u64,
}

/// Renders the default frame of `args` and its ground truth (every hair of
/// the scalp distribution, one hair each) after the same steps, and compares them.
pub fn against_full_head(b: &Bench<'_>, args: &[String]) -> Result<TruthFigures, Error> {
    let base: Vec<&str> = args.iter().map(String::as_str).collect();
    let default = bench_frames(b.ctx, &base, &b.args.sim, 1, Keep::Lit)?;
    let mut truth_args = base.clone();
    truth_args.extend([
        "--no-lod",
        "--transparency",
        "exact",
        "--sorted-fragments",
        "32",
        "--fragments-per-pixel",
        "24",
    ]);
    let truth = bench_frames(b.ctx, &truth_args, &b.args.sim, 1, Keep::Lit)?;
    let (Some(image), Some(reference)) = (&default.lit, &truth.lit) else {
        return Err("the bench kept no frame to compare".into());
    };
    let error = srgb_error_stats(image, reference, LIT_BACKGROUND).ok_or("the ground truth shows no hair")?;
    Ok(TruthFigures { error, default_strands: default.hairs, truth_strands: truth.hairs })
}
