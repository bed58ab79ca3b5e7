#version 460
// Mesh collider build, step 3a — ray parity along one axis, one invocation per
// triangle: the rays of the grid lines its projection onto the (u, v) plane
// can reach (its box there, one line more on every side; a ray farther out
// cannot pass the edge test) are tested against it as a line of sign.comp
// once tested every triangle (sdf_crossing), and a crossing toggles the
// line's mark at the first point beyond it (atomicXor). A point's parity is
// the XOR of its line's marks up to it: the same crossings, in any order,
// give the same marks. One dispatch per axis, before sign.comp's.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };
layout(std430, set = 0, binding = 6) buffer Marks { uint marks[]; };
layout(push_constant) uniform Push { SdfPush pc; };

// The grid lines along a (u or v) whose coordinate lies within [lo, hi] and
// one more on each side, clamped to the grid's n lines.
ivec2 sdf_lines_within(float lo, float hi, float origin, float cell, uint n) {
    int first = int(floor((lo - origin) / cell)) - 1;
    int last = int(floor((hi - origin) / cell)) + 1;
    return ivec2(max(first, 0), min(last, int(n) - 1));
}

void main() {
    uint t = gl_GlobalInvocationID.x;
    if (t >= sdf_pass_triangles(pc)) {
        return;
    }
    uint axis = sdf_pass_ray_axis(pc);
    uint u = (axis + 1u) % 3u;
    uint v = (axis + 2u) % 3u;
    uvec3 dims = sdf_pass_dims(pc);
    float cell = sdf_pass_cell(pc);
    vec3 origin = sdf_pass_origin(pc);
    uint nw = dims[axis];
    uint words = sdf_mark_words(dims);
    vec3 a = corners[3u * t].xyz;
    vec3 b = corners[3u * t + 1u].xyz;
    vec3 c = corners[3u * t + 2u].xyz;
    ivec2 is = sdf_lines_within(min(min(a[u], b[u]), c[u]), max(max(a[u], b[u]), c[u]), origin[u], cell, dims[u]);
    ivec2 js = sdf_lines_within(min(min(a[v], b[v]), c[v]), max(max(a[v], b[v]), c[v]), origin[v], cell, dims[v]);
    for (int j = js.x; j <= js.y; j++) {
        for (int i = is.x; i <= is.y; i++) {
            vec2 ray = sdf_ray(uint(i), uint(j), u, v, origin, cell);
            uint first = sdf_crossing(a, b, c, ray, axis, u, v, origin[axis], cell, nw);
            if (first < nw) {
                uint line = uint(j) * dims[u] + uint(i);
                atomicXor(marks[line * words + (first >> 5u)], 1u << (first & 31u));
            }
        }
    }
}
