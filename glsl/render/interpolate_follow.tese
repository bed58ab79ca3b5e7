#version 460
// Interpolation pass, evaluation stage for followers (render::Followers): the
// patch is segment `seg` of follower `f` (pc.strands followers of pc.points
// points; one isoline of one segment), its first end point i = seg grown by
// grow_follow.glsl (and the last segment's second end too): each vertex
// stored once.
#include "grow_follow.glsl"

layout(isolines, equal_spacing) in;

layout(location = 0) patch in uint p_patch;
layout(location = 1) patch in uint p_first_hair;  // 0: one follower a patch
layout(location = 2) patch in uint p_lines;       // 1

void main() {
    uint segs = pc.points - 1u;
    uint f = p_patch / segs + p_first_hair * p_lines;
    uint seg = p_patch - f * segs;
    uint j = uint(gl_TessCoord.x + 0.5);
    if (j == 0u || seg + 1u == segs) {
        grow_vertex(f, 0u, seg + j);
    }
    gl_Position = vec4(0.0);
}
