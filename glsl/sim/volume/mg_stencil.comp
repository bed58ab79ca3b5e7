#version 460
// Pressure solve, once per solve: the stencil word of every cell of every grid
// level (see volume_ops.glsl), so that the solver's kernels read one word per
// cell instead of the labels of six neighbours. Level l has ⌈dims / 2^l⌉ cells
// per axis and starts after the cells of the finer levels (GridLayout::placed).
// Coarse levels hold their labels only with the multigrid preconditioner; with
// the Jacobi preconditioner their words are written but never read.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 30) writeonly buffer Stencil { uint stencil[]; };

void main() {
    uint g = gl_GlobalInvocationID.x;
    uvec3 dims = vol_dims(vp);
    uint offset = 0u;
    uint level = 0u;
    for (; level < vol_levels(vp); ++level) {
        uint cells = dims.x * dims.y * dims.z;
        if (g < offset + cells) {
            break;
        }
        offset += cells;
        dims = (dims + 1u) / 2u;
    }
    if (level == vol_levels(vp)) {
        return;
    }
    uint word = 0u;
    if (labels[g] == VOL_FLUID) {
        uvec3 ijk = vol_cell_coords(g - offset, dims);
        uint count = 0u;
        for (uint n = 0u; n < 6u; ++n) {
            int nb = vol_neighbor(ijk, dims, n);
            uint label = nb < 0 ? VOL_AIR : labels[offset + uint(nb)];
            word |= label == VOL_FLUID ? 1u << n : 0u;
            count += label == VOL_SOLID ? 0u : 1u;
        }
        word |= VOL_STENCIL_FLUID | (count << VOL_STENCIL_COUNT_SHIFT);
    }
    stencil[g] = word;
}
