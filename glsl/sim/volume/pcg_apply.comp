#version 460
// Pressure solve: q = A d, with per-workgroup partials (d·q, 0).
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 16) readonly buffer Labels { uint labels[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 21) readonly buffer D { float d[]; };
layout(std430, set = 0, binding = 22) writeonly buffer Q { float q[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = vp.dims.xyz;
    vec2 local = vec2(0.0);
    if (c < vp.dims.w) {
        precise float qc = 0.0;
        if (labels[c] == VOL_FLUID) {
            int fluid[6];
            float diagonal = vol_stencil(vol_cell_coords(c, dims), dims, 0u, fluid);
            qc = diagonal * d[c];
            for (uint n = 0u; n < 6u; ++n) {
                if (fluid[n] >= 0) {
                    qc -= d[fluid[n]];
                }
            }
        }
        q[c] = qc;
        local = vec2(d[c] * qc, 0.0);
    }
    vec2 total = reduce_sum_max(local);
    if (gl_LocalInvocationIndex == 0u) {
        partials[gl_WorkGroupID.x] = total;
    }
}
