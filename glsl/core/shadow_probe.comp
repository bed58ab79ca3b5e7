#version 460
// Test probe: shadow_transmittance() of glsl/include/shadow.glsl at given points.
#include "shadow.glsl"

layout(local_size_x = 64) in;

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(set = 0, binding = 1) uniform sampler2D atlas;
layout(std430, set = 0, binding = 2) readonly buffer Points { vec4 points[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Out { float transmittance[]; };
layout(push_constant) uniform Push { uint map; uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    transmittance[i] = shadow_transmittance(atlas, sp.maps[pc.map], points[i].xyz);
}
