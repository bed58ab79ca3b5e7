#version 460
// Mesh collider build, step 4 — one invocation per grid point: the exact
// distance to the point's triangle, negative behind it (by the mesh's
// overall winding, `sdf_pass_inward`) where the point lies
// within SDF_FACE_BAND_CELLS cells of the triangle's face (its closest point
// inside the face), elsewhere where at least two of the three axis rays vote
// inside.
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
    float side = 0.0;
    if (t != SDF_NONE) {
        vec3 p = sdf_point(sdf_grid_point(k, dims), sdf_pass_origin(pc), sdf_pass_cell(pc));
        vec3 a = corners[3u * t].xyz;
        vec3 b = corners[3u * t + 1u].xyz;
        vec3 c = corners[3u * t + 2u].xyz;
        d = sdf_triangle_distance(p, a, b, c);
        if (d < float(SDF_FACE_BAND_CELLS) * sdf_pass_cell(pc)) {
            side = sdf_face_side(p, a, b, c);
            side = sdf_pass_inward(pc) != 0u ? -side : side;
        }
    }
    bool inside = side != 0.0 ? side < 0.0 : votes[k] >= 2u;
    field[k] = inside ? -d : d;
}
