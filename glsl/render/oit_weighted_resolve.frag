#version 460
// Fast transparency, resolve (over the rectangle the ribbons reach,
// hair_rect.vert): the weighted average colour of the pixel's hair fragments
// times their total opacity 1 − exp(−Σ absorbance), blended over the target as
// premultiplied colour.
layout(set = 0, binding = 0) uniform sampler2D weighted_sum;
layout(set = 0, binding = 1) uniform sampler2D absorbance;

layout(location = 0) out vec4 out_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 sum = texelFetch(weighted_sum, p, 0);
    if (sum.a <= 0.0) {
        discard;
    }
    float alpha = 1.0 - exp(-texelFetch(absorbance, p, 0).r);
    out_color = vec4(sum.rgb / sum.a * alpha, alpha);
}
