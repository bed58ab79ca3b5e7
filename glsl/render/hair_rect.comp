#version 460
// Transparent modes, after the vertex shading: the rectangle of pixels the
// ribbons can reach (oit_counters.glsl), where the composite then runs instead
// of over the whole target. Every corner of a ribbon lies in the cube of half
// side its drawn half width around its vertex (coverage_band, as ribbon.vert),
// so the projected cubes, two pixels wider, hold every ribbon pixel; a cube
// reaching behind the camera takes the whole target.
#include "render.glsl"
#include "oit_counters.glsl"

layout(local_size_x = 64) in;

layout(std140, set = 0, binding = 0) uniform Draw { DrawParams dp; };
layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };

// The workgroup's rectangle: x0, y0, x1, y1 (as OitCounters).
shared uint group_rect[4];

// The pixels (x0, y0, x1, y1; ends exclusive) the ribbons at a vertex at p with
// drawn half width h (m) can reach.
uvec4 vertex_rect(vec3 p, float h) {
    vec4 centre = dp.view_proj * vec4(p, 1.0);
    vec4 ax = dp.view_proj[0] * h;
    vec4 ay = dp.view_proj[1] * h;
    vec4 az = dp.view_proj[2] * h;
    vec2 lo = vec2(1e30);
    vec2 hi = vec2(-1e30);
    // A corner behind the camera (or not a number): the projection is unbounded.
    bool unbounded = false;
    for (int k = 0; k < 8; ++k) {
        vec4 q = centre + ((k & 1) != 0 ? ax : -ax) + ((k & 2) != 0 ? ay : -ay) + ((k & 4) != 0 ? az : -az);
        vec2 ndc = q.xy / q.w;
        unbounded = unbounded || !(q.w > 0.0) || !all(lessThan(abs(ndc), vec2(1e30)));
        lo = min(lo, ndc);
        hi = max(hi, ndc);
    }
    vec2 size = vec2(oit.width, oit.height);
    vec2 a = clamp(floor((lo * 0.5 + 0.5) * size) - 2.0, vec2(0.0), size);
    vec2 b = clamp(ceil((hi * 0.5 + 0.5) * size) + 2.0, vec2(0.0), size);
    return unbounded ? uvec4(0u, 0u, oit.width, oit.height) : uvec4(uvec2(a), uvec2(b));
}

// A grid-stride loop: the dispatch stays within the 65,535 workgroups every
// device offers however many vertices there are.
void main() {
    if (gl_LocalInvocationIndex == 0u) {
        group_rect[0] = 0xffffffffu;
        group_rect[1] = 0xffffffffu;
        group_rect[2] = 0u;
        group_rect[3] = 0u;
    }
    uint total = dp.counts.x * dp.counts.y;
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    uvec4 rect = uvec4(0xffffffffu, 0xffffffffu, 0u, 0u);
    for (uint i = gl_GlobalInvocationID.x; i < total; i += stride) {
        vec4 pos = hair_pos[i];
        float t = hair_tan[i].w;
        // The ribbon's drawn half width here, as ribbon.vert's coverage variant.
        float pixel = max(dp.camera.w * length(dp.camera.xyz - pos.xyz), 1e-12);
        float hair_width = mix(dp.widths.x, dp.widths.y, t) * pos.w;
        float h = coverage_band(hair_width, dp.coverage.z, mix(dp.band.x, dp.band.y, t), pixel).x;
        uvec4 r = vertex_rect(pos.xyz, h);
        rect = uvec4(min(rect.xy, r.xy), max(rect.zw, r.zw));
    }
    barrier();
    atomicMin(group_rect[0], rect.x);
    atomicMin(group_rect[1], rect.y);
    atomicMax(group_rect[2], rect.z);
    atomicMax(group_rect[3], rect.w);
    barrier();
    if (gl_LocalInvocationIndex == 0u && group_rect[0] < group_rect[2]) {
        atomicMin(oit.hair_x0, group_rect[0]);
        atomicMin(oit.hair_y0, group_rect[1]);
        atomicMax(oit.hair_x1, group_rect[2]);
        atomicMax(oit.hair_y1, group_rect[3]);
    }
}
