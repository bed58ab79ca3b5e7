#version 460
// Interpolation pass, evaluation stage: vertex j of line h of key segment `seg`
// is smoothed key vertex k = seg·level + j offset in the key frame by
// clump_coordinate(key, h) · clump_width · mix(root_width, tip_width, t),
// t = k / (stride − 1). Stored like the smoothing pass: each vertex once.
#include "render.glsl"

layout(isolines, equal_spacing) in;
layout(push_constant) uniform Push { InterpolatePush pc; };
layout(std430, set = 0, binding = 0) readonly buffer SmoothPos { vec4 smooth_pos[]; };
layout(std430, set = 0, binding = 1) readonly buffer SmoothTan { vec4 smooth_tan[]; };
layout(std430, set = 0, binding = 2) readonly buffer Reference { vec4 reference[]; };
layout(std430, set = 0, binding = 3) writeonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 4) writeonly buffer HairTan { vec4 hair_tan[]; };

layout(location = 0) patch in uint p_patch;
layout(location = 1) patch in uint p_first_hair;
layout(location = 2) patch in uint p_lines;

void main() {
    uint segs = pc.points - 1u;
    uint key = p_patch / segs;
    uint seg = p_patch - key * segs;
    uint j = uint(gl_TessCoord.x * float(pc.level) + 0.5);
    uint h = isoline_hair(p_first_hair, gl_TessCoord.y, p_lines);
    if (j < pc.level || seg + 1u == segs) {
        uint k = seg * pc.level + j;
        uint src = key * pc.stride + k;
        vec3 p = smooth_pos[src].xyz;
        vec3 t = smooth_tan[src].xyz;
        vec3 b1;
        vec3 b2;
        key_frame(t, quat_rotate(pc.head_rotation, reference[key].xyz), b1, b2);
        vec2 c = clump_coordinate(key, h);
        float s = float(k) / float(pc.stride - 1u);
        float w = pc.clump_width * mix(pc.root_width, pc.tip_width, s);
        uint dst = (key * pc.hairs + h) * pc.stride + k;
        hair_pos[dst] = vec4(p + (c.x * b1 + c.y * b2) * w, 1.0);
        hair_tan[dst] = vec4(t, s);
    }
    gl_Position = vec4(0.0);
}
