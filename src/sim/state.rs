//! Simulation state: the CPU form (reference, readback) and the GPU buffers.
//!
//! Structure of arrays, one element per particle, strand after strand, root
//! first, so consecutive invocations touch consecutive memory:
//!
//! | buffer | element | meaning |
//! | --- | --- | --- |
//! | positions ×2 | vec4 | world position, w inverse mass (0 = pinned to the head) |
//! | velocities ×2 | vec4 | world velocity (m/s) |
//! | rest | vec4 | rest position in the head frame, w collision radius |
//! | rest lengths | f32 | rest length of the segment to the next point |
//!
//! Positions and velocities are double-buffered: a step reads one half and
//! writes the other, so a renderer can read the result of step N−1 while
//! step N runs.

use std::sync::Arc;

use glam::{Vec3, Vec4};

use super::body::{RigidTransform, MAX_COLLIDERS};
use super::mesh_collider::MeshCollider;
use super::params::{SimParams, MAX_SIM_POINTS, MAX_SUBSTEPS};
use crate::error::{Error, Result};
use crate::gpu_types::{GpuCollider, SimStepParams};
use crate::groom::Groom;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;

/// Simulation state on the CPU.
#[derive(Debug, Clone, PartialEq)]
pub struct SimState {
    /// Key hairs.
    pub strands: usize,
    /// Points per key hair.
    pub points: usize,
    /// World positions, w = inverse mass.
    pub positions: Vec<Vec4>,
    /// World velocities, w = 0.
    pub velocities: Vec<Vec4>,
    /// Rest positions in the head frame, w = collision radius.
    pub rest: Vec<Vec4>,
    /// Rest length of the segment from each point to the next (0 for tips).
    pub rest_lengths: Vec<f32>,
}

impl SimState {
    /// The state at rest: the groom (given in the head frame) placed by `head`,
    /// roots pinned, velocities zero.
    pub fn from_groom(groom: &Groom, params: &SimParams, head: &RigidTransform) -> Result<Self> {
        params.validate()?;
        head.validate()?;
        let points = groom.uniform_points_per_strand().ok_or_else(|| {
            Error::incompatible("key hairs", "strands differ in point count; resample them with Groom::resampled")
        })?;
        if points > MAX_SIM_POINTS {
            return Err(Error::param(
                "points per key hair",
                points,
                format!("at most {MAX_SIM_POINTS}; resample the groom with Groom::resampled"),
            ));
        }
        let m = head.matrix();
        let n = groom.point_count();
        let mut state = SimState {
            strands: groom.strand_count(),
            points,
            positions: Vec::with_capacity(n),
            velocities: vec![Vec4::ZERO; n],
            rest: Vec::with_capacity(n),
            rest_lengths: Vec::with_capacity(n),
        };
        for s in 0..groom.strand_count() {
            let strand = groom.strand(s);
            for (i, &p) in strand.iter().enumerate() {
                let t = i as f32 / (points - 1) as f32;
                let radius = params.pearl_radius_root + (params.pearl_radius_tip - params.pearl_radius_root) * t;
                state.rest.push(p.extend(radius));
                state.positions.push(m.transform_point3(p).extend(if i == 0 { 0.0 } else { 1.0 }));
                state.rest_lengths.push(strand.get(i + 1).map_or(0.0, |q| (*q - p).length()));
            }
        }
        Ok(state)
    }

    /// Every strand's root at rest (head frame).
    pub(crate) fn rest_roots(&self) -> Vec<Vec3> {
        self.rest.iter().step_by(self.points.max(1)).map(|r| r.truncate()).collect()
    }

