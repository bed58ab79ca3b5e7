#version 460
// Exact transparency, build: every hair fragment that passes the depth test
// takes the colour of its segment's shaded ends (shade_points.comp) and its
// coverage, and is pushed onto its pixel's list (a node from the pool). When the
// pool is full it is counted and added to the overflow sums instead (colour
// premultiplied, alpha, absorbance −ln(1 − alpha); additive blending), which the
// resolve folds into the order-independent tail: nothing is lost. Early tests:
// the depth test runs before the stores.
// Constant 0 is the pool's buffer count (oit.glsl); this stage shades nothing.
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit.glsl"

layout(early_fragment_tests) in;

// The colour shade_points.comp gave the segment's ends, and the coverage inputs.
layout(location = 0) in vec3 g_color;
layout(location = 1) in vec3 g_cover;

layout(location = 0) out vec4 out_overflow;
layout(location = 1) out vec4 out_absorbance;

void main() {
    float alpha = strand_alpha(g_cover);
    if (alpha < OIT_LEAST_ALPHA) {
        discard;
    }
    vec3 color = g_color;
    uint pixel = oit_pixel(gl_FragCoord);
    float z = oit_forward(gl_FragCoord.z);
    if (alpha >= OIT_OPAQUE_ALPHA) {
        atomicMin(oit_opaque[pixel], floatBitsToUint(z));
    }
    uint node = atomicAdd(oit.used, 1u);
    if (node >= oit.capacity) {
        out_overflow = vec4(color * alpha, alpha);
        out_absorbance = vec4(-log(max(1.0 - alpha, 1e-4)), 0.0, 0.0, 0.0);
        return;
    }
    out_overflow = vec4(0.0);
    out_absorbance = vec4(0.0);
    uint next = atomicExchange(oit_heads[pixel], node);
    oit_store(node, uvec4(packHalf2x16(color.rg), packHalf2x16(vec2(color.b, alpha)),
                          floatBitsToUint(z), next));
}
