// Workgroup reduction of (sum, max) pairs, summed in a fixed order so that the
// result is the same on every run. Two ways, one per compiled variant:
// - subgroup arithmetic first, then one value per subgroup through shared
//   memory (needs subgroups of at least 4 lanes in a 256-invocation workgroup);
// - with VKHAIR_SHARED_REDUCE (devices without subgroup arithmetic in compute
//   shaders, or subgroups narrower than 4): a tree through shared memory.
#ifndef VKHAIR_REDUCE_GLSL
#define VKHAIR_REDUCE_GLSL

#ifdef VKHAIR_SHARED_REDUCE

// VOL_GROUP is a power of two (asserted where src/limits.rs defines it).
shared vec2 reduce_values[VOL_GROUP];

// Every invocation of the workgroup must call this; invocation 0 gets the result.
vec2 reduce_sum_max(vec2 value) {
    uint i = gl_LocalInvocationIndex;
    reduce_values[i] = value;
    barrier();
    for (uint stride = VOL_GROUP / 2u; stride > 0u; stride /= 2u) {
        if (i < stride) {
            vec2 other = reduce_values[i + stride];
            reduce_values[i] = vec2(reduce_values[i].x + other.x, max(reduce_values[i].y, other.y));
        }
        barrier();
    }
    return i == 0u ? reduce_values[0] : vec2(0.0);
}

#else

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

#endif
