#version 460
// Multigrid preconditioner: each fluid fine cell adds its coarse parent's
// correction (piecewise-constant interpolation, the transpose of the restriction
// up to its factor, which keeps the preconditioner symmetric).
//   dims: fine level;  coarse: coarse level (w their first cells).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 23) buffer X { float x[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = pc.dims.xyz;
    if (c >= dims.x * dims.y * dims.z) {
        return;
    }
    uint i = pc.dims.w + c;
    if (labels[i] != VOL_FLUID) {
        return;
    }
    uvec3 parent = vol_cell_coords(c, dims) / 2u;
    precise float value = x[i] + x[pc.coarse.w + vol_cell_index(parent, pc.coarse.xyz)];
    x[i] = value;
}
