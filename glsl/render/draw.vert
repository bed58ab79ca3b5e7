#version 460
// Draw pass, vertex stage: no vertex buffer; vertices 2s and 2s+1 are the ends
// of segment s of the interpolated hairs (hair-major), read from storage.
#include "render.glsl"

layout(std140, set = 0, binding = 0) uniform Draw { DrawParams dp; };
layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };

// The depth pre-pass and the shading draw must rasterize the same depths: the
// same modules in both pipelines, and no fused multiply-adds that a compiler
// could choose differently in each.
precise gl_Position;

layout(location = 0) out vec3 v_pos;
layout(location = 1) out vec3 v_tan;
layout(location = 2) out float v_t;
layout(location = 3) flat out uint v_hair;

void main() {
    uint per_hair = dp.counts.y;
    uint segs = per_hair - 1u;
    uint seg = uint(gl_VertexIndex) / 2u;
    uint hair = seg / segs;
    uint k = seg - hair * segs + (uint(gl_VertexIndex) & 1u);
    uint index = hair * per_hair + k;
    v_pos = hair_pos[index].xyz;
    v_tan = hair_tan[index].xyz;
    v_t = hair_tan[index].w;
    v_hair = hair;
    gl_Position = dp.view_proj * vec4(v_pos, 1.0);
}
