// What every transparency path keeps per pixel besides its fragments: the
// thresholds a fragment is kept and counted opaque by, the per-frame words
// (oit_counters.glsl), and the nearest half-opaque depth. The list paths
// include it through oit.glsl; the tiled rasteriser, which keeps no lists,
// on its own.
#ifndef VKHAIR_OIT_OPAQUE_GLSL
#define VKHAIR_OIT_OPAQUE_GLSL

// OIT_END, the end of a pixel's list and the "no opaque layer" depth word, is
// injected by build.rs from src/codes.rs.
// A fragment at least this opaque counts as the pixel's opaque layer: the
// nearest such depth is written to the target's depth image.
const float OIT_OPAQUE_ALPHA = 0.5;
// Fragments fainter than this are not stored (1/1024: below an 8-bit step).
const float OIT_LEAST_ALPHA = 1.0 / 1024.0;

#include "oit_counters.glsl"
// Per pixel: the nearest depth (float bits) of a fragment of alpha ≥ OIT_OPAQUE_ALPHA.
layout(std430, set = 0, binding = 12) buffer OitOpaque { uint oit_opaque[]; };

#endif
