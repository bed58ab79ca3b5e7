#version 460
// Opacity-map passes, vertex stage: the interpolated hairs (as captured by the
// interpolation pass, at the frame's level of detail) as lines seen from light
// map `pc.map`; the light-space depth goes to the fragment stage.
#include "shadow.glsl"

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(push_constant) uniform Push { uint map; } pc;

layout(location = 0) out float v_depth;

void main() {
    uint per_hair = sp.counts.y;
    uint segs = per_hair - 1u;
    uint seg = uint(gl_VertexIndex) / 2u;
    uint hair = seg / segs;
    uint k = seg - hair * segs + (uint(gl_VertexIndex) & 1u);
    vec3 p = hair_pos[hair * per_hair + k].xyz;
    ShadowMap m = sp.maps[pc.map];
    v_depth = dot(m.view_z.xyz, p) + m.view_z.w;
    gl_Position = m.view_proj * vec4(p, 1.0);
}
