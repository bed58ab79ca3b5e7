#version 460
// Pressure solve, after the multigrid preconditioner: per-workgroup partials (r·z, max |r|).
#include "volume.glsl"
// vkhair variant: VKHAIR_SHARED_REDUCE
#include "reduce.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 23) readonly buffer Z { float z[]; };
layout(std430, set = 0, binding = 25) readonly buffer R { float r[]; };
layout(std430, set = 0, binding = 27) writeonly buffer Partials { vec2 partials[]; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    vec2 local = vec2(0.0);
    if (c < vp.dims.w) {
        local = vec2(r[c] * z[c], abs(r[c]));
    }
    vec2 total = reduce_sum_max(local);
    if (gl_LocalInvocationIndex == 0u) {
        partials[gl_WorkGroupID.x] = total;
    }
}
