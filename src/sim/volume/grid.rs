//! Placement and layout of the volume grid.
//!
//! The grid is fixed in the head's frame, so it moves and turns with the head.
//! Its box covers the roots' bounding box grown by the longest strand on every
//! side (plus the largest pearl radius): inextensible hair pinned at its roots
//! can never leave it (the bound of Bertails et al.'s light-oriented map, 2l + h).
//! One more cell on each side keeps every particle's transfer stencil inside the
//! grid. Cells are cubes; with a non-cubic resolution the axis that needs the
//! largest cells sets their size.

use glam::{Mat4, Vec3, Vec4Swizzles};

use super::params::{Preconditioner, VolumeMode, VolumeParams};
use crate::codes::{vol_mode, vol_precond};
use crate::error::{Error, Result};
use crate::gpu_types::VolumeStep;
use crate::sim::mesh_collider::MeshGrid;
use crate::sim::SimState;

/// Most cells of the coarsest multigrid level (solved by one workgroup).
pub(crate) const COARSEST_CELLS: u32 = crate::limits::VOL_GROUP;

/// One level of the multigrid hierarchy (level 0 is the pressure grid).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Level {
    pub dims: [u32; 3],
    /// First cell of the level in the concatenated level arrays.
    pub offset: u32,
}

impl Level {
    pub(crate) fn cells(&self) -> u32 {
        self.dims.iter().product()
    }
}

/// The grid of a simulation: size, placement in the head frame and buffer layout.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GridLayout {
    pub dims: [u32; 3],
    /// Edge of a cell, meters.
    pub cell_size: f32,
    /// Corner of cell (0, 0, 0) in the head frame.
    pub origin: Vec3,
    pub levels: Vec<Level>,
    /// First v face, first w face, face count.
    pub faces: [u32; 3],
    pub particles: u32,
}

/// The volume grid as placed for the latest step (for hosts that sample the density).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeGrid {
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// Edge of a cell, meters.
    pub cell_size: f32,
    /// Grid coordinates (cells; cell (i, j, k) spans [i, i+1) × …) → world position.
    pub world_from_grid: Mat4,
}

