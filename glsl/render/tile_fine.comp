#version 460
// Exact transparency by the tiled rasteriser (render/draw/tiles.rs), fourth
// dispatch: one workgroup a screen tile, one invocation a pixel of it. The
// tile's run of segments (tile_lists.glsl) is taken PIXELS at a time, one
// segment an invocation, and each walks its pixels within the tile
// (strand_segment.glsl: the same pixels and fragments as the per-segment
// rasteriser, strand_raster.comp) into a shared-memory buffer of fragments,
// linked per pixel. When the buffer is full or the segments are walked, each
// invocation takes its own pixel's fragments: the depth test against the
// target's depth (LESS_OR_EQUAL), the nearest half-opaque depth, and the
// pixel's K-buffer (oit_kbuffer.glsl: its K nearest sorted, the rest in the
// order-independent tail); a segment interrupted by a full buffer resumes at
// the pixel it stopped at. Last, each invocation composites its pixel into
// `oit_resolved` (oit_resolved.frag blends it over the host's target) and
// writes its nearest half-opaque depth. No per-pixel lists in device memory
// and no device atomics per fragment (one a tile adds its count to
// oit.used): a tile's fragments never leave the multiprocessor that draws them.
// vkhair variant: VKHAIR_SORT_4
// vkhair variant: VKHAIR_SORT_8
// vkhair variant: VKHAIR_SORT_16
// Constant 1: the shading features (this stage shades nothing).
#define SHADING_FEATURES_ID 1
#include "hair_shading.glsl"
#include "oit_opaque.glsl"
#include "tile_lists.glsl"
#include "oit_kbuffer.glsl"

layout(local_size_x = TILE_SIZE, local_size_y = TILE_SIZE) in;

layout(std430, set = 0, binding = 1) readonly buffer HairPos { vec4 hair_pos[]; };
layout(std430, set = 0, binding = 2) readonly buffer HairTan { vec4 hair_tan[]; };
layout(std430, set = 0, binding = 20) readonly buffer PointColor { vec4 point_color[]; };
layout(std430, set = 0, binding = 25) readonly buffer SceneDepth { uint scene_depth[]; };
// Per pixel (rows from NDC y = −1): the resolved hair, rg and ba as half floats.
layout(std430, set = 0, binding = 28) writeonly buffer OitResolved { uvec2 oit_resolved[]; };

#include "strand_segment.glsl"

#define PIXELS (TILE_SIZE * TILE_SIZE)
const uint NONE = 0xffffffffu;
// A stored fragment's depth word carries this bit when it is at least half opaque.
const uint OPAQUE_BIT = 0x80000000u;

// The fragments of one round: packed colour and alpha, depth bits (and
// OPAQUE_BIT), the next fragment of the same pixel (NONE ends it).
shared uvec4 fragments[TILE_FRAGMENTS];
// Per pixel of the tile: its newest fragment of the round.
shared uint heads[PIXELS];
// Fragments the round's invocations asked for (more than TILE_FRAGMENTS: full).
shared uint taken;
// Whether a segment stopped at a full buffer.
shared uint pending;
// Fragments the tile kept (passed the depth test).
shared uint tile_kept;

