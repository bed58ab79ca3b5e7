#version 460
// Pressure solve, start: right-hand side b = −(net outflow) of every fluid
// cell (the divergence times the cell size), r = b, pressure 0; with the
// Jacobi preconditioner also z = r / diag. Per-workgroup partials (r·z, max |r|).
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 17) readonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 20) writeonly buffer Pressure { float pressure[]; };
layout(std430, set = 0, binding = 23) writeonly buffer Z { float z[]; };
layout(std430, set = 0, binding = 25) writeonly buffer R { float r[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };
#define VKHAIR_PRESSURE_RHS
#include "pressure_ops.glsl"

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = vol_dims(vp);
    vec2 local = vec2(0.0);
    if (c < vol_cells(vp)) {
        uvec3 ijk = vol_cell_coords(c, dims);
        precise float b = 0.0;
        precise float zc = 0.0;
        uint w = stencil[c];
        if (vol_is_fluid(w)) {
            b = pressure_rhs(ijk, dims);
            if (vol_preconditioner(vp) == VOL_PRECOND_JACOBI) {
                zc = pcg_jacobi(w, b);
            }
        }
        r[c] = b;
        z[c] = zc;
        pressure[c] = 0.0;
        local = vec2(b * zc, abs(b));
    }
    vec2 total = reduce_sum_max(local);
    if (gl_LocalInvocationIndex == 0u) {
        partials[gl_WorkGroupID.x] = total;
    }
}
