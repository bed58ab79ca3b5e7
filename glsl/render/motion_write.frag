#version 460
// Motion vectors, the write (render/draw/motion.rs): over the host's velocity
// image (one triangle, resolve.vert), each pixel takes the motion the walk
// picked (motion_raster.comp) — with supersampling, of its drawn pixels the
// one whose matched depth is nearest — and a pixel no hair reached is
// discarded, keeping what the host wrote there. Opaque frames are written
// through the host's depth test (transparent ones pick only hair their
// composite kept, which passed it).
#define OIT_COUNTERS_READONLY
#include "oit_counters.glsl"
#include "motion.glsl"

layout(std430, set = 0, binding = 35) readonly buffer MotionDepth { uint motion_depth[]; };
layout(std430, set = 0, binding = 36) readonly buffer MotionKeys { uvec2 motion_keys[]; };

layout(location = 0) out vec2 out_velocity;

void main() {
    uint n = mb.counts.y;
    uvec2 base = uvec2(gl_FragCoord.xy) * n;
    float nearest = 3.0e38;
    uint velocity = 0u;
    bool found = false;
    for (uint sy = 0u; sy < n; sy++) {
        for (uint sx = 0u; sx < n; sx++) {
            uvec2 at = base + uvec2(sx, sy);
            if (at.x >= oit.width || at.y >= oit.height) {
                continue;
            }
            uint pixel = at.y * oit.width + at.x;
            uvec2 key = motion_keys[pixel];
            // Opaque frames pick the nearest fragment: its distance is its depth.
            float depth = uintBitsToFloat(mb.counts.z != 0u ? key.y : motion_depth[pixel]);
            if (key.y != MOTION_NONE && depth < nearest) {
                nearest = depth;
                velocity = key.x;
                found = true;
            }
        }
    }
    if (!found) {
        discard;
    }
    out_velocity = unpackHalf2x16(velocity);
    // Opaque frames test the pick against the host's depth attachment (a
    // ribbon behind the host's meshes is not the pixel's): its depth in the
    // host's convention, brought toward the camera by four pixels' size at its
    // distance, so that the ribbon the draw wrote there passes (the draw's
    // ribbon and the walk's centre line differ a little in depth).
    float z_view = motion_view_z(oit_forward(nearest)) * (1.0 - 4.0 * mb.scale.z);
    float ndc = (mb.depth.x * z_view + mb.depth.y) / (mb.depth.z * z_view + mb.depth.w);
    gl_FragDepth = clamp(ndc, 0.0, 1.0);
}
