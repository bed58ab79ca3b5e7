// One segment of the interpolated hairs as vkhair's compute rasterisers see
// it (strand_raster.comp, one invocation a segment; tile_bin.comp and
// tile_fine.comp, binned into screen tiles): clipped to the depth range
// (0 ≤ z ≤ w), projected, and the band around its centre line walked column by
// column along its longer screen axis. A pixel belongs to the segment when its
// centre projects onto the segment's screen span (half-open, so that
// consecutive segments of a hair share no pixel where they meet in a line) and
// lies within the band's reach; its coverage is analytic — the fraction of the
// pixel's width across the strand that the band's true width covers
// (strand_alpha, the hardware path's formula, no least width: a sub-pixel
// strand blends by coverage) times the material's opacity. Colour, band and
// density are interpolated perspective-correctly between the segment's shaded
// ends (shade_points.comp), depth linearly in screen space, as the hardware
// interpolates them. Every rasteriser takes its pixels and fragments from
// here, so they make the same fragments.
//
// The includer declares hair_pos, hair_tan (bindings 1, 2), point_color
// (binding 20; not where it defines STRAND_SEGMENT_NO_COLOR and reads no
// colour) and scene_depth (binding 25; not where it defines
// STRAND_SEGMENT_NO_DEPTH_TEST and tests no depth), and includes
// hair_shading.glsl (dp, strand_alpha) and oit_counters.glsl (oit).
#ifndef VKHAIR_STRAND_SEGMENT_GLSL
#define VKHAIR_STRAND_SEGMENT_GLSL

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
    // A transparent strand is its band of the hairs it stands for; an opaque
    // one (dp.coverage.x 0: the motion vectors of Transparency::Off) its ribbon.
    float hairs = dp.coverage.x > 0.5 ? dp.coverage.z : 1.0;
    vec3 band = coverage_band(width, hairs, mix(dp.band.x, dp.band.y, t), pixel);
    End e;
    e.clip = dp.view_proj * vec4(pos.xyz, 1.0);
#ifdef STRAND_SEGMENT_NO_COLOR
    e.color = vec3(0.0);
#else
    e.color = point_color[vertex].rgb;
#endif
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

// A segment on screen: its clipped ends' positions (pixels, rows from NDC
// y = −1) and forward depths, and what the walk over its band needs. k is the
// major (longer) axis, m the minor.
struct Segment {
    End e0;
    End e1;
    bool last;
    float u0;
    float u1;
    vec2 a;
    vec2 dir;
    float len;
    float za;
    float zb;
    float inv_wa;
    float inv_wb;
    bool x_major;
    vec2 a_km;
    float slope;
    // Minor-axis half extent of the band at a major coordinate.
    float spread;
    // The major coordinates walked: k_lo ≤ k < k_hi.
    float k_lo;
    float k_hi;
    // The target's size along the major and minor axes.
    vec2 size_km;
};

