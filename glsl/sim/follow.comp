#version 460
// Simulation level of detail, after the step kernel's dispatch: the key hairs
// left out of the simulation (those past step_range_simulated(push) in the
// level-of-detail order) follow their guides (src/sim/lod.rs). One invocation
// per follower, root to tip, over the sub-steps [first, first+count) of the
// dispatch:
//
//   the guide's frame of segment i (points i−1, i): Q_0 = the head's
//     rotation, then Q_i = the smallest rotation taking Q_{i−1}·(the guide's
//     rest segment i) onto its current segment i, times Q_{i−1} (parallel
//     transport down the guide);
//   the follow shape: y_0 = head · rest_f[0], y_i = y_{i−1} + Q_i·(rest_f[i] − rest_f[i−1])
//     (the follower's own rest segments turned as its guide's are: lengths kept);
//   root (inverse mass 0):  x_0 = y_0                        (as the step pins roots)
//   other points:           t_i = y_i + (x_f⁻ − y⁻_i) · fade, placed at the rest
//                           length of segment i from x_{i−1} toward t_i (follow
//                           the leader), then out of the bodies of the last
//                           sub-step (as the step's collisions)
//   velocity:               v = (x − x_f⁻) / (dt · count)
//
// where ⁻ marks the positions, head and frames before the dispatch (the half
// it reads). With SIM_SCALP the head is the follower's own root frame
// (glsl/include/scalp.glsl). A follower bends and swings as its guide does (a neighbour with a
// similar rest shape, sim/lod.rs) and keeps its own shape and segment lengths,
// so it can rejoin the simulation where it is. The CPU reference
// (sim::reference::follow) runs the same operations in the same order.
#include "sim.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(push_constant) uniform Push { SimPush push; };
layout(std430, set = 0, binding = 0) readonly buffer Steps { SimStepParams steps[]; };
layout(std430, set = 0, binding = 1) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = 5) readonly buffer Rest { vec4 rest[]; };
// The step's output: the guides' new points are read, the followers' written.
layout(std430, set = 0, binding = 8) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = 9) writeonly buffer VelOut { vec4 vel_out[]; };
layout(std430, set = 0, binding = 11) writeonly buffer PosBefore { vec4 pos_before[]; };
layout(std430, set = 0, binding = 12) readonly buffer SimOrder { uint sim_order[]; };
// Each key hair's guide at the current level (itself when simulated).
layout(std430, set = 0, binding = 13) readonly buffer SimGuides { uint sim_guide[]; };
layout(std430, set = 0, binding = 7) readonly buffer Colliders { Collider colliders[]; };
layout(std430, set = 0, binding = 10) readonly buffer MeshField { float mesh_field[]; };
layout(std430, set = 0, binding = 14) readonly buffer ScalpRoots { ScalpRoot scalp_roots[]; };
layout(std430, set = 0, binding = 15) buffer ScalpPrevious { vec4 scalp_previous[]; };
layout(std430, set = 0, binding = 16) readonly buffer ScalpSource { float scalp_source[]; };
// A skinned mesh collider's grid points' bones and each sub-step's bone rows
// (glsl/include/mesh_sdf.glsl).
layout(std430, set = 0, binding = 17) readonly buffer MeshSkin { uint mesh_skin[]; };
layout(std430, set = 0, binding = 18) readonly buffer MeshBones { vec4 mesh_bones[]; };
#define VKHAIR_MESH_SKIN
#include "sim_bodies.glsl"
#include "scalp.glsl"

// A frame: three columns.
struct Frame {
    vec3 x;
    vec3 y;
    vec3 z;
};

vec3 frame_apply(Frame q, vec3 v) {
    precise vec3 r = (q.x * v.x + q.y * v.y) + q.z * v.z;
    return r;
}

