#version 460
// Mesh collider build, step 2 — one jump-flooding pass, one invocation per
// grid point: the point keeps the nearest of its own triangle and those of
// its 26 neighbours `step` points away (read from the previous pass only),
// each measured exactly; ties go to the lower triangle index.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };
layout(std430, set = 0, binding = 2) readonly buffer IdsIn { uint ids_in[]; };
layout(std430, set = 0, binding = 3) writeonly buffer IdsOut { uint ids_out[]; };
layout(push_constant) uniform Push { SdfPush pc; };

float distance_to(uint t, vec3 p) {
    return sdf_triangle_distance(p, corners[3u * t].xyz, corners[3u * t + 1u].xyz, corners[3u * t + 2u].xyz);
}

void main() {
    uint k = gl_GlobalInvocationID.x;
    uvec3 dims = sdf_pass_dims(pc);
    if (k >= dims.x * dims.y * dims.z) {
        return;
    }
    uvec3 g = sdf_grid_point(k, dims);
    vec3 p = sdf_point(g, sdf_pass_origin(pc), sdf_pass_cell(pc));
    uint best = ids_in[k];
    float best_d = best == SDF_NONE ? uintBitsToFloat(0x7f800000u) : distance_to(best, p);
    int step = int(sdf_pass_jump(pc));
    for (int dz = -1; dz <= 1; dz++) {
        for (int dy = -1; dy <= 1; dy++) {
            for (int dx = -1; dx <= 1; dx++) {
                ivec3 q = ivec3(g) + ivec3(dx, dy, dz) * step;
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(dims)))) {
                    continue;
                }
                uint t = ids_in[sdf_index(uvec3(q), dims)];
                if (t == SDF_NONE || t == best) {
                    continue;
                }
                float d = distance_to(t, p);
                if (d < best_d || (d == best_d && t < best)) {
                    best_d = d;
                    best = t;
                }
            }
        }
    }
    ids_out[k] = best;
}
