#version 460
// Transparency, depth (over the rectangle the ribbons reach, after the
// resolve): the depth of the pixel's nearest fragment of alpha ≥
// OIT_OPAQUE_ALPHA, depth-tested and written into the target's depth image so
// later host passes see the hair; pixels without such a fragment keep the
// target's depth.
#include "oit.glsl"

void main() {
    uint bits = oit_opaque[oit_pixel(gl_FragCoord)];
    if (bits == OIT_END) {
        discard;
    }
    gl_FragDepth = oit_forward(uintBitsToFloat(bits));
}
