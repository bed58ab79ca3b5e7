#version 460
// Exact transparency, resolve (over the rectangle the ribbons reach,
// hair_rect.vert): walks the pixel's list, keeps its K nearest fragments sorted
// by depth (insertion), folds every farther one into an order-independent tail
// (sum of premultiplied colour, sum of alpha, product of transmittance)
// together with the fragments the full pool could not store (the build's
// overflow sums), composites the K front to back and the tail behind them, and
// blends the result over the target as premultiplied colour. Pixels without
// hair are discarded.
//
// The kept fragments live in local arrays of SORT_CAPACITY entries (depth and
// packed half-float colour): the smallest variant that holds K is chosen
// (exact.rs), since arrays larger than needed cost registers and scratch
// memory on every pixel (on lavapipe a 32-entry array made the thesis frame
// 40 % slower at K = 8).
// vkhair variant: VKHAIR_SORT_4
// vkhair variant: VKHAIR_SORT_8
// vkhair variant: VKHAIR_SORT_16
#include "oit.glsl"

#if defined(VKHAIR_SORT_4)
#define SORT_CAPACITY 4u
#elif defined(VKHAIR_SORT_8)
#define SORT_CAPACITY 8u
#elif defined(VKHAIR_SORT_16)
#define SORT_CAPACITY 16u
#else
#define SORT_CAPACITY OIT_MAX_SORTED
#endif

// The build's sums of the fragments beyond the pool: Σ premultiplied colour and
// Σ alpha; Σ absorbance −ln(1 − alpha).
layout(set = 0, binding = 0) uniform sampler2D overflow_sum;
layout(set = 0, binding = 1) uniform sampler2D overflow_absorbance;

layout(location = 0) out vec4 out_color;

void main() {
    uint node = oit_heads[oit_pixel(gl_FragCoord)];
    vec4 overflow = texelFetch(overflow_sum, ivec2(gl_FragCoord.xy), 0);
    if (node == OIT_END && overflow.a <= 0.0) {
        discard;
    }
    float depth[SORT_CAPACITY];
    uvec2 color[SORT_CAPACITY];
    uint k = min(oit.sorted, SORT_CAPACITY);
    uint n = 0u;
    vec3 tail_sum = overflow.rgb;
    float tail_alpha = overflow.a;
    float tail_transmittance = exp(-texelFetch(overflow_absorbance, ivec2(gl_FragCoord.xy), 0).r);
    // Each stored node is on exactly one list: at most min(used, capacity) steps.
    uint steps = min(oit.used, oit.capacity);
    for (uint step = 0u; node != OIT_END && step < steps; step++) {
        uvec4 record = oit_load(node);
        node = record.w;
        float z = uintBitsToFloat(record.z);
        if (n == k) {
            // Full: the farther of this fragment and the farthest kept one goes to the tail.
            if (k == 0u || z >= depth[n - 1u]) {
                vec4 c = vec4(unpackHalf2x16(record.x), unpackHalf2x16(record.y));
                tail_sum += c.rgb * c.a;
                tail_alpha += c.a;
                tail_transmittance *= 1.0 - c.a;
                continue;
            }
            uvec2 out_p = color[n - 1u];
            vec4 out_c = vec4(unpackHalf2x16(out_p.x), unpackHalf2x16(out_p.y));
            tail_sum += out_c.rgb * out_c.a;
            tail_alpha += out_c.a;
            tail_transmittance *= 1.0 - out_c.a;
            n -= 1u;
        }
        uint i = n;
        while (i > 0u && depth[i - 1u] > z) {
            depth[i] = depth[i - 1u];
            color[i] = color[i - 1u];
            i -= 1u;
        }
        depth[i] = z;
        color[i] = record.xy;
        n += 1u;
    }
    vec3 sum = vec3(0.0);
    float transmittance = 1.0;
    for (uint i = 0u; i < n; i++) {
        vec4 c = vec4(unpackHalf2x16(color[i].x), unpackHalf2x16(color[i].y));
        sum += transmittance * c.a * c.rgb;
        transmittance *= 1.0 - c.a;
    }
    if (tail_alpha > 0.0) {
        sum += transmittance * (1.0 - tail_transmittance) * (tail_sum / tail_alpha);
        transmittance *= tail_transmittance;
    }
    out_color = vec4(sum, 1.0 - transmittance);
}