impl GridLayout {
    /// Sizes the grid for the hair of `rest` (head frame) at `params.resolution`.
    pub(crate) fn new(params: &VolumeParams, rest: &SimState) -> Result<Self> {
        params.validate()?;
        if rest.strands == 0 || rest.points < 2 {
            return Err(Error::incompatible("key hairs", "the volume stage needs at least one strand of two points"));
        }
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut reach = 0.0f32;
        for s in 0..rest.strands {
            let root = rest.rest[s * rest.points].xyz();
            lo = lo.min(root);
            hi = hi.max(root);
            let pearls = rest.rest[s * rest.points..(s + 1) * rest.points].iter().map(|p| p.w).fold(0.0, f32::max);
            reach = reach.max(rest.rest_strand_length(s) + pearls);
        }
        if !(lo.is_finite() && hi.is_finite() && reach.is_finite()) {
            return Err(Error::incompatible("key hairs", "the rest shape is not finite"));
        }
        let extent = (hi - lo) + Vec3::splat(2.0 * reach);
        let dims = params.resolution;
        let mut cell_size = 0.0f32;
        for (axis, &n) in dims.iter().enumerate() {
            cell_size = cell_size.max(extent[axis] / (n - 2) as f32);
        }
        if !(cell_size.is_finite() && cell_size > 0.0) {
            return Err(Error::incompatible("key hairs", "the hair spans no volume"));
        }
        let centre = (lo + hi) * 0.5;
        let size = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32) * cell_size;
        Ok(Self::placed(dims, cell_size, centre - size * 0.5, rest.positions.len() as u32))
    }

    /// A grid of `dims` cells of `cell_size` with cell (0, 0, 0) at `origin` (head
    /// frame), for `particles` particles.
    pub(crate) fn placed(dims: [u32; 3], cell_size: f32, origin: Vec3, particles: u32) -> Self {
        let mut levels = vec![Level { dims, offset: 0 }];
        loop {
            let last = levels[levels.len() - 1];
            if last.cells() <= COARSEST_CELLS {
                break;
            }
            let next = last.dims.map(|n| n.div_ceil(2));
            levels.push(Level { dims: next, offset: last.offset + last.cells() });
        }
        let [nx, ny, nz] = dims;
        let fu = (nx + 1) * ny * nz;
        let fv = nx * (ny + 1) * nz;
        let fw = nx * ny * (nz + 1);
        GridLayout { dims, cell_size, origin, levels, faces: [fu, fu + fv, fu + fv + fw], particles }
    }

    pub(crate) fn cells(&self) -> u32 {
        self.dims.iter().product()
    }

    /// Cells of every multigrid level together.
    pub(crate) fn level_cells(&self) -> u32 {
        self.levels.iter().map(Level::cells).sum()
    }

    /// Grid coordinates → head frame.
    fn head_from_grid(&self) -> Mat4 {
        Mat4::from_translation(self.origin) * Mat4::from_scale(Vec3::splat(self.cell_size))
    }

    /// Grid coordinates → world position with the head at `head`.
    pub(crate) fn world_from_grid(&self, head: &Mat4) -> Mat4 {
        *head * self.head_from_grid()
    }

    /// The public description for the head at `head`.
    pub(crate) fn describe(&self, head: &Mat4) -> VolumeGrid {
        VolumeGrid { dims: self.dims, cell_size: self.cell_size, world_from_grid: self.world_from_grid(head) }
    }

    /// The volume stage's parameters of one sub-step that moves the head from
    /// `previous` to `head` in `dt` seconds, with `colliders` colliders marking
    /// solid cells and the mesh collider's grid when its cells count as solid.
    pub(crate) fn step_params(
        &self,
        params: &VolumeParams,
        previous: &Mat4,
        head: &Mat4,
        dt: f32,
        colliders: u32,
        mesh: Option<&MeshGrid>,
    ) -> VolumeStep {
        let world_from_grid = self.world_from_grid(head);
        let grid_from_world = world_from_grid.inverse();
        // Head rotation only (the head transform is rigid).
        let rotation = Mat4::from_quat(head.to_scale_rotation_translation().1);
        let axes = rotation.transpose();
        // Velocity of a point fixed in the head frame, as a function of grid coordinates:
        // (head − previous) · head_from_grid / dt, turned into the grid axes.
        let motion = (*head - *previous) * self.head_from_grid() * (1.0 / dt);
        let solid_velocity = axes * motion;
        let mode = match params.mode {
            VolumeMode::Off => vol_mode::OFF,
            VolumeMode::Flip => vol_mode::FLIP,
            VolumeMode::Friction => vol_mode::FRICTION,
        };
        let preconditioner = match params.preconditioner {
            Preconditioner::Jacobi => vol_precond::JACOBI,
            Preconditioner::Multigrid => vol_precond::MULTIGRID,
        };
        let unset = MeshGrid { origin: Vec3::ZERO, cell: 1.0, dims: [0; 3] };
        let grid = mesh.unwrap_or(&unset);
        VolumeStep {
            grid_from_world,
            world_from_grid,
            axes,
            solid_velocity,
            dims: self.dims,
            cells: self.cells(),
            particles: self.particles,
            first_v_face: self.faces[0],
            first_w_face: self.faces[1],
            faces: self.faces[2],
            flip_ratio: params.flip_ratio,
            friction: params.friction,
            repulsion: params.repulsion,
            repulsion_threshold: params.repulsion_threshold,
            tolerance: params.tolerance,
            cell_size: self.cell_size,
            dt,
            mode: mode as f32,
            max_iterations: params.max_iterations,
            preconditioner,
            levels: self.levels.len() as u32,
            colliders,
            mesh_from_grid: self.head_from_grid(),
            mesh_origin: grid.origin,
            mesh_cell: grid.cell,
            mesh_dims: grid.dims,
            mesh_solid: u32::from(mesh.is_some()),
        }
    }
}
