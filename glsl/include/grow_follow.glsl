// Followers (render::Followers), one vertex: point i of follower f (pc.strands
// followers of pc.points points) is the blend of its guides at the parameter
// i / (points − 1) along their smoothed shape (pc.stride vertices each) plus
// its rest offset in the blend of their frames (in the head's frame at the
// root); stored with its tangent from its neighbours and its width factor in
// the position's w. Shared by interpolate_follow.tese and interpolate.comp's
// FOLLOW variant.
#ifndef VKHAIR_GROW_FOLLOW_GLSL
#define VKHAIR_GROW_FOLLOW_GLSL
#include "grow_io.glsl"

layout(std430, set = 0, binding = 2) readonly buffer Reference { vec4 reference[]; };
layout(std430, set = 0, binding = 6) readonly buffer Bindings { FollowerBinding bindings[]; };
layout(std430, set = 0, binding = 7) readonly buffer Offsets { float offsets[]; };
// Per follower its albedo and width factor (a) at the root (2f) and tip (2f + 1).
layout(std430, set = 0, binding = 8) readonly buffer Looks { vec4 looks[]; };

// Points per follower.
uint grow_hair_vertices() {
    return pc.points;
}

vec3 follower_point(uint f, uint i) {
    FollowerBinding b = bindings[f];
    float s = float(i) / float(pc.points - 1u);
    float u = s * float(pc.stride - 1u);
    uint k0 = min(uint(floor(u)), pc.stride - 2u);
    float a = u - float(k0);
    vec3 p = vec3(0.0);
    mat3 m = mat3(0.0);
    for (uint k = 0u; k < 3u; ++k) {
        float w = b.weights[k];
        if (w == 0.0) {
            continue;
        }
        uint base = b.guides[k] * pc.stride + k0;
        vec3 pos = mix(smooth_pos[base].xyz, smooth_pos[base + 1u].xyz, a);
        vec3 t0 = smooth_tan[base].xyz;
        vec3 t = mix(t0, smooth_tan[base + 1u].xyz, a);
        float len = length(t);
        t = len > 0.0 ? t / len : t0;
        vec3 b1;
        vec3 b2;
        key_frame(t, quat_rotate(pc.head_rotation, reference[b.guides[k]].xyz), b1, b2);
        p += w * pos;
        m += w * mat3(b1, b2, t);
    }
    uint o = (f * pc.points + i) * 3u;
    vec3 offset = vec3(offsets[o], offsets[o + 1u], offsets[o + 2u]);
    // The root's offset is in the head's frame: roots stay on the scalp.
    return p + (i == 0u ? quat_rotate(pc.head_rotation, offset) : m * offset);
}

// Point i of follower f (`h` is always 0: one follower a unit).
void grow_vertex(uint f, uint h, uint i) {
    vec3 p = follower_point(f, i);
    vec3 before = i > 0u ? follower_point(f, i - 1u) : p;
    vec3 after = i + 1u < pc.points ? follower_point(f, i + 1u) : p;
    vec3 t = after - before;
    float len = length(t);
    uint dst = f * pc.points + i;
    // The width factor along the follower, for the draw's ribbons.
    float s = float(i) / float(pc.points - 1u);
    hair_pos[dst] = vec4(p, mix(looks[2u * f].a, looks[2u * f + 1u].a, s));
    hair_tan[dst] = vec4(len > 0.0 ? t / len : vec3(0.0, -1.0, 0.0), float(i) / float(pc.points - 1u));
}

#endif
