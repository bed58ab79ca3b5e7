// Workgroup reduction of (sum, max) pairs: subgroup operations first, then one
// value per subgroup through shared memory, summed in a fixed order so that the
// result is the same on every run.
#ifndef VKHAIR_REDUCE_GLSL
#define VKHAIR_REDUCE_GLSL

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// Enough for subgroups of 4 lanes in a 256-invocation workgroup.
shared vec2 reduce_partials[64];

// Every invocation of the workgroup must call this; invocation 0 gets the result.
vec2 reduce_sum_max(vec2 value) {
    float s = subgroupAdd(value.x);
    float m = subgroupMax(value.y);
    if (subgroupElect()) {
        reduce_partials[gl_SubgroupID] = vec2(s, m);
    }
    barrier();
    vec2 total = vec2(0.0);
    if (gl_LocalInvocationIndex == 0u) {
        for (uint k = 0u; k < gl_NumSubgroups; ++k) {
            total.x += reduce_partials[k].x;
            total.y = max(total.y, reduce_partials[k].y);
        }
    }
    return total;
}

#endif
