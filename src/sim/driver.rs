//! Fixed time step with an unlocked frame rate: an accumulator of elapsed time
//! runs as many fixed steps as fit (at most a cap, so a long stall cannot
//! start a spiral of ever more steps), and the remainder gives the factor for
//! interpolating between the last two states when drawing.

use crate::error::{Error, Result};

/// What to do this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    /// Fixed steps to run now.
    pub steps: u32,
    /// Fraction of a step accumulated beyond them (0..1): blend factor between
    /// the state before the latest step and the latest state for drawing
    /// ([`crate::sim::KeyHairs::blended`]).
    pub alpha: f32,
    /// Time dropped because the cap was reached, seconds.
    pub dropped: f64,
}

/// Turns frame times into fixed simulation steps.
///
/// ```
/// let mut driver = vkhair::sim::FixedStepDriver::new(1.0 / 60.0, 4)?;
/// let plan = driver.advance(1.0 / 30.0); // a 30 Hz frame: two 60 Hz steps
/// assert_eq!(plan.steps, 2);
/// assert!(plan.alpha < 1e-3 && plan.dropped == 0.0);
/// # Ok::<(), vkhair::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct FixedStepDriver {
    step: f64,
    max_steps: u32,
    accumulator: f64,
}

impl FixedStepDriver {
    /// A driver with step length `step` seconds (> 0) and at most `max_steps` (≥ 1)
    /// steps per frame.
    pub fn new(step: f64, max_steps: u32) -> Result<Self> {
        if !(step.is_finite() && step > 0.0) {
            return Err(Error::param("step", step, "finite and > 0"));
        }
        if max_steps == 0 {
            return Err(Error::param("max_steps", max_steps, "at least 1"));
        }
        Ok(FixedStepDriver { step, max_steps, accumulator: 0.0 })
    }

    /// Adds `frame_time` seconds (negative or non-finite values count as 0) and says
    /// how many steps to run.
    pub fn advance(&mut self, frame_time: f64) -> StepPlan {
        if frame_time.is_finite() && frame_time > 0.0 {
            self.accumulator += frame_time;
        }
        let due = (self.accumulator / self.step).floor();
        let steps = due.min(f64::from(self.max_steps)) as u32;
        self.accumulator -= f64::from(steps) * self.step;
        let mut dropped = 0.0;
        if steps == self.max_steps && self.accumulator >= self.step {
            // Keep only the fraction of a step: the rest cannot be caught up.
            let keep = self.accumulator % self.step;
            dropped = self.accumulator - keep;
            self.accumulator = keep;
        }
        StepPlan { steps, alpha: (self.accumulator / self.step) as f32, dropped }
    }

    /// The fixed step length, seconds.
    pub fn step(&self) -> f64 {
        self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_accumulate_and_cap() {
        let mut d = FixedStepDriver::new(0.01, 3).expect("driver");
        assert_eq!(d.advance(0.005).steps, 0);
        let p = d.advance(0.0075);
        assert_eq!(p.steps, 1);
        assert!((p.alpha - 0.25).abs() < 1e-6, "{p:?}");
        // A long stall runs at most 3 steps and drops the rest.
        let p = d.advance(1.0);
        assert_eq!(p.steps, 3);
        assert!((p.dropped - 0.97).abs() < 1e-3, "{p:?}");
        assert!(p.alpha < 1.0);
        // 100 frames of 1/60 s with 1/120 s steps give 200 steps in total.
        let mut d = FixedStepDriver::new(1.0 / 120.0, 4).expect("driver");
        let total: u32 = (0..100).map(|_| d.advance(1.0 / 60.0).steps).sum();
        assert!((199..=200).contains(&total), "{total}");
        assert_eq!(d.advance(f64::NAN).steps, 0);
        assert!(FixedStepDriver::new(0.0, 1).is_err());
        assert!(FixedStepDriver::new(0.1, 0).is_err());
    }
}
