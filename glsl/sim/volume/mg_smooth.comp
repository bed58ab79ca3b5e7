#version 460
// Multigrid preconditioner: damped Jacobi sweeps (ω = 2/3) on one level,
// x ← x + ω (rhs − A x) / diag, non-fluid cells 0. Three forms, so that the
// V-cycle needs no pass of its own for the first sweep or the prolongation:
//   mg_smooth_mode = 0 (pre):   two sweeps from x = 0 into x; the first sweep's values of
//                     the cell and its neighbours are recomputed where needed;
//   mg_smooth_mode = 1 (post):  one sweep from x plus the coarse parent's correction
//                     (piecewise-constant prolongation, the transpose of the
//                     restriction up to its factor) into tmp;
//   mg_smooth_mode = 2 (post):  one sweep tmp → x; with mg_smooth_partials = 1 (finest level, in
//                     conjugate gradients) also the per-workgroup partials
//                     (r·z, max |r|) of z = x and r = rhs.
//   mg_smooth_dims/first: the level;  mg_smooth_coarse_dims/first: the next coarser level.
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) buffer X { float x[]; };
layout(std430, set = 0, binding = 24) buffer Tmp { float tmp[]; };
layout(std430, set = 0, binding = 25) readonly buffer Rhs { float rhs[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };
#define VKHAIR_PRESSURE_LEVELS
#include "pressure_ops.glsl"

// The first sweep from x = 0 at cell j (A x is then exactly +0).
float first_sweep(uint j) {
    uint w = stencil[j];
    return vol_is_fluid(w) ? mg_sweep(j, w, 0.0, 0.0) : 0.0;
}

// x at fluid cell `ijk` (level-array index j) with its coarse parent's correction added.
float prolonged(uint j, uvec3 ijk) {
    uint parent = mg_smooth_coarse_first(pc) + vol_cell_index(ijk / 2u, mg_smooth_coarse_dims(pc));
    precise float value = x[j] + x[parent];
    return value;
}

float source(uint j, uvec3 ijk) {
    if (mg_smooth_mode(pc) == 0u) {
        return first_sweep(j);
    }
    return mg_smooth_mode(pc) == 1u ? prolonged(j, ijk) : tmp[j];
}

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = mg_smooth_dims(pc);
    bool live = c < dims.x * dims.y * dims.z;
    uint i = mg_smooth_first(pc) + c;
    precise float value = 0.0;
    uint w = live ? stencil[i] : 0u;
    if (vol_is_fluid(w)) {
        uvec3 ijk = mg_smooth_mode(pc) == 1u ? vol_cell_coords(c, dims) : uvec3(0u);
        float own = source(i, ijk);
        precise float ax = vol_diagonal(w) * own;
        for (uint n = 0u; n < 6u; ++n) {
            if (vol_has_fluid_neighbor(w, n)) {
                uvec3 nb = ijk;
                nb[n >> 1u] = (n & 1u) == 0u ? nb[n >> 1u] - 1u : nb[n >> 1u] + 1u;
                ax -= source(vol_neighbor_index(i, dims, n), nb);
            }
        }
        value = mg_sweep(i, w, own, ax);
    }
    if (live) {
        if (mg_smooth_mode(pc) == 1u) {
            tmp[i] = value;
        } else {
            x[i] = value;
        }
    }
    if (mg_smooth_partials(pc) == 1u) {
        vec2 local = live ? vec2(rhs[i] * value, abs(rhs[i])) : vec2(0.0);
        vec2 total = reduce_sum_max(local);
        if (gl_LocalInvocationIndex == 0u) {
            partials[gl_WorkGroupID.x] = total;
        }
    }
}
