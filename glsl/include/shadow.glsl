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

// MAX_SHADOW_MAPS (render::MAX_SHADOW_MAPS) is injected by build.rs from src/limits.rs.
// A host including this header in its own shaders defines it when compiling
// them: -DMAX_SHADOW_MAPS=4u (glslc, shaderc's add_macro_definition).
#if !defined(MAX_SHADOW_MAPS)
#error "define MAX_SHADOW_MAPS as vkhair::render::MAX_SHADOW_MAPS (-DMAX_SHADOW_MAPS=4u) before including shadow.glsl"
#endif

// One light's map. Twin: gpu_types::GpuShadowMap.
struct ShadowMap {
    mat4 view_proj;   // world → the light's clip space (x, y → the tile)
    vec4 view_z;      // light-space depth of p: dot(view_z.xyz, p) + view_z.w (m);
                      // volume maps: xyz light direction (w 0) or position (w 1)
    vec4 layers;      // xyz ends of the three layers behind z0 (m), w extinction k
    vec4 tile;        // xy first texel of the tile in the atlas, zw its size (texels);
                      // volume maps: x first cell in the transmittance array
    vec4 params;      // x opacity per drawn strand's fragment, y opacity filter radius (texels), z method (SHADOW_*), w unused
};

// The SHADOW_* methods are injected by build.rs from src/codes.rs.

// The maps of a frame. Twin: gpu_types::ShadowParams.
struct ShadowParams {
    ShadowMap maps[MAX_SHADOW_MAPS];
    uvec4 light_map[2];   // map index of light i (i < 8), or 0xffffffff when it casts none
    uvec4 counts;         // x hairs, y vertices per hair, z maps, w unused
    mat4 grid_from_world; // the simulation's density volume: world → grid coordinates (cells)
    uvec4 grid_dims;      // xyz cells, w 1 when a density volume is present
    vec4 grid;            // x cell size (m), y cross-section per particle / cell volume (1/m), z step (cells), w unused
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
// m: exp(−k · opacity), the opacity averaged over (2r+1)² texels of the tile
// (r = m.params.y) before the exponential: the filter spreads the opacity of
// sparse strands over the space their hairs fill.
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
            sum += opacity;
        }
    }
    float n = float(2 * r + 1);
    return exp(-m.layers.w * sum / (n * n));
}

#ifdef VKHAIR_SHADOW_DENSITY
// Density-volume shadows (ray-marching the simulation's density toward the
// light). Define VKHAIR_SHADOW_DENSITY as the name of a readonly vec4 array
// (one per cell, w = density: summed trilinear particle weights) before
// including this file.

// Trilinear density at grid position g (cell centres at +½; outside: 0).
float shadow_density_at(ShadowParams sp, vec3 g) {
    ivec3 dims = ivec3(sp.grid_dims.xyz);
    vec3 q = g - 0.5;
    vec3 base = floor(q);
    vec3 t = q - base;
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 at = ivec3(base) + corner;
        if (any(lessThan(at, ivec3(0))) || any(greaterThanEqual(at, dims))) {
            continue;
        }
        vec3 w3 = mix(vec3(1.0) - t, t, vec3(corner));
        sum += VKHAIR_SHADOW_DENSITY[at.x + dims.x * (at.y + dims.y * at.z)].w * (w3.x * w3.y * w3.z);
    }
    return sum;
}

// Transmittance toward a light in unit direction `l` at most `reach` meters away:
// exp(−(σ / h³) · ∫ density ds) along the ray from p, until it leaves the grid.
float shadow_volume_transmittance(ShadowParams sp, vec3 p, vec3 l, float reach) {
    if (sp.grid_dims.w == 0u) {
        return 1.0;
    }
    vec3 g = (sp.grid_from_world * vec4(p, 1.0)).xyz;
    vec3 dir = mat3(sp.grid_from_world) * l;   // cells per meter along the ray
    float step_m = sp.grid.z * sp.grid.x;
    vec3 dims = vec3(sp.grid_dims.xyz);
    float optical = 0.0;
    for (int k = 1; k <= 2048; ++k) {
        float s = (float(k) - 0.5) * step_m;
        if (s > reach) {
            break;
        }
        vec3 q = g + dir * s;
        if (any(lessThan(q, vec3(-1.0))) || any(greaterThan(q, dims + 1.0))) {
            break;
        }
        optical += shadow_density_at(sp, q) * step_m;
    }
    return exp(-sp.grid.y * optical);
}

// Direction toward the light of volume map m from p, and how far the light is.
void shadow_volume_light(ShadowMap m, vec3 p, out vec3 l, out float reach) {
    if (m.view_z.w == 0.0) {
        l = -normalize(m.view_z.xyz);
        reach = 1e30;
    } else {
        vec3 to_light = m.view_z.xyz - p;
        reach = length(to_light);
        l = reach > 0.0 ? to_light / reach : vec3(0.0, 1.0, 0.0);
    }
}
#endif

#ifdef VKHAIR_SHADOW_TRANSMITTANCE
// Density-volume shadows, lookup: the transmittance toward each volume light at
// every cell centre of the density grid (computed once per frame by the renderer,
// `glsl/render/shadow_volume.comp`), interpolated trilinearly. Define
// VKHAIR_SHADOW_TRANSMITTANCE as the name of a readonly float array holding it
// (map m's cells from m.tile.x on) before including this file.
float shadow_volume_lookup(ShadowParams sp, ShadowMap m, vec3 p) {
    if (sp.grid_dims.w == 0u) {
        return 1.0;
    }
    ivec3 dims = ivec3(sp.grid_dims.xyz);
    vec3 q = (sp.grid_from_world * vec4(p, 1.0)).xyz - 0.5;
    vec3 base = floor(q);
    vec3 t = q - base;
    uint offset = uint(m.tile.x);
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 at = clamp(ivec3(base) + corner, ivec3(0), dims - 1);
        vec3 w3 = mix(vec3(1.0) - t, t, vec3(corner));
        sum += VKHAIR_SHADOW_TRANSMITTANCE[offset + uint(at.x + dims.x * (at.y + dims.y * at.z))] * (w3.x * w3.y * w3.z);
    }
    return sum;
}
#endif

#endif
