// The global shape constraint (with SIM_GLOBAL_SHAPE): each point pulled toward
// its rest position placed by the hair's frame, by sim_global_shape at full
// strength, weighted along the strand by sim_shape_weight and its target raised
// against gravity with SIM_SAG_FREE (sim_shape_target). It touches only the own
// point. Twin: src/sim/reference/constraints/global_shape.rs.

// The sub-step's target and stiffness of this invocation's point.
vec3 global_shape_target = vec3(0.0);
float global_shape_k = 0.0;

void global_shape_prepare(mat4 frame, uint lid, uint index, uint i, uint points) {
    global_shape_target = vec3(0.0);
    global_shape_k = 0.0;
    if ((step_flags() & SIM_GLOBAL_SHAPE) == 0u) {
        return;
    }
    precise float t = float(i) / float(points - 1u);
    precise float k = sim_global_shape(params) * sim_shape_weight(t, sim_global_shape_range(params));
    global_shape_k = k;
    vec3 at_rest = sim_transform_point(frame, rest[index].xyz);
    global_shape_target = sim_shape_target(at_rest, k, sim_iterations(params), step_flags(), sim_gravity(params),
                                           sim_dt(params));
}

bool global_shape_on(uint it) {
    return (step_flags() & SIM_GLOBAL_SHAPE) != 0u;
}

vec4 global_shape_apply(vec4 own) {
    if (global_shape_k > 0.0) {
        precise vec3 pulled = own.xyz + (global_shape_target - own.xyz) * global_shape_k;
        own.xyz = pulled;
    }
    return own;
}
