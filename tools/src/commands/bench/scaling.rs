//! The bench's scaling curves: simulation time against key hairs, points per
//! key hair and simulated key hairs, the FLIP stage against its grid and the
//! render frame against its size, each with the exponent of time against work
//! fitted in log-log space (`scaling.csv`, `scaling.png`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use vkhair::groom::{scenes, Groom};
use vkhair::sim::{motion, SimParams, VolumeMode};

use super::frames::{bench_frames, Keep};
use super::measure::{fitted_exponent, measure_sim, SimCase};
use super::{grown, volume_alone, write_csv, Bench};
use crate::output::Error;

/// One scaling curve: (work, GPU ms, CPU ms) per point.
pub struct Curve {
    pub axis: &'static str,
    pub unit: &'static str,
    pub points: Vec<(f64, f64, f64)>,
}

impl Curve {
    pub fn exponents(&self) -> (f64, f64) {
        let gpu: Vec<(f64, f64)> = self.points.iter().map(|p| (p.0, p.1)).collect();
        let cpu: Vec<(f64, f64)> = self.points.iter().map(|p| (p.0, p.2)).collect();
        (fitted_exponent(&gpu), fitted_exponent(&cpu))
    }
}

pub fn scaling(b: &Bench<'_>) -> Result<Vec<Curve>, Error> {
    let (ctx, a, clock) = (b.ctx, b.args, b.clock);
    let n = a.scaling_samples;
    let colliders = motion::thesis_colliders();
    let off = b.params(VolumeMode::Off, 32);
    let sim_of = |groom: &Groom, params: &SimParams, simulated: Option<usize>| {
        let params = params.clone();
        let case = SimCase { groom, colliders: &colliders, params, cpu: true, motion: a.sim.motion, simulated };
        measure_sim(ctx, &case, n, b.budget())
    };
    let sim = |groom: &Groom, params: &SimParams| sim_of(groom, params, None);
    let sim_point = |groom: &Groom, params: &SimParams| {
        sim(groom, params).map(|f| (clock.figure(&f.gpu, &f.gpu_wall).median(), f.cpu.median()))
    };
    let quick = a.quick;
    let hairs: &[usize] = if quick { &[200, 400] } else { &[1000, 4000, 16_000, 64_000] };
    let points: &[usize] = if quick { &[8, 16] } else { &[8, 16, 32, 64] };
    let grids: &[u32] = if quick { &[8, 16] } else { &[16, 32, 64] };
    // The quick run keeps a 1080p point: its default (exact) pool needs more
    // than one buffer on drivers whose storage-buffer range is 128 MiB.
    let sizes: &[(u32, u32)] =
        if quick { &[(160, 120), (1920, 1080)] } else { &[(854, 480), (1280, 720), (1920, 1080), (3840, 2160)] };
    let mut curves = Vec::new();
    let mut curve = Curve { axis: "key hairs (16 points; volume off)", unit: "particles", points: Vec::new() };
    for &h in hairs {
        let groom = grown(h, 16)?;
        let (g, c) = sim_point(&groom, &off)?;
        curve.points.push((groom.point_count() as f64, g, c));
    }
    curves.push(curve);
    let keys = if a.quick { 200 } else { 4000 };
    let mut curve = Curve { axis: "points per key hair (volume off)", unit: "particles", points: Vec::new() };
    for &p in points {
        let groom = grown(keys, p)?;
        let (g, c) = sim_point(&groom, &off)?;
        curve.points.push((groom.point_count() as f64, g, c));
    }
    curves.push(curve);
    // Simulation level of detail: the same groom with a share of its key hairs
    // simulated and the rest following them.
    let groom = grown(keys, 16)?;
    let shares: &[usize] = if quick { &[2, 1] } else { &[8, 4, 2, 1] };
    let mut curve =
        Curve { axis: "simulated key hairs (16 points; volume off)", unit: "key hairs", points: Vec::new() };
    for &share in shares {
        let simulated = keys / share;
        let f = sim_of(&groom, &off, Some(simulated))?;
        curve.points.push((simulated as f64, clock.figure(&f.gpu, &f.gpu_wall).median(), f.cpu.median()));
    }
    curves.push(curve);
    let thesis = scenes::thesis()?;
    let mut curve = Curve { axis: "grid (FLIP volume stage alone; thesis)", unit: "cells", points: Vec::new() };
    let without = sim(&thesis, &off)?;
    for &g in grids {
        let f = sim(&thesis, &b.params(VolumeMode::Flip, g))?;
        let gpu = volume_alone(&f, &without, clock).median();
        curve.points.push((f64::from(g).powi(3), gpu, f.volume_cpu.median()));
    }
    curves.push(curve);
    let mut curve = Curve { axis: "resolution (render frame; thesis)", unit: "pixels", points: Vec::new() };
    for &(w, h) in sizes {
        let (w, h) = (w.to_string(), h.to_string());
        let args: Vec<&str> =
            ["--width", &w, "--height", &h].into_iter().chain(super::quick_args(a).iter().copied()).collect();
        let f = bench_frames(ctx, &args, &a.sim, n, Keep::Figures)?;
        curve.points.push((f.pixels as f64, clock.figure(&f.gpu, &f.wall).median(), f64::NAN));
    }
    curves.push(curve);
    Ok(curves)
}

pub fn write_scaling(out: &Path, curves: &[Curve]) -> Result<PathBuf, Error> {
    let mut csv = String::from("axis,unit,work,gpu_ms,cpu_ms\n");
    for c in curves {
        for p in &c.points {
            let _ = writeln!(csv, "{},{},{},{:.4},{:.4}", c.axis, c.unit, p.0, p.1, p.2);
        }
    }
    write_csv(out, "scaling.csv", &csv)
}
