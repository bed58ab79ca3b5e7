#version 460
// Transparent modes, before the build: every vertex of the interpolated hairs
// shaded once (hair_shading.glsl at the strand's centre line). The ribbons'
// coverage variant carries the colour of each end to its fragments, which only
// compute their coverage and store: a strand's lighting and shadow vary along
// it far more than across a ribbon a few pixels wide, and a fragment costs
// several vertices' shading where ribbons are wide or overlap.
#include "hair_shading.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
// Per hair vertex: shaded colour (rgb), as hair_pos.
layout(std430, set = 0, binding = 20) writeonly buffer PointColor { vec4 point_color[]; };

// A grid-stride loop: the dispatch stays within the 65,535 workgroups every
// device offers however many vertices there are.
void main() {
    uint per_hair = dp.counts.y;
    uint total = dp.counts.x * per_hair;
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint i = gl_GlobalInvocationID.x; i < total; i += stride) {
        vec4 tan_t = hair_tan[i];
        point_color[i] = vec4(shade_hair(hair_pos[i].xyz, tan_t.xyz, tan_t.w, i / per_hair), 1.0);
    }
}
