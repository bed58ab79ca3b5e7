// Order-independent transparency of hair (render/oit.rs): the per-pixel lists
// of the exact mode and the nearest opaque-enough depth both modes keep.
#ifndef VKHAIR_OIT_GLSL
#define VKHAIR_OIT_GLSL

#include "oit_opaque.glsl"
// Per pixel: the newest node of its list (exact mode), OIT_END for none.
layout(std430, set = 0, binding = 10) buffer OitHeads { uint oit_heads[]; };
// The node pool, split over up to eight buffers (one binding's range is
// limited: 128 MiB on some drivers); node n is entry n % pool_nodes of buffer
// n / pool_nodes. Unused bindings name buffer 0. Bindings: exact.rs POOL_BINDINGS.
// A node: rg, b + alpha (half floats), depth bits, next node.
layout(std430, set = 0, binding = 11) buffer OitNodes0 { uvec4 oit_nodes0[]; };
layout(std430, set = 0, binding = 13) buffer OitNodes1 { uvec4 oit_nodes1[]; };
layout(std430, set = 0, binding = 14) buffer OitNodes2 { uvec4 oit_nodes2[]; };
layout(std430, set = 0, binding = 15) buffer OitNodes3 { uvec4 oit_nodes3[]; };
layout(std430, set = 0, binding = 16) buffer OitNodes4 { uvec4 oit_nodes4[]; };
layout(std430, set = 0, binding = 17) buffer OitNodes5 { uvec4 oit_nodes5[]; };
layout(std430, set = 0, binding = 18) buffer OitNodes6 { uvec4 oit_nodes6[]; };
layout(std430, set = 0, binding = 19) buffer OitNodes7 { uvec4 oit_nodes7[]; };

// Buffers the pool is split over (the pipeline's specialisation constant 0,
// set from the pool by exact.rs; 8, the most, by default). With one buffer the
// node index addresses it directly: no division, and no switch whose every
// case a CPU device would run.
layout(constant_id = 0) const uint OIT_POOL_BUFFERS = 8u;

uint oit_pixel(vec4 frag_coord) {
    return uint(frag_coord.y) * oit.width + uint(frag_coord.x);
}

void oit_store(uint node, uvec4 record) {
    if (OIT_POOL_BUFFERS == 1u) {
        oit_nodes0[node] = record;
        return;
    }
    uint i = node % oit.pool_nodes;
    switch (node / oit.pool_nodes) {
        case 0u: oit_nodes0[i] = record; break;
        case 1u: oit_nodes1[i] = record; break;
        case 2u: oit_nodes2[i] = record; break;
        case 3u: oit_nodes3[i] = record; break;
        case 4u: oit_nodes4[i] = record; break;
        case 5u: oit_nodes5[i] = record; break;
        case 6u: oit_nodes6[i] = record; break;
        default: oit_nodes7[i] = record; break;
    }
}

uvec4 oit_load(uint node) {
    if (OIT_POOL_BUFFERS == 1u) {
        return oit_nodes0[node];
    }
    uint i = node % oit.pool_nodes;
    switch (node / oit.pool_nodes) {
        case 0u: return oit_nodes0[i];
        case 1u: return oit_nodes1[i];
        case 2u: return oit_nodes2[i];
        case 3u: return oit_nodes3[i];
        case 4u: return oit_nodes4[i];
        case 5u: return oit_nodes5[i];
        case 6u: return oit_nodes6[i];
        default: return oit_nodes7[i];
    }
}

#endif
