#version 460
// Smoothing pass, control stage: one isoline of `level` segments per patch.
#include "render.glsl"

layout(vertices = 4) out;
layout(push_constant) uniform Push { SmoothPush pc; };

layout(location = 0) in vec3 v_pos[];
layout(location = 0) out vec3 c_pos[];
layout(location = 1) flat in uint v_patch[];
layout(location = 1) patch out uint p_patch;

void main() {
    c_pos[gl_InvocationID] = v_pos[gl_InvocationID];
    if (gl_InvocationID == 0) {
        p_patch = v_patch[0];
        gl_TessLevelOuter[0] = 1.0;
        gl_TessLevelOuter[1] = float(pc.level);
    }
}
