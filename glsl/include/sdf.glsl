// Declarations shared by the mesh collider's build kernels (glsl/sim/sdf/*.comp).
// The CPU reference is src/groom/sdf.rs (MeshSdf): the same grid, the same
// seeds, the same jump-flooding passes and tie-break, the same rays.
#ifndef VKHAIR_SDF_GLSL
#define VKHAIR_SDF_GLSL

#include "views.glsl"

// Push constants of every build kernel, read through the accessors of their
// view, `sdf_pass_*(pc)` (views.glsl). Twin: gpu_types::SdfPush, view
// gpu_types::SdfPass. SDF_NONE, the "no triangle yet" word, is injected by
// build.rs from src/codes.rs.
struct SdfPush {
    vec4 origin_cell;
    uvec4 dims;
    uvec4 pass_info;
};

uvec3 sdf_grid_point(uint k, uvec3 dims) {
    return uvec3(k % dims.x, (k / dims.x) % dims.y, k / (dims.x * dims.y));
}

uint sdf_index(uvec3 g, uvec3 dims) {
    return (g.z * dims.y + g.y) * dims.x + g.x;
}

vec3 sdf_point(uvec3 g, vec3 origin, float cell) {
    precise vec3 p = origin + vec3(g) * cell;
    return p;
}

float sdf_dot(vec3 a, vec3 b) {
    precise float r = (a.x * b.x + a.y * b.y) + a.z * b.z;
    return r;
}

float sdf_length(vec3 a) {
    precise float r = sqrt(sdf_dot(a, a));
    return r;
}

// Distance from p to triangle (a, b, c): the closest point by Voronoi region
// (vertex, edge or face), as `triangle_distance` in src/groom/sdf.rs.
float sdf_triangle_distance(vec3 p, vec3 a, vec3 b, vec3 c) {
    precise vec3 ab = b - a;
    precise vec3 ac = c - a;
    precise vec3 ap = p - a;
    precise float d1 = sdf_dot(ab, ap);
    precise float d2 = sdf_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return sdf_length(ap);
    }
    precise vec3 bp = p - b;
    precise float d3 = sdf_dot(ab, bp);
    precise float d4 = sdf_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return sdf_length(bp);
    }
    precise float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        precise float v = d1 / (d1 - d3);
        return sdf_length(p - (a + ab * v));
    }
    precise vec3 cp = p - c;
    precise float d5 = sdf_dot(ab, cp);
    precise float d6 = sdf_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return sdf_length(cp);
    }
    precise float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        precise float w = d2 / (d2 - d6);
        return sdf_length(p - (a + ac * w));
    }
    precise float va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        precise float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return sdf_length(p - (b + (c - b) * w));
    }
    precise float denom = 1.0 / (va + vb + vc);
    precise float v = vb * denom;
    precise float w = vc * denom;
    return sdf_length(p - (a + ab * v + ac * w));
}

#endif