// Segment `first`..`first + 1` of a hair (`last` when it ends the hair) on
// screen; false when nothing of it can be drawn (clipped away, seen end on, or
// not a number).
bool segment_on_screen(uint first, bool last, out Segment sg) {
    sg.e0 = end_of(first);
    sg.e1 = end_of(first + 1u);
    sg.last = last;
    // Clip to 0 ≤ z ≤ w (the depth range the hardware clips to).
    float u0 = 0.0;
    float u1 = 1.0;
    clip_to(sg.e0.clip.z, sg.e1.clip.z, u0, u1);
    clip_to(sg.e0.clip.w - sg.e0.clip.z, sg.e1.clip.w - sg.e1.clip.z, u0, u1);
    sg.u0 = u0;
    sg.u1 = u1;
    if (!(u0 < u1)) {
        return false;
    }
    vec4 ca = mix(sg.e0.clip, sg.e1.clip, u0);
    vec4 cb = mix(sg.e0.clip, sg.e1.clip, u1);
    if (!(ca.w > 1e-12 && cb.w > 1e-12)) {
        return false;
    }
    vec2 size = vec2(float(oit.width), float(oit.height));
    sg.a = (ca.xy / ca.w * 0.5 + 0.5) * size;
    vec2 b = (cb.xy / cb.w * 0.5 + 0.5) * size;
    // Forward depths (oit_forward): the lists keep them so in either convention.
    sg.za = oit_forward(ca.z / ca.w);
    sg.zb = oit_forward(cb.z / cb.w);
    vec2 along = b - sg.a;
    sg.len = length(along);
    if (!(sg.len > 1e-4) || !(sg.len < 1e9)) {
        // Seen end on (the hardware ribbon has no area either) or not a number.
        return false;
    }
    sg.dir = along / sg.len;
    // The band reaches half its true width plus half a pixel from the centre line
    // (strand_alpha is zero beyond).
    float reach = max(half_width_at(sg.e0, sg.e1, u0), half_width_at(sg.e0, sg.e1, u1)) + 0.5;
    sg.x_major = abs(sg.dir.x) >= abs(sg.dir.y);
    sg.a_km = sg.x_major ? sg.a : sg.a.yx;
    vec2 b_km = sg.x_major ? b : b.yx;
    sg.size_km = sg.x_major ? size : size.yx;
    sg.slope = (b_km.y - sg.a_km.y) / (b_km.x - sg.a_km.x);
    sg.spread = reach / max(abs(sg.x_major ? sg.dir.x : sg.dir.y), 1e-6);
    sg.k_lo = max(floor(min(sg.a_km.x, b_km.x) - reach), 0.0);
    sg.k_hi = min(ceil(max(sg.a_km.x, b_km.x) + reach), sg.size_km.x);
    sg.inv_wa = 1.0 / ca.w;
    sg.inv_wb = 1.0 / cb.w;
    return true;
}

// The minor coordinates walked in major column k: m_lo ≤ m < m_hi (.x, .y).
vec2 segment_column(Segment sg, float k) {
    float centre_m = sg.a_km.y + (k + 0.5 - sg.a_km.x) * sg.slope;
    float m_lo = max(floor(centre_m - sg.spread - 0.5), 0.0);
    float m_hi = min(ceil(centre_m + sg.spread + 0.5), sg.size_km.y);
    return vec2(m_lo, m_hi);
}

// The pixel at major coordinate k and minor m (walked by segment_column).
uvec2 segment_pixel(Segment sg, float k, float m) {
    return sg.x_major ? uvec2(k, m) : uvec2(m, k);
}

// The fragment the segment makes at the pixel at column k, row m (of its
// walk): its forward depth, colour and coverage-weighted alpha; false where
// the pixel is not the segment's.
bool segment_fragment(Segment sg, float k, float m, out float z, out vec3 color, out float alpha) {
    vec2 q = sg.x_major ? vec2(k + 0.5, m + 0.5) : vec2(m + 0.5, k + 0.5);
    float s = dot(q - sg.a, sg.dir) / sg.len;
    z = 0.0;
    color = vec3(0.0);
    alpha = 0.0;
    if (s < 0.0 || s > 1.0 || (s == 1.0 && !sg.last)) {
        return false;
    }
    float d = dot(q - sg.a, vec2(-sg.dir.y, sg.dir.x));
    // Perspective-correct position along the unclipped segment.
    float inv_w = mix(sg.inv_wa, sg.inv_wb, s);
    float u = mix(sg.u0 * sg.inv_wa, sg.u1 * sg.inv_wb, s) / inv_w;
    float half_width = half_width_at(sg.e0, sg.e1, u);
    if (abs(d) >= half_width + 0.5) {
        return false;
    }
    alpha = strand_alpha(vec3(d, half_width, mix(sg.e0.density, sg.e1.density, u)));
    z = mix(sg.za, sg.zb, s);
    color = mix(sg.e0.color, sg.e1.color, u);
    return true;
}

// Segment `seg` of the frame's hairs (hair-major, dp.counts.y vertices a
// hair): its first vertex and whether it ends its hair.
uint segment_first(uint seg, out bool last) {
    uint segs = dp.counts.y - 1u;
    uint hair = seg / segs;
    uint within = seg - hair * segs;
    last = within + 1u == segs;
    return hair * dp.counts.y + within;
}

#ifndef STRAND_SEGMENT_NO_DEPTH_TEST
// The depth of a pixel of the target as the compute rasterisers test hair
// against it (forward, oit_forward): the host's depth copied into SceneDepth
// (binding 25, declared by the includer), encoded as oit.scene_depth says;
// beyond every fragment's when there is none.
float scene_depth_limit(uint pixel) {
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
#endif

#endif
