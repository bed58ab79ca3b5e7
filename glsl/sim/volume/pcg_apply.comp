#version 460
// Pressure solve: q = A d, with per-workgroup partials (d·q, 0).
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 21) readonly buffer D { float d[]; };
layout(std430, set = 0, binding = 22) writeonly buffer Q { float q[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    uvec3 dims = vol_dims(vp);
    vec2 local = vec2(0.0);
    if (c < vol_cells(vp)) {
        precise float qc = 0.0;
        uint w = stencil[c];
        if (vol_is_fluid(w)) {
            qc = vol_diagonal(w) * d[c];
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    qc -= d[vol_neighbor_index(c, dims, n)];
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
