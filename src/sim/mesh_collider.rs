//! The mesh collider: a signed distance field of a triangle mesh (the
//! character's head and body), built on the GPU, kept in the head frame and
//! moved rigidly with the head transform — or, built with
//! [`MeshCollider::skinned`], carried by the bones that skin the mesh
//! (`mesh_skin.rs`).
//!
//! Build (`glsl/sim/sdf/*.comp`, one submission; the CPU reference is
//! [`MeshSdf::build`], which makes the same choices):
//!
//! 1. **Seed**: every triangle measures the grid points within 1.5 cells of its
//!    box exactly; each point keeps its nearest triangle (lowest index on ties).
//! 2. **Flood**: jump-flooding passes offer every point its neighbours'
//!    triangles `step` points away, steps halving from half the grid to 1, then
//!    1 again; each candidate is measured exactly.
//! 3. **Sign**: ray parity along each axis, one ray per grid line; a point is
//!    inside when two of its three rays say so (robust to open meshes such as a
//!    bust cut at the chest, whose opening misleads the rays that leave by it).
//!    Per axis, each triangle tests the rays its box reaches and marks each
//!    crossing on its line, then each line turns its marks into parities: the
//!    same crossings as testing every triangle per line, which made 3 × 64² ×
//!    5,952 edge tests for Sintel's bust (0.9 s on lavapipe, where marking
//!    takes a few tests per triangle).
//! 4. **Finalize**: the signed distance to each point's triangle, its sign
//!    from the side of that triangle's face where the point lies within
//!    `SDF_FACE_BAND_CELLS` cells of it and its closest point inside the face
//!    (the mesh's winding read by its signed volume), else from the vote.
//!
//! The field lives in a storage buffer (x fastest) and the solver samples it
//! trilinearly in the shader, with the gradient of the same trilinear
//! interpolant as the push-out direction. Sampling by hand rather than through a
//! 3D image's linear filter keeps the GPU and the CPU reference rounding alike
//! (linear filtering of 32-bit float images is optional in Vulkan and uses
//! reduced-precision weights where present).

use std::sync::Arc;

use ash::vk;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::mesh_skin::MeshSkin;
use super::scalp::VertexSkin;
use crate::codes::sentinel;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gpu_types::{SdfPass, SdfPush};
use crate::groom::mesh::TriMesh;
use crate::groom::sdf::MeshSdf;
use crate::profiler::{GpuProfiler, PassScope, ProfileReport, Timing};
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::{
    SIM_SDF_FINALIZE_COMP, SIM_SDF_FLOOD_COMP, SIM_SDF_SEED_COMP, SIM_SDF_SIGN_COMP, SIM_SDF_SIGN_MARK_COMP,
};

/// How a mesh collider's field is built.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeshColliderParams {
    /// Grid points along the longest axis of the mesh's bounds plus margins,
    /// 8..=256 (the other axes get the same cell size). Default 64.
    pub resolution: u32,
    /// Room around the mesh's bounds on every side, in the mesh's units (two more
    /// cells are always added; 0..=1000). Default 0.02.
    pub margin: f32,
}

impl MeshColliderParams {
    /// Checks both fields' ranges.
    pub fn validate(&self) -> Result<()> {
        MeshSdf::check_grid(self.resolution, self.margin)
    }
}

impl Default for MeshColliderParams {
    fn default() -> Self {
        MeshColliderParams { resolution: 64, margin: 0.02 }
    }
}

/// Where a field's samples are, as the simulation's parameters carry it
/// (`MeshGrid` of `glsl/include/mesh_sdf.glsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MeshGrid {
    /// Grid point (0, 0, 0) in the head frame.
    pub origin: Vec3,
    /// Edge of one cell.
    pub cell: f32,
    /// Grid points per axis.
    pub dims: [u32; 3],
}

/// Label and timestamp scope of the build.
pub const MESH_COLLIDER_BUILD_LABEL: &str = "vkhair mesh collider: build";

/// A mesh's signed distance field on the GPU (see the module docs), for
/// [`super::HairSim::set_mesh_collider`].
pub struct MeshCollider {
    pub(crate) field: Buffer,
    origin: Vec3,
    cell: f32,
    dims: [u32; 3],
    /// A skinned collider's grid points' bones, and their GPU copy.
    skin: Option<(MeshSkin, Buffer)>,
    pub(crate) device: Arc<Device>,
}

impl std::fmt::Debug for MeshCollider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshCollider")
            .field("origin", &self.origin)
            .field("cell", &self.cell)
            .field("dims", &self.dims)
            .field("bones", &self.skin.as_ref().map(|(s, _)| s.joints.len()))
            .finish()
    }
}

impl MeshCollider {
    /// Builds the field of `mesh` (in the head frame, the groom's units) on the GPU.
    /// This submits and waits.
    pub fn new(ctx: &GpuContext, mesh: &TriMesh, params: &MeshColliderParams) -> Result<Self> {
        Self::build(&ctx.device, mesh, params, None, false).map(|(c, _)| c)
    }

