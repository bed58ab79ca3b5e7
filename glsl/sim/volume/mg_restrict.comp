#version 460
// Multigrid preconditioner: the coarse right-hand side is half the sum of the
// fine residuals rhs − A x over a coarse cell's fluid children (the factor
// matches the coarse operator, which is the same stencil on cells twice as wide).
//   dims: fine level;  coarse: coarse level (w their first cells).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) readonly buffer X { float x[]; };
layout(std430, set = 0, binding = 25) buffer Rhs { float rhs[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 cd = level_coarse_dims(pc);
    if (c >= cd.x * cd.y * cd.z) {
        return;
    }
    uvec3 ijk = vol_cell_coords(c, cd);
    precise float sum = 0.0;
    if (vol_is_fluid(stencil[level_coarse_first(pc) + c])) {
        for (uint k = 0u; k < 8u; ++k) {
            uvec3 child = ijk * 2u + uvec3(k & 1u, (k >> 1u) & 1u, k >> 2u);
            if (any(greaterThanEqual(child, level_dims(pc)))) {
                continue;
            }
            uint i = level_first(pc) + vol_cell_index(child, level_dims(pc));
            uint w = stencil[i];
            if (!vol_is_fluid(w)) {
                continue;
            }
            precise float residual = rhs[i] - vol_diagonal(w) * x[i];
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    residual += x[vol_neighbor_index(i, level_dims(pc), n)];
                }
            }
            sum += residual;
        }
    }
    rhs[level_coarse_first(pc) + c] = 0.5 * sum;
}
