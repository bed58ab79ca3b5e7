#version 460
// Smoothing pass, evaluation stage: evaluates the B-spline position and unit
// tangent at u = j / level and stores them. Each patch writes j = 0..level−1;
// the strand's last patch also writes j = level (the tip), so every smoothed
// vertex is written exactly once.
#include "render.glsl"

layout(isolines, equal_spacing) in;
layout(push_constant) uniform Push { SmoothPush pc; };
layout(std430, set = 0, binding = 1) writeonly buffer SmoothPos { vec4 smooth_pos[]; };
layout(std430, set = 0, binding = 2) writeonly buffer SmoothTan { vec4 smooth_tan[]; };

layout(location = 0) in vec3 c_pos[];
layout(location = 1) patch in uint p_patch;

void main() {
    uint segs = pc.points - 1u;
    uint strand = p_patch / segs;
    uint seg = p_patch - strand * segs;
    uint j = uint(gl_TessCoord.x * float(pc.level) + 0.5);
    float u = float(j) / float(pc.level);
    vec4 b;
    vec4 db;
    bspline_basis(u, b, db);
    vec3 p = b.x * c_pos[0] + b.y * c_pos[1] + b.z * c_pos[2] + b.w * c_pos[3];
    vec3 d = db.x * c_pos[0] + db.y * c_pos[1] + db.z * c_pos[2] + db.w * c_pos[3];
    float len = length(d);
    vec3 t = len > 0.0 ? d / len : vec3(0.0, -1.0, 0.0);
    if (j < pc.level || seg + 1u == segs) {
        uint out_index = strand * pc.stride + seg * pc.level + j;
        smooth_pos[out_index] = vec4(p, 1.0);
        smooth_tan[out_index] = vec4(t, 0.0);
    }
    gl_Position = vec4(0.0);
}
