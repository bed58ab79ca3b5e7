// Declarations shared by the simulation kernels (glsl/sim/step.comp and the volume stage).
// The CPU reference (src/sim/reference/) mirrors every function here with
// the same operation order; `precise` keeps the compiler from fusing or
// reordering float operations so both sides round the same way.
#ifndef VKHAIR_SIM_GLSL
#define VKHAIR_SIM_GLSL

#include "hash.glsl"
#include "views.glsl"

// The packed blocks below are read only through the accessors of their views
// (views.glsl, generated from src/gpu_types/views.rs, which names every lane):
// `sim_*(p)` for SimStepParams, `step_range_*(p)` for SimPush, `state_move_*(p)`
// for MovePush, `collider_*(c)` for Collider. The SIM_* switches (src/codes.rs) and SIM_MAX_COLLIDERS and
// SIM_WORKGROUP (src/limits.rs) and SIM_KNOB_VEC4S (src/gpu_types/constraints.rs)
// are injected by build.rs.

// Per-sub-step parameters (one array entry per sub-step, binding 0). Twin:
// gpu_types::SimStepParams, view gpu_types::SimStep.
struct SimStepParams {
    mat4 head;
    vec4 gravity_dt;
    vec4 wind;
    vec4 wind_noise;
    vec4 solver;
    uvec4 counts;
    uvec4 layout_info;
    // The constraints' knobs, one lane each (src/gpu_types/constraints.rs).
    vec4 knobs[SIM_KNOB_VEC4S];
    mat4 previous_head;
    vec4 mesh_grid;
    uvec4 mesh_dims;
    vec4 scalp_lerp;
    uvec4 scalp_source;
};

// A key hair's root on its scalp triangle (one per key hair). Twin:
// gpu_types::GpuScalpRoot, view gpu_types::ScalpRootView.
struct ScalpRoot {
    uvec4 corners;
    vec4 weights;
    mat4 unbind;
};

// Push constants of the step kernel. Twin: gpu_types::SimPush, view gpu_types::StepRange.
struct SimPush {
    uvec4 range;
};

// Push constants of the state move kernel (move.comp). Twin: gpu_types::MovePush,
// view gpu_types::StateMove.
struct MovePush {
    mat4 transform;
    uvec4 info;
};

// One collider in world space. Twin: gpu_types::GpuCollider, view gpu_types::ColliderShape.
struct Collider {
    vec4 a_radius;
    vec4 b_kind;
    vec4 moved_a_friction;
    vec4 moved_b;
};


// head * vec4(p, 1), written out so that the CPU reference can match it.
vec3 sim_transform_point(mat4 m, vec3 p) {
    precise vec3 r = ((m[0].xyz * p.x + m[1].xyz * p.y) + m[2].xyz * p.z) + m[3].xyz;
    return r;
}

// Integer hash to [-1, 1); exact on every device.
float sim_hash(uint x) {
    return hash_unit(x) * 2.0 - 1.0;
}

// Smooth 1D value noise in [-1, 1] along time, one independent track per strand.
float sim_noise(float t, uint strand) {
    precise float cell = floor(t);
    precise float f = t - cell;
    precise float s = f * f * (3.0 - 2.0 * f);
    uint i = uint(int(cell) + 1048576) + strand * 7919u;
    precise float a = sim_hash(i);
    precise float b = sim_hash(i + 1u);
    precise float n = a + (b - a) * s;
    return n;
}

// a · b, in the CPU reference's order.
float sim_dot(vec3 a, vec3 b) {
    precise float r = (a.x * b.x + a.y * b.y) + a.z * b.z;
    return r;
}

// Where along collider c's core the point nearest p lies: 0 for a sphere, the
// parameter along a capsule's segment (0 at a, 1 at b).
float sim_collider_t(Collider c, vec3 p) {
    if (collider_kind(c) != float(COLLIDER_CAPSULE)) {
        return 0.0;
    }
    precise vec3 ab = collider_b(c) - collider_a(c);
    precise float len2 = sim_dot(ab, ab);
    precise float t = len2 > 0.0 ? clamp(sim_dot(p - collider_a(c), ab) / len2, 0.0, 1.0) : 0.0;
    return t;
}

// The point of collider c's core (its centre or segment) at parameter t.
vec3 sim_collider_point(Collider c, float t) {
    if (collider_kind(c) != float(COLLIDER_CAPSULE)) {
        return collider_a(c);
    }
    precise vec3 point = collider_a(c) + (collider_b(c) - collider_a(c)) * t;
    return point;
}

// Projects p out of one collider, keeping a gap of `radius` (the particle's pearl).
vec3 sim_collide(Collider c, vec3 p, float radius) {
    precise vec3 closest = sim_collider_point(c, sim_collider_t(c, p));
    precise vec3 d = p - closest;
    precise float dist = sqrt(sim_dot(d, d));
    precise float reach = collider_radius(c) + radius;
    if (dist < reach && dist > 0.0) {
        precise vec3 out_p = closest + d * (reach / dist);
        return out_p;
    }
    return p;
}

