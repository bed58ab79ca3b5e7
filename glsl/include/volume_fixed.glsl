// Fixed-point sums of the volume stage's transfer, in any order to the same
// bits: a value x is added as the 64-bit integer trunc(x · 2³²) (|x| capped
// below 2³¹, NaN as 0), kept in two uint words (low, high) and added with
// 32-bit atomics, the low word's carry going to the high one — or, in
// scatter.comp's VKHAIR_INT64 variant, as one 64-bit atomic on the pair
// (the same sums). Twin:
// `fixed_point` in src/sim/volume/reference.rs. Include after declaring the
// `accum` buffer (define VOL_FIXED_READ_ONLY first where it is read only).
#ifndef VKHAIR_VOLUME_FIXED_GLSL
#define VKHAIR_VOLUME_FIXED_GLSL

// The largest f32 below 2³¹.
const float VOL_FIXED_MAX = 2147483520.0;

// x as (low, high) words of trunc(x · 2³²), two's complement.
uvec2 vol_fixed(float x) {
    float a = abs(x);
    a = isnan(a) ? 0.0 : min(a, VOL_FIXED_MAX);
    float whole = floor(a);
    uint high = uint(whole);
    uint low = uint((a - whole) * 4294967296.0);
    if (x < 0.0) {
        low = ~low + 1u;
        high = ~high + (low == 0u ? 1u : 0u);
    }
    return uvec2(low, high);
}

#if defined(VKHAIR_INT64)
// Words at, at + 1 (`at` even) += x, as one 64-bit integer (the including
// shader declares `accum` as uint64_t; scatter.comp's INT64 variant).
void vol_fixed_add(uint at, float x) {
    uvec2 v = vol_fixed(x);
    if (v.x == 0u && v.y == 0u) {
        return;
    }
    atomicAdd(accum[at >> 1u], packUint2x32(v));
}
#elif !defined(VOL_FIXED_READ_ONLY)
// accum[at], accum[at + 1] += x.
void vol_fixed_add(uint at, float x) {
    uvec2 v = vol_fixed(x);
    if (v.x == 0u && v.y == 0u) {
        return;
    }
    uint before = atomicAdd(accum[at], v.x);
    uint high = v.y + (before + v.x < before ? 1u : 0u);
    if (high != 0u) {
        atomicAdd(accum[at + 1u], high);
    }
}
#endif

#ifndef VKHAIR_INT64
// The sum at accum[at], accum[at + 1] as a float: its magnitude's high word
// plus its low word × 2⁻³², each rounded to f32, then the sign.
float vol_fixed_value(uint at) {
    uint low = accum[at];
    uint high = accum[at + 1u];
    bool negative = int(high) < 0;
    if (negative) {
        low = ~low + 1u;
        high = ~high + (low == 0u ? 1u : 0u);
    }
    precise float x = float(high) + float(low) * 2.3283064365386963e-10;
    return negative ? -x : x;
}

#endif

#endif
