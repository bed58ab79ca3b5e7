#version 460
// Transparency composite, vertex stage (six vertices): the two triangles of the
// rectangle of pixels the frame's ribbons can reach (OitCounters' hair_*,
// found by hair_rect.comp), so that the composite's fragment stages run
// there and not over the whole target; nothing (one point) when it is empty.
#define OIT_COUNTERS_READONLY
#include "oit_counters.glsl"

void main() {
    uint c = uint(gl_VertexIndex);
    // Corners 0..5: (0, 0), (1, 0), (0, 1) and (1, 0), (1, 1), (0, 1).
    vec2 corner = vec2((c == 1u || c == 3u || c == 4u) ? 1.0 : 0.0, (c == 2u || c >= 4u) ? 1.0 : 0.0);
    vec2 lo = vec2(oit.hair_x0, oit.hair_y0);
    vec2 hi = vec2(oit.hair_x1, oit.hair_y1);
    if (!(lo.x < hi.x && lo.y < hi.y)) {
        gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec2 size = vec2(oit.width, oit.height);
    gl_Position = vec4(mix(lo, hi, corner) / size * 2.0 - 1.0, 0.0, 1.0);
}
