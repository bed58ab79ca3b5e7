#version 460
// Volume stage, last step — grid to particles, per particle (pinned particles
// and particles outside the grid keep their velocity):
//   FLIP (mode 1):  ṽ = α (v + Lerp(x, v_grid − v*_grid)) + (1 − α) Lerp(x, v_grid)
//   friction (mode 2): v ← (1 − s) v + s V(x) with V the density-weighted mean velocity, then
//     a push down the density gradient where the density exceeds the threshold.
// Lerp samples each component trilinearly on its own face grid.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 3) buffer Vel { vec4 vel[]; };
layout(std430, set = 0, binding = 10) readonly buffer GridPos { vec4 grid_pos[]; };
layout(std430, set = 0, binding = 11) readonly buffer GridVel { vec4 grid_vel[]; };
layout(std430, set = 0, binding = 15) readonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 17) readonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 18) readonly buffer FaceStar { float face_star[]; };

// Trilinear samples of component `axis` at g: x = Lerp(v_grid), y = Lerp(v_grid − v*_grid).
vec2 sample_faces(vec3 g, uint axis) {
    uvec3 fd = vol_face_dims(vol_dims(vp), axis);
    vec3 q = g - 0.5;
    q[axis] += 0.5;
    vec3 base = floor(q);
    precise vec3 t = q - base;
    precise vec2 result = vec2(0.0);
    for (uint k = 0u; k < 8u; ++k) {
        uvec3 corner = uvec3(k & 1u, (k >> 1u) & 1u, k >> 2u);
        ivec3 at = clamp(ivec3(base) + ivec3(corner), ivec3(0), ivec3(fd) - 1);
        precise vec3 w3 = mix(vec3(1.0) - t, t, vec3(corner));
        precise float w = (w3.x * w3.y) * w3.z;
        uint f = vol_face_index(uvec3(at), axis, vol_dims(vp), vol_first_v_face(vp), vol_first_w_face(vp));
        float v = face_vel[f];
        result += vec2(v, v - face_star[f]) * w;
    }
    return result;
}

// Trilinear sample of the cell-centred (momentum, density) at g: the mean velocity
// weighted by density, so that empty cells do not pull velocities toward zero.
vec4 sample_cells(vec3 g) {
    uvec3 dims = vol_dims(vp);
    vec3 q = g - 0.5;
    vec3 base = floor(q);
    precise vec3 t = q - base;
    precise vec4 result = vec4(0.0);
    for (uint k = 0u; k < 8u; ++k) {
        uvec3 corner = uvec3(k & 1u, (k >> 1u) & 1u, k >> 2u);
        ivec3 at = clamp(ivec3(base) + ivec3(corner), ivec3(0), ivec3(dims) - 1);
        precise vec3 w3 = mix(vec3(1.0) - t, t, vec3(corner));
        precise float w = (w3.x * w3.y) * w3.z;
        vec4 cell = cells[vol_cell_index(uvec3(at), dims)];
        result += vec4(cell.xyz * cell.w, cell.w) * w;
    }
    return result;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= vol_particles(vp)) {
        return;
    }
    vec4 gp = grid_pos[i];
    if (gp.w == 0.0 || vol_cell_of(gp.xyz, vol_dims(vp), vol_cells(vp)) == vol_cells(vp)) {
        return;
    }
    vec3 g = gp.xyz;
    precise vec3 v = grid_vel[i].xyz;
    if (vol_mode(vp) == float(VOL_MODE_FLIP)) {
        float alpha = vol_flip_ratio(vp);
        vec2 su = sample_faces(g, 0u);
        vec2 sv = sample_faces(g, 1u);
        vec2 sw = sample_faces(g, 2u);
        precise vec3 pic = vec3(su.x, sv.x, sw.x);
        precise vec3 flip = v + vec3(su.y, sv.y, sw.y);
        v = flip * alpha + pic * (1.0 - alpha);
    } else {
        vec4 cell = sample_cells(g);
        float s = vol_friction(vp);
        if (cell.w > 0.0) {
            precise vec3 mean = cell.xyz / cell.w;
            v = v * (1.0 - s) + mean * s;
        }
        float threshold = vol_repulsion_threshold(vp);
        if (vol_repulsion(vp) > 0.0 && cell.w > threshold) {
            uvec3 dims = vol_dims(vp);
            uvec3 c = min(uvec3(g), dims - 1u);
            vec3 gradient = vec3(0.0);
            for (uint axis = 0u; axis < 3u; ++axis) {
                uvec3 lo = c;
                uvec3 hi = c;
                lo[axis] = c[axis] > 0u ? c[axis] - 1u : 0u;
                hi[axis] = min(c[axis] + 1u, dims[axis] - 1u);
                gradient[axis] = cells[vol_cell_index(hi, dims)].w - cells[vol_cell_index(lo, dims)].w;
            }
            float len = length(gradient);
            if (len > 0.0) {
                float excess = min((cell.w - threshold) / max(threshold, 1e-6), 1.0);
                v = v - gradient * (vol_repulsion(vp) * vol_dt(vp) * excess / len);
            }
        }
    }
    // Back to world axes: the transpose of the rotation.
    mat3 to_grid = mat3(vol_axes(vp));
    vel[i] = vec4(transpose(to_grid) * v, 0.0);
}
