// Per-cell arithmetic of the pressure solve, one definition for its dispatched
// kernels (pcg_init, mg_smooth, mg_restrict, mg_coarsest) and the phases of a
// workgroup (mg_workgroup.glsl: pcg_workgroup, the solve in one workgroup, and
// mg_cycle, the dispatched solve's coarse levels). Include after volume_ops.glsl and after declaring what the
// parts used read:
//   VKHAIR_PRESSURE_RHS:       `vp` (VolumeParams) and `face_vel[]` (binding 17);
//   VKHAIR_PRESSURE_LEVELS:    `x[]` (binding 23) and `rhs[]` (binding 25);
//   VKHAIR_PRESSURE_COARSEST:  nothing (it declares its shared memory).
#ifndef VKHAIR_PRESSURE_OPS_GLSL
#define VKHAIR_PRESSURE_OPS_GLSL

#include "volume_ops.glsl"

// Damping of the multigrid preconditioner's Jacobi sweeps.
const float MG_OMEGA = 2.0 / 3.0;

// The Jacobi preconditioner's z = r / diag of a cell (word w): 0 where the cell
// is not fluid or has no non-solid neighbour.
float pcg_jacobi(uint w, float r) {
    float diagonal = vol_diagonal(w);
    return vol_is_fluid(w) && diagonal > 0.0 ? r / diagonal : 0.0;
}

#ifdef VKHAIR_PRESSURE_RHS
// b of the cell at `ijk`: −(net outflow), the divergence times the cell size.
float pressure_rhs(uvec3 ijk, uvec3 dims) {
    precise float outflow = 0.0;
    for (uint axis = 0u; axis < 3u; ++axis) {
        uvec3 up = ijk;
        up[axis] += 1u;
        outflow += face_vel[vol_face_index(up, axis, dims, vol_first_v_face(vp), vol_first_w_face(vp))]
            - face_vel[vol_face_index(ijk, axis, dims, vol_first_v_face(vp), vol_first_w_face(vp))];
    }
    precise float b = -outflow;
    return b;
}
#endif

#ifdef VKHAIR_PRESSURE_LEVELS
// A damped Jacobi sweep's value at level-array cell i (word w) from its own
// value and A·x there: x + ω (rhs − A x) / diag.
float mg_sweep(uint i, uint w, float own, float ax) {
    float diagonal = vol_diagonal(w);
    precise float value = diagonal > 0.0 ? own + MG_OMEGA * (rhs[i] - ax) / diagonal : 0.0;
    return value;
}

// The coarse right-hand side of the coarse cell at `coarse` (a fluid one): half
// the summed residuals rhs − A x of its fluid children on the level of `dims`
// cells starting at `first` (the factor matches the coarse operator, the same
// stencil on cells twice as wide).
float mg_restricted(uvec3 coarse, uint first, uvec3 dims) {
    precise float sum = 0.0;
    for (uint k = 0u; k < 8u; ++k) {
        uvec3 child = coarse * 2u + uvec3(k & 1u, (k >> 1u) & 1u, k >> 2u);
        if (any(greaterThanEqual(child, dims))) {
            continue;
        }
        uint i = first + vol_cell_index(child, dims);
        uint w = stencil[i];
        if (!vol_is_fluid(w)) {
            continue;
        }
        precise float residual = rhs[i] - vol_diagonal(w) * x[i];
        for (uint n = 0u; n < 6u; ++n) {
            if (vol_has_fluid_neighbor(w, n)) {
                residual += x[vol_neighbor_index(i, dims, n)];
            }
        }
        sum += residual;
    }
    precise float half_sum = 0.5 * sum;
    return half_sum;
}
#endif

#ifdef VKHAIR_PRESSURE_COARSEST
shared float mg_coarsest_values[2][VOL_GROUP];

// The coarsest multigrid level's solve, one cell per invocation (at most
// VOL_GROUP cells): VOL_COARSEST_SWEEPS damped Jacobi sweeps from x = 0 in
// shared memory. `c` is the invocation's cell (its word w, right-hand side b;
// w = 0 for invocations past the level), the result its value. Every invocation
// of the workgroup calls it (barriers).
float mg_coarsest_solve(uint c, uvec3 dims, uint w, float b) {
    bool fluid_cell = vol_is_fluid(w);
    float diagonal = vol_diagonal(w);
    mg_coarsest_values[0][c] = 0.0;
    barrier();
    for (uint sweep = 0u; sweep < VOL_COARSEST_SWEEPS; ++sweep) {
        uint from = sweep & 1u;
        precise float value = 0.0;
        if (fluid_cell && diagonal > 0.0) {
            precise float ax = diagonal * mg_coarsest_values[from][c];
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    ax -= mg_coarsest_values[from][vol_neighbor_index(c, dims, n)];
                }
            }
            value = mg_coarsest_values[from][c] + MG_OMEGA * (b - ax) / diagonal;
        }
        mg_coarsest_values[1u - from][c] = value;
        barrier();
    }
    return mg_coarsest_values[VOL_COARSEST_SWEEPS & 1u][c];
}
#endif

#endif
