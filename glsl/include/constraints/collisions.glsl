// Body collisions (with SIM_COLLISIONS): each point projected out of the
// sub-step's spheres and capsules and, with SIM_MESH, the mesh collider's
// field, keeping a gap of its own radius (glsl/include/sim_bodies.glsl). Twin:
// src/sim/reference/constraints/collisions.rs.

void collisions_prepare(mat4 frame, uint lid, uint index, uint i, uint points) {
}

bool collisions_on(uint it) {
    return (step_flags() & SIM_COLLISIONS) != 0u;
}

vec4 collisions_apply(vec4 own) {
    own.xyz = collide_all(own.xyz, own_radius);
    return own;
}
