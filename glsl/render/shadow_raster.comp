#version 460
// Deep opacity maps by the compute rasteriser (render/shadow/compute_maps.rs,
// Raster::Compute), in place of the hardware line passes: one invocation a
// segment of the interpolated hairs seen from light map `pc.map`, in a
// grid-stride loop. A segment is clipped to the map's depth range, projected
// into its atlas tile and walked as a one-texel line: along its longer axis,
// each texel column (or row) whose centre falls within the segment's span
// (half-open, so that the segments of a hair share no texel where they meet)
// takes the texel its centre line crosses there, weighted by the segment's
// length over the column (1 to √2 texels). The light-space depth is
// interpolated perspective-correctly (the map's clip w).
//
// The VKHAIR_SHADOW_Z0 variant (pass 1) keeps each texel's nearest depth; the
// other (pass 2) adds the strand's opacity (map params.x) times that weight
// to the layer its depth behind z0 falls in and to every layer behind it, as
// the hardware passes add a fragment's.
// vkhair variant: VKHAIR_SHADOW_Z0
#include "shadow.glsl"
#include "shadow_sums.glsl"

layout(local_size_x = 64) in;

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
// map: the map drawn; atlas_width: texels per row of the atlas.
layout(push_constant) uniform Push { uint map; uint atlas_width; } pc;

// One texel of a segment at light-space depth `depth`, standing for `weight`
// texels of the segment's length.
void texel(uint t, float depth, float weight, ShadowMap m) {
#ifdef VKHAIR_SHADOW_Z0
    atomicMin(shadow_z0[t], floatBitsToUint(max(depth, 0.0)));
#else
    float z0 = uintBitsToFloat(shadow_z0[t]);
    uint layer = shadow_layer_of(depth - z0, m.layers.xyz);
    uint add = uint(m.params.x * weight * SHADOW_OPACITY_UNIT + 0.5);
    for (uint k = layer; k < 3u; k++) {
        if (shadow_layers[3u * t + k] < SHADOW_SATURATED) {
            atomicAdd(shadow_layers[3u * t + k], add);
        }
    }
#endif
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

void raster_segment(vec3 p0, vec3 p1, ShadowMap m) {
    vec4 c0 = m.view_proj * vec4(p0, 1.0);
    vec4 c1 = m.view_proj * vec4(p1, 1.0);
    float u0 = 0.0;
    float u1 = 1.0;
    clip_to(c0.z, c1.z, u0, u1);
    clip_to(c0.w - c0.z, c1.w - c1.z, u0, u1);
    if (!(u0 < u1)) {
        return;
    }
    vec4 ca = mix(c0, c1, u0);
    vec4 cb = mix(c0, c1, u1);
    if (!(ca.w > 1e-12 && cb.w > 1e-12)) {
        return;
    }
    float d0 = dot(m.view_z.xyz, p0) + m.view_z.w;
    float d1 = dot(m.view_z.xyz, p1) + m.view_z.w;
    // Texel coordinates in the atlas (the tile's viewport).
    vec2 a = m.tile.xy + (ca.xy / ca.w * 0.5 + 0.5) * m.tile.zw;
    vec2 b = m.tile.xy + (cb.xy / cb.w * 0.5 + 0.5) * m.tile.zw;
    vec2 along = b - a;
    if (!all(lessThan(abs(along), vec2(1e9)))) {
        return;
    }
    bool x_major = abs(along.x) >= abs(along.y);
    float a_k = x_major ? a.x : a.y;
    float b_k = x_major ? b.x : b.y;
    float a_m = x_major ? a.y : a.x;
    float span = b_k - a_k;
    if (abs(span) < 1e-6) {
        return;
    }
    float slope = (x_major ? along.y : along.x) / span;
    // A texel a column stands for the segment's length over that column: up to
    // √2 texels on a diagonal, so that a strand adds opacity by its length
    // whatever its direction (as a one-texel-wide rectangle covers its texels).
    float weight = length(along) / abs(span);
    vec2 lo = m.tile.xy;
    vec2 hi = m.tile.xy + m.tile.zw;
    float k_lo = x_major ? lo.x : lo.y;
    float k_hi = x_major ? hi.x : hi.y;
    float m_lo = x_major ? lo.y : lo.x;
    float m_hi = x_major ? hi.y : hi.x;
    // Columns whose centre lies in [a_k, b_k) (or (b_k, a_k] walking back).
    float first = max(floor(min(a_k, b_k) - 0.5), k_lo);
    float last = min(ceil(max(a_k, b_k) + 0.5), k_hi);
    float inv_wa = 1.0 / ca.w;
    float inv_wb = 1.0 / cb.w;
    for (float k = first; k < last; k += 1.0) {
        float centre = k + 0.5;
        float s = (centre - a_k) / span;
        if (s < 0.0 || s >= 1.0) {
            continue;
        }
        float mm = floor(a_m + (centre - a_k) * slope);
        if (mm < m_lo || mm >= m_hi) {
            continue;
        }
        float inv_w = mix(inv_wa, inv_wb, s);
        float u = mix(u0 * inv_wa, u1 * inv_wb, s) / inv_w;
        vec2 t = x_major ? vec2(k, mm) : vec2(mm, k);
        texel(uint(t.y) * pc.atlas_width + uint(t.x), mix(d0, d1, u), weight, m);
    }
}

void main() {
    uint per_hair = sp.counts.y;
    if (per_hair < 2u) {
        return;
    }
    ShadowMap m = sp.maps[pc.map];
    uint segs = per_hair - 1u;
    uint total = sp.counts.x * segs;
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint seg = gl_GlobalInvocationID.x; seg < total; seg += stride) {
        uint hair = seg / segs;
        uint first = hair * per_hair + (seg - hair * segs);
        raster_segment(hair_pos[first].xyz, hair_pos[first + 1u].xyz, m);
    }
}
