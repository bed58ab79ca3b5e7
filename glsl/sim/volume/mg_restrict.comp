#version 460
// Multigrid preconditioner: the coarse right-hand side is half the sum of the
// fine residuals rhs − A x over a coarse cell's fluid children (the factor
// matches the coarse operator, which is the same stencil on cells twice as wide).
//   dims: fine level;  coarse: coarse level (w their first cells).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
layout(std430, set = 0, binding = 23) readonly buffer X { float x[]; };
layout(std430, set = 0, binding = 25) buffer Rhs { float rhs[]; };
#define VKHAIR_PRESSURE_LEVELS
#include "pressure_ops.glsl"

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 cd = level_coarse_dims(pc);
    if (c >= cd.x * cd.y * cd.z) {
        return;
    }
    uvec3 ijk = vol_cell_coords(c, cd);
    bool fluid = vol_is_fluid(stencil[level_coarse_first(pc) + c]);
    rhs[level_coarse_first(pc) + c] = fluid ? mg_restricted(ijk, level_first(pc), level_dims(pc)) : 0.0;
}
