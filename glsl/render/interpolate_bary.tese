#version 460
// Barycentric interpolation, evaluation stage: vertex j of line h of key
// segment `seg` of scalp triangle `tri` is grown vertex k = seg·level + j of
// the triangle's hair h (grow_bary.glsl). Each vertex stored once.
#include "grow_bary.glsl"

layout(isolines, equal_spacing) in;

layout(location = 0) patch in uint p_patch;
layout(location = 1) patch in uint p_first_hair;
layout(location = 2) patch in uint p_lines;

void main() {
    uint segs = pc.points - 1u;
    uint tri = p_patch / segs;
    uint seg = p_patch - tri * segs;
    uint j = uint(gl_TessCoord.x * float(pc.level) + 0.5);
    uint h = isoline_hair(p_first_hair, gl_TessCoord.y, p_lines);
    if (j < pc.level || seg + 1u == segs) {
        grow_vertex(tri, h, seg * pc.level + j);
    }
    gl_Position = vec4(0.0);
}
