#version 460
// The simulation step, one dispatch for every key hair and (with the volume
// stage off) every sub-step of a step: each workgroup holds `hairs per
// workgroup` whole hairs, one invocation per point, loads each point's
// position and velocity once, runs the sub-steps steps[first .. first+count)
// in registers and shared memory, and stores once. Per sub-step:
//
//   1. forces and prediction (own point only):
//        a  = gravity + wind·(1 + turbulence·noise) + spring·(rest_world − x)
//        v* = v + dt·a,  x* = x + dt·v*
//      pinned particles (inverse mass 0) follow the head: x* = head · rest
//      (with SIM_SCALP every "head" here is the key hair's root frame, see
//      glsl/include/scalp.glsl);
//   2. the constraint solve: N iterations of the constraints listed in
//      src/gpu_types/constraints.rs, in that order, each in its own include
//      (glsl/include/constraints/) called through the generated
//      constraint_solve.glsl, with a barrier between the sets. The barrier's
//      scope is the "sync group": the subgroup when every hair fits into one
//      (hairs are packed so none straddles two), else the whole workgroup
//      (barrier()). Today: distance (even, odd segments), bending (two sets of
//      centres), local shape (one sweep per hair, last iteration), global
//      shape and collisions (own point only, sharing the iteration's last
//      barrier), the stretch limit (one sweep per hair, last iteration, when
//      set); then, once per sub-step, friction against the mesh collider;
//   3. velocity from the position change, friction, damping:
//        v = (x_solved − x_old) / dt  [− s·d_{i+1} / dt in DFTL mode],
//        against each sphere and capsule touched: the velocity along its
//        surface relative to the surface's own (its motion over the sub-step)
//        loses the fraction collider_friction,  v *= 1 − damping.
//
// The final state goes to the other half of the double buffer.
//
// Both ends of a constraint compute the same correction from the same two
// positions, and each keeps its own result: every invocation holds its point
// in a register and, per set, reads its partner from one half of a
// double-buffered shared array and writes its own point to the other half, so
// one barrier per set suffices (constraints that touch only the own point share
// the last set's barrier). The arithmetic is exactly that of projecting the
// pair in one place, which the CPU reference does.
//
// The pipeline is specialised (constant 0, STEP_FEATURES) to the switches a
// dispatch can meet: a switch outside it is off whatever the parameters say,
// and its code is compiled out. A CPU device runs both sides of a branch its
// lanes disagree on, so code for switched-off features would cost as much as
// running it; the all-ones default keeps every feature.
//
// DFTL mode instead places each point at its rest distance from its parent,
// root to tip, in one sweep (with collisions) and keeps the correction
// vectors in shared memory for the velocity update.
#extension GL_KHR_shader_subgroup_basic : require
#include "sim.glsl"

layout(local_size_x = SIM_WORKGROUP) in;
layout(constant_id = 0) const uint STEP_FEATURES = 0xFFFFFFFFu;

// x: the first sub-step of this dispatch (index into `steps`), y: how many.
layout(push_constant) uniform Push { SimPush push; };
layout(std430, set = 0, binding = 0) readonly buffer Steps { SimStepParams steps[]; };
layout(std430, set = 0, binding = 1) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = 2) readonly buffer VelIn { vec4 vel_in[]; };
layout(std430, set = 0, binding = 5) readonly buffer Rest { vec4 rest[]; };
layout(std430, set = 0, binding = 6) readonly buffer RestLength { float rest_length[]; };
// SIM_MAX_COLLIDERS entries per sub-step, in the world at that sub-step.
layout(std430, set = 0, binding = 7) readonly buffer Colliders { Collider colliders[]; };
layout(std430, set = 0, binding = 8) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = 9) writeonly buffer VelOut { vec4 vel_out[]; };
layout(std430, set = 0, binding = 10) readonly buffer MeshField { float mesh_field[]; };
// The positions before the step: written by its first sub-step, for drawing
// between the last two states (render's blend by the fixed-step driver's alpha).
layout(std430, set = 0, binding = 11) writeonly buffer PosBefore { vec4 pos_before[]; };
// The key hairs in level-of-detail order (sim/lod.rs): the dispatch simulates
// the first step_range_simulated(push) of them; follow.comp moves the others.
layout(std430, set = 0, binding = 12) readonly buffer SimOrder { uint sim_order[]; };
// With SIM_SCALP: the roots' triangles, their corners after the previous step,
// and the skinned scalp's vertices (glsl/include/scalp.glsl).
layout(std430, set = 0, binding = 14) readonly buffer ScalpRoots { ScalpRoot scalp_roots[]; };
layout(std430, set = 0, binding = 15) buffer ScalpPrevious { vec4 scalp_previous[]; };
layout(std430, set = 0, binding = 16) readonly buffer ScalpSource { float scalp_source[]; };
// A skinned mesh collider's grid points' bones and each sub-step's bone rows
// (glsl/include/mesh_sdf.glsl).
layout(std430, set = 0, binding = 17) readonly buffer MeshSkin { uint mesh_skin[]; };
layout(std430, set = 0, binding = 18) readonly buffer MeshBones { vec4 mesh_bones[]; };
#define VKHAIR_MESH_SKIN
#include "sim_bodies.glsl"
#include "scalp.glsl"

