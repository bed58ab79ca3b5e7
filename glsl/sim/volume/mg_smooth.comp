#version 460
// Multigrid preconditioner: one damped Jacobi sweep (ω = 2/3) on one level,
// x ← x + ω (rhs − A x) / diag, non-fluid cells 0.
//   dims: the level (w its first cell);
//   op.x = 0: from x = 0 into tmp;  1: tmp → x;  2: x → tmp.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) buffer X { float x[]; };
layout(std430, set = 0, binding = 24) buffer Tmp { float tmp[]; };
layout(std430, set = 0, binding = 25) readonly buffer Rhs { float rhs[]; };

const float OMEGA = 2.0 / 3.0;

float read_source(uint i) {
    return pc.op.x == 0u ? 0.0 : (pc.op.x == 1u ? tmp[i] : x[i]);
}

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = pc.dims.xyz;
    if (c >= dims.x * dims.y * dims.z) {
        return;
    }
    uint i = pc.dims.w + c;
    precise float value = 0.0;
    if (labels[i] == VOL_FLUID) {
        int fluid[6];
        float diagonal = vol_stencil(vol_cell_coords(c, dims), dims, pc.dims.w, fluid);
        float own = read_source(i);
        precise float ax = diagonal * own;
        for (uint n = 0u; n < 6u; ++n) {
            if (fluid[n] >= 0) {
                ax -= read_source(uint(fluid[n]));
            }
        }
        value = diagonal > 0.0 ? own + OMEGA * (rhs[i] - ax) / diagonal : 0.0;
    }
    if (pc.op.x == 1u) {
        x[i] = value;
    } else {
        tmp[i] = value;
    }
}
