#version 460
// Stage 1 — forces and prediction, one invocation per particle:
//   a  = gravity + wind·(1 + turbulence·noise) + spring·(rest_world − x)   (each switchable)
//   v* = v + dt·a,  x* = x + dt·v*
// Pinned particles (inverse mass 0) follow the head: x* = head · rest.
#include "sim.glsl"

layout(local_size_x = SIM_WORKGROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { SimStepParams params; };
layout(std430, set = 0, binding = 1) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = 2) readonly buffer VelIn { vec4 vel_in[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Predicted { vec4 predicted[]; };
layout(std430, set = 0, binding = 5) readonly buffer Rest { vec4 rest[]; };

void main() {
    uint points = params.counts.y;
    uint index = gl_GlobalInvocationID.x;
    if (index >= params.counts.x * points) {
        return;
    }
    uint strand = index / points;
    uint flags = params.counts.w;
    float dt = params.gravity_dt.w;
    vec4 x = pos_in[index];
    vec3 rest_world = sim_transform_point(params.head, rest[index].xyz);
    if (x.w == 0.0) {
        predicted[index] = vec4(rest_world, 0.0);
        return;
    }
    precise vec3 a = vec3(0.0);
    if ((flags & SIM_GRAVITY) != 0u) {
        a = a + params.gravity_dt.xyz;
    }
    if ((flags & SIM_WIND) != 0u) {
        precise float gust = 1.0 + params.wind.w * sim_noise(params.wind_noise.y * params.wind_noise.x, strand);
        a = a + params.wind.xyz * gust;
    }
    if ((flags & SIM_SPRING) != 0u) {
        a = a + (rest_world - x.xyz) * params.wind_noise.z;
    }
    precise vec3 v = vel_in[index].xyz + a * dt;
    precise vec3 p = x.xyz + v * dt;
    predicted[index] = vec4(p, x.w);
}
