//! What `vkhair simulate` measures of a run: tip drift, points inside the mesh
//! collider, and (`--check`) how far the GPU is from the CPU reference.

use std::path::Path;

use glam::Vec3;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::sdf::MeshSdf;
use vkhair::groom::Groom;
use vkhair::sim::{Collider, CpuHairSim, RigidTransform, SimParams, SimState, REFERENCE_STEP_TOLERANCE_M};

use crate::output::CliResult;
use crate::say;

/// Share of free particles inside `field` (head frame), with the head at `head`.
pub fn share_inside(state: &SimState, field: &MeshSdf, head: &RigidTransform) -> f64 {
    let back = head.matrix().inverse();
    let free: Vec<Vec3> = state.positions.iter().filter(|p| p.w > 0.0).map(|p| p.truncate()).collect();
    let inside = free.iter().filter(|p| field.sample(back.transform_point3(**p)) < 0.0).count();
    inside as f64 / free.len().max(1) as f64
}

/// Per strand, the tip's distance from the rest shape carried by `head`, as a
/// fraction of the strand's rest length, sorted.
pub fn tip_drift(state: &SimState, head: &RigidTransform) -> Vec<f32> {
    let m = head.matrix();
    let mut drift: Vec<f32> = (0..state.strands)
        .map(|s| {
            let tip = s * state.points + state.points - 1;
            let moved = m.transform_point3(state.rest[tip].truncate());
            (state.positions[tip].truncate() - moved).length() / state.rest_strand_length(s).max(f32::MIN_POSITIVE)
        })
        .collect();
    drift.sort_by(f32::total_cmp);
    drift
}

/// The simulated strands in the input's frame and units, as a .hair file.
pub fn write_final(path: &Path, state: &SimState, head: &RigidTransform, scale: f32) -> CliResult {
    let back = head.matrix().inverse();
    let positions: Vec<Vec3> = state.positions.iter().map(|p| back.transform_point3(p.truncate()) / scale).collect();
    let counts = vec![state.points as u32; state.strands];
    let groom = Groom::new(positions, &counts)?;
    HairFile::new(groom, "vkhair simulate: strands after the last step").save(path)?;
    Ok(())
}

/// The CPU reference set up as the GPU simulation is.
pub struct Reference<'a> {
    pub params: &'a SimParams,
    pub colliders: &'a [Collider],
    pub mesh: Option<MeshSdf>,
    /// Key hairs simulated (`--simulated`), all when `None`.
    pub simulated: Option<usize>,
}

impl Reference<'_> {
    /// The reference from the groom at rest.
    pub fn start(&self, groom: &Groom) -> Result<CpuHairSim, vkhair::Error> {
        let cpu = CpuHairSim::new(groom, self.params, &RigidTransform::default())?;
        self.equip(cpu)
    }

    /// The state after one step of the reference from `state` (head at
    /// `previous`) to the head at `head`.
    pub fn step(
        &self,
        state: SimState,
        previous: &RigidTransform,
        head: &RigidTransform,
    ) -> Result<SimState, vkhair::Error> {
        let mut cpu = self.equip(CpuHairSim::from_state(state, self.params, previous)?)?;
        cpu.step(head)?;
        Ok(cpu.state().clone())
    }

    fn equip(&self, mut cpu: CpuHairSim) -> Result<CpuHairSim, vkhair::Error> {
        cpu.set_colliders(self.colliders)?;
        cpu.set_mesh_collider(self.mesh.clone());
        if let Some(count) = self.simulated {
            cpu.set_simulated_hairs(count)?;
        }
        Ok(cpu)
    }
}

/// One-step comparisons of a run.
#[derive(Default)]
pub struct StepCheck {
    worst: f32,
    steps: usize,
}

impl StepCheck {
    /// Adds one step's difference (a NaN one stays the worst).
    pub fn add(&mut self, difference: f32) {
        if difference.is_nan() || difference > self.worst {
            self.worst = difference;
        }
        self.steps += 1;
    }

    /// Says how the GPU compared (one step: [`SimState::step_difference`]) and
    /// fails beyond [`REFERENCE_STEP_TOLERANCE_M`]; the whole
    /// run's difference (without FLIP) must be zero on lavapipe (`device`), where
    /// the README promises bit-for-bit equality.
    pub fn verdict(&self, whole_run: Option<f32>, device: &str) -> CliResult {
        let exact = |d: f32| if d == 0.0 { "0 (bit for bit)".to_owned() } else { format!("{d:.3e} m") };
        say!(
            "CPU reference, one step from the GPU's state at {} points of the run: largest |Δx| + dt·|Δv| {} \
             (tolerance {REFERENCE_STEP_TOLERANCE_M:e} m)",
            self.steps,
            exact(self.worst)
        );
        if let Some(d) = whole_run {
            say!("CPU reference, the whole run from rest: largest |Δx| + dt·|Δv| {}", exact(d));
        } else {
            say!(
                "  (FLIP: the pressure solves differ within their residual, so the whole trajectories drift apart \
                 as any chaotic system's do; only single steps are compared)"
            );
        }
        if self.worst.is_nan() || self.worst > REFERENCE_STEP_TOLERANCE_M {
            return Err(format!(
                "the GPU and the CPU reference differ by {:e} m in one step, beyond the tolerance of {REFERENCE_STEP_TOLERANCE_M:e} m",
                self.worst
            )
            .into());
        }
        let lavapipe = device.contains("llvmpipe");
        if let (Some(d), true) = (whole_run, lavapipe) {
            if d != 0.0 {
                return Err(format!(
                    "on lavapipe the GPU and the CPU reference agree bit for bit without FLIP, but differ by {d:e} m"
                )
                .into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checked(differences: &[f32]) -> StepCheck {
        let mut check = StepCheck::default();
        for d in differences {
            check.add(*d);
        }
        check
    }

    #[test]
    fn a_step_beyond_the_tolerance_fails_the_check() {
        assert!(checked(&[0.0, 1e-6, REFERENCE_STEP_TOLERANCE_M]).verdict(None, "any GPU").is_ok());
        let err = checked(&[0.0, 2.0 * REFERENCE_STEP_TOLERANCE_M]).verdict(None, "any GPU").expect_err("beyond");
        assert!(err.to_string().contains("beyond the tolerance"), "{err}");
        assert!(checked(&[f32::NAN]).verdict(None, "any GPU").is_err(), "NaN is never within the tolerance");
    }

    #[test]
    fn a_whole_run_that_is_not_bitwise_on_lavapipe_fails_the_check() {
        let lavapipe = "llvmpipe (LLVM 15.0.6, 256 bits)";
        assert!(checked(&[0.0]).verdict(Some(0.0), lavapipe).is_ok());
        let err = checked(&[0.0]).verdict(Some(1e-9), lavapipe).expect_err("not bitwise");
        assert!(err.to_string().contains("bit for bit"), "{err}");
        assert!(checked(&[0.0]).verdict(Some(1e-9), "NVIDIA H100").is_ok(), "other devices round differently");
    }
}
