#version 460
// Copies LayoutProbe records through a uniform block and a storage buffer,
// transforming each position: the layout test reflects this module and a GPU
// test checks that Rust writes and GLSL reads every member at the same place.
#include "common.glsl"

layout(local_size_x = 32) in;

layout(std430, set = 0, binding = 0) readonly buffer ProbeInput { LayoutProbe probe_in; };
layout(std430, set = 0, binding = 1) buffer ProbeStorage { LayoutProbe probes[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    LayoutProbe p = probe_in;
    p.position = (p.transform * vec4(p.position, 1.0)).xyz + vec3(float(i));
    p.ids = p.ids + uvec2(i);
    p.weights[1] = p.weights[0] + p.radius;
    probes[i] = p;
}
