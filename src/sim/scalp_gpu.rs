//! A bound scalp on the GPU ([`HairSim::bind_scalp_source`],
//! [`HairSim::bind_scalp_bones`]; the rule is in [`super::scalp`]): the roots'
//! triangles and their corners after the previous step live in this
//! simulation's buffers; the skinned vertices are read from the host's buffer
//! or, with bone matrices, from one of ours that each step's uploads refill.
//! The frames are computed inside the step's, the followers' and the move's
//! dispatches: binding a scalp adds no dispatch.

use ash::vk;
use glam::{Mat4, Vec4};

use super::packing::{self, ScalpLanes};
use super::params::{SimParams, MAX_SUBSTEPS};
use super::scalp::{as_vec4, check_vertices, Scalp, ScalpBinding, ScalpSource};
use super::state::binding;
use super::HairSim;
use crate::error::{Error, Result};
use crate::gpu_types::SimStepParams;
use crate::vk::buffer::Buffer;

/// Where a bound scalp's skinned vertices come from.
pub(crate) enum VertexSource {
    /// The host's buffer.
    Host(ScalpSource),
    /// Bone matrices applied by vkhair; the vertices the next step uploads,
    /// and the latest uploaded.
    Bones { scalp: Scalp, pending: Option<Vec<Vec4>>, latest: Vec<Vec4> },
}

/// See the module docs.
pub(crate) struct GpuScalp {
    pub binding: ScalpBinding,
    pub source: VertexSource,
}

/// Binding a scalp.
impl HairSim {
    /// Binds every key hair's root to the nearest triangle of `scalp` (bind
    /// pose, head frame; a root farther than `scalp.tolerance` is refused,
    /// naming the strand) and from the next step on places each key hair's
    /// rest pose by its root's frame on the skinned scalp that `source` holds
    /// (see [`super::scalp`]): the shape constraints, the rest-shape spring, the
    /// pinned roots, the followers and a reset all follow the skin, while the
    /// head (the argument of [`HairSim::record_step`]) still places the head's
    /// colliders, the mesh collider and the volume grid and decides teleports.
    /// The next step starts from the source's vertices (no motion from before).
    /// Waits for the device to be idle; nothing is recorded.
    ///
    /// Vertex `v` of `scalp.mesh` is read at byte `offset + v · stride` of
    /// `source.buffer` (`offset` 0, or [`HairSim::set_scalp_offset`]'s), xyz in
    /// the world, by every recorded step's dispatches (storage reads in the
    /// compute stage, after the step's entry barrier, which orders any earlier
    /// write in the same queue before them).
    ///
    /// # Safety
    /// `source.buffer` is a buffer of this simulation's device created with
    /// `STORAGE_BUFFER` usage, at least `source.size` bytes long and bound to
    /// memory; it stays alive until another scalp is bound, the scalp is
    /// unbound or this simulation is dropped, each after the last step that
    /// reads it has completed. Writes to it reach the step through the same
    /// queue before the step (or through the host's semaphores), and none
    /// overlaps a step that reads it.
    pub unsafe fn bind_scalp_source(&mut self, scalp: &Scalp, source: &ScalpSource) -> Result<()> {
        let binding = ScalpBinding::new(scalp, &self.shape.rest_roots())?;
        let stride = source.validate(binding.vertices, u64::from(self.device.info.max_storage_buffer_range))?;
        let first = source.first_float(0)?;
        self.install_scalp(GpuScalp { binding, source: VertexSource::Host(*source) }, None)?;
        self.planner.scalp = Some(ScalpLanes { first, stride, restart: true });
        self.prepare_step()
    }

    /// Where the host's skinned vertices start in its buffer from the next
    /// step on, bytes (a host may keep a frame's vertices apart from the next
    /// one's in one buffer). Checked against the bound [`ScalpSource`].
    pub fn set_scalp_offset(&mut self, offset: u64) -> Result<()> {
        let (Some(scalp), Some(lanes)) = (&self.scalp, &mut self.planner.scalp) else {
            return Err(Error::incompatible("scalp offset", "no scalp is bound"));
        };
        let VertexSource::Host(source) = &scalp.source else {
            return Err(Error::incompatible("scalp offset", "the scalp is skinned from bone matrices"));
        };
        lanes.first = source.first_float(offset)?;
        Ok(())
    }

    /// As [`HairSim::bind_scalp_source`], for a host without GPU skinning:
    /// vkhair skins `scalp`'s vertices itself with `scalp.skin` (up to four
    /// bones per vertex) and `bones` (each maps the bind pose, head frame, to
    /// the world) now, and with [`HairSim::set_scalp_bones`] before each step.
    /// Uploads and waits.
    pub fn bind_scalp_bones(&mut self, scalp: &Scalp, bones: &[Mat4]) -> Result<()> {
        let binding = ScalpBinding::new(scalp, &self.shape.rest_roots())?;
        self.bind_scalp_bones_as(scalp, binding, bones, false)
    }

