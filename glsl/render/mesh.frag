#version 460
layout(push_constant) uniform Push {
    mat4 mvp;
    vec4 rotation;
    vec4 color;
    vec4 light;
    vec4 translation;
} pc;

layout(location = 0) in vec3 v_normal;
// World position (read by mesh_shadowed.frag; declared so the interfaces match).
layout(location = 1) in vec3 v_world;
layout(location = 0) out vec4 out_color;

void main() {
    float lambert = max(dot(normalize(v_normal), -normalize(pc.light.xyz)), 0.0);
    out_color = vec4(pc.color.rgb * (pc.light.w + (1.0 - pc.light.w) * lambert), 1.0);
}