    /// Checks `mesh` and `params` as [`MeshCollider::new`] does, without GPU work.
    pub fn validate(mesh: &TriMesh, params: &MeshColliderParams) -> Result<()> {
        MeshSdf::placement(mesh, params.resolution, params.margin).map(|_| ())
    }

    /// As [`MeshCollider::new`], on `device`.
    pub(crate) fn on_device(device: &Arc<Device>, mesh: &TriMesh, params: &MeshColliderParams) -> Result<Self> {
        Self::build(device, mesh, params, None, false).map(|(c, _)| c)
    }

    /// As [`MeshCollider::skinned`], on `device`, the skin checked (`joints`:
    /// the bones it names, from `mesh_skin::skin_joints`).
    pub(crate) fn build_skinned(
        device: &Arc<Device>,
        mesh: &TriMesh,
        skin: &[VertexSkin],
        joints: Vec<u32>,
        params: &MeshColliderParams,
    ) -> Result<Self> {
        let (mut collider, closest) = Self::build(device, mesh, params, None, true)?;
        let sdf = MeshSdf { origin: collider.origin, cell: collider.cell, dims: collider.dims, values: Vec::new() };
        let fitted = MeshSkin::from_closest(&sdf, mesh, skin, joints, &closest);
        let buffer = Buffer::storage(device, "vkhair mesh collider grid bones", fitted.words.len() as u64 * 4)?;
        device.upload_pod(&buffer, &fitted.words)?;
        collider.skin = Some((fitted, buffer));
        Ok(collider)
    }

    /// A skinned collider's grid points' bones (none for a rigid one).
    pub fn skin(&self) -> Option<&MeshSkin> {
        self.skin.as_ref().map(|(s, _)| s)
    }

    pub(crate) fn skin_buffer(&self) -> Option<&Buffer> {
        self.skin.as_ref().map(|(_, b)| b)
    }

    /// As [`MeshCollider::new`], timing the build with `profiler` (one scope,
    /// [`MESH_COLLIDER_BUILD_LABEL`]; it needs room for one scope per frame).
    pub fn new_profiled(
        ctx: &GpuContext,
        mesh: &TriMesh,
        params: &MeshColliderParams,
        profiler: &mut GpuProfiler,
    ) -> Result<(Self, Option<ProfileReport>)> {
        let (collider, _) = Self::build(&ctx.device, mesh, params, Some(&mut *profiler), false)?;
        Ok((collider, profiler.drain().pop()))
    }

    /// Position of grid point (0, 0, 0) in the head frame.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Cell edge, in the head frame's units.
    pub fn cell(&self) -> f32 {
        self.cell
    }

    /// Grid points per axis.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Reads the field back (this submits and waits).
    pub fn read_field(&self) -> Result<MeshSdf> {
        let n = self.dims.iter().map(|&d| d as usize).product();
        let values = self.device.readback_pod(&self.field, n)?;
        Ok(MeshSdf { origin: self.origin, cell: self.cell, dims: self.dims, values })
    }

    /// The grid as the simulation's parameters carry it.
    pub(crate) fn grid(&self) -> MeshGrid {
        MeshGrid { origin: self.origin, cell: self.cell, dims: self.dims }
    }

