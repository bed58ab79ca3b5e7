#version 460
// Mesh collider build, step 3 — ray parity along one axis, one invocation per
// grid line: a ray along the axis through the line (nudged off the lattice by
// 0.001 and 0.002 cells so that it misses edges and vertices) is tested
// against every triangle; a crossing at depth h flips the parity of every
// point of the line beyond it (w · cell > h). Points with odd parity get a
// vote. One dispatch per axis; each point is written by one line per axis.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };
layout(std430, set = 0, binding = 4) buffer Votes { uint votes[]; };
layout(push_constant) uniform Push { SdfPush pc; };

// Parity bits of one line (the most points per axis is SDF_MAX_RESOLUTION).
uint parity[SDF_MAX_RESOLUTION / 32u];

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
    float cell = sdf_pass_cell(pc);
    precise float ou = sdf_pass_origin(pc)[u] + (float(i) + 1e-3) * cell;
    precise float ov = sdf_pass_origin(pc)[v] + (float(j) + 2e-3) * cell;
    float ow = sdf_pass_origin(pc)[axis];
    uint nw = dims[axis];
    for (uint b = 0u; b < SDF_MAX_RESOLUTION / 32u; b++) {
        parity[b] = 0u;
    }
    for (uint t = 0u; t < sdf_pass_triangles(pc); t++) {
        vec3 a = corners[3u * t].xyz;
        vec3 b = corners[3u * t + 1u].xyz;
        vec3 c = corners[3u * t + 2u].xyz;
        // Edge functions of the projection onto the (u, v) plane.
        precise float w0 = (c[u] - b[u]) * (ov - b[v]) - (c[v] - b[v]) * (ou - b[u]);
        precise float w1 = (a[u] - c[u]) * (ov - c[v]) - (a[v] - c[v]) * (ou - c[u]);
        precise float w2 = (b[u] - a[u]) * (ov - a[v]) - (b[v] - a[v]) * (ou - a[u]);
        bool positive = w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0;
        bool negative = w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0;
        precise float area = w0 + w1 + w2;
        if (!(positive || negative) || area == 0.0) {
            continue;
        }
        precise float depth = (w0 * a[axis] + w1 * b[axis] + w2 * c[axis]) / area;
        precise float h = depth - ow;
        // The first point beyond the crossing.
        int first = int(clamp(floor(h / cell), 0.0, float(nw)));
        while (first > 0 && float(first - 1) * cell > h) {
            first--;
        }
        while (first < int(nw) && !(float(first) * cell > h)) {
            first++;
        }
        for (uint w = uint(first); w < nw; w++) {
            parity[w >> 5u] ^= 1u << (w & 31u);
        }
    }
    for (uint w = 0u; w < nw; w++) {
        if ((parity[w >> 5u] & (1u << (w & 31u))) != 0u) {
            uvec3 g;
            g[axis] = w;
            g[u] = i;
            g[v] = j;
            votes[sdf_index(g, dims)] += 1u;
        }
    }
}
