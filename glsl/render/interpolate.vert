#version 460
// Interpolation pass, vertex stage: no vertex buffer; vertex i is the patch of
// key segment i (strand-major), instance n grows its hairs
// n·INTERPOLATE_LINES_PER_INSTANCE onwards.
layout(location = 0) flat out uint v_patch;
layout(location = 1) flat out uint v_instance;

void main() {
    v_patch = uint(gl_VertexIndex);
    v_instance = uint(gl_InstanceIndex);
}
