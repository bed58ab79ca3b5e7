#version 460
// Pressure solve: d = z + β d.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 21) buffer D { float d[]; };
layout(std430, set = 0, binding = 23) readonly buffer Z { float z[]; };
layout(std430, set = 0, binding = 26) readonly buffer Scalars { PcgScalars scalars; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= vol_cells(vp)) {
        return;
    }
    precise float dc = z[c] + scalars.beta * d[c];
    d[c] = dc;
}
