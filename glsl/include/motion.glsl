// Motion vectors of the hair (render/draw/motion.rs): the frame's block, read
// by the walk that picks each pixel's hair (motion_raster.comp) and by the
// stage that writes the host's velocity image (motion_write.frag).
#ifndef VKHAIR_MOTION_GLSL
#define VKHAIR_MOTION_GLSL

// Twin: gpu_types::GpuMotion.
struct MotionBlock {
    mat4 now;     // world → clip of this frame, without its jitter
    mat4 before;  // world → clip of the previous frame, without its jitter
    vec4 scale;   // xy: an NDC difference (now − before) to the host's units and sign; z: world size of a target pixel at distance 1; w unused
    vec4 depth;   // the projection's clip z = x·z_view + y and clip w = z·z_view + w (this frame's)
    uvec4 counts; // x: hairs (a prefix) whose previous positions are kept (0: none); y: drawn pixels per target pixel along each axis (1, or 2 supersampled); z: 1 for opaque ribbons (the nearest covering the pixel's centre, no depth to match); w unused
};
layout(std140, set = 0, binding = 37) uniform Motion { MotionBlock mb; };

// The view-space z of a point at (target-convention) NDC depth `ndc`.
float motion_view_z(float ndc) {
    return (mb.depth.y - mb.depth.w * ndc) / (mb.depth.z * ndc - mb.depth.x);
}

// A pixel's key word pair before the walk: no hair picked.
const uint MOTION_NONE = 0xffffffffu;

#endif
