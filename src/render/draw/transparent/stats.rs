//! What the last exact-mode frame stored ([`OitStats`]), read back by the host.

use super::TransparentPass;
use crate::gpu_types::OitCounters;

/// What the last exact-mode frame stored, read by
/// [`crate::render::Renderer::transparency_stats`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OitStats {
    /// Hair fragments that passed the depth test.
    pub fragments: u64,
    /// Of those, the ones stored in the pool.
    pub stored: u64,
    /// The ones the full pool could not store: composited unsorted, in the
    /// order-independent tail behind the sorted ones (not dropped).
    pub overflowed: u64,
    /// Fragments the pool holds.
    pub capacity: u64,
    /// Fragments [`OitParams::fragments_per_pixel`](crate::render::OitParams::fragments_per_pixel) asked the pool to hold:
    /// more than `capacity` where the device's buffers could not hold them
    /// (see [`OitPool`](crate::render::OitPool)).
    pub requested: u64,
    /// Tile entries the tiled rasteriser's segments asked for
    /// ([`Raster::Tiles`](crate::render::Raster::Tiles); 0 with the other rasterisers): the frame drew those
    /// within `tile_capacity`, and the bins of the frame
    /// [`RenderParams::frames_in_flight`](crate::render::RenderParams::frames_in_flight)
    /// after it grow to hold them, up to one buffer's range.
    pub tile_entries: u64,
    /// Entries the tiled rasteriser's bins held for the frame (0 with the
    /// other rasterisers; see [`OitParams::tile_entries_per_vertex`](crate::render::OitParams::tile_entries_per_vertex)).
    pub tile_capacity: u64,
    /// The pixels the composite ran over, `[x0, y0, x1, y1]` (the last column
    /// and row excluded; rows from the top; pixels of the drawn target, twice
    /// each side with supersampling): a rectangle holding every pixel the
    /// hair's ribbons can reach. `None` when no hair was drawn.
    pub composited: Option<[u32; 4]>,
}

impl TransparentPass {
    /// What the latest exact-mode frame stored, read from host-visible memory:
    /// valid once that frame completed and before the next one is submitted.
    pub(in crate::render::draw) fn stats(&self) -> Option<OitStats> {
        // The current resources are those of the latest transparent frame.
        let res = self.current.as_ref().filter(|r| r.method.exact())?;
        let bytes = self.counters.mapped()?;
        let counters: OitCounters = bytemuck::pod_read_unaligned(bytes.get(..std::mem::size_of::<OitCounters>())?);
        let rect = [counters.hair_x0, counters.hair_y0, counters.hair_x1, counters.hair_y1];
        let composited = (rect[0] < rect[2] && rect[1] < rect[3]).then_some(rect);
        if let Some(bins) = &res.tiles {
            // Every kept fragment is sorted or in the tail: no pool.
            return Some(OitStats {
                fragments: u64::from(counters.used),
                stored: u64::from(counters.used),
                overflowed: 0,
                capacity: 0,
                requested: 0,
                tile_entries: bins.entries_asked()?,
                tile_capacity: bins.capacity(),
                composited,
            });
        }
        let pool = res.pool()?;
        let stored = counters.used.min(counters.capacity);
        Some(OitStats {
            fragments: u64::from(counters.used),
            stored: u64::from(stored),
            overflowed: u64::from(counters.used - stored),
            capacity: u64::from(counters.capacity),
            requested: pool.requested,
            tile_entries: 0,
            tile_capacity: 0,
            composited,
        })
    }
}