    /// [`HairSim::bind_scalp_bones`] with the roots already bound (one
    /// binding per key hair, corners among `scalp`'s vertices). `continuous`:
    /// the next step moves the roots from the scalp as `bones` place it (the
    /// state is already there), not from its own end.
    pub(crate) fn bind_scalp_bones_as(
        &mut self,
        scalp: &Scalp,
        binding: ScalpBinding,
        bones: &[Mat4],
        continuous: bool,
    ) -> Result<()> {
        if binding.views.len() != self.shape.strands || binding.vertices != scalp.mesh.positions.len() {
            return Err(Error::incompatible("scalp binding", "it binds other key hairs or another scalp"));
        }
        if scalp.skin.is_empty() {
            return Err(Error::incompatible("scalp bones", "the scalp has no vertex bones (Scalp::skin)"));
        }
        let skinned = scalp.skin(bones)?;
        let corners: Vec<Vec4> =
            (0..binding.views.len()).flat_map(|h| binding.corners(h, &skinned).map(|c| c.extend(0.0))).collect();
        let vertices = as_vec4(&skinned);
        let source = VertexSource::Bones { scalp: scalp.clone(), pending: None, latest: vertices.clone() };
        self.install_scalp(GpuScalp { binding, source }, Some(&vertices))?;
        if continuous {
            self.device.upload_pod(&self.gpu.scalp_previous, &corners)?;
        }
        self.planner.scalp = Some(ScalpLanes { first: 0, stride: 4, restart: !continuous });
        self.prepare_step()
    }

    /// The bones at the end of the next step (see [`HairSim::bind_scalp_bones`]):
    /// the scalp skinned now, uploaded by the next step's recording. Errors
    /// name a bone that is not finite or a joint past `bones`.
    pub fn set_scalp_bones(&mut self, bones: &[Mat4]) -> Result<()> {
        let Some(GpuScalp { source: VertexSource::Bones { scalp, pending, .. }, binding }) = &mut self.scalp else {
            return Err(Error::incompatible("scalp bones", "no scalp skinned from bone matrices is bound"));
        };
        let vertices = scalp.skin(bones)?;
        check_vertices(&vertices, binding.vertices)?;
        *pending = Some(as_vec4(&vertices));
        Ok(())
    }

    /// Simulates the key hairs whose scalp roots name parameter set `s ≥ 1`
    /// with `sets[s − 1]` from the next step on (set 0: the simulation's own
    /// parameters), in the same dispatch: each set may differ from the
    /// simulation's parameters only in the fields of `packing::SET_FIELDS`
    /// (refused otherwise, naming the fields). Waits for the device to be idle
    /// when the parameters' buffer grows.
    pub(crate) fn set_parameter_sets(&mut self, sets: Vec<SimParams>) -> Result<()> {
        sets.iter().try_for_each(|set| packing::check_set(&self.planner.params, set))?;
        let bytes = (sets.len() as u64 + 1) * u64::from(MAX_SUBSTEPS) * std::mem::size_of::<SimStepParams>() as u64;
        if self.gpu.params.size() < bytes {
            self.device.wait_idle()?;
            self.gpu.params = Buffer::storage(&self.device, "vkhair sim params", bytes)?;
            self.rewrite_sets()?;
        }
        self.planner.sets = sets;
        Ok(())
    }

    /// Roots follow the head again from the next step on (waits for the
    /// device to be idle).
    pub fn unbind_scalp(&mut self) -> Result<()> {
        self.device.wait_idle()?;
        self.scalp = None;
        self.planner.scalp = None;
        let placeholder = |name: &str| Buffer::storage(&self.device, name, 16);
        self.gpu.scalp_roots = placeholder("vkhair sim no scalp roots")?;
        self.gpu.scalp_previous = placeholder("vkhair sim no scalp corners")?;
        self.gpu.scalp_vertices = placeholder("vkhair sim no scalp vertices")?;
        self.rewrite_sets()?;
        self.prepare_step()
    }

    /// The vertices the next step uploads (bone path), taken (and kept as
    /// the latest).
    pub(crate) fn take_scalp_upload(&mut self) -> Option<Vec<Vec4>> {
        match &mut self.scalp {
            Some(GpuScalp { source: VertexSource::Bones { pending, latest, .. }, .. }) => {
                let taken = pending.take();
                if let Some(v) = &taken {
                    latest.clone_from(v);
                }
                taken
            }
            _ => None,
        }
    }

