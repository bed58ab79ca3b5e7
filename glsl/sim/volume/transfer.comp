#version 460
// Volume stage, step 5 — particle velocities to the MAC faces: each face
// gathers its component from the particles of the 2 × 3 × 3 cells within one
// cell of it, weighted trilinearly around the face (so each component works on
// a grid shifted by half a cell), and divides by the summed weight. A face next
// to a solid cell takes the colliders' velocity there instead. Both the current
// (later projected) and the saved pre-projection copy are written, with the
// summed weight.
#include "volume.glsl"

layout(local_size_x = 256) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 4) readonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 12) readonly buffer SortedPos { vec4 sorted_pos[]; };
layout(std430, set = 0, binding = 13) readonly buffer SortedVel { vec4 sorted_vel[]; };
layout(std430, set = 0, binding = 14) readonly buffer Start { uint start[]; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 17) writeonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 18) writeonly buffer FaceStar { float face_star[]; };
layout(std430, set = 0, binding = 19) writeonly buffer FaceWeight { float face_weight[]; };

void main() {
    uint f = gl_GlobalInvocationID.x;
    if (f >= vp.counts.w) {
        return;
    }
    uvec3 dims = vp.dims.xyz;
    uint n = vp.counts.x;
    uint axis = vol_face_axis(f, vp.counts);
    uint base = axis == 0u ? 0u : (axis == 1u ? vp.counts.y : vp.counts.z);
    uvec3 ijk = vol_cell_coords(f - base, vol_face_dims(dims, axis));
    vec3 x = vol_face_position(ijk, axis);
    ivec3 lo = ivec3(ijk) - 1;
    ivec3 hi = ivec3(ijk) + 1;
    hi[axis] -= 1;
    precise float sum = 0.0;
    precise float weight = 0.0;
    for (int k = lo.z; k <= hi.z; ++k) {
        for (int j = lo.y; j <= hi.y; ++j) {
            for (int i = lo.x; i <= hi.x; ++i) {
                ivec3 q = ivec3(i, j, k);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(dims)))) {
                    continue;
                }
                uint cell = vol_cell_index(uvec3(q), dims);
                for (uint s = start[cell]; s < n && keys_a[s] == cell; ++s) {
                    float w = vol_weight(sorted_pos[s].xyz - x);
                    weight += w;
                    sum += sorted_vel[s][axis] * w;
                }
            }
        }
    }
    precise float u = weight > 0.0 ? sum / weight : 0.0;
    bool solid = false;
    if (ijk[axis] > 0u) {
        uvec3 below = ijk;
        below[axis] -= 1u;
        solid = solid || labels[vol_cell_index(below, dims)] == VOL_SOLID;
    }
    if (ijk[axis] < dims[axis]) {
        solid = solid || labels[vol_cell_index(ijk, dims)] == VOL_SOLID;
    }
    if (solid) {
        u = vol_affine(vp.solid_velocity, x)[axis];
    }
    face_vel[f] = u;
    face_star[f] = u;
    face_weight[f] = weight;
}
