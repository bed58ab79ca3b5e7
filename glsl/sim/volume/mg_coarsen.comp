#version 460
// Multigrid preconditioner, once per solve and level: the label of a coarse
// cell from its (up to) 8 children — fluid if any child is fluid, else air if
// any is air, else solid.
//   dims: fine level (w its first cell);  coarse: coarse level (w its first cell).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 16) buffer Labels { uint labels[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 cd = level_coarse_dims(pc);
    if (c >= cd.x * cd.y * cd.z) {
        return;
    }
    uvec3 ijk = vol_cell_coords(c, cd);
    bool fluid = false;
    bool air = false;
    for (uint k = 0u; k < 8u; ++k) {
        uvec3 child = ijk * 2u + uvec3(k & 1u, (k >> 1u) & 1u, k >> 2u);
        if (any(greaterThanEqual(child, level_dims(pc)))) {
            continue;
        }
        uint label = labels[level_first(pc) + vol_cell_index(child, level_dims(pc))];
        fluid = fluid || label == VOL_FLUID;
        air = air || label == VOL_AIR;
    }
    labels[level_coarse_first(pc) + c] = fluid ? VOL_FLUID : (air ? VOL_AIR : VOL_SOLID);
}