    /// Moves key hairs `strands` rigidly by `transform` (new head · old head⁻¹)
    /// at the start of the next step, adding no velocity, their roots starting
    /// that step from its scalp (bone path only: their corners come from the
    /// skinned vertices). After the whole state's move when both are pending.
    pub(crate) fn teleport_hairs(&mut self, strands: std::ops::Range<usize>, transform: Mat4) -> Result<()> {
        if !matches!(&self.scalp, Some(GpuScalp { source: VertexSource::Bones { .. }, .. })) {
            return Err(Error::incompatible("teleport of some key hairs", "no scalp skinned from bones is bound"));
        }
        if strands.end > self.shape.strands || strands.is_empty() || !transform.is_finite() {
            return Err(Error::param("teleported key hairs", format!("{strands:?}"), "a run of the key hairs"));
        }
        // A second move of the same key hairs before the step composes with the first.
        match self.partial_moves.iter_mut().find(|mv| mv.strands == strands) {
            Some(pending) => pending.transform = transform * pending.transform,
            None => self.partial_moves.push(super::teleport::PartialMove { strands, transform }),
        }
        Ok(())
    }

    /// The corners of the key hairs `moves` move on the scalp of the step
    /// being recorded (`upload`, else the latest vertices), per run of
    /// consecutive key hairs: (first key hair, three vec4 a key hair).
    pub(crate) fn moved_corners(
        &self,
        moves: &[super::teleport::PartialMove],
        upload: Option<&[Vec4]>,
    ) -> Vec<(usize, Vec<Vec4>)> {
        let Some(GpuScalp { source: VertexSource::Bones { latest, .. }, binding }) = &self.scalp else {
            return Vec::new();
        };
        let vertices: Vec<glam::Vec3> = upload.unwrap_or(latest).iter().map(|v| v.truncate()).collect();
        // Overlapping moves' key hairs uploaded once (two writes of one range
        // in one upload would race).
        let mut ranges: Vec<std::ops::Range<usize>> = moves.iter().map(|mv| mv.strands.clone()).collect();
        ranges.sort_by_key(|r| r.start);
        let mut merged: Vec<std::ops::Range<usize>> = Vec::new();
        for r in ranges {
            match merged.last_mut() {
                Some(last) if r.start <= last.end => last.end = last.end.max(r.end),
                _ => merged.push(r),
            }
        }
        merged
            .into_iter()
            .map(|r| {
                let run = r.clone().flat_map(|h| binding.corners(h, &vertices).map(|c| c.extend(0.0)));
                (r.start, run.collect())
            })
            .collect()
    }

    /// Creates the scalp's buffers (with `vertices` uploaded into ours for the
    /// bone path) and points every kernel's sets at them.
    fn install_scalp(&mut self, scalp: GpuScalp, vertices: Option<&[Vec4]>) -> Result<()> {
        self.device.wait_idle()?;
        let strands = scalp.binding.roots.len() as u64;
        let d = &self.device;
        self.gpu.scalp_roots = Buffer::storage(d, "vkhair sim scalp roots", strands * 96)?;
        d.upload_pod(&self.gpu.scalp_roots, &scalp.binding.roots)?;
        self.gpu.scalp_previous = Buffer::storage(d, "vkhair sim scalp corners before the step", strands * 48)?;
        self.gpu.scalp_vertices = match vertices {
            Some(v) => {
                let buffer = Buffer::storage(d, "vkhair sim scalp vertices", v.len() as u64 * 16)?;
                d.upload_pod(&buffer, v)?;
                buffer
            }
            None => Buffer::storage(d, "vkhair sim no scalp vertices", 16)?,
        };
        self.scalp = Some(scalp);
        self.rewrite_sets()
    }

    /// Points every kernel's descriptor sets at the current buffers: the mesh
    /// collider's field, the scalp's, and the host's vertex buffer when bound.
    /// Waits for the device to be idle.
    pub(crate) fn rewrite_sets(&self) -> Result<()> {
        self.device.wait_idle()?;
        let field = self.mesh.as_ref();
        let host = match &self.scalp {
            Some(GpuScalp { source: VertexSource::Host(s), .. }) => Some(s),
            _ => None,
        };
        for parity in 0..2 {
            let sets = [
                (&self.pipeline, self.sets[parity], self.gpu.bindings(parity, field).to_vec()),
                (&self.follow, self.follow_sets[parity], self.gpu.follow_bindings(parity, field).to_vec()),
                (&self.mover.pipeline, self.mover.sets[parity], self.gpu.move_bindings(parity).to_vec()),
            ];
            for (pipeline, set, buffers) in sets {
                // SAFETY: each set was allocated by its pipeline for set 0, and the
                // device is idle; recording happens only through `&mut self`.
                unsafe { pipeline.rewrite_declared(set, 0, &buffers)? };
                if let Some(source) = host {
                    let info = vk::DescriptorBufferInfo { buffer: source.buffer, offset: 0, range: source.size };
                    // SAFETY: as above; the caller of `bind_scalp_source` vouched
                    // for the buffer, its usage and size (checked against the range).
                    unsafe { pipeline.rewrite_raw_buffer(set, 0, binding::SCALP_SOURCE, info)? };
                }
            }
        }
        Ok(())
    }
}
