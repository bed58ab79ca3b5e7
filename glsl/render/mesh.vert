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
    vec4 translation;     // xyz model translation, w index of the light whose hair shadow falls on the mesh (−1: none)
} pc;

layout(location = 0) out vec3 v_normal;
layout(location = 1) out vec3 v_world;

void main() {
    vec4 p = vertices[gl_VertexIndex];
    vec3 n = normals[gl_VertexIndex].xyz;
    vec3 t = 2.0 * cross(pc.rotation.xyz, n);
    v_normal = n + pc.rotation.w * t + cross(pc.rotation.xyz, t);
    vec3 tp = 2.0 * cross(pc.rotation.xyz, p.xyz);
    v_world = p.xyz + pc.rotation.w * tp + cross(pc.rotation.xyz, tp) + pc.translation.xyz;
    gl_Position = pc.mvp * vec4(p.xyz, 1.0);
}
