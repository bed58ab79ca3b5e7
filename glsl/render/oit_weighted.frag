#version 460
// Fast transparency (weighted blended, McGuire and Bavoil 2013), one pass:
// every hair fragment adds its weighted premultiplied colour and weight to
// attachment 0 and its absorbance −ln(1 − alpha) to attachment 1; the resolve
// turns the sums into colour and total opacity. Nearer fragments weigh more.
// Constant 0 is the pool's buffer count (oit.glsl); this stage shades nothing.
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit.glsl"

layout(early_fragment_tests) in;

// The colour shade_points.comp gave the segment's ends, and the coverage inputs.
layout(location = 0) in vec3 g_color;
layout(location = 1) in vec3 g_cover;

layout(location = 0) out vec4 out_sum;
layout(location = 1) out vec4 out_absorbance;

void main() {
    float alpha = strand_alpha(g_cover);
    if (alpha < OIT_LEAST_ALPHA) {
        discard;
    }
    vec3 color = g_color;
    float z = oit_forward(gl_FragCoord.z);
    if (alpha >= OIT_OPAQUE_ALPHA) {
        atomicMin(oit_opaque[oit_pixel(gl_FragCoord)], floatBitsToUint(z));
    }
    float weight = max(1e-2, 3e3 * pow(1.0 - z, 3.0));
    out_sum = vec4(color * alpha, alpha) * weight;
    out_absorbance = vec4(-log(max(1.0 - alpha, 1e-4)), 0.0, 0.0, 0.0);
}
