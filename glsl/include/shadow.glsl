// The shadow hook of hair shading: light transmittance (0..1) reaching
// `world_pos` from light `light`. Self-shadowing fills this in; for now
// nothing occludes.
#ifndef VKHAIR_SHADOW_GLSL
#define VKHAIR_SHADOW_GLSL

float shadow(vec3 world_pos, uint light) {
    return 1.0;
}

#endif
