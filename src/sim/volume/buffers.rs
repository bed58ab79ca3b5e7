//! GPU buffers and kernels of the volume stage.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::grid::GridLayout;
use crate::error::{Error, Result};
use crate::gpu_types::{GpuVolumeParams, PcgScalars};
use crate::limits::{VOL_CELL_WORDS, VOL_FACE_WORDS};
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::Device;
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::{self, ShaderSource};

/// Binding numbers of `glsl/sim/volume/*.comp`.
pub(crate) mod binding {
    pub const PARAMS: u32 = 0;
    pub const COLLIDERS: u32 = 1;
    pub const POSITIONS: u32 = 2;
    pub const VELOCITIES: u32 = 3;
    pub const GRID_POS: u32 = 10;
    pub const GRID_VEL: u32 = 11;
    pub const COUNTS: u32 = 14;
    pub const CELLS: u32 = 15;
    pub const LABELS: u32 = 16;
    pub const FACE_VEL: u32 = 17;
    pub const FACE_STAR: u32 = 18;
    pub const FACE_WEIGHT: u32 = 19;
    pub const PRESSURE: u32 = 20;
    pub const DIRECTION: u32 = 21;
    pub const PRODUCT: u32 = 22;
    pub const X: u32 = 23;
    pub const TMP: u32 = 24;
    pub const RHS: u32 = 25;
    pub const SCALARS: u32 = 26;
    pub const PARTIALS: u32 = 27;
    pub const INDIRECT: u32 = 28;
    pub const MESH_FIELD: u32 = 29;
    pub const STENCIL: u32 = 30;
    pub const ACCUM: u32 = 31;
}

/// Invocations of the per-cell kernels.
pub(crate) const GROUP: u32 = crate::limits::VOL_GROUP;
/// Bytes per indirect dispatch entry (a `VkDispatchIndirectCommand` padded to 16).
pub(crate) const INDIRECT_STRIDE: u64 = 16;

/// The volume stage's own buffers (the particle buffers belong to the simulation).
pub(crate) struct VolumeBuffers {
    pub params: Buffer,
    pub grid_pos: Buffer,
    pub grid_vel: Buffer,
    /// Particles per cell (the scatter's count; a cell holding one is fluid).
    pub counts: Buffer,
    /// The transfer's fixed-point sums: [`VOL_CELL_WORDS`] words per cell, then
    /// [`VOL_FACE_WORDS`] per face (`glsl/include/volume_fixed.glsl`).
    pub accum: Buffer,
    pub cells: Buffer,
    pub labels: Buffer,
    pub stencil: Buffer,
    pub face_vel: Buffer,
    pub face_star: Buffer,
    pub face_weight: Buffer,
    pub pressure: Buffer,
    pub direction: Buffer,
    pub product: Buffer,
    pub x: Buffer,
    pub tmp: Buffer,
    pub rhs: Buffer,
    pub scalars: Buffer,
    pub partials: Buffer,
    pub indirect: Buffer,
}

