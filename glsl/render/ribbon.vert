#version 460
// Draw pass, vertex stage of ribbons (no vertex buffer, no geometry stage):
// vertex 4s + c of instance i is corner c of segment RIBBON_CHUNK × i + s of
// the interpolated hairs (hair-major; corners 1 and 2 shared by the segment's
// two triangles, render/draw/ribbons.rs), a camera-facing ribbon of
// mix(root width, tip width) world units, at least `least width` pixels wide.
// Each vertex reads both ends of its segment (for the ribbon's direction) and
// places its corner.
//
// Transparent strands (the VKHAIR_COVERAGE variant, drawn with dp.coverage.x = 1) have no
// least width: their ribbon is at least one pixel wide plus half a pixel each
// side, and g_cover carries the signed distance from the centre line, the
// true half width, in pixels, and the band's density, from which the fragment
// stage computes the strand's coverage. A transparent strand standing for n
// hairs (dp.coverage.z) is a band n hair widths wide, or (1 − 1/n) of the
// spacing of the drawn strands there (dp.band) where that is wider, up to
// BAND_MAX_SPREAD × n hair widths, so that neighbouring bands meet as the hairs
// they stand for would (one hair stays one hair); its density is
// the fraction of it n hairs of width w at random across it cover,
// 1 − (1 − w / band)^n. Its vertices carry the colour shade_points.comp gave
// each end of the segment (g_color), not the inputs of per-fragment shading.
//
// vkhair variant: VKHAIR_COVERAGE
#include "render.glsl"

layout(std140, set = 0, binding = 0) uniform Draw { DrawParams dp; };
layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };

// The depth pre-pass and the shading draw must rasterize the same depths: the
// same module in both pipelines, and no fused multiply-adds that a compiler
// could choose differently in each.
precise gl_Position;

#ifdef VKHAIR_COVERAGE
// Per hair vertex: its shaded colour (shade_points.comp).
layout(std430, set = 0, binding = 20) readonly buffer PointColor { vec4 point_color[]; };
layout(location = 0) out vec3 g_color;
layout(location = 1) out vec3 g_cover;
#else
layout(location = 0) out vec3 g_pos;
layout(location = 1) out vec3 g_tan;
layout(location = 2) out float g_t;
layout(location = 3) flat out uint g_hair;
#endif

void main() {
    uint per_hair = dp.counts.y;
    uint segs = per_hair - 1u;
    // Corner c = 2 × end + side: the end of the segment (0 the first, 1 the
    // second) and the side of its centre line (0 −, 1 +).
    uint corner = uint(gl_VertexIndex) & 3u;
    uint seg = uint(gl_InstanceIndex) * RIBBON_CHUNK + uint(gl_VertexIndex) / 4u;
    uint hair = seg / segs;
    uint first = hair * per_hair + (seg - hair * segs);
    uint e = corner >> 1u;
    vec3 p0 = hair_pos[first].xyz;
    vec3 p1 = hair_pos[first + 1u].xyz;
    vec3 pos = e == 0u ? p0 : p1;
    vec4 tan_t = hair_tan[first + e];
    vec3 along = p1 - p0;
    float len = length(along);
    vec3 dir = len > 0.0 ? along / len : hair_tan[first].xyz;
    vec3 to_camera = dp.camera.xyz - pos;
    float distance_to_camera = length(to_camera);
    vec3 side = cross(dir, to_camera);
    float side_len = length(side);
    side = side_len > 1e-12 ? side / side_len : vec3(1.0, 0.0, 0.0);
    // A hair's own width factor rides in its positions' w (1 for grown hairs).
    float width = mix(dp.widths.x, dp.widths.y, tan_t.w) * (e == 0u ? hair_pos[first].w : hair_pos[first + 1u].w);
#ifdef VKHAIR_COVERAGE
    // A transparent strand standing for n hairs: its band (reference::strand_band).
    float pixel = max(dp.camera.w * distance_to_camera, 1e-12);
    vec3 band = coverage_band(width, dp.coverage.z, mix(dp.band.x, dp.band.y, tan_t.w), pixel);
    float half_drawn = band.x;
#else
    float half_drawn = 0.5 * max(width, dp.widths.z * dp.camera.w * distance_to_camera);
#endif
    float s = (corner & 1u) != 0u ? 1.0 : -1.0;
    vec3 corner_pos = pos + side * (half_drawn * s);
#ifdef VKHAIR_COVERAGE
    g_color = point_color[first + e].rgb;
    g_cover = vec3(half_drawn / pixel * s, band.y, band.z);
#else
    g_pos = corner_pos;
    g_tan = tan_t.xyz;
    g_t = tan_t.w;
    g_hair = hair;
#endif
    gl_Position = dp.view_proj * vec4(corner_pos, 1.0);
}