    /// Points of strand `s` (xyz of `positions`).
    pub fn strand(&self, s: usize) -> impl Iterator<Item = Vec3> + '_ {
        self.positions[s * self.points..(s + 1) * self.points].iter().map(|p| p.truncate())
    }

    /// Length of strand `s` along its current segments.
    pub fn strand_length(&self, s: usize) -> f32 {
        let pts: Vec<Vec3> = self.strand(s).collect();
        pts.windows(2).map(|w| (w[1] - w[0]).length()).sum()
    }

    /// Rest length of strand `s`.
    pub fn rest_strand_length(&self, s: usize) -> f32 {
        self.rest_lengths[s * self.points..(s + 1) * self.points].iter().sum()
    }

    /// How far apart the particles of two states of the same groom are one step
    /// of `dt` seconds later, before constraints: the largest |Δx| + dt·|Δv| over
    /// the particles, meters (∞ when the states differ in size). The measure of
    /// [`REFERENCE_STEP_TOLERANCE_M`](super::REFERENCE_STEP_TOLERANCE_M). A NaN
    /// anywhere counts as infinitely far.
    pub fn step_difference(&self, other: &SimState, dt: f32) -> f32 {
        if self.positions.len() != other.positions.len() || self.velocities.len() != other.velocities.len() {
            return f32::INFINITY;
        }
        let moved = self.positions.iter().zip(&other.positions).map(|(a, b)| (*a - *b).truncate().length());
        let sped = self.velocities.iter().zip(&other.velocities).map(|(a, b)| dt * (*a - *b).truncate().length());
        moved.zip(sped).map(|(x, v)| if (x + v).is_nan() { f32::INFINITY } else { x + v }).fold(0.0, f32::max)
    }

    /// Kinetic energy with unit mass per free particle, J/kg.
    pub fn kinetic_energy(&self) -> f64 {
        self.positions
            .iter()
            .zip(&self.velocities)
            .filter(|(p, _)| p.w > 0.0)
            .map(|(_, v)| 0.5 * f64::from(v.truncate().length_squared()))
            .sum()
    }

    /// Changes strand `s`'s rest length to `length` by scaling only its tip half
    /// (segments from (points − 1) / 2 on); root segments keep their length.
    /// Returns the first particle index whose rest data changed.
    pub(crate) fn set_strand_length(&mut self, s: usize, length: f32) -> Result<usize> {
        if s >= self.strands {
            return Err(Error::StrandIndex { index: s, count: self.strands });
        }
        let base = s * self.points;
        let segments = self.points - 1;
        let first_tip = segments / 2;
        let lengths = &self.rest_lengths[base..base + segments];
        let root_part: f32 = lengths[..first_tip].iter().sum();
        let tip_part: f32 = lengths[first_tip..].iter().sum();
        let minimum = root_part + tip_part * 0.05;
        if !(length.is_finite() && length > minimum && length < 1e6) {
            return Err(Error::param(
                "strand length",
                length,
                format!("finite and above {minimum} (root segments plus 5 % of the tip segments)"),
            ));
        }
        let scale = (length - root_part) / tip_part;
        for i in first_tip..segments {
            let old = self.rest[base + i + 1].truncate() - self.rest[base + i].truncate();
            self.rest_lengths[base + i] *= scale;
            let moved = self.rest[base + i].truncate() + old * scale;
            self.rest[base + i + 1] = moved.extend(self.rest[base + i + 1].w);
        }
        Ok(base + first_tip)
    }
}

/// The GPU buffers of the simulation.
pub(crate) struct GpuState {
    pub positions: [Buffer; 2],
    /// The positions before the latest step (written by its first sub-step), for
    /// drawing between the last two states.
    pub before: Buffer,
    pub velocities: [Buffer; 2],
    pub rest: Buffer,
    pub rest_lengths: Buffer,
    /// The colliders of every sub-step of a step, [`MAX_COLLIDERS`] entries each
    /// (see [`collider_offset`]).
    pub colliders: Buffer,
    /// The colliders of the current sub-step, as the volume stage reads them.
    pub volume_colliders: Buffer,
    /// The parameters of every sub-step of a step.
    pub params: Buffer,
    /// Bound as the mesh collider's field while none is set (never read then).
    pub no_mesh: Buffer,
    /// Bound as the grid points' bones while no skinned mesh collider is set.
    pub no_mesh_skin: Buffer,
    /// The bone rows of every sub-step of a step for a skinned mesh collider
    /// (see [`bone_offset`]).
    pub mesh_bones: Buffer,
    /// The key hairs in level-of-detail order (`sim::lod`), and each one's guide.
    pub order: Buffer,
    pub guides: Buffer,
    /// With a bound scalp (`sim::scalp`): each key hair's root on its triangle,
    /// its triangle's corners after the previous step, and the scalp's vertices
    /// when vkhair skins them (bone matrices); placeholders otherwise.
    pub scalp_roots: Buffer,
    pub scalp_previous: Buffer,
    pub scalp_vertices: Buffer,
}

