//! What `vkhair bench` measures: a simulation configuration's GPU step (from
//! timestamp queries, with the submission's wall time as a cross-check) and its
//! CPU reference step in the same run, interleaved sample by sample, and the work
//! the GPU step records (dispatches, barriers, bytes bound).

use std::time::Instant;

use vkhair::groom::Groom;
use vkhair::sim::{motion, Collider, CpuHairSim, HairSim, RigidTransform, SimParams, SimStage};
use vkhair::{GpuContext, GpuProfiler, ProfileReport, RecordedWork};

use crate::args::sim::MotionArg;
use crate::output::Error;
use crate::profile::percentile;

/// Samples of one figure, milliseconds.
#[derive(Debug, Clone, Default)]
pub struct Samples(pub Vec<f64>);

impl Samples {
    /// The median (nearest rank); NaN without samples.
    pub fn median(&self) -> f64 {
        self.at(50)
    }

    /// The 95th percentile (nearest rank); NaN without samples.
    pub fn p95(&self) -> f64 {
        self.at(95)
    }

    fn at(&self, percent: usize) -> f64 {
        let mut sorted = self.0.clone();
        sorted.sort_by(f64::total_cmp);
        percentile(&sorted, percent).unwrap_or(f64::NAN)
    }
}

/// The figures of one simulation configuration.
#[derive(Debug, Clone, Default)]
pub struct SimFigures {
    /// GPU time of the step (sum of its timestamp scopes), ms.
    pub gpu: Samples,
    /// Wall time of a submission holding one step (record, submit, wait), ms.
    pub gpu_wall: Samples,
    /// GPU time of the volume stage's scopes, ms.
    pub volume_gpu: Samples,
    /// CPU reference step, ms.
    pub cpu: Samples,
    /// The CPU reference's volume stage, ms.
    pub volume_cpu: Samples,
    /// What one step records.
    pub work: RecordedWork,
}

/// What a configuration runs on.
pub struct SimCase<'a> {
    pub groom: &'a Groom,
    pub colliders: &'a [Collider],
    pub params: SimParams,
    /// Whether to run the CPU reference beside the GPU.
    pub cpu: bool,
    /// How the head moves (about the thesis scene's neck).
    pub motion: MotionArg,
    /// Key hairs simulated (the others follow them); all when `None`.
    pub simulated: Option<usize>,
}

impl SimCase<'_> {
    /// The head at the end of step `i`.
    fn head(&self, i: usize) -> RigidTransform {
        self.motion.head((i + 1) as f32 / 60.0, motion::NECK_PIVOT, 0.35)
    }
}

/// The work of one step: a run of three steps less a run of one (what a
/// submission adds around its steps cancels out), halved.
fn work_per_step(ctx: &GpuContext, case: &SimCase<'_>, sim: &mut HairSim) -> Result<RecordedWork, Error> {
    let first = 0;
    let mut run = |steps: usize, from: usize| -> Result<RecordedWork, Error> {
        let before = ctx.recorded_work();
        sim.run(steps, |i| case.head(from + i), None)?;
        Ok(ctx.recorded_work() - before)
    };
    let one = run(1, first)?;
    let three = run(3, first + 1)?;
    let d = three - one;
    Ok(RecordedWork {
        dispatches: d.dispatches / 2,
        barriers: d.barriers / 2,
        bytes_read: d.bytes_read / 2,
        bytes_written: d.bytes_written / 2,
    })
}

fn volume_ms(report: &ProfileReport) -> f64 {
    let volume = SimStage::ALL.iter().filter(|s| s.is_volume()).map(|s| s.label()).collect::<Vec<_>>();
    report.passes.iter().filter(|p| volume.contains(&p.name.as_str())).map(|p| p.nanoseconds).sum::<f64>() / 1e6
}

/// Samples every figure takes however long they take (fewer only when `--samples` asks for fewer).
pub const MIN_SAMPLES: usize = 5;

