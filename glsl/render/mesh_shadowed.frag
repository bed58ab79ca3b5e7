#version 460
// The host stand-in's mesh shaded with the hair's shadows: what a host does
// with glsl/include/shadow.glsl, Renderer::shadow_uniforms and
// Renderer::shadow_atlas. Lights shadowed through the density volume are left
// unshadowed here (their per-cell transmittance is the renderer's own buffer).
#include "shadow.glsl"

layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 rotation;
    vec4 color;
    vec4 light;
    vec4 translation;
} pc;
layout(std140, set = 0, binding = 2) uniform Shadows { ShadowParams sp; };
layout(set = 0, binding = 3) uniform sampler2D shadow_atlas;

layout(location = 0) in vec3 v_normal;
layout(location = 1) in vec3 v_world;
layout(location = 0) out vec4 out_color;

void main() {
    float lambert = max(dot(normalize(v_normal), -normalize(pc.light.xyz)), 0.0);
    int light = int(pc.translation.w);
    if (light >= 0 && light < 8) {
        uint map = sp.light_map[light / 4][light % 4];
        if (map < sp.counts.z && uint(sp.maps[map].params.z) == SHADOW_DEEP_OPACITY) {
            lambert *= shadow_transmittance(shadow_atlas, sp.maps[map], v_world);
        }
    }
    out_color = vec4(pc.color.rgb * (pc.light.w + (1.0 - pc.light.w) * lambert), 1.0);
}
