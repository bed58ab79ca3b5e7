#version 460
// Interpolation pass, control stage: the isolines of instance n are hairs
// n·INTERPOLATE_LINES_PER_INSTANCE onwards, at most that many of the `hairs`
// per key segment (one isoline per interpolated hair), of `level` segments each.
#include "render.glsl"

layout(vertices = 1) out;
layout(push_constant) uniform Push { InterpolatePush pc; };

layout(location = 0) flat in uint v_patch[];
layout(location = 1) flat in uint v_instance[];
layout(location = 0) patch out uint p_patch;
layout(location = 1) patch out uint p_first_hair;
layout(location = 2) patch out uint p_lines;

void main() {
    // The draw has ceil(hairs / INTERPOLATE_LINES_PER_INSTANCE) instances, so
    // every instance grows at least one hair.
    uint first = v_instance[0] * INTERPOLATE_LINES_PER_INSTANCE;
    uint lines = min(pc.hairs - first, INTERPOLATE_LINES_PER_INSTANCE);
    p_patch = v_patch[0];
    p_first_hair = first;
    p_lines = lines;
    gl_TessLevelOuter[0] = float(lines);
    gl_TessLevelOuter[1] = float(pc.level);
}
