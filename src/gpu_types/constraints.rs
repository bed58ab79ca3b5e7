// The position-based solver's constraints, in the order the step kernel
// applies them within an iteration, with their sets and their knobs: the one
// list that ties each constraint's GLSL include to its CPU twin.
//
//     /// What it holds (the doc of its include and its twin say how).
//     name: kind ["set 0", "set 1", …] {
//         /// What the knob is, its unit.
//         knob = |p| expression of the `SimParams` p,
//     }
//
// A constraint `name` is two files that mirror each other, written in the
// same order of float operations: `glsl/include/constraints/name.glsl` and
// `src/sim/reference/constraints/name.rs`. Kinds, and what each file defines:
//
// - `pairs`: sets of independent two-point projections, one barrier-separated
//   phase per set, every iteration. GLSL: `void name_load(uint i, uint points,
//   uint index)` once per dispatch for the invocation's point (what stays the
//   same over the step: partners, rest distances), `bool name_on(uint it)`,
//   `vec4 name_apply(uint set, vec4 own, uint lid, uint src)` (own's position
//   after the set, its partner read from half `src` of `s_pos`).
// - `sweep`: one sequential pass over each hair, root to tip, by one lane per
//   hair, in place in shared memory. GLSL: `void name_prepare(mat4 frame, uint
//   lid, uint index, uint i, uint points)` per sub-step for every point,
//   `bool name_on(uint it)`, `void name_sweep(uint root, uint points, uint src)`.
// - `point`: a projection of each point on its own, sharing the iteration's
//   last barrier. GLSL: `name_prepare` as a sweep's, `bool name_on(uint it)`,
//   `vec4 name_apply(vec4 own)` (called for movable points only).
// - `after`: as `point`, once per sub-step after the last iteration
//   (`name_on` is asked with `it` = the iteration count).
//
// The CPU twin of every kind defines `on(c: &Strand, iteration: u32) -> bool`,
// `load(c: &Strand) -> Loaded` (per strand and sub-step) and
// `apply(loaded: &Loaded, set: usize, s: &mut [Vec4], c: &Strand)`, which
// applies set `set` to the strand's positions `s` as the GPU's lanes do
// together (a point constraint skips immovable points itself).
//
// Each knob gets its own lane of `SimStepParams::knobs` in the list's order:
// shaders read it as `sim_knob(params)` (views.glsl), the CPU as
// `p.knobs.knob`. Adding a constraint is its include, its twin, its row here
// and its test: build.rs calls the include from the step kernel in this
// order, and the reference calls the twin in the same place.
//
// This file is included by each of these, after its own definition of
// `sim_constraints!`: `gpu_types` (the knobs' struct and lanes), build.rs (the
// knobs' accessors and the solve's GLSL), `sim::packing` (each knob's value
// from `SimParams`), `sim::reference::constraints` (the CPU solve) and
// tests/layers.rs (each row's include and twin). Plain tokens only: no inner
// doc comments.

sim_constraints! {
    /// Distance: each segment held at its rest length (stiffness 1).
    distance: pairs ["segments (j, j + 1) with j even", "segments with j odd"] {}

    /// Bending: points i − 1 and i + 1 held at their rest distance, stiffness
    /// from root to tip (with `SIM_BENDING`).
    bending: pairs ["centres i with i mod 4 in {0, 1}", "centres i with i mod 4 in {2, 3}"] {
        /// Bending stiffness per iteration at the root (0..=1).
        bending_root = |p| per_iteration(p, p.bending_root),
        /// Bending stiffness per iteration at the tip (0..=1).
        bending_tip = |p| per_iteration(p, p.bending_tip),
    }

    /// Local shape: each segment pulled toward its rest offset carried along by
    /// its parent segment, in the last iteration (with `SIM_LOCAL_SHAPE`).
    local_shape: sweep ["root to tip, one lane per hair"] {
        /// Local shape stiffness per sub-step (0..=1).
        local_shape = |p| p.local_shape_stiffness,
    }

    /// Global shape: each point pulled toward its rest position placed by the
    /// hair's frame (with `SIM_GLOBAL_SHAPE`).
    global_shape: point ["every movable point"] {
        /// Global shape stiffness per iteration at full strength (0..=1).
        global_shape = |p| per_iteration(p, p.global_shape_stiffness),
        /// Fraction of each strand, from the root, the global shape constraint
        /// holds at full strength (0..=1).
        global_shape_range = |p| p.global_shape_range,
    }

    /// Collisions: each point projected out of the sub-step's spheres,
    /// capsules and mesh collider (with `SIM_COLLISIONS`).
    collisions: point ["every movable point"] {}

    /// Stretch limit: no segment leaves the solve longer than (1 + limit) ×
    /// its rest length; one sweep per hair in the last iteration.
    stretch_limit: sweep ["root to tip, one lane per hair"] {
        /// The most a segment may stretch, a fraction of its rest length
        /// (0 switches the limit off).
        stretch_limit = |p| p.stretch_limit,
    }

    /// Mesh friction: the motion along the mesh collider's surface braked,
    /// once per sub-step (with `SIM_MESH` and `SIM_COLLISIONS`).
    mesh_friction: after ["every movable point"] {
        /// Friction against the mesh collider (0..=1).
        mesh_friction = |p| p.mesh_friction,
    }
}
