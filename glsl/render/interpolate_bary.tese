#version 460
// Barycentric interpolation, evaluation stage: hair h of scalp triangle
// (a, b, c) blends the three key hairs' smoothed vertices with stable random
// barycentric weights (u, v, w), the same every frame.
#include "render.glsl"

layout(isolines, equal_spacing) in;
layout(push_constant) uniform Push { InterpolatePush pc; };
layout(std430, set = 0, binding = 0) readonly buffer SmoothPos { vec4 smooth_pos[]; };
layout(std430, set = 0, binding = 1) readonly buffer SmoothTan { vec4 smooth_tan[]; };
layout(std430, set = 0, binding = 3) writeonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 4) writeonly buffer HairTan { vec4 hair_tan[]; };
layout(std430, set = 0, binding = 5) readonly buffer Triangles { uvec4 triangles[]; };

layout(location = 0) patch in uint p_patch;
layout(location = 1) patch in uint p_first_hair;
layout(location = 2) patch in uint p_lines;

void main() {
    uint segs = pc.points - 1u;
    uint tri = p_patch / segs;
    uint seg = p_patch - tri * segs;
    uint j = uint(gl_TessCoord.x * float(pc.level) + 0.5);
    uint h = isoline_hair(p_first_hair, gl_TessCoord.y, p_lines);
    if (j < pc.level || seg + 1u == segs) {
        uint k = seg * pc.level + j;
        uvec3 keys = triangles[tri].xyz;
        vec3 w = barycentric_weights(tri, h);
        vec3 p = w.x * smooth_pos[keys.x * pc.stride + k].xyz + w.y * smooth_pos[keys.y * pc.stride + k].xyz
            + w.z * smooth_pos[keys.z * pc.stride + k].xyz;
        vec3 t = w.x * smooth_tan[keys.x * pc.stride + k].xyz + w.y * smooth_tan[keys.y * pc.stride + k].xyz
            + w.z * smooth_tan[keys.z * pc.stride + k].xyz;
        float len = length(t);
        uint dst = (tri * pc.hairs + h) * pc.stride + k;
        hair_pos[dst] = vec4(p, 1.0);
        hair_tan[dst] = vec4(len > 0.0 ? t / len : smooth_tan[keys.x * pc.stride + k].xyz, float(k) / float(pc.stride - 1u));
    }
    gl_Position = vec4(0.0);
}
