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
//   2. the constraint solve: N iterations with a barrier between the sets.
//      The barrier's scope is the "sync group": the subgroup when every hair
//      fits into one (hairs are packed so none straddles two), else the whole
//      workgroup (barrier()). The sets are:
//        a. distance constraints of even segments, b. of odd segments,
//        c. bending (distance between points i−1 and i+1, rest from the rest
//           shape, stiffness from root to tip) centred on i mod 4 ∈ {0,1},
//           d. on {2,3},
//        e. (with SIM_LOCAL_SHAPE, in the last iteration only, so that its
//           stiffness is the fraction removed per sub-step whatever the
//           iteration count) the local shape constraints, swept root to tip by
//           one invocation per hair (Gauss-Seidel: a correction reaches
//           the tip within the sweep): segment (j−1, j) is pulled toward its
//           rest offset carried along by the smallest rotation taking the
//           parent segment's rest direction onto its current one (parallel
//           transport of the rest frame; the first segment's frame is the
//           head's); both ends move, by their inverse masses, so the
//           constraint conserves momentum like the distance constraints,
//        f. the global shape constraint (each point pulled toward its rest
//           position in the head's frame; it touches only the own point) and
//           body collisions (spheres, capsules and, with SIM_MESH, the mesh
//           collider's field; each particle has its own radius),
//      then, with the mesh collider, friction against it (once per sub-step);
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
// one barrier per set suffices (collisions, which touch only the own point,
// share the last set's barrier). The arithmetic is exactly that of projecting
// the pair in one place, which the CPU reference does.
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
#include "sim_bodies.glsl"
#include "scalp.glsl"

shared vec4 s_pos[2][SIM_WORKGROUP];
shared float s_length[SIM_WORKGROUP];
// Local shape, per point i ≥ 1 (its segment from i−1): the parent segment's rest
// direction (world, unit; zero for the first segment and degenerate ones) and
// the rest offset of i from i−1 (world).
shared vec3 s_local_dir[SIM_WORKGROUP];
// In DFTL mode s_local_offset holds each point's correction vector instead.
shared vec3 s_local_offset[SIM_WORKGROUP];

// The parameters of the sub-step being run, and where its colliders start.
SimStepParams params;
uint collider_base;

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

