#version 460
// Pressure solve: p += α d, r −= α q; with the Jacobi preconditioner also
// z = r / diag and per-workgroup partials (r·z, max |r|).
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 20) buffer Pressure { float pressure[]; };
layout(std430, set = 0, binding = 21) readonly buffer D { float d[]; };
layout(std430, set = 0, binding = 22) readonly buffer Q { float q[]; };
layout(std430, set = 0, binding = 23) writeonly buffer Z { float z[]; };
layout(std430, set = 0, binding = 25) buffer R { float r[]; };
layout(std430, set = 0, binding = 26) readonly buffer Scalars { PcgScalars scalars; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };
#include "pressure_ops.glsl"

void main() {
    uint c = gl_GlobalInvocationID.x;
    vec2 local = vec2(0.0);
    if (c < vol_cells(vp)) {
        float alpha = scalars.alpha;
        precise float pc = pressure[c] + alpha * d[c];
        precise float rc = r[c] - alpha * q[c];
        pressure[c] = pc;
        r[c] = rc;
        if (vol_preconditioner(vp) == VOL_PRECOND_JACOBI) {
            float zc = pcg_jacobi(stencil[c], rc);
            z[c] = zc;
            local = vec2(rc * zc, abs(rc));
        }
    }
    vec2 total = reduce_sum_max(local);
    if (gl_LocalInvocationIndex == 0u) {
        partials[gl_WorkGroupID.x] = total;
    }
}
