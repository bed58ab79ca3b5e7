#version 460
// Deep opacity maps by the compute rasteriser, last step: each atlas texel
// from its sums (shadow_sums.glsl) — the three layers' opacity in RGB, z0 in
// A, all zero where no strand reaches it — as the hardware passes leave it.
#include "shadow_sums.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform writeonly image2D atlas;

void main() {
    ivec2 size = imageSize(atlas);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) {
        return;
    }
    uint t = uint(p.y * size.x + p.x);
    uint z0 = shadow_z0[t];
    vec4 value = vec4(0.0);
    if (z0 != SHADOW_NO_HAIR) {
        vec3 layers = vec3(float(shadow_layers[3u * t]), float(shadow_layers[3u * t + 1u]),
                           float(shadow_layers[3u * t + 2u]));
        value = vec4(layers / SHADOW_OPACITY_UNIT, uintBitsToFloat(z0));
    }
    imageStore(atlas, p, value);
}
