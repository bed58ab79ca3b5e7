// Exact transparency, one pixel's K-buffer: its K nearest fragments kept
// sorted by depth (one compare-and-swap pass over the SORT_CAPACITY slots per
// fragment), every farther one folded into an order-independent tail (sum of
// premultiplied colour, sum of alpha, product of transmittance), and the K
// composited front to back with the tail behind them. Shared by the resolve of
// the per-pixel lists (oit_resolve.glsl) and the tiled rasteriser's fine pass
// (tile_fine.comp), which hold the same fragments in the same slots.
//
// The slots live in per-invocation arrays of SORT_CAPACITY entries (depth and
// packed half-float colour), every pass over them unrolled: the smallest
// variant that holds K is chosen (exact.rs), since each fragment costs
// SORT_CAPACITY compare-and-swaps whatever K is. The includer defines
// VKHAIR_SORT_4/8/16 (else OIT_MAX_SORTED slots).
#ifndef VKHAIR_OIT_KBUFFER_GLSL
#define VKHAIR_OIT_KBUFFER_GLSL
#extension GL_EXT_control_flow_attributes : require

#if defined(VKHAIR_SORT_4)
#define SORT_CAPACITY 4u
#elif defined(VKHAIR_SORT_8)
#define SORT_CAPACITY 8u
#elif defined(VKHAIR_SORT_16)
#define SORT_CAPACITY 16u
#else
#define SORT_CAPACITY OIT_MAX_SORTED
#endif

// The depth of an empty slot: beyond every fragment's (depths lie in 0..1).
const float EMPTY = 2.0;

// A fragment's colour and alpha from their half floats (as stored: rg, b + alpha).
vec4 unpack_color(uvec2 packed) {
    return vec4(unpackHalf2x16(packed.x), unpackHalf2x16(packed.y));
}

// A fragment's colour and alpha as half floats (rg, b + alpha).
uvec2 pack_color(vec3 color, float alpha) {
    return uvec2(packHalf2x16(color.rg), packHalf2x16(vec2(color.b, alpha)));
}

// Slot i holds the i-th nearest kept fragment; an empty slot holds depth
// EMPTY, beyond every fragment's. Every index is a constant once the loops
// are unrolled: the arrays stay in registers (a dynamically indexed local
// array is scratch memory, gathered and scattered per lane on a CPU device,
// and cost the resolve about a third of its time on lavapipe).
float kb_depth[SORT_CAPACITY];
uvec2 kb_color[SORT_CAPACITY];
// Slots in use: K, at most SORT_CAPACITY.
uint kb_k;
vec3 kb_tail_sum;
float kb_tail_alpha;
float kb_tail_transmittance;

// Empties the slots, K of them kept sorted, and starts the tail from sums of
// fragments kept elsewhere (Σ premultiplied colour and Σ alpha, Σ absorbance).
void kb_begin(uint k, vec4 tail, float absorbance) {
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        kb_depth[i] = EMPTY;
        kb_color[i] = uvec2(0u);
    }
    kb_k = min(k, SORT_CAPACITY);
    kb_tail_sum = tail.rgb;
    kb_tail_alpha = tail.a;
    kb_tail_transmittance = exp(-absorbance);
}

// One fragment at depth `z` with packed colour `c`: the fragment in hand swaps
// places with every kept one farther than it, so the slots stay sorted
// (fragments at one depth in no set order, as they arrive in none) and what is
// left in hand is the farthest of the K + 1 — the new fragment or one pushed
// out — bound for the tail.
void kb_insert(float z, uvec2 c) {
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        bool swap = i < kb_k && z < kb_depth[i];
        float kept_z = kb_depth[i];
        uvec2 kept_c = kb_color[i];
        kb_depth[i] = swap ? z : kept_z;
        kb_color[i] = swap ? c : kept_c;
        z = swap ? kept_z : z;
        c = swap ? kept_c : c;
    }
    // An empty slot's colour is zero: handed out, it adds nothing.
    vec4 out_c = unpack_color(c);
    kb_tail_sum += out_c.rgb * out_c.a;
    kb_tail_alpha += out_c.a;
    kb_tail_transmittance *= 1.0 - out_c.a;
}

// The pixel's hair: the K front to back, the tail behind them, as
// premultiplied colour and coverage.
vec4 kb_composite() {
    vec3 sum = vec3(0.0);
    float transmittance = 1.0;
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        vec4 c = unpack_color(kb_color[i]);
        sum += transmittance * c.a * c.rgb;
        transmittance *= 1.0 - c.a;
    }
    if (kb_tail_alpha > 0.0) {
        sum += transmittance * (1.0 - kb_tail_transmittance) * (kb_tail_sum / kb_tail_alpha);
        transmittance *= kb_tail_transmittance;
    }
    return vec4(sum, 1.0 - transmittance);
}

// The depth of the kept fragment at which the K, composited front to back,
// first reach an opacity of `threshold`: the hair a pixel's motion vector
// follows (render/draw/motion.rs). EMPTY when the K never reach it (the tail,
// unordered, is not searched).
float kb_crossing(float threshold) {
    float transmittance = 1.0;
    float depth = EMPTY;
    [[unroll]] for (uint i = 0u; i < SORT_CAPACITY; i++) {
        transmittance *= 1.0 - unpack_color(kb_color[i]).a;
        if (depth == EMPTY && 1.0 - transmittance >= threshold) {
            depth = kb_depth[i];
        }
    }
    return depth;
}

// Per pixel the depth its motion vector follows (kb_crossing), written when
// the frame writes motion vectors (render/draw/motion.rs).
layout(std430, set = 0, binding = 35) writeonly buffer MotionDepth { uint motion_depth[]; };

// Writes kb_crossing's depth for the frame's motion threshold (OitCounters'
// motion_threshold; nothing when it is 0: no motion vectors) for `pixel`.
void kb_write_motion_depth(uint pixel) {
    if (oit.motion_threshold > 0.0) {
        float crossing = kb_crossing(oit.motion_threshold);
        motion_depth[pixel] = crossing < EMPTY ? floatBitsToUint(crossing) : OIT_END;
    }
}

#endif
