// Exact transparency, one pixel's resolve (oit_resolve.frag over the
// rectangle the ribbons reach; oit_resolve.comp after the compute
// rasteriser): walks the pixel's list, keeps its K nearest fragments sorted by
// depth (one compare-and-swap pass over the first K of the SORT_CAPACITY slots
// per fragment), folds every farther one into an order-independent tail (sum
// of premultiplied colour, sum of alpha, product of transmittance) together
// with the fragments the full pool could not store (the build's overflow
// sums), and composites the K front to back and the tail behind them.
//
// The K-buffer is oit_kbuffer.glsl's. The including shader defines
// VKHAIR_SORT_4/8/16 (else OIT_MAX_SORTED slots) and VKHAIR_OVERFLOW_BUFFER
// (the compute rasteriser's fixed-point overflow sums, oit_overflow.glsl;
// else the hardware build's blended images at bindings 0 and 1).
#ifndef VKHAIR_OIT_RESOLVE_GLSL
#define VKHAIR_OIT_RESOLVE_GLSL
#include "oit.glsl"
#include "oit_kbuffer.glsl"

#ifdef VKHAIR_OVERFLOW_BUFFER
#include "oit_overflow.glsl"
#else
// The build's sums of the fragments beyond the pool: Σ premultiplied colour and
// Σ alpha; Σ absorbance −ln(1 − alpha).
layout(set = 0, binding = 0) uniform sampler2D overflow_sum;
layout(set = 0, binding = 1) uniform sampler2D overflow_absorbance;
#endif

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
    kb_begin(oit.sorted, overflow, absorbance_sum);
    // Each stored node is on exactly one list: at most min(used, capacity) steps.
    uint steps = min(oit.used, oit.capacity);
    for (uint step = 0u; node != OIT_END && step < steps; step++) {
        uvec4 record = oit_load(node);
        node = record.w;
        kb_insert(uintBitsToFloat(record.z), record.xy);
    }
    result = kb_composite();
    kb_write_motion_depth(pixel);
    return true;
}

#endif
