#version 460
// Volume stage, step 3 — after the sort (keys and particle indices in A):
// particle data in cell order and the first sorted index of every occupied cell
// (the start array was filled with the particle count beforehand, which marks
// empty cells).
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 4) readonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 5) readonly buffer ValsA { uint vals_a[]; };
layout(std430, set = 0, binding = 10) readonly buffer GridPos { vec4 grid_pos[]; };
layout(std430, set = 0, binding = 11) readonly buffer GridVel { vec4 grid_vel[]; };
layout(std430, set = 0, binding = 12) writeonly buffer SortedPos { vec4 sorted_pos[]; };
layout(std430, set = 0, binding = 13) writeonly buffer SortedVel { vec4 sorted_vel[]; };
layout(std430, set = 0, binding = 14) writeonly buffer Start { uint start[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= vol_particles(vp)) {
        return;
    }
    uint key = keys_a[i];
    uint p = vals_a[i];
    sorted_pos[i] = grid_pos[p];
    sorted_vel[i] = grid_vel[p];
    if (i == 0u || keys_a[i - 1u] != key) {
        start[key] = i;
    }
}
