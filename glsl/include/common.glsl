// Shared declarations for every vkhair shader.
#ifndef VKHAIR_COMMON_GLSL
#define VKHAIR_COMMON_GLSL

// Every struct here has a #[repr(C)] + bytemuck::Pod twin in src/gpu_types.rs;
// tests compare member offsets and sizes reflected from the SPIR-V with it.

// Push constants of core/scale_add.comp: dst[i] = scale * src[i] + bias.
struct ScaleAddPush {
    uint count;
    float scale;
    float bias;
    uint pad0;
};

// A struct that exercises std430 rules (vec3 followed by a scalar, a matrix,
// an array and a vector after a scalar) so that a layout mismatch between
// Rust and GLSL shows up in tests before real stages rely on it.
struct LayoutProbe {
    vec3 position;
    float radius;
    mat4 transform;
    uvec2 ids;
    float weights[2];
    vec4 color;
};

#endif
