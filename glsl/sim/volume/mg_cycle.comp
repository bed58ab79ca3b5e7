#version 460
// Multigrid preconditioner of the dispatched solve (PressureSolver::Dispatched),
// its coarse levels in one workgroup: from level mg_cycle_first_level(pc)
// (at most 4,096 cells, 16³: record.rs) — whose restricted
// residual mg_restrict left — down to the coarsest and back up, as phases
// separated by workgroup barriers (mg_workgroup.glsl, the arithmetic of the
// per-level kernels), leaving that level's correction x for the finer level's
// post-smoothing. One dispatch in place of four a level: on a GPU each
// dispatch and its barrier cost microseconds that small levels never fill.
#include "volume.glsl"

layout(local_size_x = VOL_GROUP) in;

layout(std140, set = 0, binding = 0) uniform Params { VolumeParams vp; };
layout(push_constant) uniform Push { VolumePush pc; };
layout(std430, set = 0, binding = 30) readonly buffer Stencil { uint stencil[]; };
#include "volume_ops.glsl"
layout(std430, set = 0, binding = 23) coherent buffer X { float x[]; };
layout(std430, set = 0, binding = 24) coherent buffer Tmp { float tmp[]; };
layout(std430, set = 0, binding = 25) coherent buffer Rhs { float rhs[]; };
#define VKHAIR_PRESSURE_LEVELS
#define VKHAIR_PRESSURE_COARSEST
#include "pressure_ops.glsl"
#include "mg_workgroup.glsl"

void main() {
    mg_vcycle_from(mg_cycle_first_level(pc));
}
