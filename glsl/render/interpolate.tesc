#version 460
// Interpolation pass, control stage: `hairs` isolines (one per interpolated
// hair) of `level` segments each, per key segment.
#include "render.glsl"

layout(vertices = 1) out;
layout(push_constant) uniform Push { InterpolatePush pc; };

layout(location = 0) flat in uint v_patch[];
layout(location = 0) patch out uint p_patch;

void main() {
    p_patch = v_patch[0];
    gl_TessLevelOuter[0] = float(pc.hairs);
    gl_TessLevelOuter[1] = float(pc.level);
}
