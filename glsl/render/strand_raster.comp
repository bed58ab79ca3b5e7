#version 460
// Exact transparency, build by the compute rasteriser (render/draw/raster.rs,
// Raster::Compute), in place of the ribbons' hardware draw and
// oit_build.frag: one invocation a segment of the interpolated hairs
// (hair-major, as the ribbons), in a grid-stride loop.
//
// A segment is clipped to the depth range (0 ≤ z ≤ w), projected, and its
// band walked pixel by pixel: along its longer screen axis, column by column
// (or row by row), the pixels whose centres lie within the band's reach of the
// centre line. A pixel belongs to the segment when its centre projects onto the
// segment's screen span (the span half-open, so that consecutive segments of a
// hair share no pixel where they meet in a line). Its coverage is analytic:
// the fraction of the pixel's width across the strand that the band's true
// width covers (strand_alpha, the hardware path's formula, with the band's
// true half width and density at the pixel — no least width: a sub-pixel
// strand blends by coverage), times the material's opacity. Colour, band and
// density are interpolated perspective-correctly between the segment's
// shaded ends (shade_points.comp), depth linearly in screen space, as the
// hardware interpolates them.
//
// Each fragment is depth-tested (LESS_OR_EQUAL, as the hardware path) against
// the host's depth copied into SceneDepth, then stored as oit_build.frag
// stores: pushed onto its pixel's list, or, beyond the pool, added to the
// fixed-point overflow sums (oit_overflow.glsl); a fragment at least half
// opaque lowers the pixel's nearest opaque depth. A segment walks its pixels
// twice — counting the fragments it keeps, then storing them into the nodes
// one atomic took for all of them — so the pool's counter takes an atomic a
// segment, not a fragment (README, "Raster").
// Constant 0 is the pool's buffer count (oit.glsl); constant 1 the shading
// features (this stage shades nothing: strand_alpha only).
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit.glsl"
#include "oit_overflow.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
// Per hair vertex: its shaded colour (shade_points.comp).
layout(std430, set = 0, binding = 20) readonly buffer PointColor { vec4 point_color[]; };
// The target's depth, one pixel after another from the top row
// (oit.scene_depth says how it is encoded; unread for SCENE_DEPTH_NONE).
layout(std430, set = 0, binding = 25) readonly buffer SceneDepth { uint scene_depth[]; };

// The forward depth (oit_forward) a fragment at `pixel` must not exceed to be drawn.
float depth_limit(uint pixel) {
    if (oit.scene_depth == SCENE_DEPTH_FLOAT32) {
        return oit_forward(uintBitsToFloat(scene_depth[pixel]));
    }
    if (oit.scene_depth == SCENE_DEPTH_UNORM24) {
        return oit_forward(float(scene_depth[pixel] & 0xFFFFFFu) / 16777215.0);
    }
    if (oit.scene_depth == SCENE_DEPTH_UNORM16) {
        return oit_forward(float((scene_depth[pixel >> 1u] >> (16u * (pixel & 1u))) & 0xFFFFu) / 65535.0);
    }
    return 3.0e38;
}

// Whether a fragment of coverage-weighted `alpha` at depth `z` is stored.
bool kept(uint pixel, float z, float alpha) {
    return alpha >= OIT_LEAST_ALPHA && z <= depth_limit(pixel);
}

// One kept fragment of coverage-weighted `alpha`, colour `color` at depth
// `z`, into pool node `node` (the segment's nodes were taken at once).
void store(uint pixel, float z, vec3 color, float alpha, uint node) {
    if (alpha >= OIT_OPAQUE_ALPHA) {
        atomicMin(oit_opaque[pixel], floatBitsToUint(z));
    }
    if (node >= oit.capacity) {
        oit_overflow_add(pixel, color, alpha);
        return;
    }
    uint next = atomicExchange(oit_heads[pixel], node);
    oit_store(node, uvec4(packHalf2x16(color.rg), packHalf2x16(vec2(color.b, alpha)), floatBitsToUint(z), next));
}

// One end of a segment: its clip position, shaded colour, and its band's half
// true width (m) and density (coverage_band, as ribbon.vert).
struct End {
    vec4 clip;
    vec3 color;
    float half_width;
    float density;
};

End end_of(uint vertex) {
    vec4 pos = hair_pos[vertex];
    float t = hair_tan[vertex].w;
    float pixel = max(dp.camera.w * length(dp.camera.xyz - pos.xyz), 1e-12);
    float width = mix(dp.widths.x, dp.widths.y, t) * pos.w;
    vec3 band = coverage_band(width, dp.coverage.z, mix(dp.band.x, dp.band.y, t), pixel);
    End e;
    e.clip = dp.view_proj * vec4(pos.xyz, 1.0);
    e.color = point_color[vertex].rgb;
    e.half_width = band.y * pixel;
    e.density = band.z;
    return e;
}

// Half the band's true width in pixels at u along the segment: its world half
// width over the size of a pixel at that depth (clip w, the view depth of a
// perspective projection), as the band projects — as wide on screen as the
// hardware's ribbon and the reference's quad.
float half_width_at(End e0, End e1, float u) {
    return mix(e0.half_width, e1.half_width, u) / (dp.camera.w * mix(e0.clip.w, e1.clip.w, u));
}

