#version 460
// A triangle with no vertex buffer: checks the graphics pipeline path
// (reflection across stages, dynamic rendering, host-given formats).
layout(push_constant) uniform Push { vec4 color; vec2 offset; vec2 scale; } pc;

void main() {
    const vec2 corners[3] = vec2[](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.0, 0.5));
    gl_Position = vec4(corners[gl_VertexIndex] * pc.scale + pc.offset, 0.5, 1.0);
}
