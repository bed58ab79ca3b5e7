#version 460
// Mesh collider build, step 3b — ray parity along one axis, one invocation per
// grid line: the parity of each point of the line is the XOR of the line's
// crossing marks up to it (sign_mark.comp toggled a mark at the first point
// beyond each crossing of the line's ray with a triangle, so a crossing at
// depth h flips the parity of every point w with w · cell > h). Points with
// odd parity get a vote. The line's marks are cleared for the next axis. One
// dispatch per axis; each point is written by one line per axis.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 4) buffer Votes { uint votes[]; };
layout(std430, set = 0, binding = 6) buffer Marks { uint marks[]; };
layout(push_constant) uniform Push { SdfPush pc; };

void main() {
    uint axis = sdf_pass_ray_axis(pc);
    uint u = (axis + 1u) % 3u;
    uint v = (axis + 2u) % 3u;
    uvec3 dims = sdf_pass_dims(pc);
    uint line = gl_GlobalInvocationID.x;
    if (line >= dims[u] * dims[v]) {
        return;
    }
    uint i = line % dims[u];
    uint j = line / dims[u];
    uint nw = dims[axis];
    uint words = sdf_mark_words(dims);
    uint parity = 0u;
    for (uint w = 0u; w < nw; w++) {
        parity ^= (marks[line * words + (w >> 5u)] >> (w & 31u)) & 1u;
        if (parity != 0u) {
            uvec3 g;
            g[axis] = w;
            g[u] = i;
            g[v] = j;
            votes[sdf_index(g, dims)] += 1u;
        }
    }
    for (uint k = 0u; k < words; k++) {
        marks[line * words + k] = 0u;
    }
}
