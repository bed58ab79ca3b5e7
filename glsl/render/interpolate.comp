#version 460
// Interpolation pass in compute (render/interpolate.rs, Interpolator::Compute):
// one invocation per grown vertex, the same vertex the tessellation evaluation
// stages store (grow_*.glsl), numbered as it is stored — unit after unit
// (key hair, scalp triangle or follower), hair after hair, vertex after vertex
// — so neighbouring invocations write neighbouring vertices. The dispatch is
// two-dimensional past maxComputeWorkGroupCount's least x (65,535 workgroups):
// workgroup (x, y) is number y · gl_NumWorkGroups.x + x.
// vkhair variant: VKHAIR_BARY
// vkhair variant: VKHAIR_FOLLOW
#if defined(VKHAIR_FOLLOW)
#include "grow_follow.glsl"
#elif defined(VKHAIR_BARY)
#include "grow_bary.glsl"
#else
#include "grow_single.glsl"
#endif

layout(local_size_x = 256) in;

void main() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint vertex = group * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    uint per_hair = grow_hair_vertices();
    uint per_unit = pc.hairs * per_hair;
    if (vertex >= pc.strands * per_unit) {
        return;
    }
    uint unit = vertex / per_unit;
    uint rest = vertex - unit * per_unit;
    uint h = rest / per_hair;
    grow_vertex(unit, h, rest - h * per_hair);
}
