#version 460
// Volume stage, step 1 — binning: per particle, the grid position, the velocity
// along the grid axes and the cell id (the cell count for particles outside the
// grid, which the sort puts last and no later kernel reads). Keys and particle
// indices go to the sort.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 2) readonly buffer Pos { vec4 pos[]; };
layout(std430, set = 0, binding = 3) readonly buffer Vel { vec4 vel[]; };
layout(std430, set = 0, binding = 4) writeonly buffer KeysA { uint keys_a[]; };
layout(std430, set = 0, binding = 5) writeonly buffer ValsA { uint vals_a[]; };
layout(std430, set = 0, binding = 10) writeonly buffer GridPos { vec4 grid_pos[]; };
layout(std430, set = 0, binding = 11) writeonly buffer GridVel { vec4 grid_vel[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= vol_particles(vp)) {
        return;
    }
    vec4 p = pos[i];
    vec3 g = vol_affine(vol_grid_from_world(vp), p.xyz);
    vec3 v = vol_linear(vol_axes(vp), vel[i].xyz);
    keys_a[i] = vol_cell_of(g, vol_dims(vp), vol_cells(vp));
    vals_a[i] = i;
    grid_pos[i] = vec4(g, p.w);
    grid_vel[i] = vec4(v, 0.0);
}
