#version 460
// Trivial compute kernel used to check the compute path end to end:
// dst[i] = scale * src[i] + bias for i < count.
#include "common.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Src { float src[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Dst { float dst[]; };
layout(push_constant) uniform Push { ScaleAddPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    dst[i] = pc.scale * src[i] + pc.bias;
}
