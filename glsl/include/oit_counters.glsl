// The transparency passes' per-frame words (render/draw/transparent/), in a
// header of their own for the stages that use no list: hair_rect.comp finds
// the hair's rectangle, the composite's vertex stage (hair_rect.vert) draws
// it. Define OIT_COUNTERS_READONLY before including it in a stage that only
// reads them.
#ifndef VKHAIR_OIT_COUNTERS_GLSL
#define VKHAIR_OIT_COUNTERS_GLSL

#ifdef OIT_COUNTERS_READONLY
#define OIT_COUNTERS_ACCESS readonly
#else
#define OIT_COUNTERS_ACCESS
#endif

// Twin: gpu_types::OitCounters.
layout(std430, set = 0, binding = 9) OIT_COUNTERS_ACCESS buffer OitCounters {
    uint used;       // fragments offered this frame (stored = min(used, capacity))
    uint capacity;   // nodes in the pool
    uint width;      // pixels per row of the target
    uint sorted;     // K: fragments sorted exactly per pixel in the exact mode
    uint pool_nodes; // nodes per buffer of the pool
    uint height;     // pixel rows of the target
    // The pixels the frame's ribbons can reach: columns hair_x0..hair_x1 and
    // rows hair_y0..hair_y1 (ends exclusive), rows counted from NDC y = −1;
    // empty (x0 > x1) when no hair vertex was shaded.
    uint hair_x0;
    uint hair_y0;
    uint hair_x1;
    uint hair_y1;
    // How the compute rasteriser's copy of the target's depth is encoded
    // (SCENE_DEPTH_*; NONE: no depth test).
    uint scene_depth;
    // 1 when the target's depth is reversed (near = 1, `Camera::depth_reversed`).
    uint reverse_z;
    // The accumulated opacity at which a pixel's motion vector takes its hair
    // (render/draw/motion.rs); 0 when the frame writes none.
    float motion_threshold;
} oit;

// A depth of the target's convention as the lists keep it, forward (near 0,
// far 1), and back: the same map both ways. The lists, their sorting and the
// nearest opaque depth always run forward.
float oit_forward(float z) {
    return oit.reverse_z != 0u ? 1.0 - z : z;
}

#endif
