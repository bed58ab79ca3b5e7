#version 460
// Opacity-map pass 1: the light-space depth of the nearest hair (z0), kept by
// the depth test.
layout(location = 0) in float v_depth;
layout(location = 0) out float out_z0;

void main() {
    out_z0 = v_depth;
}
