#version 460
// Multigrid preconditioner, coarsest level (at most 256 cells), one workgroup:
// op.z damped Jacobi sweeps (an even number) from x = 0 in shared memory.
//   dims: the level (w its first cell).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) writeonly buffer X { float x[]; };
layout(std430, set = 0, binding = 25) readonly buffer Rhs { float rhs[]; };

shared float values[2][VOL_GROUP];

const float OMEGA = 2.0 / 3.0;

void main() {
    uint c = gl_LocalInvocationID.x;
    uvec3 dims = pc.dims.xyz;
    bool live = c < dims.x * dims.y * dims.z;
    uint i = pc.dims.w + c;
    bool fluid_cell = live && labels[i] == VOL_FLUID;
    int fluid[6];
    float diagonal = 0.0;
    float b = 0.0;
    if (fluid_cell) {
        diagonal = vol_stencil(vol_cell_coords(c, dims), dims, pc.dims.w, fluid);
        b = rhs[i];
    }
    values[0][c] = 0.0;
    barrier();
    for (uint sweep = 0u; sweep < pc.op.z; ++sweep) {
        uint from = sweep & 1u;
        precise float value = 0.0;
        if (fluid_cell && diagonal > 0.0) {
            precise float ax = diagonal * values[from][c];
            for (uint n = 0u; n < 6u; ++n) {
                if (fluid[n] >= 0) {
                    ax -= values[from][uint(fluid[n]) - pc.dims.w];
                }
            }
            value = values[from][c] + OMEGA * (b - ax) / diagonal;
        }
        values[1u - from][c] = value;
        barrier();
    }
    if (live) {
        x[i] = values[pc.op.z & 1u][c];
    }
}
