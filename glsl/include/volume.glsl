// Declarations shared by the volume (FLIP) stage, glsl/sim/volume/*.comp.
//
// Grid coordinates are in cells: cell (i, j, k) covers [i, i+1) × [j, j+1) ×
// [k, k+1), its pressure sample sits at the centre (i+½, j+½, k+½). The MAC
// faces carry one velocity component each: the u face (i, j, k) sits at
// (i, j+½, k+½) between cells i−1 and i, and likewise for v and w. Velocities
// are expressed along the grid's axes (which turn with the head), in m/s.
//
// Cell index  c = i + nx·(j + ny·k).
// Face index  offset[a] + i + fx·(j + fy·k) with (fx, fy, fz) = dims + e_a;
// the u faces come first, then v, then w.
#ifndef VKHAIR_VOLUME_GLSL
#define VKHAIR_VOLUME_GLSL

#include "sim.glsl"
#include "views.glsl"

// The packed blocks below are read only through the accessors of their views
// (views.glsl, generated from src/gpu_types/views.rs): `vol_*(p)` for
// VolumeParams; for VolumePush, which means something else to each kernel
// family, `reduce_*`, `level_*`, `mg_smooth_*` and
// `mg_coarsest_*`. The VOL_* codes (cell labels, modes, preconditioners,
// statuses, stencil bits: src/codes.rs), the workgroup size VOL_GROUP and the
// transfer's words per cell and face, VOL_CELL_WORDS and VOL_FACE_WORDS
// (src/limits.rs), are injected by build.rs.

// Per-sub-step parameters (uniform block, binding 0). Twin:
// gpu_types::GpuVolumeParams, view gpu_types::VolumeStep.
struct VolumeParams {
    mat4 grid_from_world;
    mat4 world_from_grid;
    mat4 axes;
    mat4 solid_velocity;
    uvec4 dims;
    uvec4 counts;
    vec4 transfer;
    vec4 solve;
    uvec4 config;
    mat4 mesh_from_grid;
    vec4 mesh_grid;
    uvec4 mesh_dims;
};

// Push constants shared by the volume kernels. Twin: gpu_types::VolumePush.
struct VolumePush {
    uvec4 dims;
    uvec4 coarse;
    uvec4 op;
};

// Scalars of the conjugate-gradient solve, kept on the GPU between kernels.
struct PcgScalars {
    float sigma;       // r·z of the current iteration
    float alpha;
    float beta;
    float bmax;        // max |b| (right-hand side)
    float rmax;        // max |r| after the latest iteration
    uint iterations;   // iterations done
    uint converged;    // 1 once the residual is below tolerance (or the solve stopped)
    uint status;       // VOL_STATUS_*
};

// m · (p, 1) written out so that the CPU reference can match the rounding.
vec3 vol_affine(mat4 m, vec3 p) {
    precise vec3 r = ((m[0].xyz * p.x + m[1].xyz * p.y) + m[2].xyz * p.z) + m[3].xyz;
    return r;
}

// m · (v, 0).
vec3 vol_linear(mat4 m, vec3 v) {
    precise vec3 r = (m[0].xyz * v.x + m[1].xyz * v.y) + m[2].xyz * v.z;
    return r;
}

uint vol_cell_index(uvec3 c, uvec3 dims) {
    return c.x + dims.x * (c.y + dims.y * c.z);
}

uvec3 vol_cell_coords(uint c, uvec3 dims) {
    return uvec3(c % dims.x, (c / dims.x) % dims.y, c / (dims.x * dims.y));
}

// The cell holding grid position g, or `dims.w`-style `outside` when g is outside
// the grid (or not finite).
uint vol_cell_of(vec3 g, uvec3 dims, uint outside) {
    if (all(greaterThanEqual(g, vec3(0.0))) && all(lessThan(g, vec3(dims)))) {
        return vol_cell_index(min(uvec3(g), dims - 1u), dims);
    }
    return outside;
}

// Axis of face f, given the first v and w faces (the u faces come first).
uint vol_face_axis(uint f, uint first_v, uint first_w) {
    return f < first_v ? 0u : (f < first_w ? 1u : 2u);
}

uvec3 vol_face_dims(uvec3 dims, uint axis) {
    uvec3 d = dims;
    d[axis] += 1u;
    return d;
}

// Index of face ijk of `axis`, given the first v and w faces.
uint vol_face_index(uvec3 ijk, uint axis, uvec3 dims, uint first_v, uint first_w) {
    uint base = axis == 0u ? 0u : (axis == 1u ? first_v : first_w);
    uvec3 fd = vol_face_dims(dims, axis);
    return base + ijk.x + fd.x * (ijk.y + fd.y * ijk.z);
}

// Position of a face in grid coordinates.
vec3 vol_face_position(uvec3 ijk, uint axis) {
    vec3 p = vec3(ijk) + 0.5;
    p[axis] -= 0.5;
    return p;
}

// Neighbour n (0..5: −x, +x, −y, +y, −z, +z) of cell ijk, or −1 outside the grid.
int vol_neighbor(uvec3 ijk, uvec3 dims, uint n) {
    uint axis = n >> 1u;
    ivec3 c = ivec3(ijk);
    c[axis] += (n & 1u) == 0u ? -1 : 1;
    if (c[axis] < 0 || c[axis] >= int(dims[axis])) {
        return -1;
    }
    return int(vol_cell_index(uvec3(c), dims));
}

#endif
