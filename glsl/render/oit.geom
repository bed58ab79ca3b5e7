#version 460
// Draw pass, geometry stage of transparent hair: the ribbons of ribbon.glsl
// with the coverage varying the fragment stage needs.
#define VKHAIR_COVERAGE
#include "ribbon.glsl"