shared vec4 s_pos[2][SIM_WORKGROUP];
// Each point's rest length to its child (DFTL mode keeps its correction
// vectors in the local shape's s_local_offset: the modes do not meet, and the
// step's shared memory bounds how many of its workgroups a multiprocessor holds).
shared float s_length[SIM_WORKGROUP];

// The parameters of the sub-step being run, and where its colliders start.
SimStepParams params;
uint collider_base;
// The own point's radius, and its position at the start of the sub-step.
float own_radius = 0.0;
vec4 own_start = vec4(0.0);

// The switches of the sub-step being run, within the pipeline's features.
uint step_flags() {
    return sim_flags(params) & STEP_FEATURES;
}

// Ends a constraint set: makes every shared-memory write of the sync group visible.
// `group` is uniform over the dispatch, so barrier() stays in uniform control flow.
void sync(uint group) {
    if (group == SIM_WORKGROUP) {
        barrier();
    } else {
        subgroupBarrier();
    }
}

// p projected out of the bodies of the sub-step being run.
vec3 collide_all(vec3 p, float radius) {
    return sim_collide_bodies(params, step_flags(), collider_base, p, radius);
}

// Where the rest pose of key hair `strand` is placed at the end of the
// sub-step being run: the head, or with SIM_SCALP its root's frame.
mat4 hair_frame(uint strand) {
    if ((step_flags() & SIM_SCALP) != 0u) {
        return scalp_frame(params, strand, sim_scalp_to(params), sim_head(params));
    }
    return sim_head(params);
}

#include "constraint_solve.glsl"

// Stage 1 for the own point: its predicted position (w: inverse mass) from the
// position `x` and velocity `v` at the start of the sub-step, its rest
// position placed by `frame`.
vec4 predict(vec4 x, vec3 v, vec3 rest_head, uint strand, mat4 frame) {
    uint flags = step_flags();
    float dt = sim_dt(params);
    vec3 rest_world = sim_transform_point(frame, rest_head);
    if (x.w == 0.0) {
        return vec4(rest_world, 0.0);
    }
    precise vec3 a = vec3(0.0);
    if ((flags & SIM_GRAVITY) != 0u) {
        a = a + sim_gravity(params);
    }
    if ((flags & SIM_WIND) != 0u) {
        precise float gust = 1.0 + sim_wind_turbulence(params) * sim_noise(sim_time(params) * sim_wind_frequency(params), strand);
        a = a + sim_wind(params) * gust;
    }
    if ((flags & SIM_SPRING) != 0u) {
        a = a + (rest_world - x.xyz) * sim_spring_stiffness(params);
    }
    precise vec3 moved = v + a * dt;
    precise vec3 p = x.xyz + moved * dt;
    return vec4(p, x.w);
}

