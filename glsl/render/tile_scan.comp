#version 460
// Exact transparency by the tiled rasteriser (render/draw/tiles.rs), second
// dispatch, one workgroup: the tiles' counts into runs of the one list — each
// tile's first entry (an exclusive prefix sum, in row-major tile order), the
// fill's cursors set to it, and the total the frame asked for. Each invocation
// sums a block of consecutive tiles, the blocks' sums are scanned in shared
// memory, and each invocation writes its block's starts.
#include "tile_lists.glsl"

layout(local_size_x = TILE_SCAN_GROUP) in;

shared uint block_sum[TILE_SCAN_GROUP];

void main() {
    uint i = gl_LocalInvocationIndex;
    uint count = tiles.tiles_x * tiles.tiles_y;
    uint per = (count + TILE_SCAN_GROUP - 1u) / TILE_SCAN_GROUP;
    uint first = min(i * per, count);
    uint end = min(first + per, count);
    uint sum = 0u;
    for (uint t = first; t < end; ++t) {
        sum += tile_count[t];
    }
    block_sum[i] = sum;
    barrier();
    // Inclusive scan of the blocks' sums (Hillis–Steele).
    for (uint step = 1u; step < TILE_SCAN_GROUP; step <<= 1u) {
        uint add = i >= step ? block_sum[i - step] : 0u;
        barrier();
        block_sum[i] += add;
        barrier();
    }
    uint start = block_sum[i] - sum;
    for (uint t = first; t < end; ++t) {
        tile_start[t] = start;
        tile_cursor[t] = start;
        start += tile_count[t];
    }
    if (i == TILE_SCAN_GROUP - 1u) {
        tiles.entries = block_sum[i];
    }
}
