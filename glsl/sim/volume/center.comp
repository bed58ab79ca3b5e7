#version 460
// Volume stage, step 4 — per cell: density and mean velocity gathered from the
// particles of the 27 surrounding cells with trilinear weights around the cell
// centre, and the cell's label: solid when its centre lies inside a collider,
// else fluid when a particle lies in it, else air.
#include "volume.glsl"

layout(local_size_x = 256) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std140, set = 0, binding = 1) uniform Colliders { Collider colliders[SIM_MAX_COLLIDERS]; };
layout(std430, set = 0, binding = 4) readonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 12) readonly buffer SortedPos { vec4 sorted_pos[]; };
layout(std430, set = 0, binding = 13) readonly buffer SortedVel { vec4 sorted_vel[]; };
layout(std430, set = 0, binding = 14) readonly buffer Start { uint start[]; };
layout(std430, set = 0, binding = 15) writeonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 16) writeonly buffer Labels { uint labels[]; };

bool inside_collider(vec3 p) {
    for (uint k = 0u; k < vp.config.w; ++k) {
        Collider c = colliders[k];
        vec3 closest = c.a_radius.xyz;
        if (c.b_kind.w > 0.5) {
            vec3 ab = c.b_kind.xyz - c.a_radius.xyz;
            float len2 = dot(ab, ab);
            float t = len2 > 0.0 ? clamp(dot(p - c.a_radius.xyz, ab) / len2, 0.0, 1.0) : 0.0;
            closest = c.a_radius.xyz + ab * t;
        }
        vec3 d = p - closest;
        if (dot(d, d) < c.a_radius.w * c.a_radius.w) {
            return true;
        }
    }
    return false;
}

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = vp.dims.xyz;
    uint n = vp.counts.x;
    if (c >= vp.dims.w) {
        return;
    }
    ivec3 ijk = ivec3(vol_cell_coords(c, dims));
    vec3 centre = vec3(ijk) + 0.5;
    precise float density = 0.0;
    precise vec3 momentum = vec3(0.0);
    for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                ivec3 q = ijk + ivec3(dx, dy, dz);
                if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(dims)))) {
                    continue;
                }
                uint cell = vol_cell_index(uvec3(q), dims);
                for (uint s = start[cell]; s < n && keys_a[s] == cell; ++s) {
                    float w = vol_weight(sorted_pos[s].xyz - centre);
                    density += w;
                    momentum += sorted_vel[s].xyz * w;
                }
            }
        }
    }
    uint label = start[c] < n ? VOL_FLUID : VOL_AIR;
    if (inside_collider(vol_affine(vp.world_from_grid, centre))) {
        label = VOL_SOLID;
    }
    precise vec3 mean = density > 0.0 ? momentum / density : vec3(0.0);
    cells[c] = vec4(mean, density);
    labels[c] = label;
}
