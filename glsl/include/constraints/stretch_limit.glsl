// The stretch limit (with sim_stretch_limit > 0, in the last iteration, after
// the collisions): one sweep root to tip that shortens each segment longer
// than (1 + sim_stretch_limit) × its rest length to that length, moving the
// child only (its parent is already placed), so that no segment leaves the
// solve longer, whatever the iteration count. Twin:
// src/sim/reference/constraints/stretch_limit.rs.

// The longest each segment may be comes from its rest length in s_length
// (no shared array of its own: the step's shared memory bounds how many of
// its workgroups a multiprocessor holds).
void stretch_limit_prepare(mat4 frame, uint lid, uint index, uint i, uint points) {
}

bool stretch_limit_on(uint it) {
    return sim_stretch_limit(params) > 0.0 && it + 1u == sim_iterations(params);
}

// The hair whose root sits at invocation `root`, in place in half `src`.
void stretch_limit_sweep(uint root, uint points, uint src) {
    vec4 parent = s_pos[src][root];
    for (uint j = 1u; j < points; j++) {
        vec4 child = s_pos[src][root + j];
        precise vec3 d = child.xyz - parent.xyz;
        precise float len = sqrt(sim_dot(d, d));
        precise float most = s_length[root + j - 1u] * (1.0 + sim_stretch_limit(params));
        if (child.w > 0.0 && len > most) {
            precise vec3 placed = parent.xyz + d * (most / len);
            child.xyz = placed;
            s_pos[src][root + j] = child;
        }
        parent = child;
    }
}
