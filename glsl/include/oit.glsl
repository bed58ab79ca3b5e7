// Order-independent transparency of hair (render/oit.rs): the per-pixel lists
// of the exact mode and the nearest opaque-enough depth both modes keep.
#ifndef VKHAIR_OIT_GLSL
#define VKHAIR_OIT_GLSL

// OIT_END, the end of a pixel's list and the "no opaque layer" depth word, is
// injected by build.rs from src/codes.rs.
// A fragment at least this opaque counts as the pixel's opaque layer: the
// nearest such depth is written to the target's depth image.
const float OIT_OPAQUE_ALPHA = 0.5;
// Fragments fainter than this are not stored (1/1024: below an 8-bit step).
const float OIT_LEAST_ALPHA = 1.0 / 1024.0;

// Per-frame words. Twin: gpu_types::OitCounters.
layout(std430, set = 0, binding = 9) buffer OitCounters {
    uint used;       // fragments offered this frame (stored = min(used, capacity))
    uint capacity;   // nodes in the pool
    uint width;      // pixels per row of the lists' image
    uint sorted;     // K: fragments sorted exactly per pixel in the exact mode
} oit;
// Per pixel: the newest node of its list (exact mode), OIT_END for none.
layout(std430, set = 0, binding = 10) buffer OitHeads { uint oit_heads[]; };
// Nodes: rg, b + alpha (half floats), depth bits, next node.
layout(std430, set = 0, binding = 11) buffer OitNodes { uvec4 oit_nodes[]; };
// Per pixel: the nearest depth (float bits) of a fragment of alpha ≥ OIT_OPAQUE_ALPHA.
layout(std430, set = 0, binding = 12) buffer OitOpaque { uint oit_opaque[]; };

uint oit_pixel(vec4 frag_coord) {
    return uint(frag_coord.y) * oit.width + uint(frag_coord.x);
}

#endif
