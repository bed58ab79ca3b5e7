//! The render frame of a bench scene in each transparency mode: GPU time,
//! memory, and the error against the exact reference (`transparency.csv`,
//! `transparency.png`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::{Vec3, Vec4};

use super::frames::{bench_frames, Keep};
use super::{Bench, Row};
use crate::output::Error;
use crate::say;

/// The modes measured: the tool's default first (exact, K = 8), then the others.
const MODES: [(Option<&str>, u32); 5] =
    [(None, 8), (Some("off"), 8), (Some("fast"), 8), (Some("exact"), 4), (Some("exact"), 16)];

/// One mode's figures on one scene.
pub(super) struct ModeRow {
    scene: String,
    mode: String,
    gpu_ms: f64,
    mib: f64,
    error: f64,
}

/// The exact image of a frame's hairs and the hairs it was drawn from: the
/// modes draw the same hairs (the simulation is deterministic), so one
/// reference serves them all, and a frame whose hairs differ gets its own.
type Reference = (Vec<Vec<Vec4>>, Vec<Vec3>);

/// Measures the render frame `args` of scene `scene` in every mode of [`MODES`],
/// pushing a row of the table and one of the mode chart for each.
pub(super) fn render_rows(
    b: &Bench<'_>,
    scene: &str,
    args: &[String],
    rows: &mut Vec<Row>,
    modes: &mut Vec<ModeRow>,
) -> Result<(), Error> {
    let (ctx, samples, clock) = (b.ctx, b.args.samples, b.clock);
    let mut reference: Option<Reference> = None;
    for (mode, k) in MODES {
        let k = k.to_string();
        let mut with_mode: Vec<&str> = args.iter().map(String::as_str).collect();
        if let Some(mode) = mode {
            with_mode.extend(["--transparency", mode, "--sorted-fragments", &k]);
        }
        let f = bench_frames(ctx, &with_mode, &b.args.sim, samples, Keep::Unlit)?;
        let mib = f.transparency_bytes as f64 / (1024.0 * 1024.0);
        let label = match mode {
            None => default_exact(),
            Some("exact") => format!("exact K = {k}"),
            Some("off") => OFF.to_owned(),
            Some(m) => m.to_owned(),
        };
        let stage = match mode {
            None => format!("render frame, {} hairs, {} segments", f.hairs, f.segments),
            Some(_) => format!("render frame, transparency {label}, {mib:.1} MiB"),
        };
        let error = match &f.unlit {
            Some(unlit) => {
                if reference.as_ref().is_none_or(|r| r.0 != unlit.strands) {
                    let started = std::time::Instant::now();
                    reference = Some((unlit.strands.clone(), unlit.reference()));
                    say!("{scene}: exact reference in {:.1} s", started.elapsed().as_secs_f64());
                }
                reference.as_ref().map_or(f64::NAN, |r| unlit.error(&r.1))
            }
            None => f64::NAN,
        };
        let gpu = clock.figure(&f.gpu, &f.wall);
        modes.push(ModeRow { scene: scene.to_owned(), mode: label, gpu_ms: gpu.median(), mib, error });
        let mut row = Row::new(scene, &stage, "frame", gpu, f.gpu, f.work);
        row.error = Some(error);
        rows.push(row);
    }
    Ok(())
}

/// Label of the off mode's row.
pub(super) const OFF: &str = "off";

/// Label of the default mode's row (exact, vkhair's default K).
pub(super) fn default_exact() -> String {
    format!("exact K = {} (default)", vkhair::render::OitParams::default().sorted_fragments)
}

/// The GPU figure (median, ms) of `scene`'s frame in the mode labelled `mode`
/// ([`OFF`], [`default_exact`]); NaN where it was not measured.
pub(super) fn frame_ms(modes: &[ModeRow], scene: Option<&str>, mode: &str) -> f64 {
    modes.iter().find(|m| Some(m.scene.as_str()) == scene && m.mode == mode).map_or(f64::NAN, |m| m.gpu_ms)
}

/// Writes `transparency.csv` into `out`: scene, mode, GPU ms, MiB, error.
pub(super) fn write_modes(out: &Path, modes: &[ModeRow]) -> Result<PathBuf, Error> {
    let mut csv = String::from("scene,mode,gpu_ms,memory_mib,error_srgb_steps\n");
    for m in modes {
        let _ = writeln!(csv, "{},{},{:.4},{:.3},{:.3}", m.scene, m.mode, m.gpu_ms, m.mib, m.error);
    }
    super::write_csv(out, "transparency.csv", &csv)
}
