#version 460
// Draw pass, geometry stage of opaque hair (see ribbon.glsl).
#include "ribbon.glsl"
