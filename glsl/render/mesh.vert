#version 460
// A lit triangle mesh (the host's head in tools, tests and examples): vertices
// pulled from storage, three per triangle.
layout(std430, set = 0, binding = 0) readonly buffer Vertices { vec4 vertices[]; };
layout(std430, set = 0, binding = 1) readonly buffer Normals { vec4 normals[]; };
layout(push_constant) uniform Push {
    mat4 mvp;             // model → clip
    vec4 rotation;        // model rotation quaternion (normals)
    vec4 color;           // rgb albedo
    vec4 light;           // xyz direction light travels, w ambient
} pc;

layout(location = 0) out vec3 v_normal;

void main() {
    vec4 p = vertices[gl_VertexIndex];
    vec3 n = normals[gl_VertexIndex].xyz;
    vec3 t = 2.0 * cross(pc.rotation.xyz, n);
    v_normal = n + pc.rotation.w * t + cross(pc.rotation.xyz, t);
    gl_Position = pc.mvp * vec4(p.xyz, 1.0);
}
