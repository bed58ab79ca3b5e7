// Roots bound to a skinned scalp (src/sim/scalp.rs), for the kernels that
// place the rest pose per key hair (step.comp, follow.comp, move.comp). The
// including shader declares, before including this file:
//   scalp_roots[]     ScalpRoot per key hair (triangle corners, weights, the
//                     bind-pose triangle frame's inverse),
//   scalp_previous[]  vec4 ×3 per key hair: its triangle's corners at the end
//                     of the previous step (world),
//   scalp_source[]    float: the skinned scalp's vertices this step (world),
//                     vertex v's xyz at sim_scalp_first + v · sim_scalp_stride.
// The CPU reference (sim::scalp) runs the same operations in the same order.
#ifndef VKHAIR_SCALP_GLSL
#define VKHAIR_SCALP_GLSL

// Vertex `v` of the skinned scalp this step.
vec3 scalp_vertex(SimStepParams p, uint v) {
    uint at = sim_scalp_first(p) + v * sim_scalp_stride(p);
    return vec3(scalp_source[at], scalp_source[at + 1u], scalp_source[at + 2u]);
}

// Corner k of key hair h's triangle at `f` of the step (0: where the previous
// step left it, 1: this step's): linear in the corners, as the body's
// colliders move across sub-steps.
vec3 scalp_corner(SimStepParams p, uint h, uint k, float f) {
    vec3 now = scalp_vertex(p, scalp_root_corners(scalp_roots[h])[k]);
    vec3 before = sim_scalp_restart(p) != 0u ? now : scalp_previous[h * 3u + k].xyz;
    precise vec3 c = before * (1.0 - f) + now * f;
    return c;
}

// World from head frame for key hair h at `f` of the step: the triangle's frame
// now (origin the root's bound point, z the unit normal, x the first edge made
// perpendicular to it, y = z × x) times the bind pose's inverse. A collapsed
// triangle (no normal or edge) takes `fallback` (the head).
mat4 scalp_frame(SimStepParams p, uint h, float f, mat4 fallback) {
    vec3 a = scalp_corner(p, h, 0u, f);
    vec3 b = scalp_corner(p, h, 1u, f);
    vec3 c = scalp_corner(p, h, 2u, f);
    vec3 w = scalp_root_weights(scalp_roots[h]);
    precise vec3 origin = (a * w.x + b * w.y) + c * w.z;
    precise vec3 e1 = b - a;
    precise vec3 e2 = c - a;
    precise vec3 n = vec3(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
    precise float n_len = sqrt(sim_dot(n, n));
    if (!(n_len > 0.0)) {
        return fallback;
    }
    precise vec3 z = n / n_len;
    precise vec3 t = e1 - z * sim_dot(z, e1);
    precise float t_len = sqrt(sim_dot(t, t));
    if (!(t_len > 0.0)) {
        return fallback;
    }
    precise vec3 x = t / t_len;
    precise vec3 y = vec3(z.y * x.z - z.z * x.y, z.z * x.x - z.x * x.z, z.x * x.y - z.y * x.x);
    mat4 frame = mat4(vec4(x, 0.0), vec4(y, 0.0), vec4(z, 0.0), vec4(origin, 1.0));
    mat4 u = scalp_root_unbind(scalp_roots[h]);
    return mat4(vec4(sim_rotate(frame, u[0].xyz), 0.0), vec4(sim_rotate(frame, u[1].xyz), 0.0),
                vec4(sim_rotate(frame, u[2].xyz), 0.0), vec4(sim_transform_point(frame, u[3].xyz), 1.0));
}

// At the end of a step's last sub-step: keeps key hair h's corners of this
// step as the next step's previous ones.
void scalp_keep_corners(SimStepParams p, uint h) {
    for (uint k = 0u; k < 3u; k++) {
        scalp_previous[h * 3u + k] = vec4(scalp_vertex(p, scalp_root_corners(scalp_roots[h])[k]), 0.0);
    }
}

#endif
