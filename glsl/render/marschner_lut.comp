#version 460
// Builds the two Marschner lookup tables: M indexed by (sin θi, sin θo) in
// [−1, 1]², N indexed by (cos φ in [−1, 1], cos θd in [0, 1]), texel centres
// at the ends of the ranges.
#include "marschner.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba16f) uniform writeonly image2D m_table;
layout(set = 0, binding = 1, rgba16f) uniform writeonly image2D n_table;
layout(push_constant) uniform Push { MarschnerPush pc; };

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (xy.x >= pc.size || xy.y >= pc.size) {
        return;
    }
    vec2 t = vec2(xy) / float(pc.size - 1u);
    imageStore(m_table, ivec2(xy), marschner_m(pc, 2.0 * t.x - 1.0, 2.0 * t.y - 1.0));
    imageStore(n_table, ivec2(xy), marschner_n(pc, 2.0 * t.x - 1.0, t.y));
}
