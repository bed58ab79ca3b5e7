#version 460
// Trivial compute kernel used to check the compute path end to end:
// dst[i] = scale * src[i] + bias · BIAS_TIMES for i < count (BIAS_TIMES: a
// specialisation constant, to check pipeline variants).
#include "common.glsl"

layout(local_size_x = ITEM_GROUP) in;
layout(constant_id = 0) const uint BIAS_TIMES = 1u;

layout(std430, set = 0, binding = 0) readonly buffer Src { float src[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Dst { float dst[]; };
layout(push_constant) uniform Push { ScaleAddPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    dst[i] = pc.scale * src[i] + pc.bias * float(BIAS_TIMES);
}
