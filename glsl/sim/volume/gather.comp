#version 460
// Volume stage, steps 4–5 in one pass — invocation (i, j, k) of a grid one cell
// larger than the cells along every axis visits the particles of the 3 × 3 × 3
// cells around cell (i, j, k) once and accumulates, each with trilinear weights:
//   - the density and mean velocity around the centre of cell (i, j, k), and its
//     label (solid when the centre lies inside a collider or the mesh
//     collider's field, else fluid when a
//     particle lies in it, else air);
//   - the u, v and w faces (i, j, k) — each component on its own grid, shifted
//     by half a cell — whose supports (2 × 3 × 3 cells) lie inside those 27.
// A face next to a solid cell takes the colliders' velocity instead. Faces get
// the velocity (later projected), a saved pre-projection copy, and the summed
// weight. Cells are visited z, then y, then x, so every sum adds its terms in
// the order the CPU reference does.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std140, set = 0, binding = 1) uniform Colliders { Collider colliders[SIM_MAX_COLLIDERS]; };
layout(std430, set = 0, binding = 4) readonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 12) readonly buffer SortedPos { vec4 sorted_pos[]; };
layout(std430, set = 0, binding = 13) readonly buffer SortedVel { vec4 sorted_vel[]; };
layout(std430, set = 0, binding = 14) readonly buffer Start { uint start[]; };
layout(std430, set = 0, binding = 15) writeonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 16) writeonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 17) writeonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 18) writeonly buffer FaceStar { float face_star[]; };
layout(std430, set = 0, binding = 19) writeonly buffer FaceWeight { float face_weight[]; };
layout(std430, set = 0, binding = 29) readonly buffer MeshField { float mesh_field[]; };
#include "mesh_sdf.glsl"

bool inside_collider(vec3 p) {
    for (uint k = 0u; k < vol_colliders(vp); ++k) {
        Collider c = colliders[k];
        vec3 closest = collider_a(c);
        if (collider_kind(c) == float(COLLIDER_CAPSULE)) {
            vec3 ab = collider_b(c) - collider_a(c);
            float len2 = dot(ab, ab);
            float t = len2 > 0.0 ? clamp(dot(p - collider_a(c), ab) / len2, 0.0, 1.0) : 0.0;
            closest = collider_a(c) + ab * t;
        }
        vec3 d = p - closest;
        if (dot(d, d) < collider_radius(c) * collider_radius(c)) {
            return true;
        }
    }
    return false;
}

// Whether cell q (possibly outside the grid, which is never solid) is solid.
bool solid_cell(ivec3 q) {
    if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(vol_dims(vp))))) {
        return false;
    }
    vec3 centre = vec3(q) + 0.5;
    if (vol_mesh_solid(vp) == 1u && mesh_sample(MeshGrid(vol_mesh_origin(vp), vol_mesh_cell(vp), vol_mesh_dims(vp)), vol_affine(vol_mesh_from_grid(vp), centre)).w < 0.0) {
        return true;
    }
    return inside_collider(vol_affine(vol_world_from_grid(vp), centre));
}

void main() {
    uvec3 dims = vol_dims(vp);
    uvec3 ext = dims + 1u;
    uint t = gl_GlobalInvocationID.x;
    if (t >= ext.x * ext.y * ext.z) {
        return;
    }
    uint n = vol_particles(vp);
    ivec3 ijk = ivec3(vol_cell_coords(t, ext));
    bool has_cell = all(lessThan(ijk, ivec3(dims)));
    // Face a exists when the other two coordinates are inside the grid.
    bvec3 has_face = bvec3(ijk.y < int(dims.y) && ijk.z < int(dims.z), ijk.x < int(dims.x) && ijk.z < int(dims.z),
                           ijk.x < int(dims.x) && ijk.y < int(dims.y));
    vec3 centre = vec3(ijk) + 0.5;
    precise float density = 0.0;
    precise vec3 momentum = vec3(0.0);
    precise vec3 sums = vec3(0.0);
    precise vec3 weights = vec3(0.0);
    for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                ivec3 q = ijk + ivec3(dx, dy, dz);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(dims)))) {
                    continue;
                }
                // Face a's support spans cells −1..0 along a.
                bvec3 in_face = bvec3(has_face.x && dx <= 0, has_face.y && dy <= 0, has_face.z && dz <= 0);
                if (!has_cell && !any(in_face)) {
                    continue;
                }
                uint cell = vol_cell_index(uvec3(q), dims);
                for (uint s = start[cell]; s < n && keys_a[s] == cell; ++s) {
                    vec3 p = sorted_pos[s].xyz;
                    vec3 v = sorted_vel[s].xyz;
                    if (has_cell) {
                        float w = vol_weight(p - centre);
                        density += w;
                        momentum += v * w;
                    }
                    for (uint a = 0u; a < 3u; ++a) {
                        if (in_face[a]) {
                            vec3 x = centre;
                            x[a] -= 0.5;
                            float w = vol_weight(p - x);
                            weights[a] += w;
                            sums[a] += v[a] * w;
                        }
                    }
                }
            }
        }
    }
    bool solid_here = solid_cell(ijk);
    if (has_cell) {
        precise vec3 mean = density > 0.0 ? momentum / density : vec3(0.0);
        uint c = vol_cell_index(uvec3(ijk), dims);
        cells[c] = vec4(mean, density);
        labels[c] = solid_here ? VOL_SOLID : (start[c] < n ? VOL_FLUID : VOL_AIR);
    }
    for (uint a = 0u; a < 3u; ++a) {
        if (!has_face[a]) {
            continue;
        }
        ivec3 below = ijk;
        below[a] -= 1;
        vec3 x = centre;
        x[a] -= 0.5;
        precise float u = weights[a] > 0.0 ? sums[a] / weights[a] : 0.0;
        if (solid_here || solid_cell(below)) {
            u = vol_affine(vol_solid_velocity(vp), x)[a];
        }
        uint f = vol_face_index(uvec3(ijk), a, dims, vol_first_v_face(vp), vol_first_w_face(vp));
        face_vel[f] = u;
        face_star[f] = u;
        face_weight[f] = weights[a];
    }
}
