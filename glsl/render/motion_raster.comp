#version 460
// Motion vectors, the walk (render/draw/motion.rs): one invocation a segment
// of the drawn hairs, walking its pixels as the compute rasterisers do
// (strand_segment.glsl), after the frame's composite. Each pixel has a depth
// to match (MotionDepth: where the exact mode's composite first reaches the
// motion threshold, or the fast mode's nearest half-opaque depth; OIT_END
// where no hair does): of the fragments there, the one nearest that depth
// gives the pixel its motion — this frame's position of the point, against
// the same point of the hair in the previous frame, each projected without
// its frame's jitter. The pick is the smallest (|depth − match|, velocity
// bits) pair: one 64-bit atomic minimum (INT64 variant), or two walks of
// 32-bit ones (the distance, then the velocity bits among fragments at that
// distance) — the same pair either way, whatever the order of the fragments.
// vkhair variant: VKHAIR_INT64
#ifdef VKHAIR_INT64
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#endif
// Constant 1: the shading features (this stage shades nothing).
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#define OIT_COUNTERS_READONLY
#include "oit_counters.glsl"
#include "motion.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
// The drawn positions of the previous frame (the same vertex layout for the
// first mb.counts.x hairs).
layout(std430, set = 0, binding = 34) readonly buffer Previous { vec4 previous_pos[]; };
// Per pixel the depth (forward, float bits) whose fragment gives its motion.
layout(std430, set = 0, binding = 35) readonly buffer MotionDepth { uint motion_depth[]; };
#ifdef VKHAIR_INT64
// Per pixel: velocity (two half floats) in the low word, distance bits in the high one.
layout(std430, set = 0, binding = 36) buffer MotionKeys { uint64_t motion_keys[]; };
#else
layout(std430, set = 0, binding = 36) buffer MotionKeys { uvec2 motion_keys[]; };
// Which of the two walks: 0 the distances, 1 the velocities.
layout(push_constant) uniform Walk { uint walk; } pc;
#endif

// Fragments fainter than this are not stored by any mode (oit_opaque.glsl).
const float LEAST_ALPHA = 1.0 / 1024.0;

// The fragments were depth-tested by the frame's draw: the depths matched are
// of kept ones. Their colours do not matter here.
#define STRAND_SEGMENT_NO_DEPTH_TEST
#define STRAND_SEGMENT_NO_COLOR
#include "strand_segment.glsl"

// The motion of the point at u along segment `first` (the vertex it starts
// at), in the host's units, as two half floats.
uint motion_of(uint first, float u) {
    vec3 now = mix(hair_pos[first].xyz, hair_pos[first + 1u].xyz, u);
    vec3 before = now;
    if (first / dp.counts.y < mb.counts.x) {
        before = mix(previous_pos[first].xyz, previous_pos[first + 1u].xyz, u);
    }
    vec4 c = mb.now * vec4(now, 1.0);
    vec4 o = mb.before * vec4(before, 1.0);
    vec2 v = vec2(0.0);
    // A point behind the previous frame's camera has no place on its screen: no motion.
    if (c.w > 1e-12 && o.w > 1e-12) {
        v = (c.xy / c.w - o.xy / o.w) * mb.scale.xy;
    }
    // Half floats end at 65504; a non-number moves nothing.
    v = clamp(v, vec2(-65504.0), vec2(65504.0));
    if (any(isnan(v))) {
        v = vec2(0.0);
    }
    return packHalf2x16(v);
}

void walk_segment(uint first, bool last) {
    Segment sg;
    if (!segment_on_screen(first, last, sg)) {
        return;
    }
    for (float k = sg.k_lo; k < sg.k_hi; k += 1.0) {
        vec2 column = segment_column(sg, k);
        for (float m = column.x; m < column.y; m += 1.0) {
            float z;
            vec3 color;
            float alpha;
            if (!segment_fragment(sg, k, m, z, color, alpha) || alpha < LEAST_ALPHA) {
                continue;
            }
            uvec2 at = segment_pixel(sg, k, m);
            uint pixel = at.y * oit.width + at.x;
            // Perspective-correct position along the unclipped segment (as segment_fragment).
            vec2 q = sg.x_major ? vec2(k + 0.5, m + 0.5) : vec2(m + 0.5, k + 0.5);
            float s = clamp(dot(q - sg.a, sg.dir) / sg.len, 0.0, 1.0);
            float inv_w = mix(sg.inv_wa, sg.inv_wb, s);
            float u = mix(sg.u0 * sg.inv_wa, sg.u1 * sg.inv_wb, s) / inv_w;
            uint distance;
            if (mb.counts.z != 0u) {
                // Opaque ribbons: the nearest whose ribbon (at least the least
                // pixel width) covers the pixel's centre, as the draw shaded it.
                float d = abs(dot(q - sg.a, vec2(-sg.dir.y, sg.dir.x)));
                if (d > max(half_width_at(sg.e0, sg.e1, u), 0.5 * dp.widths.z)) {
                    continue;
                }
                distance = floatBitsToUint(max(z, 0.0));
            } else {
                uint match = motion_depth[pixel];
                if (match == OIT_END) {
                    continue;
                }
                // The gap between the fragment and the depth to match, in view
                // space: a fragment of the hair the composite picked lies within
                // the hair's width and a pixel's of it (the hardware's ribbons and
                // this walk cover a pixel a little differently); beyond, the
                // pixel's hair made no fragment here and another hair must not
                // stand in for it.
                float gap = abs(motion_view_z(oit_forward(z)) - motion_view_z(oit_forward(uintBitsToFloat(match))));
                float reach = (2.0 * half_width_at(sg.e0, sg.e1, u) + 2.0) * dp.camera.w / inv_w;
                if (!(gap <= reach)) {
                    continue;
                }
                distance = floatBitsToUint(gap);
            }
#ifdef VKHAIR_INT64
            atomicMin(motion_keys[pixel], (uint64_t(distance) << 32) | uint64_t(motion_of(first, u)));
#else
            if (pc.walk == 0u) {
                atomicMin(motion_keys[pixel].y, distance);
            } else if (motion_keys[pixel].y == distance) {
                atomicMin(motion_keys[pixel].x, motion_of(first, u));
            }
#endif
        }
    }
}

void main() {
    if (dp.counts.y < 2u) {
        return;
    }
    uint total = dp.counts.x * (dp.counts.y - 1u);
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint seg = gl_GlobalInvocationID.x; seg < total; seg += stride) {
        bool last;
        uint first = segment_first(seg, last);
        walk_segment(first, last);
    }
}