    fn build(
        device: &Arc<Device>,
        mesh: &TriMesh,
        params: &MeshColliderParams,
        mut profiler: Option<&mut GpuProfiler>,
        keep_closest: bool,
    ) -> Result<(Self, Vec<u32>)> {
        let (origin, cell, dims) = MeshSdf::placement(mesh, params.resolution, params.margin)?;
        let device = device.clone();
        let triangles = mesh.triangles.len();
        let corners: Vec<[f32; 4]> =
            (0..triangles).flat_map(|t| mesh.corners(t).map(|c| c.extend(0.0).to_array())).collect();
        let corner_bytes = corners.len() as u64 * 16;
        if corner_bytes > u64::from(device.info.max_storage_buffer_range) || triangles > u32::MAX as usize / 3 {
            return Err(Error::device(
                "the mesh collider",
                format!("{triangles} triangles need {corner_bytes} bytes, above the device's storage buffer range"),
            ));
        }
        let points = dims.iter().map(|&d| d as u64).product::<u64>();
        let storage = |name: &str, size: u64| Buffer::storage(&device, name, size);
        let corner_buffer = storage("vkhair mesh collider corners", corner_bytes)?;
        let distance = storage("vkhair mesh collider seed distances", points * 4)?;
        let ids = [
            storage("vkhair mesh collider triangles 0", points * 4)?,
            storage("vkhair mesh collider triangles 1", points * 4)?,
        ];
        let votes = storage("vkhair mesh collider votes", points * 4)?;
        let field = storage("vkhair mesh collider field", points * 4)?;
        // A line's crossing marks: a bit per point of the longest axis
        // (sdf_mark_words), for the axis with the most lines.
        let words = u64::from(dims.iter().max().copied().unwrap_or(1).div_ceil(32));
        let lines = (0..3).map(|a| u64::from(dims[(a + 1) % 3]) * u64::from(dims[(a + 2) % 3])).max().unwrap_or(1);
        let marks = storage("vkhair mesh collider crossing marks", lines * words * 4)?;
        device.upload_pod(&corner_buffer, &corners)?;

        let seed = ComputePipeline::new(&device, &SIM_SDF_SEED_COMP, 1)?;
        let flood = ComputePipeline::new(&device, &SIM_SDF_FLOOD_COMP, 2)?;
        let sign_mark = ComputePipeline::new(&device, &SIM_SDF_SIGN_MARK_COMP, 1)?;
        let sign = ComputePipeline::new(&device, &SIM_SDF_SIGN_COMP, 1)?;
        let finalize = ComputePipeline::new(&device, &SIM_SDF_FINALIZE_COMP, 1)?;
        let table = |from: usize| {
            [
                (0, &corner_buffer),
                (1, &distance),
                (2, &ids[from]),
                (3, &ids[1 - from]),
                (4, &votes),
                (5, &field),
                (6, &marks),
            ]
        };
        let seed_set = seed.declared_buffer_set(0, &table(0))?;
        let flood_sets = [flood.declared_buffer_set(0, &table(0))?, flood.declared_buffer_set(0, &table(1))?];
        let sign_mark_set = sign_mark.declared_buffer_set(0, &table(0))?;
        let sign_set = sign.declared_buffer_set(0, &table(0))?;
        let steps = MeshSdf::flood_steps(dims);
        // After the floods the choices sit in buffer `result`.
        let result = steps.len() % 2;
        let finalize_set = finalize.declared_buffer_set(0, &table(result))?;

        let inward = u32::from(crate::groom::sdf::winds_inward(mesh));
        let base = SdfPass { origin, cell, dims, triangles: triangles as u32, inward, ..SdfPass::default() };
        let with = |pass: SdfPass| SdfPush::from(&pass);
        let filled = barrier::memory(&[AccessKind::TransferWrite], barrier::COMPUTE_READ_WRITE);
        let between = barrier::memory(&[AccessKind::ComputeWrite], barrier::COMPUTE_READ_WRITE);
        let points = points as u32;
        device.submit_once("vkhair mesh collider build", |cmd| {
            let d = &device;
            // SAFETY: a recording command buffer of this device; every buffer belongs
            // to it and lives until submit_once has waited for the work; each dispatch
            // is ordered after the writes it reads by the barrier before it.
            unsafe {
                if let Some(p) = profiler.as_deref_mut() {
                    let frame = p.latest().map_or(0, |r| r.frame + 1);
                    let _ = p.begin_frame(cmd, frame);
                }
                PassScope::record(
                    d,
                    cmd,
                    Timing::of(profiler.as_deref()),
                    MESH_COLLIDER_BUILD_LABEL,
                    LabelColor::Compute,
                    || {
                        d.raw.cmd_fill_buffer(cmd, distance.raw(), 0, vk::WHOLE_SIZE, sentinel::SDF_NONE);
                        d.raw.cmd_fill_buffer(cmd, ids[0].raw(), 0, vk::WHOLE_SIZE, sentinel::SDF_NONE);
                        d.raw.cmd_fill_buffer(cmd, votes.raw(), 0, vk::WHOLE_SIZE, 0);
                        d.raw.cmd_fill_buffer(cmd, marks.raw(), 0, vk::WHOLE_SIZE, 0);
                        d.cmd_barrier(cmd, &[filled], &[], &[]);
                        seed.bind(cmd, &[seed_set]);
                        for mode in 0..2 {
                            seed.push(cmd, &with(SdfPass { seed_mode: mode, ..base }));
                            seed.dispatch_threads(cmd, [triangles as u32, 1, 1]);
                            d.cmd_barrier(cmd, &[between], &[], &[]);
                        }
                        for (k, &step) in steps.iter().enumerate() {
                            flood.bind(cmd, &[flood_sets[k % 2]]);
                            flood.push(cmd, &with(SdfPass { jump: step, ..base }));
                            flood.dispatch_threads(cmd, [points, 1, 1]);
                            d.cmd_barrier(cmd, &[between], &[], &[]);
                        }
                        for axis in 0..3usize {
                            let lines = dims[(axis + 1) % 3] * dims[(axis + 2) % 3];
                            let pass = with(SdfPass { ray_axis: axis as u32, ..base });
                            sign_mark.bind(cmd, &[sign_mark_set]);
                            sign_mark.push(cmd, &pass);
                            sign_mark.dispatch_threads(cmd, [triangles as u32, 1, 1]);
                            d.cmd_barrier(cmd, &[between], &[], &[]);
                            sign.bind(cmd, &[sign_set]);
                            sign.push(cmd, &pass);
                            sign.dispatch_threads(cmd, [lines, 1, 1]);
                            d.cmd_barrier(cmd, &[between], &[], &[]);
                        }
                        finalize.bind(cmd, &[finalize_set]);
                        finalize.push(cmd, &with(base));
                        finalize.dispatch_threads(cmd, [points, 1, 1]);
                    },
                );
            }
        })?;
        // Each grid point's closest triangle, for a skinned collider's bones.
        let closest = if keep_closest { device.readback_pod(&ids[result], points as usize)? } else { Vec::new() };
        Ok((MeshCollider { field, origin, cell, dims, skin: None, device }, closest))
    }
}
