#version 460
// Exact transparency after the compute rasteriser, the resolve in compute
// (render/draw/transparent/): one invocation per pixel of the rectangle the
// hair reaches (OitCounters' hair_*; the dispatch covers the target, the rest
// return at once) resolves its list (oit_resolve.glsl) into `oit_resolved`
// as premultiplied colour and coverage in four half floats, coverage 0 for a
// pixel without hair; oit_resolved.frag then blends it over the host's target.
// The lists are walked by every unit of the GPU, not by its graphics stages.
// vkhair variant: VKHAIR_SORT_4
// vkhair variant: VKHAIR_SORT_8
// vkhair variant: VKHAIR_SORT_16
#define VKHAIR_OVERFLOW_BUFFER
#include "oit_resolve.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// Per pixel (rows from NDC y = −1, as the lists): rg and ba as half floats.
layout(std430, set = 0, binding = 28) writeonly buffer OitResolved { uvec2 oit_resolved[]; };

void main() {
    uvec2 at = gl_GlobalInvocationID.xy;
    if (at.x < oit.hair_x0 || at.x >= oit.hair_x1 || at.y < oit.hair_y0 || at.y >= oit.hair_y1
        || at.x >= oit.width || at.y >= oit.height) {
        return;
    }
    uint pixel = at.y * oit.width + at.x;
    vec4 result;
    oit_resolve_pixel(pixel, ivec2(at), result);
    oit_resolved[pixel] = uvec2(packHalf2x16(result.rg), packHalf2x16(result.ba));
}
