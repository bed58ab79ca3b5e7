// The pressure matrix A of a grid level, as stencil words written once per
// solve by mg_stencil.comp, for kernels that declare
//   layout(... binding = 30) buffer Stencil { uint stencil[]; };
// before including this file. Row of a fluid cell: the number of non-solid
// neighbours on the diagonal (outside the grid counts as air, p = 0), −1 for
// each fluid neighbour; solid neighbours drop out (Neumann boundary).
//
// Word of a cell: bit n (0..5: −x, +x, −y, +y, −z, +z) set when neighbour n is
// fluid, the diagonal in bits 8..10, VOL_STENCIL_FLUID when the cell itself is
// fluid; 0 for air and solid cells.
#ifndef VKHAIR_VOLUME_OPS_GLSL
#define VKHAIR_VOLUME_OPS_GLSL

#include "volume.glsl"

bool vol_is_fluid(uint word) {
    return (word & VOL_STENCIL_FLUID) != 0u;
}

bool vol_has_fluid_neighbor(uint word, uint n) {
    return (word & (1u << n)) != 0u;
}

// Diagonal of the row (an integer, exactly as a sum of ones).
float vol_diagonal(uint word) {
    return float((word >> VOL_STENCIL_COUNT_SHIFT) & 7u);
}

// Level-array index of neighbour n of the cell at level-array index i, on a
// level of `dims` cells; meaningful only where the neighbour exists.
uint vol_neighbor_index(uint i, uvec3 dims, uint n) {
    uint stride = n < 2u ? 1u : (n < 4u ? dims.x : dims.x * dims.y);
    return (n & 1u) == 0u ? i - stride : i + stride;
}

#endif
