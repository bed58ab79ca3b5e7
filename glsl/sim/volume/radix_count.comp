#version 460
// Counting sort by cell id, one radix digit per pass — histogram: each
// workgroup counts the digits of its 256 keys and stores the counts digit-major
// (table[digit · blocks + block]) so that one exclusive scan of the table gives
// every (digit, block) its first output slot.
//   radix_source: 0 = keys in A, 1 = keys in B;  radix_shift: digit shift;
//   radix_keys: key count;  radix_blocks: blocks;  radix_digit_bits: digit bits.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 4) readonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 6) readonly buffer KeysB { uint keys_b[]; };
layout(std430, set = 0, binding = 8) writeonly buffer Table { uint table[]; };

shared uint histogram[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint digits = 1u << radix_digit_bits(pc);
    histogram[t] = 0u;
    barrier();
    uint i = block * VOL_SORT_BLOCK + t;
    if (i < radix_keys(pc)) {
        uint key = radix_source(pc) == 0u ? keys_a[i] : keys_b[i];
        atomicAdd(histogram[(key >> radix_shift(pc)) & (digits - 1u)], 1u);
    }
    barrier();
    if (t < digits) {
        table[t * radix_blocks(pc) + block] = histogram[t];
    }
}
