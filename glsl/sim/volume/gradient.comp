#version 460
// Volume stage, after the pressure solve: subtract the pressure difference
// across every face between a fluid cell and a non-solid neighbour (outside the
// grid counts as air at p = 0). Skipped entirely when the solve produced
// non-finite numbers, so that no NaN reaches the particles.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 17) buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 20) readonly buffer Pressure { float pressure[]; };
layout(std430, set = 0, binding = 26) readonly buffer Scalars { PcgScalars scalars; };

void main() {
    uint f = gl_GlobalInvocationID.x;
    if (f >= vol_faces(vp) || scalars.status == VOL_STATUS_NONFINITE) {
        return;
    }
    uvec3 dims = vol_dims(vp);
    uint axis = vol_face_axis(f, vol_first_v_face(vp), vol_first_w_face(vp));
    uint base = axis == 0u ? 0u : (axis == 1u ? vol_first_v_face(vp) : vol_first_w_face(vp));
    uvec3 ijk = vol_cell_coords(f - base, vol_face_dims(dims, axis));
    uint below_label = VOL_AIR;
    uint above_label = VOL_AIR;
    float below_p = 0.0;
    float above_p = 0.0;
    if (ijk[axis] > 0u) {
        uvec3 below = ijk;
        below[axis] -= 1u;
        uint c = vol_cell_index(below, dims);
        below_label = labels[c];
        below_p = below_label == VOL_FLUID ? pressure[c] : 0.0;
    }
    if (ijk[axis] < dims[axis]) {
        uint c = vol_cell_index(ijk, dims);
        above_label = labels[c];
        above_p = above_label == VOL_FLUID ? pressure[c] : 0.0;
    }
    bool fluid = below_label == VOL_FLUID || above_label == VOL_FLUID;
    bool solid = below_label == VOL_SOLID || above_label == VOL_SOLID;
    if (fluid && !solid) {
        precise float u = face_vel[f] - (above_p - below_p);
        face_vel[f] = u;
    }
}