impl VolumeBuffers {
    pub(crate) fn new(device: &Arc<Device>, grid: &GridLayout) -> Result<Self> {
        let n = u64::from(grid.particles);
        let cells = u64::from(grid.cells());
        let levels = u64::from(grid.level_cells());
        let faces = u64::from(grid.faces[2]);
        let accum = 4 * (u64::from(VOL_CELL_WORDS) * cells + u64::from(VOL_FACE_WORDS) * faces);
        let limit = u64::from(device.info.max_storage_buffer_range);
        let sizes = [("particles", n * 16), ("cells", levels * 4), ("faces", faces * 4), ("cells", cells * 16)];
        for (what, bytes) in sizes.into_iter().chain([("the transfer's sums", accum)]) {
            if bytes > limit {
                return Err(Error::device(
                    "the volume grid",
                    format!("{what} need {bytes} bytes per buffer, above the device's {limit} byte range"),
                ));
            }
        }
        let storage = |name: &str, size: u64| Buffer::storage(device, name, size.max(4));
        // The density is read (shadows, hand-offs) before the first step writes it:
        // it starts empty rather than undefined.
        let density = storage("vkhair volume density", cells * 16)?;
        device.upload(&density, 0, &vec![0u8; density.size() as usize])?;
        Ok(VolumeBuffers {
            params: Buffer::uniform(device, "vkhair volume params", std::mem::size_of::<GpuVolumeParams>() as u64)?,
            grid_pos: storage("vkhair volume grid positions", n * 16)?,
            grid_vel: storage("vkhair volume grid velocities", n * 16)?,
            counts: storage("vkhair volume particles per cell", cells * 4)?,
            accum: storage("vkhair volume transfer sums", accum)?,
            cells: density,
            labels: storage("vkhair volume labels", levels * 4)?,
            stencil: storage("vkhair volume stencil words", levels * 4)?,
            face_vel: storage("vkhair volume face velocities", faces * 4)?,
            face_star: storage("vkhair volume transferred face velocities", faces * 4)?,
            face_weight: storage("vkhair volume face weights", faces * 4)?,
            pressure: storage("vkhair volume pressure", cells * 4)?,
            direction: storage("vkhair volume search direction", cells * 4)?,
            product: storage("vkhair volume matrix product", cells * 4)?,
            x: storage("vkhair volume preconditioned residual", levels * 4)?,
            tmp: storage("vkhair volume smoothing scratch", levels * 4)?,
            rhs: storage("vkhair volume residual", levels * 4)?,
            scalars: storage("vkhair volume solver scalars", std::mem::size_of::<PcgScalars>() as u64)?,
            partials: storage("vkhair volume partial sums", cells.div_ceil(u64::from(GROUP)) * 8)?,
            indirect: Buffer::new(
                device,
                &BufferDesc {
                    name: "vkhair volume indirect dispatches",
                    size: (grid.levels.len() as u64 + 1) * INDIRECT_STRIDE,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER
                        | vk::BufferUsageFlags::INDIRECT_BUFFER
                        | vk::BufferUsageFlags::TRANSFER_DST
                        | vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
        })
    }

    /// Buffers by binding number, with the simulation's particle buffers and colliders.
    pub(crate) fn table<'a>(
        &'a self,
        colliders: &'a Buffer,
        mesh_field: &'a Buffer,
        positions: &'a Buffer,
        velocities: &'a Buffer,
    ) -> [(u32, &'a Buffer); 24] {
        use binding::*;
        [
            (PARAMS, &self.params),
            (MESH_FIELD, mesh_field),
            (COLLIDERS, colliders),
            (POSITIONS, positions),
            (VELOCITIES, velocities),
            (GRID_POS, &self.grid_pos),
            (GRID_VEL, &self.grid_vel),
            (COUNTS, &self.counts),
            (ACCUM, &self.accum),
            (CELLS, &self.cells),
            (LABELS, &self.labels),
            (STENCIL, &self.stencil),
            (FACE_VEL, &self.face_vel),
            (FACE_STAR, &self.face_star),
            (FACE_WEIGHT, &self.face_weight),
            (PRESSURE, &self.pressure),
            (DIRECTION, &self.direction),
            (PRODUCT, &self.product),
            (X, &self.x),
            (TMP, &self.tmp),
            (RHS, &self.rhs),
            (SCALARS, &self.scalars),
            (PARTIALS, &self.partials),
            (INDIRECT, &self.indirect),
        ]
    }
}

/// The kernels of the volume stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kernel {
    Scatter,
    Cells,
    Mark,
    PcgInit,
    PcgApply,
    PcgUpdate,
    PcgDirection,
    PcgReduce,
    Gradient,
    MgCoarsen,
    MgStencil,
    MgSmooth,
    MgRestrict,
    MgCoarsest,
    MgCycle,
    PcgWorkgroup,
    G2p,
}

impl Kernel {
    pub(crate) const ALL: [Kernel; 17] = [
        Kernel::Scatter,
        Kernel::Cells,
        Kernel::Mark,
        Kernel::PcgInit,
        Kernel::PcgApply,
        Kernel::PcgUpdate,
        Kernel::PcgDirection,
        Kernel::PcgReduce,
        Kernel::Gradient,
        Kernel::MgCoarsen,
        Kernel::MgStencil,
        Kernel::MgSmooth,
        Kernel::MgRestrict,
        Kernel::MgCoarsest,
        Kernel::MgCycle,
        Kernel::PcgWorkgroup,
        Kernel::G2p,
    ];

