#version 460
// Interpolation pass, vertex stage: no vertex buffer; vertex i is the patch of
// key segment i (strand-major).
layout(location = 0) flat out uint v_patch;

void main() {
    v_patch = uint(gl_VertexIndex);
}
