// Exact transparency, one pixel's resolve (oit_resolve.frag over the
// rectangle the ribbons reach; oit_resolve.comp after the compute
// rasteriser): walks the pixel's list, keeps its K nearest fragments sorted by
// depth (one compare-and-swap pass over the first K of the SORT_CAPACITY slots
// per fragment), folds every farther one into an order-independent tail (sum
// of premultiplied colour, sum of alpha, product of transmittance) together
// with the fragments the full pool could not store (the build's overflow
// sums), and composites the K front to back and the tail behind them.
//
// The kept fragments live in local arrays of SORT_CAPACITY entries (depth and
// packed half-float colour), every pass over them unrolled: the smallest
// variant that holds K is chosen (exact.rs), since each fragment costs
// SORT_CAPACITY compare-and-swaps whatever K is. The including shader defines
// VKHAIR_SORT_4/8/16 (else OIT_MAX_SORTED slots) and VKHAIR_OVERFLOW_BUFFER
// (the compute rasteriser's fixed-point overflow sums, oit_overflow.glsl;
// else the hardware build's blended images at bindings 0 and 1).
#ifndef VKHAIR_OIT_RESOLVE_GLSL
#define VKHAIR_OIT_RESOLVE_GLSL
#extension GL_EXT_control_flow_attributes : require
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

#ifdef VKHAIR_OVERFLOW_BUFFER
#include "oit_overflow.glsl"
#else
// The build's sums of the fragments beyond the pool: Σ premultiplied colour and
// Σ alpha; Σ absorbance −ln(1 − alpha).
layout(set = 0, binding = 0) uniform sampler2D overflow_sum;
layout(set = 0, binding = 1) uniform sampler2D overflow_absorbance;
#endif

// The depth of an empty slot: beyond every fragment's (depths lie in 0..1).
const float EMPTY = 2.0;

// A node's colour and alpha from their half floats (oit_build.frag packs them).
vec4 unpack_color(uvec2 packed) {
    return vec4(unpackHalf2x16(packed.x), unpackHalf2x16(packed.y));
}

// Pixel `pixel` (at `coord`) composited: its hair as premultiplied colour and
// coverage; false (and nothing to blend) for a pixel without hair.
bool oit_resolve_pixel(uint pixel, ivec2 coord, out vec4 result) {
    uint node = oit_heads[pixel];
#ifdef VKHAIR_OVERFLOW_BUFFER
    vec4 overflow = oit_overflow_sum(pixel);
    float absorbance_sum = oit_overflow_absorbance(pixel);
#else
    vec4 overflow = texelFetch(overflow_sum, coord, 0);
    float absorbance_sum = texelFetch(overflow_absorbance, coord, 0).r;
#endif
    result = vec4(0.0);
    if (node == OIT_END && overflow.a <= 0.0) {
        return false;
    }
    // Slot i holds the i-th nearest kept fragment; an empty slot holds depth
    // EMPTY, beyond every fragment's. Every index below is a constant once the
    // loops are unrolled: the arrays stay in registers (a dynamically indexed
    // local array is scratch memory, gathered and scattered per lane on a CPU
    // device, and cost the resolve about a third of its time on lavapipe).
    float depth[SORT_CAPACITY];
    uvec2 color[SORT_CAPACITY];
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        depth[i] = EMPTY;
        color[i] = uvec2(0u);
    }
    uint k = min(oit.sorted, SORT_CAPACITY);
    vec3 tail_sum = overflow.rgb;
    float tail_alpha = overflow.a;
    float tail_transmittance = exp(-absorbance_sum);
    // Each stored node is on exactly one list: at most min(used, capacity) steps.
    uint steps = min(oit.used, oit.capacity);
    for (uint step = 0u; node != OIT_END && step < steps; step++) {
        uvec4 record = oit_load(node);
        node = record.w;
        // Insertion by one pass over the k slots: the fragment in hand swaps
        // places with every kept one farther than it, so the slots stay sorted
        // (fragments at one depth in no set order, as they reach the list in
        // none) and what is left in hand is the farthest of the k + 1 — the
        // new fragment or one pushed out — bound for the tail.
        float z = uintBitsToFloat(record.z);
        uvec2 c = record.xy;
        [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
            bool swap = i < k && z < depth[i];
            float kept_z = depth[i];
            uvec2 kept_c = color[i];
            depth[i] = swap ? z : kept_z;
            color[i] = swap ? c : kept_c;
            z = swap ? kept_z : z;
            c = swap ? kept_c : c;
        }
        // An empty slot's colour is zero: handed out, it adds nothing.
        vec4 out_c = unpack_color(c);
        tail_sum += out_c.rgb * out_c.a;
        tail_alpha += out_c.a;
        tail_transmittance *= 1.0 - out_c.a;
    }
    vec3 sum = vec3(0.0);
    float transmittance = 1.0;
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        vec4 c = unpack_color(color[i]);
        sum += transmittance * c.a * c.rgb;
        transmittance *= 1.0 - c.a;
    }
    if (tail_alpha > 0.0) {
        sum += transmittance * (1.0 - tail_transmittance) * (tail_sum / tail_alpha);
        transmittance *= tail_transmittance;
    }
    result = vec4(sum, 1.0 - transmittance);
    return true;
}

#endif
