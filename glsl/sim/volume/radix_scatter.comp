#version 460
// Counting sort pass — stable scatter: a key goes to its (digit, block) slot
// from the scanned table plus the number of keys before it in the block with
// the same digit, so equal keys keep their order and the result is the same on
// every run. Push constants as in radix_count.comp; A → B when radix_source = 0.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 4) buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 5) buffer ValsA { uint vals_a[]; };
layout(std430, set = 0, binding = 6) buffer KeysB { uint keys_b[]; };
layout(std430, set = 0, binding = 7) buffer ValsB { uint vals_b[]; };
layout(std430, set = 0, binding = 8) readonly buffer Table { uint table[]; };

shared uint block_digits[VOL_SORT_BLOCK];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint block = gl_WorkGroupID.x;
    uint i = block * VOL_SORT_BLOCK + t;
    bool live = i < radix_keys(pc);
    uint key = 0u;
    uint value = 0u;
    uint digit = 0xffffffffu;
    if (live) {
        key = radix_source(pc) == 0u ? keys_a[i] : keys_b[i];
        value = radix_source(pc) == 0u ? vals_a[i] : vals_b[i];
        digit = (key >> radix_shift(pc)) & ((1u << radix_digit_bits(pc)) - 1u);
    }
    block_digits[t] = digit;
    barrier();
    if (!live) {
        return;
    }
    uint rank = 0u;
    for (uint s = 0u; s < t; ++s) {
        rank += block_digits[s] == digit ? 1u : 0u;
    }
    uint dst = table[digit * radix_blocks(pc) + block] + rank;
    if (radix_source(pc) == 0u) {
        keys_b[dst] = key;
        vals_b[dst] = value;
    } else {
        keys_a[dst] = key;
        vals_a[dst] = value;
    }
}
