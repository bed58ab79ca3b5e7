#version 460
// Exclusive prefix sum of a uint array in tiles of 1024 (4 per invocation):
//   scan_mode = 0: each workgroup stores the sum of its tile in tile_sums;
//   scan_mode = 1: one workgroup scans tile_sums (scan_tiles of them) in place;
//   scan_mode = 2: each workgroup scans its tile and adds its tile's offset.
//   scan_len: element count.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 8) buffer Data { uint data[]; };
layout(std430, set = 0, binding = 9) buffer TileSums { uint tile_sums[]; };

shared uint scan_values[VOL_GROUP];

// Exclusive scan of one value per invocation across the workgroup; `total` gets the sum.
uint workgroup_exclusive(uint value, out uint total) {
    uint t = gl_LocalInvocationID.x;
    scan_values[t] = value;
    barrier();
    for (uint offset = 1u; offset < VOL_GROUP; offset <<= 1u) {
        uint add = t >= offset ? scan_values[t - offset] : 0u;
        barrier();
        scan_values[t] += add;
        barrier();
    }
    total = scan_values[255];
    uint inclusive = scan_values[t];
    barrier();
    return inclusive - value;
}

// Scans the 4 values of invocation t in the tile at `base` of `array_len` elements;
// returns the tile total.
uint scan_tile(uint base, uint array_len, uint offset, bool tiles) {
    uint t = gl_LocalInvocationID.x;
    uint v[4];
    uint own = 0u;
    for (uint e = 0u; e < 4u; ++e) {
        uint i = base + t * 4u + e;
        uint x = 0u;
        if (i < array_len) {
            x = tiles ? tile_sums[i] : data[i];
        }
        v[e] = own;
        own += x;
    }
    uint total;
    uint before = workgroup_exclusive(own, total) + offset;
    for (uint e = 0u; e < 4u; ++e) {
        uint i = base + t * 4u + e;
        if (i < array_len) {
            if (tiles) {
                tile_sums[i] = before + v[e];
            } else {
                data[i] = before + v[e];
            }
        }
    }
    return total;
}

void main() {
    uint t = gl_LocalInvocationID.x;
    uint tile = gl_WorkGroupID.x;
    uint n = scan_len(pc);
    if (scan_mode(pc) == 0u) {
        uint own = 0u;
        for (uint e = 0u; e < 4u; ++e) {
            uint i = tile * VOL_SCAN_TILE + t * 4u + e;
            own += i < n ? data[i] : 0u;
        }
        uint total;
        workgroup_exclusive(own, total);
        if (t == 0u) {
            tile_sums[tile] = total;
        }
    } else if (scan_mode(pc) == 1u) {
        uint carry = 0u;
        for (uint base = 0u; base < scan_tiles(pc); base += VOL_SCAN_TILE) {
            carry += scan_tile(base, scan_tiles(pc), carry, true);
        }
    } else {
        scan_tile(tile * VOL_SCAN_TILE, n, tile_sums[tile], false);
    }
}
