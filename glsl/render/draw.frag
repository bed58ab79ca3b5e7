#version 460
// Draw pass, fragment stage (opaque hair): the shading of hair_shading.glsl.
#include "hair_shading.glsl"

layout(location = 0) in vec3 g_pos;
layout(location = 1) in vec3 g_tan;
layout(location = 2) in float g_t;
layout(location = 3) flat in uint g_hair;

layout(location = 0) out vec4 out_color;

void main() {
    out_color = vec4(shade_hair(g_pos, g_tan, g_t, g_hair), 1.0);
}
