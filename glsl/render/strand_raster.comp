#version 460
// Exact transparency, build by the compute rasteriser (render/draw/raster.rs,
// Raster::Compute), in place of the ribbons' hardware draw and
// oit_build.frag: one invocation a segment of the interpolated hairs
// (hair-major, as the ribbons), in a grid-stride loop.
//
// Its pixels and fragments: strand_segment.glsl.
//
// Each fragment is depth-tested (LESS_OR_EQUAL, as the hardware path) against
// the host's depth copied into SceneDepth, then stored as oit_build.frag
// stores: pushed onto its pixel's list, or, beyond the pool, added to the
// fixed-point overflow sums (oit_overflow.glsl); a fragment at least half
// opaque lowers the pixel's nearest opaque depth. A segment walks its pixels
// twice — counting the fragments it keeps, then storing them into the nodes
// one atomic took for all of them — so the pool's counter takes an atomic a
// segment, not a fragment (README, "Raster").
// Constant 0 is the pool's buffer count (oit.glsl); constant 1 the shading
// features (this stage shades nothing: strand_alpha only).
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit.glsl"
#include "oit_overflow.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
// Per hair vertex: its shaded colour (shade_points.comp).
layout(std430, set = 0, binding = 20) readonly buffer PointColor { vec4 point_color[]; };
// The target's depth, one pixel after another from the top row
// (oit.scene_depth says how it is encoded; unread for SCENE_DEPTH_NONE).
layout(std430, set = 0, binding = 25) readonly buffer SceneDepth { uint scene_depth[]; };

#include "strand_segment.glsl"

// Whether a fragment of coverage-weighted `alpha` at depth `z` is stored.
bool kept(uint pixel, float z, float alpha) {
    return alpha >= OIT_LEAST_ALPHA && z <= scene_depth_limit(pixel);
}

// One kept fragment of coverage-weighted `alpha`, colour `color` at depth
// `z`, into pool node `node` (the segment's nodes were taken at once).
void store(uint pixel, float z, vec3 color, float alpha, uint node) {
    if (alpha >= OIT_OPAQUE_ALPHA) {
        atomicMin(oit_opaque[pixel], floatBitsToUint(z));
    }
    if (node >= oit.capacity) {
        oit_overflow_add(pixel, color, alpha);
        return;
    }
    uint next = atomicExchange(oit_heads[pixel], node);
    oit_store(node, uvec4(packHalf2x16(color.rg), packHalf2x16(vec2(color.b, alpha)), floatBitsToUint(z), next));
}

void raster_segment(uint first, bool last) {
    Segment sg;
    if (!segment_on_screen(first, last, sg)) {
        return;
    }
    // Two walks over the same pixels: the first counts the fragments kept,
    // then one atomic takes that many nodes of the pool, and the second
    // stores them — one atomic on the pool's counter a segment, not a
    // fragment.
    // The second walk never stores more than the first counted (should a
    // driver evaluate the two walks' arithmetic differently, a node is left
    // unused rather than one of another segment's taken).
    uint count = 0u;
    uint base = 0u;
    uint taken = 0u;
    for (uint walk = 0u; walk < 2u; ++walk) {
        if (walk == 1u) {
            if (count == 0u) {
                return;
            }
            taken = count;
            base = atomicAdd(oit.used, taken);
            count = 0u;
        }
        for (float k = sg.k_lo; k < sg.k_hi; k += 1.0) {
            vec2 column = segment_column(sg, k);
            for (float m = column.x; m < column.y; m += 1.0) {
                float z;
                vec3 color;
                float alpha;
                if (!segment_fragment(sg, k, m, z, color, alpha)) {
                    continue;
                }
                uvec2 at = segment_pixel(sg, k, m);
                uint pixel = at.y * oit.width + at.x;
                if (!kept(pixel, z, alpha)) {
                    continue;
                }
                if (walk == 1u) {
                    if (count == taken) {
                        return;
                    }
                    store(pixel, z, color, alpha, base + count);
                }
                count++;
            }
        }
    }
}

void main() {
    if (dp.counts.y < 2u) {
        return;
    }
    uint total = dp.counts.x * (dp.counts.y - 1u);
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint seg = gl_GlobalInvocationID.x; seg < total; seg += stride) {
        bool last;
        uint first = segment_first(seg, last);
        raster_segment(first, last);
    }
}
