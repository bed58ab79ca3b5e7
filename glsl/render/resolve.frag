#version 460
// vkhair variant: VKHAIR_REVERSE_Z
// Supersampling resolve (thesis 3.5): the hair was drawn at twice the target's
// size over transparent black. Each target pixel averages five bilinear taps —
// its centre (the corner its four sub-samples share) and its four corners — a
// tent over 4×4 sub-samples, and is blended as premultiplied coverage over the
// host's image. Its depth is the nearest hair depth among its own four
// sub-samples (the least depth, the greatest with VKHAIR_REVERSE_Z for a
// reversed depth buffer), so the host's depth test still hides hair behind its
// geometry.
layout(set = 0, binding = 0) uniform sampler2D hair_color;
layout(set = 0, binding = 1) uniform sampler2D hair_depth;

layout(location = 0) out vec4 out_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 texel = 1.0 / vec2(textureSize(hair_color, 0));
    vec2 c = (2.0 * vec2(p) + 1.0) * texel;
    vec4 sum = texture(hair_color, c)
        + texture(hair_color, c + vec2(-texel.x, -texel.y))
        + texture(hair_color, c + vec2(texel.x, -texel.y))
        + texture(hair_color, c + vec2(-texel.x, texel.y))
        + texture(hair_color, c + texel);
    vec4 color = sum * 0.2;
    if (color.a <= 0.0) {
        discard;
    }
    ivec2 s = 2 * p;
    vec4 d4 = vec4(texelFetch(hair_depth, s, 0).r, texelFetch(hair_depth, s + ivec2(1, 0), 0).r,
                   texelFetch(hair_depth, s + ivec2(0, 1), 0).r, texelFetch(hair_depth, s + ivec2(1, 1), 0).r);
#ifdef VKHAIR_REVERSE_Z
    float d = max(max(d4.x, d4.y), max(d4.z, d4.w));
#else
    float d = min(min(d4.x, d4.y), min(d4.z, d4.w));
#endif
    gl_FragDepth = d;
    out_color = color;
}
