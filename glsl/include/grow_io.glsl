// What every interpolation mode's vertex function (grow_*.glsl) reads and
// writes: the push block, the smoothed key hairs (positions, tangents) and the
// grown hairs (positions, (tangent, t)). Binding numbers: render/interpolate.rs.
#ifndef VKHAIR_GROW_IO_GLSL
#define VKHAIR_GROW_IO_GLSL
#include "render.glsl"

layout(push_constant) uniform Push { InterpolatePush pc; };
layout(std430, set = 0, binding = 0) readonly buffer SmoothPos { vec4 smooth_pos[]; };
layout(std430, set = 0, binding = 1) readonly buffer SmoothTan { vec4 smooth_tan[]; };
layout(std430, set = 0, binding = 3) writeonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 4) writeonly buffer HairTan { vec4 hair_tan[]; };

#endif
