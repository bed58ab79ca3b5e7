#version 460
// Density-volume shadows, once per frame and light: the transmittance toward
// volume map `pc.map`'s light at every cell centre of the simulation's density
// grid, ray-marched through the density (seed 003 4.3.4, precomputed per cell
// as in Bertails et al.'s light-oriented map so that shading needs one
// trilinear lookup).

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 1) readonly buffer Density { vec4 density_cells[]; };
#define VKHAIR_SHADOW_DENSITY density_cells
#include "shadow.glsl"

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(std430, set = 0, binding = 2) writeonly buffer Transmittance { float transmittance[]; };
layout(push_constant) uniform Push { uint map; } pc;

void main() {
    uvec3 dims = sp.grid_dims.xyz;
    uint c = gl_GlobalInvocationID.x;
    if (c >= dims.x * dims.y * dims.z) {
        return;
    }
    uvec3 ijk = uvec3(c % dims.x, (c / dims.x) % dims.y, c / (dims.x * dims.y));
    ShadowMap m = sp.maps[pc.map];
    vec3 p = (inverse(sp.grid_from_world) * vec4(vec3(ijk) + 0.5, 1.0)).xyz;
    vec3 l;
    float reach;
    shadow_volume_light(m, p, l, reach);
    transmittance[uint(m.tile.x) + c] = shadow_volume_transmittance(sp, p, l, reach);
}
