#version 460
// Mesh collider build, step 1 — seeds, one invocation per triangle, over the
// grid points within 1.5 cells of the triangle's box. Mode 0 keeps each
// point's least distance (float bits of a non-negative float order like
// unsigned integers); mode 1 then keeps, among the triangles at exactly that
// distance, the lowest index. Both are order-independent, so every run and
// the CPU reference pick the same seed.
#include "sdf.glsl"

layout(local_size_x = ITEM_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Corners { vec4 corners[]; };
layout(std430, set = 0, binding = 1) buffer Distance { uint distance_bits[]; };
layout(std430, set = 0, binding = 2) buffer Ids { uint ids[]; };
layout(push_constant) uniform Push { SdfPush pc; };

void main() {
    uint t = gl_GlobalInvocationID.x;
    if (t >= sdf_pass_triangles(pc)) {
        return;
    }
    vec3 a = corners[3u * t].xyz;
    vec3 b = corners[3u * t + 1u].xyz;
    vec3 c = corners[3u * t + 2u].xyz;
    float cell = sdf_pass_cell(pc);
    precise vec3 lo = min(min(a, b), c) - vec3(1.5 * cell);
    precise vec3 hi = max(max(a, b), c) + vec3(1.5 * cell);
    precise vec3 first_f = max(ceil((lo - sdf_pass_origin(pc)) / cell), vec3(0.0));
    precise vec3 last_f = floor((hi - sdf_pass_origin(pc)) / cell);
    uvec3 first = uvec3(first_f);
    // Negative ends saturate to 0, as `as u32` does on the CPU.
    uvec3 last = min(uvec3(max(last_f, vec3(0.0))), sdf_pass_dims(pc) - 1u);
    for (uint z = first.z; z <= last.z; z++) {
        for (uint y = first.y; y <= last.y; y++) {
            for (uint x = first.x; x <= last.x; x++) {
                uvec3 g = uvec3(x, y, z);
                uint k = sdf_index(g, sdf_pass_dims(pc));
                float d = sdf_triangle_distance(sdf_point(g, sdf_pass_origin(pc), sdf_pass_cell(pc)), a, b, c);
                if (sdf_pass_seed_mode(pc) == 0u) {
                    atomicMin(distance_bits[k], floatBitsToUint(d));
                } else if (floatBitsToUint(d) == distance_bits[k]) {
                    atomicMin(ids[k], t);
                }
            }
        }
    }
}
