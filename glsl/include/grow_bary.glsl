// Barycentric interpolation, one vertex (render/interpolate.rs): hair h of
// scalp triangle (a, b, c) blends the three key hairs' smoothed vertices with
// stable random barycentric weights (u, v, w), the same every frame. Shared by
// interpolate_bary.tese and interpolate.comp's BARY variant.
#ifndef VKHAIR_GROW_BARY_GLSL
#define VKHAIR_GROW_BARY_GLSL
#include "grow_io.glsl"

layout(std430, set = 0, binding = 5) readonly buffer Triangles { uvec4 triangles[]; };

// Smoothed vertices per grown hair.
uint grow_hair_vertices() {
    return pc.stride;
}

void grow_vertex(uint tri, uint h, uint k) {
    uvec3 keys = triangles[tri].xyz;
    vec3 w = barycentric_weights(tri, h);
    vec3 p = w.x * smooth_pos[keys.x * pc.stride + k].xyz + w.y * smooth_pos[keys.y * pc.stride + k].xyz
        + w.z * smooth_pos[keys.z * pc.stride + k].xyz;
    vec3 t = w.x * smooth_tan[keys.x * pc.stride + k].xyz + w.y * smooth_tan[keys.y * pc.stride + k].xyz
        + w.z * smooth_tan[keys.z * pc.stride + k].xyz;
    float len = length(t);
    uint dst = (tri * pc.hairs + h) * pc.stride + k;
    hair_pos[dst] = vec4(p, 1.0);
    hair_tan[dst] = vec4(len > 0.0 ? t / len : smooth_tan[keys.x * pc.stride + k].xyz, float(k) / float(pc.stride - 1u));
}

#endif