// One end of a constraint between this invocation's point `own` and the point
// `offset` invocations away, read from half `src`. `first`: own is the lower
// index (a) of the pair. Returns own's projected position.
vec4 project_end(vec4 own, uint lid, int offset, bool first, float rest_d, float k, uint src) {
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

// Sweeps the local shape constraints of the hair whose root sits at invocation
// `root`, root to tip, in place in half `src` (see the header). The segments'
// rest data are in s_local (direction of the parent segment, offset). The two
// points before the segment are carried in registers: they are what the
// previous segment left in shared memory.
void local_shape_sweep(uint root, uint points, uint src) {
    vec4 grandparent = vec4(0.0);
    vec4 parent = s_pos[src][root];
    for (uint j = 1u; j < points; j++) {
        vec4 child = s_pos[src][root + j];
        precise vec3 carried = s_local_offset[root + j];
        vec3 dir = s_local_dir[root + j];
        if (j >= 2u && sim_dot(dir, dir) > 0.0) {
            precise vec3 d = parent.xyz - grandparent.xyz;
            precise float len = sqrt(sim_dot(d, d));
            if (len > 0.0) {
                carried = sim_rotate_between(dir, d / len, carried);
            }
        }
        precise float w = parent.w + child.w;
        if (w > 0.0) {
            precise vec3 delta = (carried - (child.xyz - parent.xyz)) * sim_local_shape(params);
            precise vec3 moved_parent = parent.xyz - delta * (parent.w / w);
            precise vec3 moved_child = child.xyz + delta * (child.w / w);
            parent.xyz = moved_parent;
            child.xyz = moved_child;
            s_pos[src][root + j - 1u] = parent;
            s_pos[src][root + j] = child;
        }
        grandparent = parent;
        parent = child;
    }
}

// Where the rest pose of key hair `strand` is placed at the end of the
// sub-step being run: the head, or with SIM_SCALP its root's frame.
mat4 hair_frame(uint strand) {
    if ((step_flags() & SIM_SCALP) != 0u) {
        return scalp_frame(params, strand, sim_scalp_to(params), sim_head(params));
    }
    return sim_head(params);
}

// The rest offset of particle k from its parent, rotated into the world by `frame`.
vec3 local_rest_offset(mat4 frame, uint k) {
    return sim_rotate(frame, rest[k].xyz - rest[k - 1u].xyz);
}

// The unit rest direction of the segment ending at particle k, in the world
// (zero for a degenerate segment).
vec3 local_rest_dir(mat4 frame, uint k) {
    vec3 d = local_rest_offset(frame, k);
    precise float len = sqrt(sim_dot(d, d));
    return len > 0.0 ? d / len : vec3(0.0);
}

// Rest distance and stiffness of the bending constraint centred on point c.
vec2 bend_at(uint strand_base, uint c, uint points) {
    precise vec3 r = rest[strand_base + c + 1u].xyz - rest[strand_base + c - 1u].xyz;
    precise float t = float(c) / float(points - 1u);
    precise float k = sim_bending_root(params) + (sim_bending_tip(params) - sim_bending_root(params)) * t;
    return vec2(sqrt(dot(r, r)), k);
}

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
    uint base = strand * points;
    // The sequential sweeps (local shape, DFTL) of the sync group's hairs run on
    // its first lanes side by side, lane h for its h-th hair, rather than on each
    // hair's root: neighbouring lanes share a SIMD batch or subgroup.
    uint swept = sync_index * per_sync + lane;
    uint swept_slot = gl_WorkGroupID.x * per_group + swept;
    bool sweeps = lane < per_sync && swept < per_group && swept_slot < simulated;
    uint sweep_root = sync_index * group + lane * points;
    uint sweep_base = sweeps ? sim_order[swept_slot] * points : 0u;

    // What stays the same over the step: the state (in registers from here to the
    // store), the rest data and each constraint set's partner, rest distance and
    // stiffness.
    bool bending = (step_flags() & SIM_BENDING) != 0u;
    vec4 x = vec4(0.0);
    vec3 v = vec3(0.0);
    vec3 rest_head = vec3(0.0);
    float radius = 0.0;
    // Per set: partner offset (0 = none), whether own is the pair's first point,
    // rest distance and stiffness.
    int off_even = 0, off_odd = 0, off_bend_a = 0, off_bend_b = 0;
    bool first_even = false, first_odd = false, first_bend_a = false, first_bend_b = false;
    float rest_even = 0.0, rest_odd = 0.0;
    vec2 bend_a = vec2(0.0), bend_b = vec2(0.0);
    if (live) {
        x = pos_in[index];
        if (step_range_first(push) == 0u) {
            pos_before[index] = x;
        }
        v = vel_in[index].xyz;
        vec4 r = rest[index];
        rest_head = r.xyz;
        radius = r.w;
        s_length[lid] = rest_length[index];
        bool has_next = i + 1u < points;
        float len_next = rest_length[index];
        float len_prev = i > 0u ? rest_length[index - 1u] : 0.0;
        // Distance sets: segment (j, j+1) is even when j is even.
        if ((i & 1u) == 0u) {
            if (has_next) { off_even = 1; first_even = true; rest_even = len_next; }
            if (i > 0u) { off_odd = -1; rest_odd = len_prev; }
        } else {
            off_even = -1; rest_even = len_prev;
            if (has_next) { off_odd = 1; first_odd = true; rest_odd = len_next; }
        }
        // Bending sets: centre c joins c−1 and c+1; set A has c mod 4 ∈ {0,1}.
        if (bending) {
            if (i + 2u < points) {
                uint c = i + 1u;
                vec2 bk = bend_at(base, c, points);
                if (bk.y > 0.0) {
                    if ((c & 3u) < 2u) { off_bend_a = 2; first_bend_a = true; bend_a = bk; }
                    else { off_bend_b = 2; first_bend_b = true; bend_b = bk; }
                }
            }
            if (i >= 2u) {
                uint c = i - 1u;
                vec2 bk = bend_at(base, c, points);
                if (bk.y > 0.0) {
                    if ((c & 3u) < 2u) { off_bend_a = -2; bend_a = bk; }
                    else { off_bend_b = -2; bend_b = bk; }
                }
            }
        }
    }

    for (uint sub = 0u; sub < step_range_count(push); sub++) {
        // The first sub-step's parameters were loaded above.
        if (sub > 0u) {
            params = steps[step_range_first(push) + sub];
        }
        collider_base = (step_range_first(push) + sub) * SIM_MAX_COLLIDERS;
        uint flags = step_flags();
        bool collisions = (flags & SIM_COLLISIONS) != 0u;
        bool global_shape = (flags & SIM_GLOBAL_SHAPE) != 0u;
        bool local_shape = (flags & SIM_LOCAL_SHAPE) != 0u;
        vec3 shape_target = vec3(0.0);
        float shape_k = 0.0;

        // 1. Prediction, and what the shape constraints need of this sub-step's head.
        vec4 own = vec4(0.0);
        if (live) {
            mat4 frame = hair_frame(strand);
            own = predict(x, v, rest_head, strand, frame);
            s_pos[0][lid] = own;
            if (global_shape) {
                precise float t = float(i) / float(points - 1u);
                precise float k = sim_global_shape(params) * sim_shape_weight(t, sim_global_shape_range(params));
                shape_k = k;
                vec3 at_rest = sim_transform_point(frame, rest_head);
                shape_target = sim_shape_target(at_rest, k, sim_iterations(params), flags, sim_gravity(params), sim_dt(params));
            }
            if (local_shape && i >= 1u) {
                s_local_offset[lid] = local_rest_offset(frame, index);
                s_local_dir[lid] = i >= 2u ? local_rest_dir(frame, index - 1u) : vec3(0.0);
            }
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
                own = project_end(own, lid, off_even, first_even, rest_even, 1.0, src);
                if (live) { s_pos[1u - src][lid] = own; }
                sync(group);
                src = 1u - src;
                own = project_end(own, lid, off_odd, first_odd, rest_odd, 1.0, src);
                if (live) { s_pos[1u - src][lid] = own; }
                sync(group);
                src = 1u - src;
                // Without bending the two sets move nothing: they are skipped
                // (`bending` is uniform, so are the barriers inside).
                if (bending) {
                    own = project_end(own, lid, off_bend_a, first_bend_a, bend_a.x, bend_a.y, src);
                    if (live) { s_pos[1u - src][lid] = own; }
                    sync(group);
                    src = 1u - src;
                    own = project_end(own, lid, off_bend_b, first_bend_b, bend_b.x, bend_b.y, src);
                }
                if (local_shape && it + 1u == sim_iterations(params)) {
                    if (live) { s_pos[1u - src][lid] = own; }
                    sync(group);
                    src = 1u - src;
                    if (sweeps) {
                        local_shape_sweep(sweep_root, points, src);
                    }
                    sync(group);
                    if (live) { own = s_pos[src][lid]; }
                }
                if (global_shape && live && own.w > 0.0 && shape_k > 0.0) {
                    precise vec3 pulled = own.xyz + (shape_target - own.xyz) * shape_k;
                    own.xyz = pulled;
                }
                if (collisions && live && own.w > 0.0) {
                    own.xyz = collide_all(own.xyz, radius);
                }
                if (live) { s_pos[1u - src][lid] = own; }
                sync(group);
                src = 1u - src;
            }
            if ((flags & SIM_MESH) != 0u && collisions && live && own.w > 0.0) {
                own.xyz = mesh_friction(sim_head(params), sim_previous_head(params), sim_mesh_grid(params), own.xyz,
                                        x.xyz, radius, sim_mesh_friction(params));
            }
        }

        // 3. Velocity from the position change, damping.
        if (live) {
            float dt = sim_dt(params);
            precise vec3 vel = (own.xyz - x.xyz) / dt;
            if ((flags & SIM_DFTL) != 0u && i + 1u < points) {
                vel = vel - s_local_offset[lid + 1u] * (sim_dftl_damping(params) / dt);
            }
            if ((flags & SIM_COLLISIONS) != 0u && own.w > 0.0) {
                vel = sim_collider_friction_all(params, collider_base, own.xyz, vel, radius);
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