void main() {
    params = steps[step_range_first(push)];
    uint points = sim_points(params);
    uint per_group = sim_hairs_per_group(params);
    uint group = sim_sync_group(params);
    uint per_sync = group / points;
    // With subgroup sync (always full subgroups) hairs are laid out by subgroup.
    uint lid = group == SIM_WORKGROUP ? gl_LocalInvocationID.x : gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
    uint sync_index = lid / group;
    uint lane = lid - sync_index * group;
    uint in_sync = lane / points;
    uint i = lane - in_sync * points;
    uint hair = sync_index * per_sync + in_sync;
    uint slot = gl_WorkGroupID.x * per_group + hair;
    uint simulated = step_range_simulated(push);
    bool live = in_sync < per_sync && hair < per_group && slot < simulated;
    uint strand = live ? sim_order[slot] : 0u;
    uint index = strand * points + i;
    // A crowd member's key hair reads its member's parameter set (the same
    // switches, iterations and sweeps' knobs as every set: uniform control flow).
    uint param_base = step_range_first(push);
    if (live && (step_flags() & SIM_SCALP) != 0u) {
        param_base += scalp_root_set(scalp_roots[strand]) * step_range_stride(push);
        params = steps[param_base];
    }
    // The sequential sweeps (local shape, DFTL) of the sync group's hairs run on
    // its first lanes side by side, lane h for its h-th hair, rather than on each
    // hair's root: neighbouring lanes share a SIMD batch or subgroup.
    uint swept = sync_index * per_sync + lane;
    uint swept_slot = gl_WorkGroupID.x * per_group + swept;
    bool sweeps = lane < per_sync && swept < per_group && swept_slot < simulated;
    uint sweep_root = sync_index * group + lane * points;
    uint sweep_base = sweeps ? sim_order[swept_slot] * points : 0u;

    // What stays the same over the step: the state (in registers from here to the
    // store), the rest data and what the constraints load (partners, rest
    // distances, stiffnesses).
    vec4 x = vec4(0.0);
    vec3 v = vec3(0.0);
    vec3 rest_head = vec3(0.0);
    if (live) {
        x = pos_in[index];
        if (step_range_first(push) == 0u) {
            pos_before[index] = x;
        }
        v = vel_in[index].xyz;
        vec4 r = rest[index];
        rest_head = r.xyz;
        own_radius = r.w;
        s_length[lid] = rest_length[index];
        constraints_load(i, points, index);
    }

    for (uint sub = 0u; sub < step_range_count(push); sub++) {
        // The first sub-step's parameters were loaded above.
        if (sub > 0u) {
            params = steps[param_base + sub];
        }
        collider_base = (step_range_first(push) + sub) * SIM_MAX_COLLIDERS;
        uint flags = step_flags();
        bool collisions = (flags & SIM_COLLISIONS) != 0u;
        own_start = x;

        // 1. Prediction, and what the constraints need of this sub-step's frame.
        vec4 own = vec4(0.0);
        if (live) {
            mat4 frame = hair_frame(strand);
            own = predict(x, v, rest_head, strand, frame);
            s_pos[0][lid] = own;
            constraints_prepare(frame, lid, index, i, points);
        }
        sync(group);
        vec4 predicted = own;

        // 2. The constraint solve.
        if ((flags & SIM_DFTL) != 0u) {
            // Follow the leader: sequential down each hair, by its sweeping lane.
            if (sweeps) {
                for (uint k = 1u; k < points; k++) {
                    vec4 parent = s_pos[0][sweep_root + k - 1u];
                    vec4 q = s_pos[0][sweep_root + k];
                    if (q.w > 0.0) {
                        precise vec3 d = q.xyz - parent.xyz;
                        precise float len = sqrt(dot(d, d));
                        precise vec3 placed = len > 0.0 ? parent.xyz + d * (s_length[sweep_root + k - 1u] / len) : q.xyz;
                        if (collisions) {
                            placed = collide_all(placed, rest[sweep_base + k].w);
                        }
                        s_pos[0][sweep_root + k] = vec4(placed, q.w);
                    }
                }
            }
            sync(group);
            if (live) {
                own = s_pos[0][lid];
                precise vec3 d = own.xyz - predicted.xyz;
                s_local_offset[lid] = d;
            }
            sync(group);
        } else {
            // Halves alternate: each set reads `src` and writes the other one.
            uint src = 0u;
            for (uint it = 0u; it < sim_iterations(params); it++) {
                own = constraints_iterate(own, it, src, lid, live, group, sweeps, sweep_root, points);
            }
            own = constraints_after(own, sim_iterations(params), live);
        }

        // 3. Velocity from the position change, damping.
        if (live) {
            float dt = sim_dt(params);
            precise vec3 vel = (own.xyz - x.xyz) / dt;
            if ((flags & SIM_DFTL) != 0u && i + 1u < points) {
                vel = vel - s_local_offset[lid + 1u] * (sim_dftl_damping(params) / dt);
            }
            if ((flags & SIM_COLLISIONS) != 0u && own.w > 0.0) {
                vel = sim_collider_friction_all(params, collider_base, own.xyz, vel, own_radius);
            }
            vel = vel * (1.0 - sim_damping(params));
            x = own;
            v = vel;
        }
    }
    if (live) {
        pos_out[index] = x;
        vel_out[index] = vec4(v, 0.0);
        // Every lane read the corners it needed before the last sub-step's barriers.
        if (i == 0u && (step_flags() & SIM_SCALP) != 0u && sim_scalp_last(params) != 0u) {
            scalp_keep_corners(params, strand);
        }
    }
}
