// Integer hash (a 32-bit finaliser: xor-shift / multiply rounds), exact on every
// device. Mirrored by `crate::hash::hash_u32` for the CPU references.
#ifndef VKHAIR_HASH_GLSL
#define VKHAIR_HASH_GLSL

uint hash_u32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// 24 hash bits as a float in [0, 1); the scale is a power of two, so exact.
float hash_unit(uint x) {
    return float(hash_u32(x) >> 8) * (1.0 / 16777216.0);
}

#endif