void main() {
    uvec2 tile = gl_WorkGroupID.xy;
    uint lid = gl_LocalInvocationIndex;
    uvec2 at = gl_GlobalInvocationID.xy;
    bool inside = at.x < oit.width && at.y < oit.height;
    uint pixel = at.y * oit.width + at.x;
    uint t = tile.y * tiles.tiles_x + tile.x;
    uint begin = tile_start[t];
    uint end = begin + min(tile_count[t], tiles.capacity - min(begin, tiles.capacity));
    if (begin == end) {
        // No segment reaches the tile (most of a frame): no hair here.
        if (inside) {
            oit_resolved[pixel] = uvec2(0u);
            oit_opaque[pixel] = OIT_END;
        }
        return;
    }
    float limit = inside ? scene_depth_limit(pixel) : -1.0;
    kb_begin(oit.sorted, vec4(0.0), 0.0);
    uint opaque = OIT_END;
    uint kept = 0u;
    if (lid == 0u) {
        tile_kept = 0u;
    }
    barrier();
    const float side = float(TILE_SIZE);
    vec2 origin = vec2(tile) * side;
    for (uint chunk = begin; chunk < end; chunk += PIXELS) {
        // This invocation's segment of the chunk and where its walk within the
        // tile stands: column k (of k_end), rows m..m_end of it, and the
        // tile's rows.
        Segment sg;
        bool walking = false;
        float k = 0.0;
        float k_end = 0.0;
        float m = 0.0;
        float m_end = 0.0;
        vec2 rows = vec2(0.0);
        // An entry the fill never wrote (only past a mismatch of its run) is
        // skipped where it names no segment of the frame.
        uint seg = chunk + lid < end ? tile_list[chunk + lid] : NONE;
        if (seg < dp.counts.x * (dp.counts.y - 1u)) {
            bool last;
            uint first = segment_first(seg, last);
            if (segment_on_screen(first, last, sg)) {
                vec2 origin_km = sg.x_major ? origin : origin.yx;
                rows = vec2(origin_km.y, origin_km.y + side);
                k = max(sg.k_lo, origin_km.x);
                k_end = min(sg.k_hi, origin_km.x + side);
                walking = k < k_end;
                vec2 column = segment_column(sg, k);
                m = max(column.x, rows.x);
                m_end = min(column.y, rows.y);
            }
        }
        // Rounds: the invocations walk their segments until the shared
        // buffer is full or every segment is walked; then each sorts its
        // pixel's fragments; a full buffer takes another round.
        for (;;) {
            heads[lid] = NONE;
            if (lid == 0u) {
                taken = 0u;
                pending = 0u;
            }
            barrier();
            while (walking) {
                if (m >= m_end) {
                    k += 1.0;
                    walking = k < k_end;
                    if (walking) {
                        vec2 column = segment_column(sg, k);
                        m = max(column.x, rows.x);
                        m_end = min(column.y, rows.y);
                    }
                    continue;
                }
                float z;
                vec3 color;
                float alpha;
                if (segment_fragment(sg, k, m, z, color, alpha) && alpha >= OIT_LEAST_ALPHA) {
                    uint slot = atomicAdd(taken, 1u);
                    if (slot >= TILE_FRAGMENTS) {
                        // Full: this pixel again in the next round.
                        atomicOr(pending, 1u);
                        break;
                    }
                    uvec2 p = segment_pixel(sg, k, m) - tile * TILE_SIZE;
                    uint next = atomicExchange(heads[p.y * TILE_SIZE + p.x], slot);
                    // Depths lie in 0..1 (clipped); a −0 or a rounding below 0 is 0,
                    // so that the sign bit is free for the flag.
                    uint depth = floatBitsToUint(max(z, 0.0)) | (alpha >= OIT_OPAQUE_ALPHA ? OPAQUE_BIT : 0u);
                    fragments[slot] = uvec4(pack_color(color, alpha), depth, next);
                }
                m += 1.0;
            }
            barrier();
            for (uint node = heads[lid]; node != NONE;) {
                uvec4 f = fragments[node];
                node = f.w;
                uint depth = f.z & ~OPAQUE_BIT;
                if (uintBitsToFloat(depth) <= limit) {
                    if ((f.z & OPAQUE_BIT) != 0u) {
                        opaque = min(opaque, depth);
                    }
                    kb_insert(uintBitsToFloat(depth), f.xy);
                    kept++;
                }
            }
            bool again = pending != 0u;
            barrier();
            if (!again) {
                break;
            }
        }
    }
    atomicAdd(tile_kept, kept);
    barrier();
    if (lid == 0u && tile_kept != 0u) {
        atomicAdd(oit.used, tile_kept);
    }
    if (inside) {
        vec4 result = kb_composite();
        oit_resolved[pixel] = uvec2(packHalf2x16(result.rg), packHalf2x16(result.ba));
        oit_opaque[pixel] = opaque;
        kb_write_motion_depth(pixel);
    }
}
