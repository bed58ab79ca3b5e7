// The exact mode's overflow as the compute rasteriser keeps it
// (render/draw/raster.rs): per pixel, fixed-point sums of the fragments the
// full pool could not store — premultiplied colour (rgb), alpha, and
// absorbance −ln(1 − alpha) — added with integer atomics, so the sums do not
// depend on the order the fragments arrive in. The composite's
// VKHAIR_OVERFLOW_BUFFER variant reads them where the hardware path samples
// the build's blended sums images.
#ifndef VKHAIR_OIT_OVERFLOW_GLSL
#define VKHAIR_OIT_OVERFLOW_GLSL

// Two planes (each within one binding's range at 3840×2160 on a device of
// 128 MiB ranges): per pixel the premultiplied colour sums (rgb), and the
// alpha and absorbance sums.
layout(std430, set = 0, binding = 26) buffer OitOverflowColor { uint oit_overflow_color[]; };
layout(std430, set = 0, binding = 27) buffer OitOverflowAlpha { uvec2 oit_overflow_alpha[]; };

// Units of one in the colour and alpha sums (2^16) and in the absorbance sum
// (2^10: a fragment adds at most −ln(1e−4) ≈ 9.2).
const float OIT_OVERFLOW_COLOR_UNIT = 65536.0;
const float OIT_OVERFLOW_ABSORBANCE_UNIT = 1024.0;

// Past this a sum takes no more (2^31: 32,768 fully opaque fragments, or
// over 2 million of absorbance): it cannot wrap around to a small value while
// the adds in flight finish.
const uint OIT_OVERFLOW_SATURATED = 0x80000000u;

// Adds `value` (in its unit) to `sum` unless the sum is saturated.
#define OIT_SATURATING_ADD(sum, value) \
    if ((sum) < OIT_OVERFLOW_SATURATED) { atomicAdd(sum, value); }

// Adds a fragment of colour `color` (linear, not premultiplied) and `alpha` to
// pixel `pixel`'s sums.
void oit_overflow_add(uint pixel, vec3 color, float alpha) {
    // Radiance above 64 (far past any display's white) is counted as 64, so
    // that one add stays within a word.
    vec3 premultiplied = clamp(color, vec3(0.0), vec3(64.0)) * alpha;
    uint c = 3u * pixel;
    OIT_SATURATING_ADD(oit_overflow_color[c], uint(premultiplied.r * OIT_OVERFLOW_COLOR_UNIT + 0.5))
    OIT_SATURATING_ADD(oit_overflow_color[c + 1u], uint(premultiplied.g * OIT_OVERFLOW_COLOR_UNIT + 0.5))
    OIT_SATURATING_ADD(oit_overflow_color[c + 2u], uint(premultiplied.b * OIT_OVERFLOW_COLOR_UNIT + 0.5))
    OIT_SATURATING_ADD(oit_overflow_alpha[pixel].x, uint(alpha * OIT_OVERFLOW_COLOR_UNIT + 0.5))
    float absorbance = -log(max(1.0 - alpha, 1e-4));
    OIT_SATURATING_ADD(oit_overflow_alpha[pixel].y, uint(absorbance * OIT_OVERFLOW_ABSORBANCE_UNIT + 0.5))
}

// Pixel `pixel`'s sums: Σ premultiplied colour and Σ alpha.
vec4 oit_overflow_sum(uint pixel) {
    vec3 color = vec3(float(oit_overflow_color[3u * pixel]), float(oit_overflow_color[3u * pixel + 1u]),
                      float(oit_overflow_color[3u * pixel + 2u]));
    return vec4(color, float(oit_overflow_alpha[pixel].x)) / OIT_OVERFLOW_COLOR_UNIT;
}

// Pixel `pixel`'s Σ absorbance.
float oit_overflow_absorbance(uint pixel) {
    return float(oit_overflow_alpha[pixel].y) / OIT_OVERFLOW_ABSORBANCE_UNIT;
}

#endif
