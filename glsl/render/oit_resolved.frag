#version 460
// Exact transparency after the compute rasteriser, the composite (over the
// rectangle the ribbons reach, hair_rect.vert): blends what oit_resolve.comp
// resolved for the pixel over the target as premultiplied colour; pixels
// without hair are discarded.
#define OIT_COUNTERS_READONLY
#include "oit_counters.glsl"

layout(std430, set = 0, binding = 28) readonly buffer OitResolved { uvec2 oit_resolved[]; };

layout(location = 0) out vec4 out_color;

void main() {
    uvec2 packed = oit_resolved[uint(gl_FragCoord.y) * oit.width + uint(gl_FragCoord.x)];
    vec4 c = vec4(unpackHalf2x16(packed.x), unpackHalf2x16(packed.y));
    if (!(c.a > 0.0)) {
        discard;
    }
    out_color = c;
}
