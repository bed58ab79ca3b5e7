// The named views of the packed parameter blocks, defined here once.
//
// A parameter block is a `#[repr(C)]` struct of `vec4`/`uvec4`/`mat4`
// members shared with GLSL (std140 alignment); its scalars are packed into
// vector lanes. Each view below names every lane a reader uses:
//
//     View for Block in "header.glsl" as "GlslStructName" prefix "p" {
//         /// What it is, its unit.
//         field: kind = member.lanes,   // or `= member` for a whole mat4
//     }
//
// This file is included three times, each time after a different definition
// of `shader_views!`:
// - by the crate (`gpu_types/mod.rs`): every view becomes a plain Rust struct
//   with these fields and docs, and `From` conversions to and from its block
//   (the only code that knows the packing);
// - by build.rs (`gpu_types/views_table.rs`): a GLSL header of accessors,
//   `#define p_field(b) ((b).member.lanes)`, that every shader can include
//   (`#include "views.glsl"`), and a probe shader that writes every accessor
//   of every view back for `gpu_types::tests`;
// - by tests/layers.rs (the same table): which members are packed, so that no
//   simulation shader reads one but through an accessor.
//
// Kinds: float, uint (one lane), vec3, uvec3 (lanes xyz), mat4 (a whole
// member), knobs (the array of the constraints' knobs, `constraints.rs`: one
// accessor per knob, its lanes in that list's order). A view names each lane at most once; a block may have several
// views (the volume kernels' push constants mean different things to
// different kernels).