/// Byte offset of sub-step `k`'s colliders in [`GpuState::colliders`].
pub(crate) fn collider_offset(k: usize) -> u64 {
    (k * MAX_COLLIDERS * std::mem::size_of::<GpuCollider>()) as u64
}

/// Byte offset of sub-step `k`'s bone rows in [`GpuState::mesh_bones`]
/// (`mesh_bone_base` of `glsl/include/mesh_sdf.glsl`: six vec4 per bone).
pub(crate) fn bone_offset(k: usize) -> u64 {
    (k * crate::limits::SIM_MESH_MAX_BONES as usize * 96) as u64
}

/// Binding numbers of the step kernel (see `glsl/sim/step.comp`).
pub(crate) mod binding {
    pub const PARAMS: u32 = 0;
    pub const POS_IN: u32 = 1;
    pub const VEL_IN: u32 = 2;
    pub const REST: u32 = 5;
    pub const REST_LENGTH: u32 = 6;
    pub const COLLIDERS: u32 = 7;
    pub const POS_OUT: u32 = 8;
    pub const VEL_OUT: u32 = 9;
    pub const MESH_FIELD: u32 = 10;
    pub const POS_BEFORE: u32 = 11;
    pub const ORDER: u32 = 12;
    /// The follower kernel's (`glsl/sim/follow.comp`) only.
    pub const GUIDES: u32 = 13;
    pub const SCALP_ROOTS: u32 = 14;
    pub const SCALP_PREVIOUS: u32 = 15;
    pub const SCALP_SOURCE: u32 = 16;
    pub const MESH_SKIN: u32 = 17;
    pub const MESH_BONES: u32 = 18;
}

impl GpuState {
    /// Creates the buffers and uploads `state` into half 0, with the key hairs'
    /// level-of-detail `order` and each one's guide (`sim::lod`; this submits
    /// and waits).
    pub(crate) fn new(device: &Arc<Device>, state: &SimState, order: &[u32], guides: &[u32]) -> Result<Self> {
        let n = state.positions.len() as u64;
        let vec4_bytes = n * 16;
        if vec4_bytes > u64::from(device.info.max_storage_buffer_range) {
            return Err(Error::device(
                "the key hairs",
                format!(
                    "{n} particles need {vec4_bytes} bytes per buffer, above the device's {} byte range",
                    device.info.max_storage_buffer_range
                ),
            ));
        }
        let storage = |name: &str, size: u64| Buffer::storage(device, name, size);
        let gpu = GpuState {
            positions: [storage("vkhair sim positions 0", vec4_bytes)?, storage("vkhair sim positions 1", vec4_bytes)?],
            before: storage("vkhair sim positions before the step", vec4_bytes)?,
            velocities: [
                storage("vkhair sim velocities 0", vec4_bytes)?,
                storage("vkhair sim velocities 1", vec4_bytes)?,
            ],
            rest: storage("vkhair sim rest", vec4_bytes)?,
            rest_lengths: storage("vkhair sim rest lengths", n * 4)?,
            colliders: storage("vkhair sim colliders", collider_offset(MAX_SUBSTEPS as usize))?,
            volume_colliders: Buffer::uniform(device, "vkhair sim volume colliders", collider_offset(1))?,
            params: storage(
                "vkhair sim params",
                u64::from(MAX_SUBSTEPS) * std::mem::size_of::<SimStepParams>() as u64,
            )?,
            no_mesh: storage("vkhair sim no mesh collider", 16)?,
            no_mesh_skin: storage("vkhair sim no mesh collider bones", 16)?,
            mesh_bones: storage("vkhair sim mesh collider bone rows", bone_offset(MAX_SUBSTEPS as usize))?,
            order: storage("vkhair sim level-of-detail order", 4 * state.strands as u64)?,
            guides: storage("vkhair sim followers' guides", 4 * state.strands as u64)?,
            scalp_roots: storage("vkhair sim no scalp roots", 16)?,
            scalp_previous: storage("vkhair sim no scalp corners", 16)?,
            scalp_vertices: storage("vkhair sim no scalp vertices", 16)?,
        };
        gpu.upload(device, state, 0)?;
        device.upload_pod(&gpu.order, order)?;
        device.upload_pod(&gpu.guides, guides)?;
        device.upload_pod(&gpu.rest, &state.rest)?;
        device.upload_pod(&gpu.rest_lengths, &state.rest_lengths)?;
        Ok(gpu)
    }

