// The tiled rasteriser's bins (render/draw/tiles.rs): per screen tile of
// TILE_SIZE × TILE_SIZE pixels (row-major, rows from NDC y = −1) the segments
// whose band reaches it, as a run of the one list: tile_bin.comp counts them,
// tile_scan.comp turns the counts into runs, tile_bin.comp's fill variant
// writes them, tile_fine.comp draws each tile's.
#ifndef VKHAIR_TILE_LISTS_GLSL
#define VKHAIR_TILE_LISTS_GLSL

// Twin: gpu_types::TileCounters.
layout(std430, set = 0, binding = 29) buffer TileCounters {
    uint entries;  // tile entries the frame's segments asked for (the scan's total)
    uint capacity; // entries the list holds; those past it are not drawn
    uint tiles_x;  // tiles per row
    uint tiles_y;  // rows of tiles
} tiles;

// Per tile: its segments (tile_bin.comp's count), the first entry of its run
// (tile_scan.comp) and the next entry to fill (the fill's atomics).
layout(std430, set = 0, binding = 30) buffer TileCount { uint tile_count[]; };
layout(std430, set = 0, binding = 31) buffer TileStart { uint tile_start[]; };
layout(std430, set = 0, binding = 32) buffer TileCursor { uint tile_cursor[]; };
// The runs, one after another: segment indices (hair-major, as strand_segment.glsl's segment_first).
layout(std430, set = 0, binding = 33) buffer TileList { uint tile_list[]; };

#endif
