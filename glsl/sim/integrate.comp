#version 460
// Stage 3 — velocity from the position change, damping, final state:
//   v = (x_solved − x_old) / dt  [+ s·(−d_{i+1}) / dt in DFTL mode],  v *= 1 − damping
// written to the other half of the double-buffered state.
#include "sim.glsl"

layout(local_size_x = SIM_WORKGROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { SimStepParams params; };
layout(std430, set = 0, binding = 1) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = 3) readonly buffer Predicted { vec4 predicted[]; };
layout(std430, set = 0, binding = 4) readonly buffer Correction { vec4 correction[]; };
layout(std430, set = 0, binding = 8) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = 9) writeonly buffer VelOut { vec4 vel_out[]; };

void main() {
    uint points = params.counts.y;
    uint index = gl_GlobalInvocationID.x;
    if (index >= params.counts.x * points) {
        return;
    }
    uint i = index % points;
    float dt = params.gravity_dt.w;
    vec4 solved = predicted[index];
    precise vec3 v = (solved.xyz - pos_in[index].xyz) / dt;
    if ((params.counts.w & SIM_DFTL) != 0u && i + 1u < points) {
        v = v - correction[index + 1u].xyz * (params.bending.z / dt);
    }
    v = v * (1.0 - params.wind_noise.w);
    pos_out[index] = solved;
    vel_out[index] = vec4(v, 0.0);
}
