#version 460
// Test probe of glsl/include/shadow.glsl at given points: volume = 0
// shadow_transmittance() of map `map`; 1 shadow_volume_transmittance() toward
// `to_light`; 2 shadow_volume_lookup() of map `map`.

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 4) readonly buffer Density { vec4 density_cells[]; };
layout(std430, set = 0, binding = 5) readonly buffer Transmittance { float volume_transmittance[]; };
#define VKHAIR_SHADOW_DENSITY density_cells
#define VKHAIR_SHADOW_TRANSMITTANCE volume_transmittance
#include "shadow.glsl"

layout(std140, set = 0, binding = 0) uniform Shadows { ShadowParams sp; };
layout(set = 0, binding = 1) uniform sampler2D atlas;
layout(std430, set = 0, binding = 2) readonly buffer Points { vec4 points[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Out { float transmittance[]; };
layout(push_constant) uniform Push {
    uint map;
    uint count;
    uint volume;
    uint pad;
    vec4 to_light;
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    vec3 p = points[i].xyz;
    if (pc.volume == 1u) {
        transmittance[i] = shadow_volume_transmittance(sp, p, pc.to_light.xyz, 1e30);
    } else if (pc.volume == 2u) {
        transmittance[i] = shadow_volume_lookup(sp, sp.maps[pc.map], p);
    } else {
        transmittance[i] = shadow_transmittance(atlas, sp.maps[pc.map], p);
    }
}
