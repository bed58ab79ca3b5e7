#version 460
// A cut or teleport (src/sim/teleport.rs), recorded before a step when one is
// pending: every point of every key hair (simulated or following) in the half
// the step reads, in place — or, for a crowd member's teleport, the points of
// its key hairs (from state_move_first). Teleport: x = T·x and v = R·v with T the rigid
// motion from the old head to the new one and R its rotation, so the hair
// keeps its shape and motion relative to the head and gains no velocity.
// Reset: x = head·rest (the rest pose placed by the head, or with a bound
// scalp by each key hair's root frame), v = 0. Inverse
// masses (x.w) and velocity w are kept. The CPU reference
// (sim::reference::move_state) runs the same operations.
#include "sim.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(push_constant) uniform Push { MovePush push; };
layout(std430, set = 0, binding = 1) buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = 2) buffer VelIn { vec4 vel_in[]; };
layout(std430, set = 0, binding = 5) readonly buffer Rest { vec4 rest[]; };
// With SIM_SCALP in the step's parameters, a reset places each key hair by its
// root's frame on this step's scalp (glsl/include/scalp.glsl).
layout(std430, set = 0, binding = 0) readonly buffer Steps { SimStepParams steps[]; };
layout(std430, set = 0, binding = 14) readonly buffer ScalpRoots { ScalpRoot scalp_roots[]; };
layout(std430, set = 0, binding = 15) buffer ScalpPrevious { vec4 scalp_previous[]; };
layout(std430, set = 0, binding = 16) readonly buffer ScalpSource { float scalp_source[]; };
#include "scalp.glsl"

// A grid-stride loop: the dispatch stays within the 65,535 workgroups every
// device offers however many points there are.
void main() {
    mat4 m = state_move_transform(push);
    bool reset = state_move_reset(push) != 0u;
    uint total = state_move_points(push);
    uint first_point = state_move_first(push);
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    SimStepParams first = steps[0];
    bool scalp = reset && (sim_flags(first) & SIM_SCALP) != 0u;
    for (uint k = gl_GlobalInvocationID.x; k < total; k += stride) {
        uint i = first_point + k;
        vec4 x = pos_in[i];
        vec4 v = vel_in[i];
        if (reset) {
            // The step restarts from this scalp (sim_scalp_restart): its frame at 0.
            mat4 placed = scalp ? scalp_frame(first, i / sim_points(first), 0.0, m) : m;
            pos_in[i] = vec4(sim_transform_point(placed, rest[i].xyz), x.w);
            vel_in[i] = vec4(0.0, 0.0, 0.0, v.w);
        } else {
            pos_in[i] = vec4(sim_transform_point(m, x.xyz), x.w);
            vel_in[i] = vec4(sim_rotate(m, v.xyz), v.w);
        }
    }
}
