// Friction against the mesh collider (with SIM_MESH and SIM_COLLISIONS), once
// per sub-step after the iterations: a point touching the surface loses the
// fraction sim_mesh_friction of its motion over the sub-step along it
// (`mesh_friction` in glsl/include/mesh_sdf.glsl). Twin:
// src/sim/reference/constraints/mesh_friction.rs.

void mesh_friction_prepare(mat4 frame, uint lid, uint index, uint i, uint points) {
}

bool mesh_friction_on(uint it) {
    uint flags = step_flags();
    return (flags & SIM_MESH) != 0u && (flags & SIM_COLLISIONS) != 0u;
}

vec4 mesh_friction_apply(vec4 own) {
    if ((step_flags() & SIM_MESH_SKIN) != 0u) {
        own.xyz = mesh_friction_skinned(sim_head(params), sim_mesh_grid(params),
                                        mesh_bone_base(collider_base / SIM_MAX_COLLIDERS), own.xyz, own_start.xyz,
                                        own_radius, sim_mesh_friction(params));
        return own;
    }
    own.xyz = mesh_friction(sim_head(params), sim_previous_head(params), sim_mesh_grid(params), own.xyz, own_start.xyz,
                            own_radius, sim_mesh_friction(params));
    return own;
}