    /// Uploads positions and velocities into half `parity`, and the positions as
    /// the state before the latest step too (a state set has no motion to draw
    /// between; submits and waits).
    pub(crate) fn upload(&self, device: &Arc<Device>, state: &SimState, parity: usize) -> Result<()> {
        device.upload_pod(&self.positions[parity], &state.positions)?;
        device.upload_pod(&self.before, &state.positions)?;
        device.upload_pod(&self.velocities[parity], &state.velocities)
    }

    /// Buffers by binding number for half `parity` (reads `parity`, writes the other),
    /// with `mesh`'s field and grid points' bones (none: the placeholders).
    pub(crate) fn bindings<'a>(&'a self, parity: usize, mesh: Option<&'a MeshCollider>) -> [(u32, &'a Buffer); 16] {
        use binding::*;
        [
            (MESH_SKIN, mesh.and_then(MeshCollider::skin_buffer).unwrap_or(&self.no_mesh_skin)),
            (MESH_BONES, &self.mesh_bones),
            (SCALP_ROOTS, &self.scalp_roots),
            (SCALP_PREVIOUS, &self.scalp_previous),
            (SCALP_SOURCE, &self.scalp_vertices),
            (PARAMS, &self.params),
            (POS_IN, &self.positions[parity]),
            (VEL_IN, &self.velocities[parity]),
            (REST, &self.rest),
            (REST_LENGTH, &self.rest_lengths),
            (COLLIDERS, &self.colliders),
            (POS_OUT, &self.positions[1 - parity]),
            (VEL_OUT, &self.velocities[1 - parity]),
            (MESH_FIELD, mesh.map_or(&self.no_mesh, |m| &m.field)),
            (POS_BEFORE, &self.before),
            (ORDER, &self.order),
        ]
    }

    /// The follower kernel's buffers for half `parity` (as [`GpuState::bindings`]).
    pub(crate) fn follow_bindings<'a>(
        &'a self,
        parity: usize,
        mesh: Option<&'a MeshCollider>,
    ) -> [(u32, &'a Buffer); 15] {
        use binding::*;
        [
            (MESH_SKIN, mesh.and_then(MeshCollider::skin_buffer).unwrap_or(&self.no_mesh_skin)),
            (MESH_BONES, &self.mesh_bones),
            (SCALP_ROOTS, &self.scalp_roots),
            (SCALP_PREVIOUS, &self.scalp_previous),
            (SCALP_SOURCE, &self.scalp_vertices),
            (COLLIDERS, &self.colliders),
            (MESH_FIELD, mesh.map_or(&self.no_mesh, |m| &m.field)),
            (PARAMS, &self.params),
            (POS_IN, &self.positions[parity]),
            (REST, &self.rest),
            (POS_OUT, &self.positions[1 - parity]),
            (VEL_OUT, &self.velocities[1 - parity]),
            (POS_BEFORE, &self.before),
            (ORDER, &self.order),
            (GUIDES, &self.guides),
        ]
    }

    /// The move kernel's buffers for half `parity` (it moves that half in place).
    pub(crate) fn move_bindings(&self, parity: usize) -> [(u32, &Buffer); 7] {
        use binding::*;
        [
            (PARAMS, &self.params),
            (POS_IN, &self.positions[parity]),
            (VEL_IN, &self.velocities[parity]),
            (REST, &self.rest),
            (SCALP_ROOTS, &self.scalp_roots),
            (SCALP_PREVIOUS, &self.scalp_previous),
            (SCALP_SOURCE, &self.scalp_vertices),
        ]
    }
}
