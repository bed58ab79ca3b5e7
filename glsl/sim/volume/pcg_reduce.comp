#version 460
// Pressure solve, one workgroup: sums the per-workgroup partials in a fixed
// order and advances the conjugate-gradient scalars.
//   reduce_mode = 0 (start):  σ = Σ r·z, bmax = max |b|; nothing to do when b = 0.
//   reduce_mode = 1 (step):   α = σ / Σ d·q.
//   reduce_mode = 2 (check):  one more iteration; converged when max |r| ≤ tol · bmax,
//                      else β = Σ r·z / σ, σ = Σ r·z.
//   reduce_partials: partials;  reduce_dispatches: indirect dispatch entries.
// Once converged (or broken down, or not finite) every indirect dispatch of the
// remaining recorded iterations is set to zero workgroups.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(push_constant) uniform Push { VolumePush pc; };
layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(std430, set = 0, binding = 26) buffer Scalars { PcgScalars scalars; };
layout(std430, set = 0, binding = 27) readonly buffer Partials { vec2 partials[]; };
layout(std430, set = 0, binding = 28) buffer Indirect { uvec4 indirect[]; };

shared vec2 sums[VOL_GROUP];

void main() {
    uint t = gl_LocalInvocationID.x;
    vec2 own = vec2(0.0);
    for (uint k = t; k < reduce_partials(pc); k += VOL_GROUP) {
        own.x += partials[k].x;
        own.y = max(own.y, partials[k].y);
    }
    sums[t] = own;
    barrier();
    for (uint width = 128u; width > 0u; width >>= 1u) {
        if (t < width) {
            sums[t] = vec2(sums[t].x + sums[t + width].x, max(sums[t].y, sums[t + width].y));
        }
        barrier();
    }
    if (t != 0u) {
        return;
    }
    vec2 total = sums[0];
    bool stop = false;
    if (reduce_mode(pc) == 0u) {
        scalars.sigma = total.x;
        scalars.alpha = 0.0;
        scalars.beta = 0.0;
        scalars.bmax = total.y;
        scalars.rmax = total.y;
        scalars.iterations = 0u;
        scalars.converged = 0u;
        scalars.status = VOL_STATUS_OK;
        if (isnan(total.x) || isinf(total.x) || isnan(total.y) || isinf(total.y)) {
            scalars.status = VOL_STATUS_NONFINITE;
            stop = true;
        } else if (total.y <= 0.0 || total.x <= 0.0) {
            stop = true;
        }
    } else if (reduce_mode(pc) == 1u) {
        if (total.x > 0.0 && !isinf(total.x)) {
            scalars.alpha = scalars.sigma / total.x;
        } else {
            scalars.alpha = 0.0;
            scalars.status = isnan(total.x) || isinf(total.x) ? VOL_STATUS_NONFINITE : VOL_STATUS_BREAKDOWN;
            stop = true;
        }
    } else {
        scalars.iterations += 1u;
        scalars.rmax = total.y;
        if (isnan(total.x) || isinf(total.x) || isnan(total.y) || isinf(total.y)) {
            scalars.status = VOL_STATUS_NONFINITE;
            stop = true;
        } else if (total.y <= vol_tolerance(vp) * scalars.bmax) {
            stop = true;
        } else if (total.x > 0.0 && scalars.sigma > 0.0) {
            scalars.beta = total.x / scalars.sigma;
            scalars.sigma = total.x;
        } else {
            scalars.status = VOL_STATUS_BREAKDOWN;
            stop = true;
        }
    }
    if (stop) {
        scalars.converged = 1u;
        for (uint k = 0u; k < reduce_dispatches(pc); ++k) {
            indirect[k].x = 0u;
        }
    }
}
