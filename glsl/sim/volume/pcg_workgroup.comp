#version 460
// Pressure solve in one workgroup (PressureSolver::Workgroup): the whole
// preconditioned conjugate-gradient solve of the pcg_* kernels, with their
// preconditioner (one multigrid V-cycle as mg_smooth, mg_restrict and
// mg_coarsest compute it, or Jacobi), as phases over the cells separated by
// workgroup barriers; it stops at the tolerance or the cap and leaves the same
// scalars as pcg_reduce.comp. A dispatch does at most pcg_wg_iterations(pc)
// iterations (record.rs sizes the shares so that no loop of a share passes its
// back edge more than CPU drivers allow: lavapipe leaves any loop after 65,535);
// the first share (pcg_wg_start(pc) = 1) starts the solve, the others go on from
// the scalars and vectors the previous one left, or return at once once it stopped.
// Per cell the arithmetic is the dispatched kernels'; sums are reduced in a
// fixed order (each invocation over its cells in turn, then a tree), so the
// result is the same on every run.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 17) readonly buffer FaceVel { float face_vel[]; };
layout(std430, set = 0, binding = 20) coherent buffer Pressure { float pressure[]; };
layout(std430, set = 0, binding = 21) coherent buffer D { float d[]; };
layout(std430, set = 0, binding = 22) coherent buffer Q { float q[]; };
// z = M r on level 0, the V-cycle's corrections on the coarser levels.
layout(std430, set = 0, binding = 23) coherent buffer X { float x[]; };
layout(std430, set = 0, binding = 24) coherent buffer Tmp { float tmp[]; };
// r on level 0, the restricted residuals on the coarser levels.
layout(std430, set = 0, binding = 25) coherent buffer Rhs { float rhs[]; };
layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 26) buffer Scalars { PcgScalars scalars; };
#define VKHAIR_PRESSURE_RHS
#define VKHAIR_PRESSURE_LEVELS
#define VKHAIR_PRESSURE_COARSEST
#include "pressure_ops.glsl"

shared vec2 sums[VOL_GROUP];

#include "mg_workgroup.glsl"

// (Σ, max) over the workgroup, the same in every invocation.
vec2 group_sum_max(vec2 value) {
    uint t = gl_LocalInvocationIndex;
    sums[t] = value;
    barrier();
    for (uint width = VOL_GROUP / 2u; width > 0u; width >>= 1u) {
        if (t < width) {
            sums[t] = vec2(sums[t].x + sums[t + width].x, max(sums[t].y, sums[t + width].y));
        }
        barrier();
    }
    vec2 total = sums[0];
    barrier();
    return total;
}

bool finite(vec2 v) {
    return !any(isnan(v)) && !any(isinf(v));
}

// z = M r into x (level 0), then (r·z, max |r|).
vec2 precondition() {
    uint cells = vol_cells(vp);
    if (vol_preconditioner(vp) == VOL_PRECOND_JACOBI) {
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            x[c] = pcg_jacobi(stencil[c], rhs[c]);
        }
        sync();
    } else {
        mg_vcycle_from(0u);
    }
    vec2 local = vec2(0.0);
    for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
        local.x += rhs[c] * x[c];
        local.y = max(local.y, abs(rhs[c]));
    }
    return group_sum_max(local);
}

void main() {
    uint cells = vol_cells(vp);
    uvec3 dims = vol_dims(vp);
    float sigma;
    float bmax;
    float alpha = 0.0;
    float beta = 0.0;
    float rmax;
    uint iterations = 0u;
    uint status = VOL_STATUS_OK;
    bool stop = false;
    if (pcg_wg_start(pc) == 1u) {
        // b = −(net outflow) of every fluid cell (pcg_init), r = b, pressure 0.
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            uvec3 ijk = vol_cell_coords(c, dims);
            float b = vol_is_fluid(stencil[c]) ? pressure_rhs(ijk, dims) : 0.0;
            rhs[c] = b;
            pressure[c] = 0.0;
        }
        sync();
        vec2 start = precondition();
        sigma = start.x;
        bmax = start.y;
        rmax = bmax;
        if (!finite(start)) {
            status = VOL_STATUS_NONFINITE;
            stop = true;
        } else if (bmax <= 0.0 || sigma <= 0.0) {
            stop = true;
        }
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            d[c] = x[c];
        }
        sync();
    } else {
        PcgScalars before = scalars;
        sync();
        if (before.converged == 1u) {
            return;
        }
        sigma = before.sigma;
        bmax = before.bmax;
        rmax = before.rmax;
        alpha = before.alpha;
        beta = before.beta;
        iterations = before.iterations;
    }
    uint until = min(iterations + pcg_wg_iterations(pc), vol_max_iterations(vp));
    while (!stop && status == VOL_STATUS_OK && iterations < until) {
        // q = A d and d·q (pcg_apply), then the step length.
        vec2 local = vec2(0.0);
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            precise float qc = 0.0;
            uint w = stencil[c];
            if (vol_is_fluid(w)) {
                qc = vol_diagonal(w) * d[c];
                for (uint n = 0u; n < 6u; ++n) {
                    if (vol_has_fluid_neighbor(w, n)) {
                        qc -= d[vol_neighbor_index(c, dims, n)];
                    }
                }
            }
            q[c] = qc;
            local.x += d[c] * qc;
        }
        float dq = group_sum_max(local).x;
        if (!(dq > 0.0) || isinf(dq)) {
            alpha = 0.0;
            status = isnan(dq) || isinf(dq) ? VOL_STATUS_NONFINITE : VOL_STATUS_BREAKDOWN;
            break;
        }
        alpha = sigma / dq;
        // p += α d, r −= α q (pcg_update), and max |r| for the convergence check
        // (pcg_reduce mode 2), made before the preconditioner so that the last
        // iteration spares its V-cycle.
        local = vec2(0.0);
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            precise float pn = pressure[c] + alpha * d[c];
            precise float rc = rhs[c] - alpha * q[c];
            pressure[c] = pn;
            rhs[c] = rc;
            local.y = max(local.y, abs(rc));
        }
        sync();
        iterations += 1u;
        rmax = group_sum_max(local).y;
        if (isnan(rmax) || isinf(rmax)) {
            status = VOL_STATUS_NONFINITE;
            break;
        }
        if (rmax <= vol_tolerance(vp) * bmax) {
            stop = true;
            break;
        }
        // z = M r and r·z, then the next direction.
        vec2 total = precondition();
        if (!finite(total)) {
            status = VOL_STATUS_NONFINITE;
            break;
        }
        if (!(total.x > 0.0 && sigma > 0.0)) {
            status = VOL_STATUS_BREAKDOWN;
            break;
        }
        beta = total.x / sigma;
        sigma = total.x;
        for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
            precise float dc = x[c] + beta * d[c];
            d[c] = dc;
        }
        sync();
    }
    if (gl_LocalInvocationIndex == 0u) {
        scalars.sigma = sigma;
        scalars.alpha = alpha;
        scalars.beta = beta;
        scalars.bmax = bmax;
        scalars.rmax = rmax;
        scalars.iterations = iterations;
        scalars.converged = stop || status != VOL_STATUS_OK ? 1u : 0u;
        scalars.status = status;
    }
}