// head⁻¹ · p for a rigid `m` (rotation and translation): Rᵀ(p − t), written out.
vec3 sim_to_head(mat4 m, vec3 p) {
    precise vec3 d = p - m[3].xyz;
    precise float x = (m[0].x * d.x + m[0].y * d.y) + m[0].z * d.z;
    precise float y = (m[1].x * d.x + m[1].y * d.y) + m[1].z * d.z;
    precise float z = (m[2].x * d.x + m[2].y * d.y) + m[2].z * d.z;
    return vec3(x, y, z);
}

// R · v for the rotation of a rigid `m`, written out.
vec3 sim_rotate(mat4 m, vec3 v) {
    precise vec3 r = (m[0].xyz * v.x + m[1].xyz * v.y) + m[2].xyz * v.z;
    return r;
}

// Friction against one collider, on the velocity: a particle at p (its pearl
// `radius`) touching the surface loses the fraction collider_friction(c) of
// its velocity v along the surface relative to the
// surface's own (collider_moved_a/b over the sub-step of `dt` seconds, blended
// along a capsule), less in proportion up to a pearl radius off the surface
// and none beyond, so a moving body carries the hair resting on it; the
// positions, and so the constraints and the non-penetration the solve left,
// are untouched. Twin: `collider_friction` in src/sim/reference/bodies.rs.
vec3 sim_collider_friction(Collider c, vec3 p, vec3 v, float radius, float dt) {
    precise float friction = collider_friction(c);
    if (!(friction > 0.0)) {
        return v;
    }
    precise float t = sim_collider_t(c, p);
    precise vec3 d = p - sim_collider_point(c, t);
    precise float dist = sqrt(sim_dot(d, d));
    precise float reach = collider_radius(c) + radius;
    precise float contact = reach + radius;
    if (!(dist < contact) || !(dist > 0.0)) {
        return v;
    }
    precise vec3 surface = collider_moved_a(c) + (collider_moved_b(c) - collider_moved_a(c)) * t;
    // Whole at the surface, fading to none a pearl radius off it: the velocity
    // does not jump where contact begins.
    precise float share = dist > reach ? (contact - dist) / radius : 1.0;
    precise vec3 n = d / dist;
    precise vec3 relative = v - surface / dt;
    precise vec3 along = relative - n * sim_dot(n, relative);
    precise vec3 held = v - along * (friction * share);
    return held;
}

// v rotated by the smallest rotation taking unit vector a onto unit vector b
// (Rodrigues with axis a × b, unnormalised): v·c + (a×b)×v + (a×b)((a×b)·v)/(1 + c).
// Unchanged when a and b are (nearly) opposite, where that rotation is undefined.
vec3 sim_rotate_between(vec3 a, vec3 b, vec3 v) {
    precise float c = sim_dot(a, b);
    if (c <= -0.999) {
        return v;
    }
    precise vec3 axis = vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
    precise vec3 cross_v = vec3(axis.y * v.z - axis.z * v.y, axis.z * v.x - axis.x * v.z, axis.x * v.y - axis.y * v.x);
    precise vec3 r = (v * c + cross_v) + axis * (sim_dot(axis, v) / (1.0 + c));
    return r;
}

// Weight of the global shape constraint at strand parameter t (0 root, 1 tip):
// 1 up to `range`, falling linearly to 0 over the next quarter of the strand.
float sim_shape_weight(float t, float range) {
    if (t <= range) {
        return 1.0;
    }
    precise float w = (range + 0.25 - t) * 4.0;
    return max(w, 0.0);
}

// The global shape constraint's target for a particle whose rest position is
// `target` (world) and whose per-iteration stiffness is k. With SIM_SAG_FREE
// the target is raised against gravity by the particle's static sag, so that a
// still head holds the authored shape: per sub-step gravity moves a particle
// by g·dt², and N iterations of stiffness k remove the fraction
// s = 1 − (1 − k)^N of its offset, so the offset at rest is g·dt²·(1/s − 1).
// Fractions below 1 % (a nearly free particle) get no compensation.
vec3 sim_shape_target(vec3 target, float k, uint iterations, uint flags, vec3 gravity, float dt) {
    if ((flags & SIM_SAG_FREE) == 0u || (flags & SIM_GRAVITY) == 0u || k <= 0.0) {
        return target;
    }
    precise float keep = 1.0;
    for (uint n = 0u; n < iterations; n++) {
        keep = keep * (1.0 - k);
    }
    precise float s = 1.0 - keep;
    if (s < 0.01) {
        return target;
    }
    precise float f = 1.0 / s - 1.0;
    precise vec3 step_sag = gravity * (dt * dt);
    precise vec3 sag = step_sag * f;
    precise vec3 raised = target - sag;
    return raised;
}

#endif
