// Declarations shared by the render passes (glsl/render/*).
#ifndef VKHAIR_RENDER_GLSL
#define VKHAIR_RENDER_GLSL

// Push constants of the smoothing pass. Twin: gpu_types::SmoothPush.
struct SmoothPush {
    uint strands;         // key hairs
    uint points;          // points per key hair
    uint level;           // smoothed segments per key segment
    uint stride;          // smoothed vertices per key hair: (points − 1)·level + 1
};

// Uniform cubic B-spline basis at u and its derivative (weights of p0..p3).
void bspline_basis(float u, out vec4 b, out vec4 db) {
    float u2 = u * u;
    float u3 = u2 * u;
    float v = 1.0 - u;
    b = vec4(v * v * v, 3.0 * u3 - 6.0 * u2 + 4.0, -3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0, u3) / 6.0;
    db = vec4(-v * v, 3.0 * u2 - 4.0 * u, -3.0 * u2 + 2.0 * u + 1.0, u2) * 0.5;
}

#endif
