#version 460
// Mesh collider build, step 4 — one invocation per grid point: the exact
// distance to the point's triangle, negative where at least two of the three
// axis rays vote inside.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };
layout(std430, set = 0, binding = 2) readonly buffer Ids { uint ids[]; };
layout(std430, set = 0, binding = 4) readonly buffer Votes { uint votes[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Field { float field[]; };
layout(push_constant) uniform Push { SdfPush pc; };

void main() {
    uint k = gl_GlobalInvocationID.x;
    uvec3 dims = sdf_pass_dims(pc);
    if (k >= dims.x * dims.y * dims.z) {
        return;
    }
    uint t = ids[k];
    // Unreachable: the seeds cover the mesh and the floods reach every point.
    float d = 3.40282347e38;
    if (t != SDF_NONE) {
        vec3 p = sdf_point(sdf_grid_point(k, dims), sdf_pass_origin(pc), sdf_pass_cell(pc));
        d = sdf_triangle_distance(p, corners[3u * t].xyz, corners[3u * t + 1u].xyz, corners[3u * t + 2u].xyz);
    }
    field[k] = votes[k] >= 2u ? -d : d;
}
