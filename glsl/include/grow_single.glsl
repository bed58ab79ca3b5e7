// Single-strand interpolation, one vertex (render/interpolate.rs): vertex k of
// hair h of key hair `key` is smoothed key vertex k offset in the key frame by
// clump_coordinate(key, h) · clump_width · mix(root_width, tip_width, t),
// t = k / (stride − 1). Shared by the tessellation evaluation stage
// (interpolate.tese) and the compute stage (interpolate.comp), which differ
// only in how they reach (key, h, k).
#ifndef VKHAIR_GROW_SINGLE_GLSL
#define VKHAIR_GROW_SINGLE_GLSL
#include "grow_io.glsl"

layout(std430, set = 0, binding = 2) readonly buffer Reference { vec4 reference[]; };

// Smoothed vertices per grown hair.
uint grow_hair_vertices() {
    return pc.stride;
}

void grow_vertex(uint key, uint h, uint k) {
    uint src = key * pc.stride + k;
    vec3 p = smooth_pos[src].xyz;
    vec3 t = smooth_tan[src].xyz;
    vec3 b1;
    vec3 b2;
    key_frame(t, quat_rotate(pc.head_rotation, reference[key].xyz), b1, b2);
    vec2 c = clump_coordinate(key, h);
    float s = float(k) / float(pc.stride - 1u);
    float w = pc.clump_width * mix(pc.root_width, pc.tip_width, s);
    uint dst = (key * pc.hairs + h) * pc.stride + k;
    hair_pos[dst] = vec4(p + (c.x * b1 + c.y * b2) * w, 1.0);
    hair_tan[dst] = vec4(t, s);
}

#endif
