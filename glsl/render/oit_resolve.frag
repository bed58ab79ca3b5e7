#version 460
// Exact transparency, composite (over the rectangle the ribbons reach,
// hair_rect.vert): each pixel's list resolved (oit_resolve.glsl) and blended
// over the target as premultiplied colour; pixels without hair are discarded.
// The compute rasteriser's frames resolve in compute instead
// (oit_resolve.comp, then oit_resolved.frag).
// vkhair variant: VKHAIR_SORT_4
// vkhair variant: VKHAIR_SORT_8
// vkhair variant: VKHAIR_SORT_16
#include "oit_resolve.glsl"

layout(location = 0) out vec4 out_color;

void main() {
    vec4 result;
    if (!oit_resolve_pixel(oit_pixel(gl_FragCoord), ivec2(gl_FragCoord.xy), result)) {
        discard;
    }
    out_color = result;
}
