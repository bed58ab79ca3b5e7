#version 460
// Opacity-map pass 2 (additive, no depth test): each fragment adds the strand
// opacity to the layer its depth behind z0 falls in and to every layer behind
// it; alpha carries z0 (blended with MAX, so every fragment of a texel writing
// the same z0 leaves it unchanged).
#include "shadow.glsl"

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(set = 0, binding = 2) uniform sampler2D z0_atlas;
layout(push_constant) uniform Push { uint map; } pc;

layout(location = 0) in float v_depth;
layout(location = 0) out vec4 out_layers;

void main() {
    ShadowMap m = sp.maps[pc.map];
    float z0 = texelFetch(z0_atlas, ivec2(gl_FragCoord.xy), 0).r;
    uint layer = shadow_layer_of(v_depth - z0, m.layers.xyz);
    vec3 mask = vec3(greaterThanEqual(uvec3(0u, 1u, 2u), uvec3(layer)));
    out_layers = vec4(mask * m.params.x, z0);
}
