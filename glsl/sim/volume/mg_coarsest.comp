#version 460
// Multigrid preconditioner, coarsest level (at most 256 cells), one workgroup:
// VOL_COARSEST_SWEEPS damped Jacobi sweeps from x = 0 in shared memory;
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
#define VKHAIR_PRESSURE_COARSEST
#include "pressure_ops.glsl"

void main() {
    uint c = gl_LocalInvocationID.x;
    uvec3 dims = mg_coarsest_dims(pc);
    bool live = c < dims.x * dims.y * dims.z;
    uint i = mg_coarsest_first(pc) + c;
    uint w = live ? stencil[i] : 0u;
    float result = mg_coarsest_solve(c, dims, w, vol_is_fluid(w) ? rhs[i] : 0.0);
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
