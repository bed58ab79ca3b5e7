// Declarations shared by the render passes (glsl/render/*).
#ifndef VKHAIR_RENDER_GLSL
#define VKHAIR_RENDER_GLSL

#include "hash.glsl"

// Push constants of the smoothing pass. Twin: gpu_types::SmoothPush.
struct SmoothPush {
    uint strands;         // key hairs
    uint points;          // points per key hair
    uint level;           // smoothed segments per key segment
    uint stride;          // smoothed vertices per key hair: (points − 1)·level + 1
    float alpha;          // 0: the state before the latest step, 1: the latest
};

// Push constants of the interpolation pass. Twin: gpu_types::InterpolatePush.
struct InterpolatePush {
    vec4 head_rotation;   // unit quaternion (xyz, w): world from head
    uint strands;         // key hairs
    uint points;          // points per key hair
    uint level;           // smoothed segments per key segment
    uint stride;          // smoothed vertices per hair
    uint hairs;           // interpolated hairs per key hair
    float clump_width;    // offset radius scale (m)
    float root_width;     // fraction of clump_width at the root
    float tip_width;      // fraction of clump_width at the tip
};

// One follower's guides and weights (render::Followers). Twin:
// gpu_types::FollowerBinding.
struct FollowerBinding {
    uvec4 guides;         // three guide indices (w unused)
    vec4 weights;         // their weights, summing to 1 (w unused)
};

// Interpolated hair `first + i` of the isoline at tessellation coordinate y
// among `lines` isolines (y = i / lines): the hair an evaluation of the
// interpolation pass stores.
uint isoline_hair(uint first, float y, uint lines) {
    return first + min(uint(y * float(lines) + 0.5), lines - 1u);
}

vec3 quat_rotate(vec4 q, vec3 v) {
    vec3 t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

// The stable random clump coordinate of interpolated hair `hair` of key `key`:
// uniform in the unit disk, the same every frame.
vec2 clump_coordinate(uint key, uint hair) {
    uint seed = key * INTERPOLATE_MAX_HAIRS_PER_KEY + hair;
    float r = sqrt(hash_unit(seed * 2u + 0x9e3779b9u));
    float a = 6.28318530718 * hash_unit(seed * 2u + 0x7f4a7c15u);
    return r * vec2(cos(a), sin(a));
}

// Stable random barycentric weights of hair `hair` of scalp triangle `tri`:
// uniform over the triangle (the square-root warp), summing to 1.
vec3 barycentric_weights(uint tri, uint hair) {
    uint seed = tri * INTERPOLATE_MAX_HAIRS_PER_KEY + hair;
    float r1 = sqrt(hash_unit(seed * 2u + 0x51ed270bu));
    float r2 = hash_unit(seed * 2u + 0x2545f491u);
    float u = 1.0 - r1;
    float v = r1 * (1.0 - r2);
    return vec3(u, v, 1.0 - u - v);
}

// Offset frame of a key vertex: B1 = the reference with its tangent part
// removed, B2 = T × B1. The reference is the key hair's rest-plane normal turned
// with the head, nearly perpendicular to the strand wherever it bends, so the
// frame does not flip.
void key_frame(vec3 t, vec3 reference, out vec3 b1, out vec3 b2) {
    vec3 r = reference - dot(reference, t) * t;
    float len = length(r);
    if (len < 1e-4) {
        vec3 any_axis = abs(t.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        r = any_axis - dot(any_axis, t) * t;
        len = length(r);
    }
    b1 = r / len;
    b2 = cross(t, b1);
}

// MAX_LIGHTS (render::MAX_LIGHTS) is injected by build.rs from src/limits.rs,
// the LIGHT_* kinds and SHADING_* models from src/codes.rs.

// One light. Twin: gpu_types::GpuLight.
struct Light {
    vec4 position_kind;   // xyz position (point, spot), w kind (LIGHT_*)
    vec4 direction_cone;  // xyz direction the light travels (directional, spot), w cos(outer half-angle)
    vec4 color_range;     // rgb color × intensity, w cos(inner half-angle) (spot)
};

// Uniform block of the draw pass. Twin: gpu_types::DrawParams.
struct DrawParams {
    mat4 view_proj;       // world → clip
    vec4 camera;          // xyz camera position, w world size of one pixel at distance 1
    vec4 root_color;      // rgb albedo at the root, a ambient
    vec4 tip_color;       // rgb albedo at the tip, a diffuse wrap (0..1)
    vec4 primary;         // rgb primary highlight color, w exponent
    vec4 secondary;       // rgb secondary highlight color, w exponent
    vec4 shifts;          // x primary shift, y secondary shift, z shift jitter, w highlight breakup
    vec4 widths;          // x root width (m), y tip width (m), z least width (pixels), w 1: hairs have their own albedo (hair_looks)
    vec4 coverage;        // x 1 for transparent strands (coverage, no least width), y opacity, z hairs a strand stands for, w unused
    vec4 band;            // x spacing of the drawn strands at the root (m), y at the tip (m), zw unused
    uvec4 counts;         // x hairs, y vertices per hair, z lights, w shading mode (0 Kajiya-Kay, 1 Marschner)
    Light lights[MAX_LIGHTS];
};

// A transparent strand's band at one of its vertices (reference::strand_band):
// from the width of one hair there (m), the hairs the strand stands for, the
// drawn strands' spacing there (m) and the world size of a pixel there (m):
// x half the drawn ribbon's width (m; the band at least a pixel wide, plus half
// a pixel each side), y half the band's true width (pixels), z its density, the
// fraction of the band its hairs at random across it cover. Shared by the
// ribbons (ribbon.vert) and the rectangle they reach (hair_rect.comp).
vec3 coverage_band(float hair_width, float hairs, float spacing, float pixel) {
    float n = max(hairs, 1.0);
    float spread = (1.0 - 1.0 / n) * spacing;
    float width = max(n * hair_width, min(spread, float(BAND_MAX_SPREAD) * n * hair_width));
    float density = width > 0.0 ? 1.0 - pow(max(1.0 - hair_width / width, 0.0), n) : 0.0;
    float half_true = 0.5 * width / pixel;
    return vec3((max(half_true, 0.5) + 0.5) * pixel, half_true, density);
}

// Uniform cubic B-spline basis at u and its derivative (weights of p0..p3).
void bspline_basis(float u, out vec4 b, out vec4 db) {
    float u2 = u * u;
    float u3 = u2 * u;
    float v = 1.0 - u;
    b = vec4(v * v * v, 3.0 * u3 - 6.0 * u2 + 4.0, -3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0, u3) / 6.0;
    db = vec4(-v * v, 3.0 * u2 - 4.0 * u, -3.0 * u2 + 2.0 * u + 1.0, u2) * 0.5;
}

#endif