// Narrows [u0, u1] to where mix(a, b, u) ≥ 0 (empty: u0 ≥ u1).
void clip_to(float a, float b, inout float u0, inout float u1) {
    if (a < 0.0 && b < 0.0) {
        u1 = -1.0;
    } else if (a < 0.0) {
        u0 = max(u0, a / (a - b));
    } else if (b < 0.0) {
        u1 = min(u1, a / (a - b));
    }
}

void raster_segment(End e0, End e1, bool last) {
    // Clip to 0 ≤ z ≤ w (the depth range the hardware clips to).
    float u0 = 0.0;
    float u1 = 1.0;
    clip_to(e0.clip.z, e1.clip.z, u0, u1);
    clip_to(e0.clip.w - e0.clip.z, e1.clip.w - e1.clip.z, u0, u1);
    if (!(u0 < u1)) {
        return;
    }
    vec4 ca = mix(e0.clip, e1.clip, u0);
    vec4 cb = mix(e0.clip, e1.clip, u1);
    if (!(ca.w > 1e-12 && cb.w > 1e-12)) {
        return;
    }
    vec2 size = vec2(float(oit.width), float(oit.height));
    // Screen positions (pixels, rows from NDC y = −1) and depths of the clipped ends.
    vec2 a = (ca.xy / ca.w * 0.5 + 0.5) * size;
    vec2 b = (cb.xy / cb.w * 0.5 + 0.5) * size;
    // Forward depths (oit_forward): the lists keep them so in either convention.
    float za = oit_forward(ca.z / ca.w);
    float zb = oit_forward(cb.z / cb.w);
    vec2 along = b - a;
    float len = length(along);
    if (!(len > 1e-4) || !(len < 1e9)) {
        // Seen end on (the hardware ribbon has no area either) or not a number.
        return;
    }
    vec2 dir = along / len;
    vec2 normal = vec2(-dir.y, dir.x);
    // The band reaches half its true width plus half a pixel from the centre line
    // (strand_alpha is zero beyond).
    float reach = max(half_width_at(e0, e1, u0), half_width_at(e0, e1, u1)) + 0.5;
    // Walk the longer axis: k the major coordinate, m the minor.
    bool x_major = abs(dir.x) >= abs(dir.y);
    vec2 a_km = x_major ? a : a.yx;
    vec2 b_km = x_major ? b : b.yx;
    vec2 size_km = x_major ? size : size.yx;
    float slope = (b_km.y - a_km.y) / (b_km.x - a_km.x);
    // Minor-axis half extent of the band at a major coordinate.
    float spread = reach / max(abs(x_major ? dir.x : dir.y), 1e-6);
    float k_lo = max(floor(min(a_km.x, b_km.x) - reach), 0.0);
    float k_hi = min(ceil(max(a_km.x, b_km.x) + reach), size_km.x);
    float inv_wa = 1.0 / ca.w;
    float inv_wb = 1.0 / cb.w;
    // Two walks over the same pixels: the first counts the fragments kept,
    // then one atomic takes that many nodes of the pool, and the second
    // stores them — one atomic on the pool's counter a segment, not a
    // fragment.
    // The second walk never stores more than the first counted (should a
    // driver evaluate the two walks' arithmetic differently, a node is left
    // unused rather than one of another segment's taken).
    uint count = 0u;
    uint base = 0u;
    uint taken = 0u;
    for (uint walk = 0u; walk < 2u; ++walk) {
        if (walk == 1u) {
            if (count == 0u) {
                return;
            }
            taken = count;
            base = atomicAdd(oit.used, taken);
            count = 0u;
        }
        for (float k = k_lo; k < k_hi; k += 1.0) {
            float centre_m = a_km.y + (k + 0.5 - a_km.x) * slope;
            float m_lo = max(floor(centre_m - spread - 0.5), 0.0);
            float m_hi = min(ceil(centre_m + spread + 0.5), size_km.y);
            for (float m = m_lo; m < m_hi; m += 1.0) {
                vec2 q = x_major ? vec2(k + 0.5, m + 0.5) : vec2(m + 0.5, k + 0.5);
                float s = dot(q - a, dir) / len;
                if (s < 0.0 || s > 1.0 || (s == 1.0 && !last)) {
                    continue;
                }
                float d = dot(q - a, normal);
                // Perspective-correct position along the unclipped segment.
                float inv_w = mix(inv_wa, inv_wb, s);
                float u = mix(u0 * inv_wa, u1 * inv_wb, s) / inv_w;
                float half_width = half_width_at(e0, e1, u);
                if (abs(d) >= half_width + 0.5) {
                    continue;
                }
                float alpha = strand_alpha(vec3(d, half_width, mix(e0.density, e1.density, u)));
                float z = mix(za, zb, s);
                uint pixel = uint(q.y) * oit.width + uint(q.x);
                if (!kept(pixel, z, alpha)) {
                    continue;
                }
                if (walk == 1u) {
                    if (count == taken) {
                        return;
                    }
                    store(pixel, z, mix(e0.color, e1.color, u), alpha, base + count);
                }
                count++;
            }
        }
    }
}

void main() {
    uint per_hair = dp.counts.y;
    if (per_hair < 2u) {
        return;
    }
    uint segs = per_hair - 1u;
    uint total = dp.counts.x * segs;
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint seg = gl_GlobalInvocationID.x; seg < total; seg += stride) {
        uint hair = seg / segs;
        uint within = seg - hair * segs;
        uint first = hair * per_hair + within;
        raster_segment(end_of(first), end_of(first + 1u), within + 1u == segs);
    }
}
