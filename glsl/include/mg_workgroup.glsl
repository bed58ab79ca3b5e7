// The multigrid V-cycle as phases of one workgroup separated by workgroup
// barriers (pcg_workgroup.comp, the whole solve in one workgroup; and
// mg_cycle.comp, the coarse levels of the dispatched solve): per cell the
// arithmetic of mg_smooth, mg_restrict and mg_coarsest. The including shader
// declares, before including it: the VolumeParams block `vp`, the stencil
// words (and volume_ops.glsl), the coherent buffers x (binding 23), tmp (24)
// and rhs (25), and pressure_ops.glsl with VKHAIR_PRESSURE_LEVELS and
// VKHAIR_PRESSURE_COARSEST; a workgroup of VOL_GROUP invocations.
#ifndef VKHAIR_MG_WORKGROUP_GLSL
#define VKHAIR_MG_WORKGROUP_GLSL

// Every write of every invocation before it is visible to all after it.
void sync() {
    memoryBarrierBuffer();
    memoryBarrierShared();
    barrier();
}

uvec3 lvl_dims(uint level) {
    uvec3 dims = vol_dims(vp);
    for (uint l = 0u; l < level; ++l) {
        dims = (dims + 1u) / 2u;
    }
    return dims;
}

uint lvl_first(uint level) {
    uvec3 dims = vol_dims(vp);
    uint first = 0u;
    for (uint l = 0u; l < level; ++l) {
        first += dims.x * dims.y * dims.z;
        dims = (dims + 1u) / 2u;
    }
    return first;
}

// One sweep from tmp into x on a level.
void sweep_tmp_into_x(uint first, uint cells, uvec3 dims) {
    for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
        uint i = first + c;
        uint w = stencil[i];
        precise float value = 0.0;
        if (vol_is_fluid(w)) {
            float own = tmp[i];
            precise float ax = vol_diagonal(w) * own;
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    ax -= tmp[vol_neighbor_index(i, dims, n)];
                }
            }
            value = mg_sweep(i, w, own, ax);
        }
        x[i] = value;
    }
    sync();
}

// Two sweeps from x = 0 on a level (tmp holds the first).
void pre_smooth(uint first, uint cells, uvec3 dims) {
    for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
        uint i = first + c;
        uint w = stencil[i];
        tmp[i] = vol_is_fluid(w) ? mg_sweep(i, w, 0.0, 0.0) : 0.0;
    }
    sync();
    sweep_tmp_into_x(first, cells, dims);
}

// Half the summed residuals of a coarse cell's fluid children (mg_restrict).
void restrict_residual(uint first, uvec3 dims, uint coarse_first, uvec3 coarse_dims) {
    uint coarse_cells = coarse_dims.x * coarse_dims.y * coarse_dims.z;
    for (uint c = gl_LocalInvocationIndex; c < coarse_cells; c += VOL_GROUP) {
        bool fluid = vol_is_fluid(stencil[coarse_first + c]);
        rhs[coarse_first + c] = fluid ? mg_restricted(vol_cell_coords(c, coarse_dims), first, dims) : 0.0;
    }
    sync();
}

// The coarsest level's solve (mg_coarsest) into x.
void solve_coarsest(uint first, uvec3 dims) {
    uint c = gl_LocalInvocationIndex;
    bool live = c < dims.x * dims.y * dims.z;
    uint i = first + c;
    uint w = live ? stencil[i] : 0u;
    float result = mg_coarsest_solve(c, dims, w, vol_is_fluid(w) ? rhs[i] : 0.0);
    if (live) {
        x[i] = result;
    }
    sync();
}

// x at cell j of a level plus its coarse parent's correction.
float prolonged(uint j, uvec3 ijk, uint coarse_first, uvec3 coarse_dims) {
    precise float value = x[j] + x[coarse_first + vol_cell_index(ijk / 2u, coarse_dims)];
    return value;
}

// The prolongation with the first post-sweep (into tmp), then the second (into x).
void post_smooth(uint first, uint cells, uvec3 dims, uint coarse_first, uvec3 coarse_dims) {
    for (uint c = gl_LocalInvocationIndex; c < cells; c += VOL_GROUP) {
        uint i = first + c;
        uint w = stencil[i];
        precise float value = 0.0;
        if (vol_is_fluid(w)) {
            uvec3 ijk = vol_cell_coords(c, dims);
            float own = prolonged(i, ijk, coarse_first, coarse_dims);
            precise float ax = vol_diagonal(w) * own;
            for (uint n = 0u; n < 6u; ++n) {
                if (vol_has_fluid_neighbor(w, n)) {
                    uvec3 nb = ijk;
                    nb[n >> 1u] = (n & 1u) == 0u ? nb[n >> 1u] - 1u : nb[n >> 1u] + 1u;
                    ax -= prolonged(vol_neighbor_index(i, dims, n), nb, coarse_first, coarse_dims);
                }
            }
            value = mg_sweep(i, w, own, ax);
        }
        tmp[i] = value;
    }
    sync();
    sweep_tmp_into_x(first, cells, dims);
}

// x = V-cycle(rhs) on level `from`, given its rhs: down to the coarsest level
// and back up, every level from `from` on.
void mg_vcycle_from(uint from) {
    uint last = vol_levels(vp) - 1u;
    for (uint l = from; l < last; ++l) {
        uvec3 dims = lvl_dims(l);
        uint first = lvl_first(l);
        pre_smooth(first, dims.x * dims.y * dims.z, dims);
        restrict_residual(first, dims, lvl_first(l + 1u), lvl_dims(l + 1u));
    }
    solve_coarsest(lvl_first(last), lvl_dims(last));
    for (uint l = last; l > from; --l) {
        uvec3 dims = lvl_dims(l - 1u);
        post_smooth(lvl_first(l - 1u), dims.x * dims.y * dims.z, dims, lvl_first(l), lvl_dims(l));
    }
}

#endif