    /// The kernel's module; `shared` picks the shared-memory reductions of the
    /// pressure solve's kernels (devices without subgroup arithmetic), `int64`
    /// the scatter's 64-bit atomics.
    fn shader(self, shared: bool, int64: bool) -> &'static ShaderSource {
        use shaders::*;
        if self == Kernel::Scatter && int64 {
            return &SIM_VOLUME_SCATTER_COMP_INT64;
        }
        match (self, shared) {
            (Kernel::PcgInit, true) => return &SIM_VOLUME_PCG_INIT_COMP_SHARED_REDUCE,
            (Kernel::PcgApply, true) => return &SIM_VOLUME_PCG_APPLY_COMP_SHARED_REDUCE,
            (Kernel::PcgUpdate, true) => return &SIM_VOLUME_PCG_UPDATE_COMP_SHARED_REDUCE,
            (Kernel::MgSmooth, true) => return &SIM_VOLUME_MG_SMOOTH_COMP_SHARED_REDUCE,
            (Kernel::MgCoarsest, true) => return &SIM_VOLUME_MG_COARSEST_COMP_SHARED_REDUCE,
            _ => {}
        }
        match self {
            Kernel::Scatter => &SIM_VOLUME_SCATTER_COMP,
            Kernel::Cells => &SIM_VOLUME_CELLS_COMP,
            Kernel::Mark => &SIM_VOLUME_MARK_COMP,
            Kernel::PcgInit => &SIM_VOLUME_PCG_INIT_COMP,
            Kernel::PcgApply => &SIM_VOLUME_PCG_APPLY_COMP,
            Kernel::PcgUpdate => &SIM_VOLUME_PCG_UPDATE_COMP,
            Kernel::PcgDirection => &SIM_VOLUME_PCG_DIRECTION_COMP,
            Kernel::PcgReduce => &SIM_VOLUME_PCG_REDUCE_COMP,
            Kernel::Gradient => &SIM_VOLUME_GRADIENT_COMP,
            Kernel::MgCoarsen => &SIM_VOLUME_MG_COARSEN_COMP,
            Kernel::MgStencil => &SIM_VOLUME_MG_STENCIL_COMP,
            Kernel::MgSmooth => &SIM_VOLUME_MG_SMOOTH_COMP,
            Kernel::MgRestrict => &SIM_VOLUME_MG_RESTRICT_COMP,
            Kernel::MgCoarsest => &SIM_VOLUME_MG_COARSEST_COMP,
            Kernel::MgCycle => &SIM_VOLUME_MG_CYCLE_COMP,
            Kernel::PcgWorkgroup => &SIM_VOLUME_PCG_WORKGROUP_COMP,
            Kernel::G2p => &SIM_VOLUME_G2P_COMP,
        }
    }
}

/// One kernel's pipeline and a descriptor set per particle-buffer variant.
pub(crate) struct KernelPipeline {
    pub pipeline: ComputePipeline,
    pub sets: Vec<vk::DescriptorSet>,
}

/// Makes every kernel's layout, with one descriptor set per `(positions,
/// velocities)` variant; none is compiled yet.
pub(crate) fn kernels(
    device: &Arc<Device>,
    buffers: &VolumeBuffers,
    colliders: &Buffer,
    mesh_field: &Buffer,
    particles: &[(&Buffer, &Buffer)],
) -> Result<Vec<KernelPipeline>> {
    Kernel::ALL
        .iter()
        .map(|kernel| {
            let shared = device.shared_reductions.load(std::sync::atomic::Ordering::Relaxed);
            let int64 = device.int64_atomics.load(std::sync::atomic::Ordering::Relaxed);
            // Compiled for the parameters' mode and solver (`VolumeStage::set_params`).
            let pipeline =
                ComputePipeline::deferred(device, kernel.shader(shared, int64), particles.len() as u32, false)?;
            let sets = particles
                .iter()
                .map(|(pos, vel)| pipeline.declared_buffer_set(0, &buffers.table(colliders, mesh_field, pos, vel)))
                .collect::<Result<Vec<_>>>()?;
            Ok(KernelPipeline { pipeline, sets })
        })
        .collect()
}
