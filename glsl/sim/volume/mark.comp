#version 460
// Volume stage, after the transfer: an air cell all of whose six faces carry
// particle weight becomes fluid too. Key-hair particles are sparse (a few
// centimetres apart along a strand), so cells between them would otherwise be
// air at p = 0 inside the hair and let it collapse; every face of such a cell
// holds a measured velocity, so its divergence is meaningful.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 16) buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 19) readonly buffer FaceWeight { float face_weight[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= vol_cells(vp) || labels[c] != VOL_AIR) {
        return;
    }
    uvec3 dims = vol_dims(vp);
    uvec3 ijk = vol_cell_coords(c, dims);
    bool covered = true;
    for (uint axis = 0u; axis < 3u; ++axis) {
        uvec3 up = ijk;
        up[axis] += 1u;
        covered = covered && face_weight[vol_face_index(ijk, axis, dims, vol_first_v_face(vp), vol_first_w_face(vp))] > 0.0
            && face_weight[vol_face_index(up, axis, dims, vol_first_v_face(vp), vol_first_w_face(vp))] > 0.0;
    }
    if (covered) {
        labels[c] = VOL_FLUID;
    }
}
