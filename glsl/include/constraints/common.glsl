// What the solver's constraints share (glsl/include/constraints/, one file per
// constraint, listed in src/gpu_types/constraints.rs). Twin:
// src/sim/reference/constraints/mod.rs.
#ifndef VKHAIR_CONSTRAINTS_COMMON_GLSL
#define VKHAIR_CONSTRAINTS_COMMON_GLSL

// One end of a two-point constraint between this invocation's point `own` and
// the point `offset` invocations away, read from half `src` of s_pos. `first`:
// own is the pair's lower index (a). Both ends compute the same correction from
// the same two positions, each keeping its own (`project` in the twin moves
// both at once). Returns own's projected position; own unchanged for offset 0.
vec4 constraint_project_end(vec4 own, uint lid, int offset, bool first, float rest_d, float k, uint src) {
    if (offset == 0) {
        return own;
    }
    vec4 other = s_pos[src][uint(int(lid) + offset)];
    vec4 a = first ? own : other;
    vec4 b = first ? other : own;
    precise float w = a.w + b.w;
    precise vec3 d = b.xyz - a.xyz;
    precise float len = sqrt(dot(d, d));
    if (w > 0.0 && len > 0.0) {
        precise float c = ((len - rest_d) / (len * w)) * k;
        if (first) {
            precise vec3 pa = a.xyz + d * (a.w * c);
            own.xyz = pa;
        } else {
            precise vec3 pb = b.xyz - d * (b.w * c);
            own.xyz = pb;
        }
    }
    return own;
}

#endif
