// Body collisions of a simulation stage (glsl/sim/step.comp, follow.comp). The
// including shader includes sim.glsl and declares, before the #include, the
// sub-steps' colliders and the mesh collider's field:
//     layout(std430, ...) readonly buffer Colliders { Collider colliders[]; };
//     layout(std430, ...) readonly buffer MeshField { float mesh_field[]; };
// and, with VKHAIR_MESH_SKIN defined, the skinned field's buffers (mesh_sdf.glsl).
// The CPU twin is `Bodies::collide` in src/sim/reference/bodies.rs.
#ifndef VKHAIR_SIM_BODIES_GLSL
#define VKHAIR_SIM_BODIES_GLSL
#include "mesh_sdf.glsl"

// The mesh collider's grid of the sub-step parameters p.
MeshGrid sim_mesh_grid(SimStepParams p) {
    return MeshGrid(sim_mesh_origin(p), sim_mesh_cell(p), sim_mesh_dims(p));
}

// x projected out of every body of the sub-step parameters p, keeping a gap of
// `radius`: its colliders (from entry `base` of `colliders`, sub-step
// base / SIM_MAX_COLLIDERS), then the mesh collider's field when `flags` has
// SIM_MESH (following the sub-step's bones with SIM_MESH_SKIN).
vec3 sim_collide_bodies(SimStepParams p, uint flags, uint base, vec3 x, float radius) {
    for (uint c = 0u; c < sim_colliders(p); c++) {
        x = sim_collide(colliders[base + c], x, radius);
    }
    if ((flags & SIM_MESH) != 0u) {
#ifdef VKHAIR_MESH_SKIN
        if ((flags & SIM_MESH_SKIN) != 0u) {
            return mesh_collide_skinned(sim_head(p), sim_mesh_grid(p), mesh_bone_base(base / SIM_MAX_COLLIDERS), x,
                                        radius);
        }
#endif
        x = mesh_collide(sim_head(p), sim_mesh_grid(p), x, radius);
    }
    return x;
}

// The velocity v of a particle at x after friction against every sphere and
// capsule it touches (from entry `base`; see sim_collider_friction).
vec3 sim_collider_friction_all(SimStepParams p, uint base, vec3 x, vec3 v, float radius) {
    for (uint c = 0u; c < sim_colliders(p); c++) {
        v = sim_collider_friction(colliders[base + c], x, v, radius, sim_dt(p));
    }
    return v;
}

#endif
