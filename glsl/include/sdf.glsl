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

// Words of a grid line's crossing marks (sign_mark.comp, sign.comp): a bit
// per point of the longest axis. Twin: MeshCollider::build's marks buffer.
uint sdf_mark_words(uvec3 dims) {
    return (max(dims.x, max(dims.y, dims.z)) + 31u) / 32u;
}

// The ray of grid line (i, j) of the (u, v) plane: its u and v coordinates,
// nudged off the lattice by 0.001 and 0.002 cells so that it misses edges
// and vertices.
vec2 sdf_ray(uint i, uint j, uint u, uint v, vec3 origin, float cell) {
    precise float ou = origin[u] + (float(i) + 1e-3) * cell;
    precise float ov = origin[v] + (float(j) + 2e-3) * cell;
    return vec2(ou, ov);
}

// The first point of a line beyond the crossing of its ray with triangle
// (a, b, c) along `axis` (w · cell > depth − ow), or nw where the ray misses
// the triangle or crosses it beyond the last point. Twin: MeshSdf's ray parity.
uint sdf_crossing(vec3 a, vec3 b, vec3 c, vec2 ray, uint axis, uint u, uint v, float ow, float cell, uint nw) {
    float ou = ray.x;
    float ov = ray.y;
    // Edge functions of the projection onto the (u, v) plane.
    precise float w0 = (c[u] - b[u]) * (ov - b[v]) - (c[v] - b[v]) * (ou - b[u]);
    precise float w1 = (a[u] - c[u]) * (ov - c[v]) - (a[v] - c[v]) * (ou - c[u]);
    precise float w2 = (b[u] - a[u]) * (ov - a[v]) - (b[v] - a[v]) * (ou - a[u]);
    bool positive = w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0;
    bool negative = w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0;
    precise float area = w0 + w1 + w2;
    if (!(positive || negative) || area == 0.0) {
        return nw;
    }
    precise float depth = (w0 * a[axis] + w1 * b[axis] + w2 * c[axis]) / area;
    precise float h = depth - ow;
    int first = int(clamp(floor(h / cell), 0.0, float(nw)));
    while (first > 0 && float(first - 1) * cell > h) {
        first--;
    }
    while (first < int(nw) && !(float(first) * cell > h)) {
        first++;
    }
    return uint(first);
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

// Which side of triangle (a, b, c) p lies on when its closest point is inside
// the face, not on an edge or a corner: -1 behind it (against the normal of
// its winding), 1 in front, 0 otherwise. As `face_side` in src/groom/sdf.rs.
float sdf_face_side(vec3 p, vec3 a, vec3 b, vec3 c) {
    precise vec3 ab = b - a;
    precise vec3 ac = c - a;
    precise vec3 ap = p - a;
    precise vec3 bp = p - b;
    precise vec3 cp = p - c;
    precise float d1 = sdf_dot(ab, ap);
    precise float d2 = sdf_dot(ac, ap);
    precise float d3 = sdf_dot(ab, bp);
    precise float d4 = sdf_dot(ac, bp);
    precise float d5 = sdf_dot(ab, cp);
    precise float d6 = sdf_dot(ac, cp);
    precise float va = d3 * d6 - d5 * d4;
    precise float vb = d5 * d2 - d1 * d6;
    precise float vc = d1 * d4 - d3 * d2;
    if (!(va > 0.0 && vb > 0.0 && vc > 0.0)) {
        return 0.0;
    }
    precise vec3 n = vec3(ab.y * ac.z - ab.z * ac.y, ab.z * ac.x - ab.x * ac.z, ab.x * ac.y - ab.y * ac.x);
    precise float s = sdf_dot(n, ap);
    return s < 0.0 ? -1.0 : (s > 0.0 ? 1.0 : 0.0);
}

#endif
