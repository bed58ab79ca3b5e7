//! The integer hash shared with the shaders (`glsl/include/hash.glsl`), for the
//! CPU references.

/// 32-bit finaliser: xor-shift / multiply rounds.
pub(crate) fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// 24 hash bits as a float in [0, 1) (exact: the scale is a power of two).
pub(crate) fn hash_unit(x: u32) -> f32 {
    (hash_u32(x) >> 8) as f32 * (1.0 / 16_777_216.0)
}