/// Measures `samples` steps of `case` (after two warm-up steps), GPU and CPU
/// reference alternating; past [`MIN_SAMPLES`], stops early once the samples
/// have taken `budget` (a large groom's CPU reference takes seconds a step).
pub fn measure_sim(
    ctx: &GpuContext,
    case: &SimCase<'_>,
    samples: usize,
    budget: std::time::Duration,
) -> Result<SimFigures, Error> {
    let start = RigidTransform::default();
    let mut gpu = HairSim::new(ctx, case.groom, &case.params, &start)?;
    gpu.set_colliders(case.colliders)?;
    if let Some(n) = case.simulated {
        gpu.set_simulated_hairs(n)?;
    }
    let mut cpu = match case.cpu {
        true => {
            let mut cpu = CpuHairSim::new(case.groom, &case.params, &start)?;
            cpu.set_colliders(case.colliders)?;
            if let Some(n) = case.simulated {
                cpu.set_simulated_hairs(n)?;
            }
            Some(cpu)
        }
        false => None,
    };
    let mut profiler = GpuProfiler::new(ctx, 1, 16 * case.params.substeps)?;
    let work = work_per_step(ctx, case, &mut gpu)?;
    let mut figures = SimFigures { work, ..SimFigures::default() };
    let warm_up = 2;
    let mut measuring = Instant::now();
    for i in 0..samples + warm_up {
        if i == warm_up {
            measuring = Instant::now();
        } else if i > warm_up + MIN_SAMPLES - 1 && measuring.elapsed() >= budget {
            break;
        }
        let step = 4 + i;
        let started = Instant::now();
        let report = gpu
            .run(1, |_| case.head(step), Some(&mut profiler))?
            .ok_or("the device wrote no timestamps (the bench needs timestamp queries)")?;
        let wall = started.elapsed().as_secs_f64() * 1e3;
        let cpu_ms = match &mut cpu {
            Some(cpu) => {
                let started = Instant::now();
                cpu.step(&case.head(step))?;
                Some((started.elapsed().as_secs_f64() * 1e3, cpu.last_volume_time().as_secs_f64() * 1e3))
            }
            None => None,
        };
        if i < warm_up {
            continue;
        }
        figures.gpu.0.push(report.total_nanoseconds() / 1e6);
        figures.gpu_wall.0.push(wall);
        figures.volume_gpu.0.push(volume_ms(&report));
        if let Some((step_ms, volume)) = cpu_ms {
            figures.cpu.0.push(step_ms);
            figures.volume_cpu.0.push(volume);
        }
    }
    Ok(figures)
}

/// The exponent b of time ≈ a·work^b fitted by least squares in log-log space;
/// NaN with fewer than two usable points.
pub fn fitted_exponent(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> =
        points.iter().filter(|(w, t)| *w > 0.0 && *t > 0.0).map(|(w, t)| (w.ln(), t.ln())).collect();
    let n = logs.len() as f64;
    if logs.len() < 2 {
        return f64::NAN;
    }
    let (mx, my) = (logs.iter().map(|p| p.0).sum::<f64>() / n, logs.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    if sxx > 0.0 {
        sxy / sxx
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_known_exponents() {
        let line: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&w| (w, 3.0 * w)).collect();
        assert!((fitted_exponent(&line) - 1.0).abs() < 1e-12);
        let square: Vec<(f64, f64)> = [1.0, 3.0, 9.0].iter().map(|&w| (w, 0.5 * w * w)).collect();
        assert!((fitted_exponent(&square) - 2.0).abs() < 1e-12);
        assert!(fitted_exponent(&[(1.0, 1.0)]).is_nan());
    }

    #[test]
    fn median_and_p95_are_nearest_ranks() {
        let s = Samples((1..=20).map(f64::from).rev().collect());
        assert_eq!(s.median(), 10.0);
        assert_eq!(s.p95(), 19.0);
        assert!(Samples::default().median().is_nan());
    }
}
