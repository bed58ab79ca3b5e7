// Deep opacity map sampling (Yuksel & Keyser 2008), includable by a host that
// wants to shade its own surfaces (a head mesh) with the hair's shadows. It
// declares no bindings: pass the opacity atlas and the map's parameters.
//
// One atlas tile per shadow-casting light holds, per texel, the opacity summed
// up to the end of each of three layers behind z0 (RGB) and z0 itself (A),
// where z0 is the light-space depth at which the hair starts and depths are
// distances along the light's axis in meters. A = 0 marks texels no hair covers.
#ifndef VKHAIR_SHADOW_GLSL
#define VKHAIR_SHADOW_GLSL

// Most shadow-casting lights (render::MAX_SHADOW_MAPS).
const uint MAX_SHADOW_MAPS = 4u;

// One light's map. Twin: gpu_types::GpuShadowMap.
struct ShadowMap {
    mat4 view_proj;   // world → the light's clip space (x, y → the tile)
    vec4 view_z;      // light-space depth of p: dot(view_z.xyz, p) + view_z.w (m)
    vec4 layers;      // xyz ends of the three layers behind z0 (m), w extinction k
    vec4 tile;        // xy first texel of the tile in the atlas, zw its size (texels)
    vec4 params;      // x opacity per strand fragment, y PCF radius (texels), z unused, w unused
};

// The maps of a frame. Twin: gpu_types::ShadowParams.
struct ShadowParams {
    ShadowMap maps[MAX_SHADOW_MAPS];
    uvec4 light_map[2];   // map index of light i (i < 8), or 0xffffffff when it casts none
    uvec4 counts;         // x hairs, y vertices per hair, z maps, w unused
};

// Opacity in front of depth d behind z0 from the three layer sums `o`,
// interpolated linearly inside each layer (0 at z0; constant beyond the last).
float shadow_layer_opacity(float d, vec3 o, vec3 ends) {
    if (d <= 0.0) {
        return 0.0;
    }
    if (d < ends.x) {
        return o.x * (d / ends.x);
    }
    if (d < ends.y) {
        return mix(o.x, o.y, (d - ends.x) / (ends.y - ends.x));
    }
    if (d < ends.z) {
        return mix(o.y, o.z, (d - ends.y) / (ends.z - ends.y));
    }
    return o.z;
}

// The layer (0..2) a fragment d behind z0 adds its opacity to, together with
// every layer behind it; fragments beyond the last layer count in the last.
uint shadow_layer_of(float d, vec3 ends) {
    return d <= ends.x ? 0u : (d <= ends.y ? 1u : 2u);
}

// Light transmittance (0..1) reaching world position p through the hair of map
// m: exp(−k · opacity), averaged over (2r+1)² texels of the tile (PCF).
float shadow_transmittance(sampler2D atlas, ShadowMap m, vec3 p) {
    vec4 clip = m.view_proj * vec4(p, 1.0);
    if (clip.w <= 0.0) {
        return 1.0;
    }
    vec2 ndc = clip.xy / clip.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) {
        return 1.0;
    }
    float depth = dot(m.view_z.xyz, p) + m.view_z.w;
    vec2 texel = m.tile.xy + (ndc * 0.5 + 0.5) * m.tile.zw;
    ivec2 lo = ivec2(m.tile.xy);
    ivec2 hi = lo + ivec2(m.tile.zw) - 1;
    ivec2 centre = clamp(ivec2(floor(texel)), lo, hi);
    int r = int(m.params.y);
    float sum = 0.0;
    for (int y = -r; y <= r; ++y) {
        for (int x = -r; x <= r; ++x) {
            vec4 s = texelFetch(atlas, clamp(centre + ivec2(x, y), lo, hi), 0);
            float opacity = s.a > 0.0 ? shadow_layer_opacity(depth - s.a, s.rgb, m.layers.xyz) : 0.0;
            sum += exp(-m.layers.w * opacity);
        }
    }
    float n = float(2 * r + 1);
    return sum / (n * n);
}

#endif