shader_views! {
    /// One simulation sub-step's parameters (`SimStepParams`, one per sub-step):
    /// what the step kernel, the volume stage and the CPU reference read.
    SimStep for SimStepParams in "sim.glsl" as "SimStepParams" prefix "sim" {
        /// World-from-head transform at the end of the sub-step.
        head: mat4 = head,
        /// Gravity, m/s².
        gravity: vec3 = gravity_dt.xyz,
        /// Sub-step length, s.
        dt: float = gravity_dt.w,
        /// Wind acceleration (direction × strength), m/s².
        wind: vec3 = wind.xyz,
        /// Relative strength of the gust noise (0..=1).
        wind_turbulence: float = wind.w,
        /// Gust noise frequency, 1/s.
        wind_frequency: float = wind_noise.x,
        /// Simulated time at the end of the sub-step, s.
        time: float = wind_noise.y,
        /// Stiffness of the rest-shape spring, 1/s².
        spring_stiffness: float = wind_noise.z,
        /// Fraction of velocity removed per sub-step.
        damping: float = wind_noise.w,
        /// DFTL velocity correction factor.
        dftl_damping: float = solver.x,
        /// Share of a follower's deviation from its guide kept per step
        /// (`sim::lod::FOLLOW_FADE`).
        follow_fade: float = solver.y,
        /// Key hairs.
        strands: uint = counts.x,
        /// Points per key hair.
        points: uint = counts.y,
        /// Constraint iterations.
        iterations: uint = counts.z,
        /// `SIM_*` switches (`codes::sim_flags`).
        flags: uint = counts.w,
        /// Colliders of the sub-step (entries used of its `SIM_MAX_COLLIDERS`).
        colliders: uint = layout_info.x,
        /// Key hairs per solver workgroup.
        hairs_per_group: uint = layout_info.y,
        /// Index of the sub-step since the simulation started (wraps).
        step_index: uint = layout_info.z,
        /// Invocations a constraint set's barrier spans: a subgroup, or the
        /// whole workgroup (`SIM_WORKGROUP`).
        sync_group: uint = layout_info.w,
        /// The solver constraints' knobs (`gpu_types/constraints.rs`), each
        /// in its own lane, read as `sim_KNOB(params)`.
        knobs: knobs = knobs,
        /// World-from-head transform at the start of the sub-step.
        previous_head: mat4 = previous_head,
        /// Mesh collider: grid point (0, 0, 0) in the head frame.
        mesh_origin: vec3 = mesh_grid.xyz,
        /// Mesh collider: edge of one grid cell.
        mesh_cell: float = mesh_grid.w,
        /// Mesh collider: grid points per axis.
        mesh_dims: uvec3 = mesh_dims.xyz,
        /// 1 when a mesh collider is set.
        mesh_set: uint = mesh_dims.w,
        /// Scalp (with `SIM_SCALP`): where the sub-step starts between the
        /// previous step's scalp (0) and this step's (1).
        scalp_from: float = scalp_lerp.x,
        /// Scalp: where the sub-step ends, likewise.
        scalp_to: float = scalp_lerp.y,
        /// Scalp: the source buffer's float holding vertex 0's x this step.
        scalp_first: uint = scalp_source.x,
        /// Scalp: floats from one vertex to the next in the source buffer.
        scalp_stride: uint = scalp_source.y,
        /// Scalp: 1 when the step starts from this step's scalp (bound anew,
        /// teleported or reset: no motion from the previous one).
        scalp_restart: uint = scalp_source.z,
        /// Scalp: 1 for the step's last sub-step (its dispatch keeps this
        /// step's corners as the next step's previous ones).
        scalp_last: uint = scalp_source.w,
    }

    /// A key hair's root on its scalp triangle (`ScalpRoot`, one per key hair).
    ScalpRootView for GpuScalpRoot in "sim.glsl" as "ScalpRoot" prefix "scalp_root" {
        /// The triangle's three vertices (indices into the scalp's vertices).
        corners: uvec3 = corners.xyz,
        /// Barycentric weights of the root on the triangle.
        weights: vec3 = weights.xyz,
        /// Bind-pose triangle frame's inverse: head frame → triangle frame.
        unbind: mat4 = unbind,
        /// The parameter set the key hair is simulated with (a crowd member's,
        /// [`crate::crowd`]; 0, the simulation's own, otherwise).
        set: uint = corners.w,
    }

    /// Which sub-steps one dispatch of the step kernel runs (`SimPush`).
    StepRange for SimPush in "sim.glsl" as "SimPush" prefix "step_range" {
        /// The first sub-step (index into the per-sub-step arrays).
        first: uint = range.x,
        /// How many sub-steps.
        count: uint = range.y,
        /// How many key hairs are simulated: the first of the level-of-detail
        /// order (`sim::lod`); the others follow them.
        simulated: uint = range.z,
        /// Sub-steps per parameter set: a key hair of parameter set `s` reads
        /// its sub-step `first + k` at entry `s · stride + first + k`.
        stride: uint = range.w,
    }

    /// A cut or teleport applied to the whole state before a step (`MovePush`,
    /// `glsl/sim/move.comp`).
    StateMove for MovePush in "sim.glsl" as "MovePush" prefix "state_move" {
        /// Teleport: the rigid motion from the old head to the new one (new ·
        /// old⁻¹), applied to positions and, its rotation, to velocities. Reset:
        /// the head, placing the rest positions (head frame) in the world.
        transform: mat4 = transform,
        /// 1 for a reset to the rest pose (velocities zero), 0 for a teleport.
        reset: uint = info.x,
        /// Points moved, from `first` on (every key hair's for a whole move).
        points: uint = info.y,
        /// The first point moved (0 for a whole move; a crowd member's first
        /// point for one of its own, [`crate::crowd::Crowd::teleport`]).
        first: uint = info.z,
    }

    /// One collider in world space at one sub-step (`Collider`).
    ColliderShape for GpuCollider in "sim.glsl" as "Collider" prefix "collider" {
        /// Centre (sphere) or first end (capsule), m.
        a: vec3 = a_radius.xyz,
        /// Radius, m.
        radius: float = a_radius.w,
        /// Second end (capsule), m.
        b: vec3 = b_kind.xyz,
        /// `COLLIDER_*` kind (`codes::collider_kind`), as a float.
        kind: float = b_kind.w,
        /// How far the centre or first end moved during the sub-step, m.
        moved_a: vec3 = moved_a_friction.xyz,
        /// Friction against it (0..=1; `SimParams::collider_friction`).
        friction: float = moved_a_friction.w,
        /// How far the second end moved during the sub-step, m.
        moved_b: vec3 = moved_b.xyz,
    }

    /// One pass of the mesh collider's field build (`SdfPush`).
    SdfPass for SdfPush in "sdf.glsl" as "SdfPush" prefix "sdf_pass" {
        /// Grid point (0, 0, 0) in the mesh frame.
        origin: vec3 = origin_cell.xyz,
        /// Edge of one grid cell.
        cell: float = origin_cell.w,
        /// Grid points per axis.
        dims: uvec3 = dims.xyz,
        /// Triangles of the mesh.
        triangles: uint = dims.w,
        /// Seeding: 0 stores distances, 1 the nearest triangle's index.
        seed_mode: uint = pass_info.x,
        /// Sign pass: the axis the rays run along (0, 1, 2).
        ray_axis: uint = pass_info.y,
        /// Jump flooding: the jump, in grid points.
        jump: uint = pass_info.z,
        /// Finalize: 1 when the mesh's faces wind inward (a negative signed
        /// volume), so that the side of a face is read the other way.
        inward: uint = pass_info.w,
    }

    /// The volume stage's parameters of one sub-step (`VolumeParams`).
    VolumeStep for GpuVolumeParams in "volume.glsl" as "VolumeParams" prefix "vol" {
        /// World position → grid coordinates (cells).
        grid_from_world: mat4 = grid_from_world,
        /// Grid coordinates → world position.
        world_from_grid: mat4 = world_from_grid,
        /// Upper 3×3: world vector → grid axes.
        axes: mat4 = axes,
        /// Grid coordinates → velocity of the colliders' rigid motion along the
        /// grid axes (affine).
        solid_velocity: mat4 = solid_velocity,
        /// Cells per axis.
        dims: uvec3 = dims.xyz,
        /// Cells.
        cells: uint = dims.w,
        /// Particles.
        particles: uint = counts.x,
        /// Index of the first v face (the u faces come first).
        first_v_face: uint = counts.y,
        /// Index of the first w face.
        first_w_face: uint = counts.z,
        /// Faces of all three axes.
        faces: uint = counts.w,
        /// FLIP/PIC blend (1 FLIP, 0 PIC).
        flip_ratio: float = transfer.x,
        /// Friction of the density-friction mode (0..=1).
        friction: float = transfer.y,
        /// Repulsion above the threshold density, m/s².
        repulsion: float = transfer.z,
        /// Density above which repulsion acts.
        repulsion_threshold: float = transfer.w,
        /// Pressure solve tolerance (relative max-norm residual).
        tolerance: float = solve.x,
        /// Edge of one cell, m.
        cell_size: float = solve.y,
        /// Sub-step length, s.
        dt: float = solve.z,
        /// `VOL_MODE_*` (`codes::vol_mode`), as a float.
        mode: float = solve.w,
        /// Iteration cap of the pressure solve.
        max_iterations: uint = config.x,
        /// `VOL_PRECOND_*` (`codes::vol_precond`).
        preconditioner: uint = config.y,
        /// Multigrid levels.
        levels: uint = config.z,
        /// Colliders that mark solid cells.
        colliders: uint = config.w,
        /// Grid coordinates → the mesh collider's frame (the head frame).
        mesh_from_grid: mat4 = mesh_from_grid,
        /// Mesh collider: grid point (0, 0, 0) in its frame.
        mesh_origin: vec3 = mesh_grid.xyz,
        /// Mesh collider: edge of one grid cell.
        mesh_cell: float = mesh_grid.w,
        /// Mesh collider: grid points per axis.
        mesh_dims: uvec3 = mesh_dims.xyz,
        /// 1 when the mesh collider's cells count as solid.
        mesh_solid: uint = mesh_dims.w,
    }

    /// The conjugate-gradient scalar updates (`VolumePush` of `pcg_reduce`).
    ReducePass for VolumePush in "volume.glsl" as "VolumePush" prefix "reduce" {
        /// 0: start; 1: the step length; 2: the convergence check and direction.
        mode: uint = op.x,
        /// Per-workgroup partials to sum.
        partials: uint = op.z,
        /// Indirect dispatch entries to zero once the solve stops.
        dispatches: uint = op.w,
    }

    /// A multigrid pass between two levels (`VolumePush` of `mg_coarsen` and `mg_restrict`).
    LevelPass for VolumePush in "volume.glsl" as "VolumePush" prefix "level" {
        /// Cells per axis of the level worked on.
        dims: uvec3 = dims.xyz,
        /// Its first cell in the per-level arrays.
        first: uint = dims.w,
        /// Cells per axis of the next coarser level.
        coarse_dims: uvec3 = coarse.xyz,
        /// Its first cell.
        coarse_first: uint = coarse.w,
    }

    /// A multigrid smoothing pass (`VolumePush` of `mg_smooth`).
    SmoothingPass for VolumePush in "volume.glsl" as "VolumePush" prefix "mg_smooth" {
        /// Cells per axis of the level smoothed.
        dims: uvec3 = dims.xyz,
        /// Its first cell in the per-level arrays.
        first: uint = dims.w,
        /// Cells per axis of the next coarser level.
        coarse_dims: uvec3 = coarse.xyz,
        /// Its first cell.
        coarse_first: uint = coarse.w,
        /// 0: the two pre-sweeps; 1: the first post-sweep with the
        /// prolongation; 2: the last post-sweep.
        mode: uint = op.x,
        /// 1: the last post-sweep also writes the partials of r·z and max |r|.
        partials: uint = op.y,
    }

    /// The coarsest level's sweeps (`VolumePush` of `mg_coarsest`).
    CoarsestPass for VolumePush in "volume.glsl" as "VolumePush" prefix "mg_coarsest" {
        /// Cells per axis of the coarsest level.
        dims: uvec3 = dims.xyz,
        /// Its first cell in the per-level arrays.
        first: uint = dims.w,
        /// 1: the grid has one level, so this pass also writes the partials.
        partials: uint = op.y,
    }

    /// The coarse levels' V-cycle in one workgroup (`VolumePush` of `mg_cycle`).
    CyclePass for VolumePush in "volume.glsl" as "VolumePush" prefix "mg_cycle" {
        /// The finest level the cycle starts at (its restricted residual
        /// given, its correction x left): every level from it down.
        first_level: uint = op.x,
    }

    /// A share of the solve in one workgroup (`VolumePush` of `pcg_workgroup`).
    WorkgroupSolvePass for VolumePush in "volume.glsl" as "VolumePush" prefix "pcg_wg" {
        /// 1: the first share, which starts the solve; 0: one that goes on from
        /// the scalars the previous share left.
        start: uint = op.x,
        /// Iterations this share may do at most.
        iterations: uint = op.y,
    }
}
