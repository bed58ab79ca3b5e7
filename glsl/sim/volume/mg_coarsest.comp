#version 460
// Multigrid preconditioner, coarsest level (at most 256 cells), one workgroup:
// mg_coarsest_sweeps damped Jacobi sweeps (an even number) from x = 0 in shared memory;
// with mg_coarsest_partials = 1 (a grid of one level) also the partials (r·z, max |r|) of the
// conjugate gradients, as the finest level's last sweep gives them otherwise.
//   mg_coarsest_dims/first: the level.
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) writeonly buffer X { float x[]; };
layout(std430, set = 0, binding = 25) readonly buffer Rhs { float rhs[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };

shared float values[2][VOL_GROUP];

const float OMEGA = 2.0 / 3.0;

void main() {
    uint c = gl_LocalInvocationID.x;
    uvec3 dims = mg_coarsest_dims(pc);
    bool live = c < dims.x * dims.y * dims.z;
    uint i = mg_coarsest_first(pc) + c;
    uint w = live ? stencil[i] : 0u;
    bool fluid_cell = vol_is_fluid(w);
    float diagonal = vol_diagonal(w);
    float b = fluid_cell ? rhs[i] : 0.0;
    values[0][c] = 0.0;
    barrier();
    for (uint sweep = 0u; sweep < mg_coarsest_sweeps(pc); ++sweep) {
        uint from = sweep & 1u;
        precise float value = 0.0;
        if (fluid_cell && diagonal > 0.0) {
            precise float ax = diagonal * values[from][c];
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    ax -= values[from][vol_neighbor_index(c, dims, n)];
                }
            }
            value = values[from][c] + OMEGA * (b - ax) / diagonal;
        }
        values[1u - from][c] = value;
        barrier();
    }
    float result = values[mg_coarsest_sweeps(pc) & 1u][c];
    if (live) {
        x[i] = result;
    }
    if (mg_coarsest_partials(pc) == 1u) {
        vec2 total = reduce_sum_max(live ? vec2(rhs[i] * result, abs(rhs[i])) : vec2(0.0));
        if (gl_LocalInvocationIndex == 0u) {
            partials[0] = total;
        }
    }
}
