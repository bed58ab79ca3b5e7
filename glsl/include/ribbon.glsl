// The draw pass's geometry stage (draw.geom; oit.geom defines VKHAIR_COVERAGE):
// each segment becomes a camera-facing ribbon of
// mix(root width, tip width) world units, at least `least width` pixels wide.
// Transparent strands (dp.coverage.x = 1) have no least width: their ribbon is
// at least one pixel wide plus half a pixel each side, and g_cover carries the
// signed distance from the centre line and the true half width, in pixels,
// from which the fragment stage computes the strand's coverage. A transparent
// strand standing for n hairs (dp.coverage.z) is a band n hair widths wide.
#include "render.glsl"

layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
layout(std140, set = 0, binding = 0) uniform Draw { DrawParams dp; };

layout(location = 0) in vec3 v_pos[];
layout(location = 1) in vec3 v_tan[];
layout(location = 2) in float v_t[];
layout(location = 3) flat in uint v_hair[];

// The depth pre-pass and the shading draw must rasterize the same depths: the
// same modules in both pipelines, and no fused multiply-adds that a compiler
// could choose differently in each.
precise gl_Position;

layout(location = 0) out vec3 g_pos;
layout(location = 1) out vec3 g_tan;
layout(location = 2) out float g_t;
layout(location = 3) flat out uint g_hair;
#ifdef VKHAIR_COVERAGE
layout(location = 4) out vec2 g_cover;
#endif

void main() {
    vec3 along = v_pos[1] - v_pos[0];
    float len = length(along);
    vec3 dir = len > 0.0 ? along / len : v_tan[0];
    for (int e = 0; e < 2; e++) {
        vec3 to_camera = dp.camera.xyz - v_pos[e];
        float distance_to_camera = length(to_camera);
        vec3 side = cross(dir, to_camera);
        float side_len = length(side);
        side = side_len > 1e-12 ? side / side_len : vec3(1.0, 0.0, 0.0);
        float width = mix(dp.widths.x, dp.widths.y, v_t[e]);
        if (dp.coverage.x > 0.5) {
            // A transparent strand standing for n hairs is a band of n hair widths.
            width *= dp.coverage.z;
        }
        float half_drawn = 0.5 * max(width, dp.widths.z * dp.camera.w * distance_to_camera);
        float pixel = max(dp.camera.w * distance_to_camera, 1e-12);
        float half_true = 0.5 * width / pixel;
        if (dp.coverage.x > 0.5) {
            half_drawn = (max(half_true, 0.5) + 0.5) * pixel;
        }
        for (int s = -1; s <= 1; s += 2) {
            g_pos = v_pos[e] + side * (half_drawn * float(s));
#ifdef VKHAIR_COVERAGE
            g_cover = vec2(half_drawn / pixel * float(s), half_true);
#endif
            g_tan = v_tan[e];
            g_t = v_t[e];
            g_hair = v_hair[e];
            gl_Position = dp.view_proj * vec4(g_pos, 1.0);
            EmitVertex();
        }
    }
    EndPrimitive();
}
