#version 460
// Volume stage, steps 1–2 — per particle: its grid position and its velocity
// along the grid axes (kept for the update), the count of its cell, and its
// trilinear weight w and weighted velocity v·w added to the 8 cell centres
// around it and, in FLIP (the friction mode reads only the cells), to the 8
// faces of each axis around it, in fixed point (volume_fixed.glsl): the sums come out the same whatever
// order the particles add in. Particles outside the grid (or not finite) add
// nothing: they are rejected, not clamped. Accumulators: per cell (w, w·vx,
// w·vy, w·vz), then per face (w, w·v_axis), two words each.
//
// The INT64 variant (devices with shaderInt64 and shaderBufferInt64Atomics,
// buffers.rs) adds each value's two words as one 64-bit integer: one atomic
// whose result is not waited for, instead of two 32-bit ones the second of
// which waits for the first's carry — the same sums, bit for bit.
// vkhair variant: VKHAIR_INT64
#ifdef VKHAIR_INT64
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#endif
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 2) readonly buffer Pos { vec4 pos[]; };
layout(std430, set = 0, binding = 3) readonly buffer Vel { vec4 vel[]; };
layout(std430, set = 0, binding = 10) writeonly buffer GridPos { vec4 grid_pos[]; };
layout(std430, set = 0, binding = 11) writeonly buffer GridVel { vec4 grid_vel[]; };
layout(std430, set = 0, binding = 14) buffer Counts { uint counts[]; };
#ifdef VKHAIR_INT64
// The accumulators' word pairs (low, high) as one little-endian 64-bit word each.
layout(std430, set = 0, binding = 31) buffer Accum { uint64_t accum[]; };
#else
layout(std430, set = 0, binding = 31) buffer Accum { uint accum[]; };
#endif
#include "volume_fixed.glsl"

// Corner k (bit 0: +x, bit 1: +y, bit 2: +z) of the 8 grid points around s,
// a position in that grid's own coordinates: the point, inside `extent` or
// not, and its trilinear weight, the product (x · y) · z of 1 − t below and
// t above along each axis (t: s's offset from the point below). Twin:
// `reference::trilinear`.
ivec3 corner_of(vec3 s, uint k, uvec3 extent, out bool inside, out float weight) {
    vec3 below = floor(s);
    precise vec3 t = s - below;
    precise vec3 lower = 1.0 - t;
    bvec3 up = bvec3((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u);
    ivec3 q = ivec3(below) + ivec3(up);
    inside = all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(extent)));
    vec3 a = mix(lower, t, up);
    precise float w = (a.x * a.y) * a.z;
    weight = w;
    return q;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= vol_particles(vp)) {
        return;
    }
    vec4 p = pos[i];
    vec3 g = vol_affine(vol_grid_from_world(vp), p.xyz);
    vec3 v = vol_linear(vol_axes(vp), vel[i].xyz);
    grid_pos[i] = vec4(g, p.w);
    grid_vel[i] = vec4(v, 0.0);
    uvec3 dims = vol_dims(vp);
    uint cell = vol_cell_of(g, dims, vol_cells(vp));
    if (cell == vol_cells(vp)) {
        return;
    }
    atomicAdd(counts[cell], 1u);
    bool flip = vol_mode(vp) == float(VOL_MODE_FLIP);
    // Cell centres (i + ½, j + ½, k + ½) within a cell of g along every axis.
    vec3 s = g - 0.5;
    for (uint k = 0u; k < 8u; ++k) {
        bool inside;
        float w;
        ivec3 q = corner_of(s, k, dims, inside, w);
        if (!inside) {
            continue;
        }
        uint at = VOL_CELL_WORDS * vol_cell_index(uvec3(q), dims);
        vol_fixed_add(at, w);
        vol_fixed_add(at + 2u, v.x * w);
        vol_fixed_add(at + 4u, v.y * w);
        vol_fixed_add(at + 6u, v.z * w);
    }
    if (!flip) {
        return;
    }
    // Faces of each axis: at whole coordinates along it, half ones across.
    uint faces = VOL_CELL_WORDS * vol_cells(vp);
    for (uint axis = 0u; axis < 3u; ++axis) {
        vec3 fs = s;
        fs[axis] = g[axis];
        for (uint k = 0u; k < 8u; ++k) {
            bool inside;
            float w;
            ivec3 q = corner_of(fs, k, vol_face_dims(dims, axis), inside, w);
            if (!inside) {
                continue;
            }
            uint at = faces + VOL_FACE_WORDS * vol_face_index(uvec3(q), axis, dims, vol_first_v_face(vp), vol_first_w_face(vp));
            vol_fixed_add(at, w);
            vol_fixed_add(at + 2u, v[axis] * w);
        }
    }
}
