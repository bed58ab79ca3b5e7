// The pressure matrix A of a grid level, for kernels that declare
//   layout(... binding = 16) buffer Labels { uint labels[]; };
// before including this file. Row of a fluid cell: the number of non-solid
// neighbours on the diagonal (outside the grid counts as air, p = 0), −1 for
// each fluid neighbour; solid neighbours drop out (Neumann boundary).
#ifndef VKHAIR_VOLUME_OPS_GLSL
#define VKHAIR_VOLUME_OPS_GLSL

#include "volume.glsl"

// Diagonal of cell `ijk` of the level at `offset` with `dims` cells; `fluid[n]`
// gets the level-array index of neighbour n when it is fluid, else −1.
float vol_stencil(uvec3 ijk, uvec3 dims, uint offset, out int fluid[6]) {
    float diagonal = 0.0;
    for (uint n = 0u; n < 6u; ++n) {
        int nb = vol_neighbor(ijk, dims, n);
        uint label = nb < 0 ? VOL_AIR : labels[offset + uint(nb)];
        fluid[n] = label == VOL_FLUID ? int(offset) + nb : -1;
        diagonal += label == VOL_SOLID ? 0.0 : 1.0;
    }
    return diagonal;
}

#endif