// Turns q by the smallest rotation taking q·rest_segment onto segment (kept
// when either is degenerate).
Frame transport(Frame q, vec3 rest_segment, vec3 segment) {
    vec3 carried = frame_apply(q, rest_segment);
    precise float rest_len = sqrt(sim_dot(carried, carried));
    precise float len = sqrt(sim_dot(segment, segment));
    if (rest_len > 0.0 && len > 0.0) {
        vec3 a = carried / rest_len;
        vec3 b = segment / len;
        q = Frame(sim_rotate_between(a, b, q.x), sim_rotate_between(a, b, q.y), sim_rotate_between(a, b, q.z));
    }
    return q;
}

void main() {
    uint first = step_range_first(push);
    uint count = step_range_count(push);
    SimStepParams start = steps[first];
    SimStepParams end = steps[first + count - 1u];
    uint points = sim_points(end);
    uint simulated = step_range_simulated(push);
    uint h = gl_GlobalInvocationID.x;
    if (h >= sim_strands(end) - simulated) {
        return;
    }
    uint f = sim_order[simulated + h];
    uint g = sim_guide[f];
    mat4 before_head = sim_previous_head(start);
    mat4 head = sim_head(end);
    bool scalp = (sim_flags(end) & SIM_SCALP) != 0u;
    if (scalp) {
        before_head = scalp_frame(start, f, sim_scalp_from(start), before_head);
        head = scalp_frame(end, f, sim_scalp_to(end), head);
    }
    Frame q_old = Frame(before_head[0].xyz, before_head[1].xyz, before_head[2].xyz);
    Frame q_new = Frame(head[0].xyz, head[1].xyz, head[2].xyz);
    vec3 y_old = vec3(0.0);
    vec3 y_new = vec3(0.0);
    vec3 placed_before = vec3(0.0);
    float rest_length = 0.0;
    precise float span = sim_dt(end) * float(count);
    for (uint i = 0u; i < points; i++) {
        uint fi = f * points + i;
        uint gi = g * points + i;
        vec4 old = pos_in[fi];
        if (first == 0u) {
            pos_before[fi] = old;
        }
        vec3 rest_f = rest[fi].xyz;
        if (i == 0u) {
            y_old = sim_transform_point(before_head, rest_f);
            y_new = sim_transform_point(head, rest_f);
        } else {
            precise vec3 rest_segment = rest[gi].xyz - rest[gi - 1u].xyz;
            precise vec3 old_segment = pos_in[gi].xyz - pos_in[gi - 1u].xyz;
            precise vec3 new_segment = pos_out[gi].xyz - pos_out[gi - 1u].xyz;
            q_old = transport(q_old, rest_segment, old_segment);
            q_new = transport(q_new, rest_segment, new_segment);
            precise vec3 own_segment = rest_f - rest[fi - 1u].xyz;
            precise float own_length = sqrt(sim_dot(own_segment, own_segment));
            rest_length = own_length;
            precise vec3 next_old = y_old + frame_apply(q_old, own_segment);
            precise vec3 next_new = y_new + frame_apply(q_new, own_segment);
            y_old = next_old;
            y_new = next_new;
        }
        vec4 x;
        if (old.w == 0.0 || i == 0u) {
            x = vec4(y_new, old.w);
        } else {
            precise vec3 kept = (old.xyz - y_old) * sim_follow_fade(end);
            precise vec3 target = y_new + kept;
            precise vec3 d = target - placed_before;
            precise float len = sqrt(sim_dot(d, d));
            precise vec3 p = len > 0.0 ? placed_before + d * (rest_length / len) : target;
            if ((sim_flags(end) & SIM_COLLISIONS) != 0u) {
                p = sim_collide_bodies(end, sim_flags(end), (first + count - 1u) * SIM_MAX_COLLIDERS, p, rest[fi].w);
            }
            x = vec4(p, old.w);
        }
        placed_before = x.xyz;
        precise vec3 v = (x.xyz - old.xyz) / span;
        pos_out[fi] = x;
        vel_out[fi] = vec4(v, 0.0);
    }
    if (scalp && sim_scalp_last(end) != 0u) {
        scalp_keep_corners(end, f);
    }
}
