#version 460
// Volume stage, steps 3–4 — invocation (i, j, k) of a grid one cell larger than
// the cells along every axis reads the fixed-point sums the scatter left
// (scatter.comp) for:
//   - cell (i, j, k): its density (summed weight) and mean velocity, and its
//     label (solid when the centre lies inside a collider or the mesh
//     collider's field, else fluid when a particle lies in it, else air);
//   - in FLIP, the u, v and w faces (i, j, k): velocity = Σ w·v / Σ w (0
//     without weight), or the colliders' velocity next to a solid cell. Faces
//     get the velocity (later projected), a saved pre-projection copy, and the
//     summed weight. (The friction mode reads only the cells: the scatter left
//     it no face sums.)
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std140, set = 0, binding = 1) uniform Colliders { Collider colliders[SIM_MAX_COLLIDERS]; };
layout(std430, set = 0, binding = 14) readonly buffer Counts { uint counts[]; };
layout(std430, set = 0, binding = 15) writeonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 16) writeonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 17) writeonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 18) writeonly buffer FaceStar { float face_star[]; };
layout(std430, set = 0, binding = 19) writeonly buffer FaceWeight { float face_weight[]; };
layout(std430, set = 0, binding = 29) readonly buffer MeshField { float mesh_field[]; };
layout(std430, set = 0, binding = 31) readonly buffer Accum { uint accum[]; };
#include "mesh_sdf.glsl"
#define VOL_FIXED_READ_ONLY
#include "volume_fixed.glsl"

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
    ivec3 ijk = ivec3(vol_cell_coords(t, ext));
    bool has_cell = all(lessThan(ijk, ivec3(dims)));
    // Face a exists when the other two coordinates are inside the grid.
    bvec3 has_face = bvec3(ijk.y < int(dims.y) && ijk.z < int(dims.z), ijk.x < int(dims.x) && ijk.z < int(dims.z),
                           ijk.x < int(dims.x) && ijk.y < int(dims.y));
    bool solid_here = solid_cell(ijk);
    if (has_cell) {
        uint c = vol_cell_index(uvec3(ijk), dims);
        uint at = VOL_CELL_WORDS * c;
        float density = vol_fixed_value(at);
        vec3 momentum = vec3(vol_fixed_value(at + 2u), vol_fixed_value(at + 4u), vol_fixed_value(at + 6u));
        precise vec3 mean = density > 0.0 ? momentum / density : vec3(0.0);
        cells[c] = vec4(mean, density);
        labels[c] = solid_here ? VOL_SOLID : (counts[c] > 0u ? VOL_FLUID : VOL_AIR);
    }
    if (vol_mode(vp) != float(VOL_MODE_FLIP)) {
        return;
    }
    uint faces = VOL_CELL_WORDS * vol_cells(vp);
    for (uint a = 0u; a < 3u; ++a) {
        if (!has_face[a]) {
            continue;
        }
        ivec3 below = ijk;
        below[a] -= 1;
        uint f = vol_face_index(uvec3(ijk), a, dims, vol_first_v_face(vp), vol_first_w_face(vp));
        float weight = vol_fixed_value(faces + VOL_FACE_WORDS * f);
        float sum = vol_fixed_value(faces + VOL_FACE_WORDS * f + 2u);
        precise float u = weight > 0.0 ? sum / weight : 0.0;
        if (solid_here || solid_cell(below)) {
            u = vol_affine(vol_solid_velocity(vp), vol_face_position(uvec3(ijk), a))[a];
        }
        face_vel[f] = u;
        face_star[f] = u;
        face_weight[f] = weight;
    }
}
