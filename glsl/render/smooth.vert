#version 460
// Smoothing pass, vertex stage: control point k of the patch of key segment
// `seg` is key point seg − 1 + k. Outside the strand, points are mirrored
// (2·p0 − p1 at the root, 2·pn − pn−1 at the tip), so that the uniform cubic
// B-spline passes exactly through root and tip with the strand's end tangents.
#include "render.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Keys { vec4 keys[]; };
// The key hairs before the latest step: drawn at pc.alpha between them and the latest.
layout(std430, set = 0, binding = 3) readonly buffer KeysBefore { vec4 keys_before[]; };
layout(push_constant) uniform Push { SmoothPush pc; };

layout(location = 0) out vec3 v_pos;
// The patch index, from gl_VertexIndex: lavapipe restarts gl_PrimitiveID in the
// evaluation stage every 8192 patches, so it is not used.
layout(location = 1) flat out uint v_patch;

// Key point i drawn at pc.alpha: exactly one of the two states at 0 and 1.
vec3 key(uint i) {
    vec3 latest = keys[i].xyz;
    if (pc.alpha >= 1.0) {
        return latest;
    }
    vec3 before = keys_before[i].xyz;
    if (pc.alpha <= 0.0) {
        return before;
    }
    return before + (latest - before) * pc.alpha;
}

void main() {
    uint segs = pc.points - 1u;
    uint patch_index = uint(gl_VertexIndex) / 4u;
    int k = int(uint(gl_VertexIndex) % 4u);
    uint strand = patch_index / segs;
    uint seg = patch_index - strand * segs;
    uint base = strand * pc.points;
    v_patch = patch_index;
    int idx = int(seg) - 1 + k;
    if (idx < 0) {
        v_pos = 2.0 * key(base) - key(base + 1u);
    } else if (idx >= int(pc.points)) {
        uint last = base + pc.points - 1u;
        v_pos = 2.0 * key(last) - key(last - 1u);
    } else {
        v_pos = key(base + uint(idx));
    }
}
