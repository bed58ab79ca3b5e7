// Local shape constraints (with SIM_LOCAL_SHAPE, in the last iteration only, so
// that sim_local_shape is the fraction removed per sub-step whatever the
// iteration count), swept root to tip by one lane per hair (Gauss-Seidel: a
// correction reaches the tip within the sweep): segment (j − 1, j) is pulled
// toward its rest offset carried along by the smallest rotation taking the
// parent segment's rest direction onto its current one (parallel transport of
// the rest frame; the first segment's frame is the hair's). Both ends move, by
// their inverse masses, so the constraint conserves momentum like the distance
// constraints. Twin: src/sim/reference/constraints/local_shape.rs.

// Per point i ≥ 1 (its segment from i − 1), placed each sub-step: the parent
// segment's rest direction (world, unit; zero for the first segment and
// degenerate ones) and the rest offset of i from i − 1 (world).
shared vec3 s_local_dir[SIM_WORKGROUP];
shared vec3 s_local_offset[SIM_WORKGROUP];

// The rest offset of particle k from its parent, rotated into the world by `frame`.
vec3 local_shape_rest_offset(mat4 frame, uint k) {
    return sim_rotate(frame, rest[k].xyz - rest[k - 1u].xyz);
}

// The unit rest direction of the segment ending at particle k, in the world
// (zero for a degenerate segment).
vec3 local_shape_rest_dir(mat4 frame, uint k) {
    vec3 d = local_shape_rest_offset(frame, k);
    precise float len = sqrt(sim_dot(d, d));
    return len > 0.0 ? d / len : vec3(0.0);
}

void local_shape_prepare(mat4 frame, uint lid, uint index, uint i, uint points) {
    if ((step_flags() & SIM_LOCAL_SHAPE) != 0u && i >= 1u) {
        s_local_offset[lid] = local_shape_rest_offset(frame, index);
        s_local_dir[lid] = i >= 2u ? local_shape_rest_dir(frame, index - 1u) : vec3(0.0);
    }
}

bool local_shape_on(uint it) {
    return (step_flags() & SIM_LOCAL_SHAPE) != 0u && it + 1u == sim_iterations(params);
}

// The hair whose root sits at invocation `root`, in place in half `src`. The
// two points before the segment are carried in registers: they are what the
// previous segment left in shared memory.
void local_shape_sweep(uint root, uint points, uint src) {
    vec4 grandparent = vec4(0.0);
    vec4 parent = s_pos[src][root];
    for (uint j = 1u; j < points; j++) {
        vec4 child = s_pos[src][root + j];
        precise vec3 carried = s_local_offset[root + j];
        vec3 dir = s_local_dir[root + j];
        if (j >= 2u && sim_dot(dir, dir) > 0.0) {
            precise vec3 d = parent.xyz - grandparent.xyz;
            precise float len = sqrt(sim_dot(d, d));
            if (len > 0.0) {
                carried = sim_rotate_between(dir, d / len, carried);
            }
        }
        precise float w = parent.w + child.w;
        if (w > 0.0) {
            precise vec3 delta = (carried - (child.xyz - parent.xyz)) * sim_local_shape(params);
            precise vec3 moved_parent = parent.xyz - delta * (parent.w / w);
            precise vec3 moved_child = child.xyz + delta * (child.w / w);
            parent.xyz = moved_parent;
            child.xyz = moved_child;
            s_pos[src][root + j - 1u] = parent;
            s_pos[src][root + j] = child;
        }
        grandparent = parent;
        parent = child;
    }
}
