#version 460
// Draw pass, geometry stage: each segment becomes a camera-facing ribbon of
// mix(root width, tip width) world units, at least `least width` pixels wide.
#include "render.glsl"

layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
layout(std140, set = 0, binding = 0) uniform Draw { DrawParams dp; };

layout(location = 0) in vec3 v_pos[];
layout(location = 1) in vec3 v_tan[];
layout(location = 2) in float v_t[];
layout(location = 3) flat in uint v_hair[];

// The depth pre-pass and the shading draw must rasterize the same depths: the
// same modules in both pipelines, and no fused multiply-adds that a compiler
// could choose differently in each.
precise gl_Position;

layout(location = 0) out vec3 g_pos;
layout(location = 1) out vec3 g_tan;
layout(location = 2) out float g_t;
layout(location = 3) flat out uint g_hair;

void main() {
    vec3 along = v_pos[1] - v_pos[0];
    float len = length(along);
    vec3 dir = len > 0.0 ? along / len : v_tan[0];
    for (int e = 0; e < 2; e++) {
        vec3 to_camera = dp.camera.xyz - v_pos[e];
        float distance_to_camera = length(to_camera);
        vec3 side = cross(dir, to_camera);
        float side_len = length(side);
        side = side_len > 1e-12 ? side / side_len : vec3(1.0, 0.0, 0.0);
        float width = mix(dp.widths.x, dp.widths.y, v_t[e]);
        width = max(width, dp.widths.z * dp.camera.w * distance_to_camera);
        for (int s = -1; s <= 1; s += 2) {
            g_pos = v_pos[e] + side * (0.5 * width * float(s));
            g_tan = v_tan[e];
            g_t = v_t[e];
            g_hair = v_hair[e];
            gl_Position = dp.view_proj * vec4(g_pos, 1.0);
            EmitVertex();
        }
    }
    EndPrimitive();
}
