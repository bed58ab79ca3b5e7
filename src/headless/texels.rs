//! Colour texels of the offscreen formats read back as linear RGBA.

use ash::vk;
use glam::Vec4;

/// One 8-bit sRGB channel as linear light (IEC 61966-2-1).
fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// An unsigned float of 5 exponent bits and `mantissa_bits` mantissa bits
/// (the channels of `B10G11R11_UFLOAT_PACK32`, as the Vulkan specification's
/// "Unsigned 11-Bit / 10-Bit Floating-Point Numbers" defines them).
fn small_float(bits: u32, mantissa_bits: u32) -> f32 {
    let mantissa = bits & ((1 << mantissa_bits) - 1);
    let exponent = bits >> mantissa_bits;
    let fraction = mantissa as f32 / (1u32 << mantissa_bits) as f32;
    match exponent {
        0 => fraction * 2f32.powi(-14),
        31 if mantissa == 0 => f32::INFINITY,
        31 => f32::NAN,
        e => 2f32.powi(e as i32 - 15) * (1.0 + fraction),
    }
}

/// Half float `i` of texel `t`.
fn half(t: &[u8], i: usize) -> f32 {
    half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32()
}

/// The texels of `bytes`, tightly packed rows of a velocity format (one of
/// `render::VELOCITY_FORMATS`), as two floats each.
pub(super) fn decode_velocity(format: vk::Format, bytes: &[u8]) -> Vec<glam::Vec2> {
    match format {
        vk::Format::R16G16_SFLOAT => bytes.chunks_exact(4).map(|t| glam::Vec2::new(half(t, 0), half(t, 1))).collect(),
        _ => bytes
            .chunks_exact(8)
            .map(|t| {
                let c = |i: usize| f32::from_le_bytes([t[4 * i], t[4 * i + 1], t[4 * i + 2], t[4 * i + 3]]);
                glam::Vec2::new(c(0), c(1))
            })
            .collect(),
    }
}

/// The texels of `bytes`, tightly packed rows of `format` (one of
/// `OFFSCREEN_COLOR_FORMATS`), as linear RGBA.
pub(super) fn decode(format: vk::Format, bytes: &[u8]) -> Vec<Vec4> {
    match format {
        vk::Format::R16G16B16A16_SFLOAT => {
            bytes.chunks_exact(8).map(|t| Vec4::new(half(t, 0), half(t, 1), half(t, 2), half(t, 3))).collect()
        }
        vk::Format::B10G11R11_UFLOAT_PACK32 => bytes
            .chunks_exact(4)
            .map(|t| {
                let w = u32::from_le_bytes([t[0], t[1], t[2], t[3]]);
                Vec4::new(small_float(w & 0x7FF, 6), small_float((w >> 11) & 0x7FF, 6), small_float(w >> 22, 5), 1.0)
            })
            .collect(),
        _ => bytes
            .chunks_exact(4)
            .map(|t| {
                Vec4::new(srgb_to_linear(t[0]), srgb_to_linear(t[1]), srgb_to_linear(t[2]), f32::from(t[3]) / 255.0)
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values whose encodings are written out by hand from the formats'
    /// definitions.
    #[test]
    fn each_format_decodes_known_texels() {
        // 1.0 = exponent 15, mantissa 0: 15 << 6 (11-bit), 15 << 5 (10-bit);
        // 0.5 = exponent 14; 2^-15 = the 11-bit denormal of mantissa 32.
        let packed = (15u32 << 6) | ((14u32 << 6) << 11) | ((16u32 << 5) << 22);
        let t = decode(vk::Format::B10G11R11_UFLOAT_PACK32, &packed.to_le_bytes());
        assert_eq!(t, vec![Vec4::new(1.0, 0.5, 2.0, 1.0)]);
        assert_eq!(small_float(32, 6), 2f32.powi(-15));
        assert_eq!(small_float(31 << 6, 6), f32::INFINITY);
        // Half floats: 1.0 = 0x3C00, 2.5 = 0x4100, 0.25 = 0x3400, 65504 = 0x7BFF.
        let bytes: Vec<u8> = [0x3C00u16, 0x4100, 0x3400, 0x7BFF].iter().flat_map(|h| h.to_le_bytes()).collect();
        assert_eq!(decode(vk::Format::R16G16B16A16_SFLOAT, &bytes), vec![Vec4::new(1.0, 2.5, 0.25, 65504.0)]);
        // sRGB: 0 → 0, 255 → 1, 188 → 0.5 within the 8-bit step.
        let t = decode(vk::Format::R8G8B8A8_SRGB, &[0, 255, 188, 255]);
        assert_eq!((t[0].x, t[0].y, t[0].w), (0.0, 1.0, 1.0));
        assert!((t[0].z - 0.5).abs() < 0.003, "{}", t[0].z);
    }
}
