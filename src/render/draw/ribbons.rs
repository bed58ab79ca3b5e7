//! The ribbons' index buffer: each hair segment's ribbon is a quad of four
//! corners (`ribbon.vert`), its two triangles indexing them, so a device with
//! a vertex cache (lavapipe's) shades the two corners they share once: four
//! vertices a segment where six unindexed vertices ran the vertex stage six
//! times (the rasterized triangles are the same, vertex for vertex). The
//! indices number [`RIBBON_CHUNK`] segments in 16 bits; a draw takes as many
//! instances of them as it needs, the shader offsetting each by its instance.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::error::Result;
use crate::limits::RIBBON_CHUNK;
use crate::vk::buffer::{Buffer, BufferDesc};
use crate::vk::device::Device;

/// A segment's two triangles over its corners, numbered 2 × end + side (end 0
/// the segment's first point, side 1 the + side of its centre line), in the
/// order the corners were drawn before they were indexed: (0, −), (0, +),
/// (1, −) and (0, +), (1, +), (1, −).
const QUAD: [u16; 6] = [0, 1, 2, 1, 3, 2];

// Every corner of a chunk is numbered in 16 bits. The last is 0xFFFF, which a
// pipeline with primitive restart would read as a restart: the ribbon
// pipelines draw triangle lists, which restart never applies to.
const _: () = assert!(4 * RIBBON_CHUNK <= 1 << 16);

/// Indices of the first [`RIBBON_CHUNK`] segments' ribbons.
pub(super) struct RibbonIndices {
    buffer: Buffer,
}

impl RibbonIndices {
    /// The index buffer, uploaded (this submits and waits).
    pub(super) fn new(device: &Arc<Device>) -> Result<Self> {
        let indices = chunk_indices();
        let buffer = Buffer::new(
            device,
            &BufferDesc {
                name: "vkhair ribbon indices",
                size: std::mem::size_of_val(indices.as_slice()) as u64,
                usage: vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        device.upload_pod(&buffer, &indices)?;
        Ok(RibbonIndices { buffer })
    }

    /// Records the ribbons of `segments` segments with the bound pipeline:
    /// whole chunks as instances of one indexed draw, the rest as one more
    /// instance. Leaves this index buffer bound.
    ///
    /// # Safety
    /// `cmd` is recording inside a rendering instance on this buffer's device,
    /// with a pipeline of `ribbon.vert` bound.
    pub(super) unsafe fn draw(&self, device: &Device, cmd: vk::CommandBuffer, segments: u32) {
        let (whole, rest) = (segments / RIBBON_CHUNK, segments % RIBBON_CHUNK);
        let per_segment = QUAD.len() as u32;
        // SAFETY: guaranteed by the caller; the buffer holds RIBBON_CHUNK
        // segments' indices, and no draw reads past them.
        unsafe {
            device.raw.cmd_bind_index_buffer(cmd, self.buffer.raw(), 0, vk::IndexType::UINT16);
            if whole > 0 {
                device.raw.cmd_draw_indexed(cmd, RIBBON_CHUNK * per_segment, whole, 0, 0, 0);
            }
            if rest > 0 {
                device.raw.cmd_draw_indexed(cmd, rest * per_segment, 1, 0, 0, whole);
            }
        }
    }
}

/// The indices of [`RIBBON_CHUNK`] segments' ribbons, four corners a segment.
fn chunk_indices() -> Vec<u16> {
    (0..RIBBON_CHUNK as u16).flat_map(|segment| QUAD.map(|corner| 4 * segment + corner)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each segment's six indices are its own corners in the order the
    /// unindexed draw gave its vertices — (end, side): (0, −), (0, +),
    /// (1, −) and (0, +), (1, +), (1, −) — corner 2 × end + side; the last
    /// index is the chunk's last corner.
    #[test]
    fn the_chunk_indexes_each_segments_corners_in_the_drawn_order() {
        let drawn = [(0, 0), (0, 1), (1, 0), (0, 1), (1, 1), (1, 0)];
        let indices = chunk_indices();
        assert_eq!(indices.len(), 6 * RIBBON_CHUNK as usize);
        for (segment, triangles) in indices.chunks(6).enumerate() {
            let expected = drawn.map(|(end, side)| 4 * segment as u32 + 2 * end + side);
            let got: Vec<u32> = triangles.iter().map(|&i| u32::from(i)).collect();
            assert_eq!(got, expected, "segment {segment}");
        }
        assert_eq!(indices.last().copied().map(u32::from), Some(4 * RIBBON_CHUNK - 2));
    }
}
