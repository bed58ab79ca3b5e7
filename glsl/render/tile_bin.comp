#version 460
// Exact transparency by the tiled rasteriser (render/draw/tiles.rs), first
// and third dispatch: one invocation a segment (grid-stride) finds the tiles
// its band reaches — per tile column along its major axis, the tile rows that
// column's pixel walk (strand_segment.glsl's segment_column at the column's
// first and last pixel column; the centre line is straight) can visit, so
// every pixel the segment can draw lies in a tile it is binned to — and
// counts itself in each (this variant) or writes itself into each tile's run
// (VKHAIR_TILE_FILL, after tile_scan.comp), never past its tile's run nor
// the list's capacity (the fine pass reads only what fits).
// vkhair variant: VKHAIR_TILE_FILL
// Constant 1: the shading features (this stage shades nothing).
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit_opaque.glsl"
#include "tile_lists.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
layout(std430, set = 0, binding = 20) readonly buffer PointColor { vec4 point_color[]; };
layout(std430, set = 0, binding = 25) readonly buffer SceneDepth { uint scene_depth[]; };

#include "strand_segment.glsl"

void bin_segment(uint seg, uint first, bool last) {
    Segment sg;
    if (!segment_on_screen(first, last, sg)) {
        return;
    }
    const float side = float(TILE_SIZE);
    for (float tk = floor(sg.k_lo / side); tk * side < sg.k_hi; tk += 1.0) {
        // The columns of this tile column the walk visits, and the rows they can reach.
        vec2 c0 = segment_column(sg, max(sg.k_lo, tk * side));
        vec2 c1 = segment_column(sg, min(sg.k_hi, tk * side + side) - 1.0);
        float m_lo = min(c0.x, c1.x);
        float m_hi = max(c0.y, c1.y);
        for (float tm = floor(m_lo / side); tm * side < m_hi; tm += 1.0) {
            uvec2 tile = sg.x_major ? uvec2(tk, tm) : uvec2(tm, tk);
            uint t = tile.y * tiles.tiles_x + tile.x;
#ifdef VKHAIR_TILE_FILL
            // Within the tile's own run (the count's) and the list, whatever
            // the two variants' arithmetic.
            uint slot = atomicAdd(tile_cursor[t], 1u);
            if (slot < tile_start[t] + tile_count[t] && slot < tiles.capacity) {
                tile_list[slot] = seg;
            }
#else
            atomicAdd(tile_count[t], 1u);
#endif
        }
    }
}

void main() {
    if (dp.counts.y < 2u) {
        return;
    }
    uint total = dp.counts.x * (dp.counts.y - 1u);
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint seg = gl_GlobalInvocationID.x; seg < total; seg += stride) {
        bool last;
        uint first = segment_first(seg, last);
        bin_segment(seg, first, last);
    }
}
