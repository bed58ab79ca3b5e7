// The compute rasteriser's deep opacity maps (render/shadow/compute_maps.rs):
// per atlas texel the nearest light-space depth z0 as an ordered key, and the
// three layers' opacity sums in fixed point, added with integer atomics (so
// their order does not matter); shadow_resolve.comp turns them into the atlas
// the hardware passes draw.
#ifndef VKHAIR_SHADOW_SUMS_GLSL
#define VKHAIR_SHADOW_SUMS_GLSL

// Per texel: z0's float bits (light-space depths are ≥ 0, so their bits order
// as the depths do), SHADOW_NO_HAIR where no strand reaches it.
layout(std430, set = 0, binding = 3) buffer ShadowZ0 { uint shadow_z0[]; };
// Per texel: the opacity summed to the end of each of the three layers.
layout(std430, set = 0, binding = 4) buffer ShadowLayers { uint shadow_layers[]; };

const uint SHADOW_NO_HAIR = 0xFFFFFFFFu;
// Units of one in the opacity sums (2^16: each fragment's opacity is rounded
// to 1/65,536).
const float SHADOW_OPACITY_UNIT = 65536.0;
// Past this a sum takes no more (2^31: an opacity of 32,768, far past any
// light getting through), so that it cannot wrap around to a small value.
const uint SHADOW_SATURATED = 0x80000000u;

#endif
