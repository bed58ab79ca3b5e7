//! A storage buffer filled from the CPU, standing in for a host's GPU buffer
//! (a skinning pass's output that vkhair reads, [`crate::sim::scalp::ScalpSource`]).

use std::sync::Arc;

use ash::vk;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::sim::scalp::ScalpSource;
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;

/// See the module docs. The buffer has `STORAGE_BUFFER` usage and is
/// destroyed with this value.
pub struct HostBuffer {
    device: Arc<Device>,
    buffer: Buffer,
}

impl HostBuffer {
    /// A buffer of `size` bytes (a multiple of 4, above 0) on `ctx`'s device.
    pub fn new(ctx: &GpuContext, name: &str, size: u64) -> Result<Self> {
        if size == 0 || !size.is_multiple_of(4) {
            return Err(Error::param("host buffer size", size, "a multiple of 4 above 0"));
        }
        Ok(HostBuffer { device: ctx.device.clone(), buffer: Buffer::storage(&ctx.device, name, size)? })
    }

    /// Writes `bytes` at `offset` (this submits and waits: call it between
    /// frames, after the last one reading the buffer has completed).
    pub fn write(&self, offset: u64, bytes: &[u8]) -> Result<()> {
        self.buffer.check_range("host buffer write", offset, bytes.len() as u64)?;
        self.device.upload(&self.buffer, offset, bytes)
    }

    /// The raw buffer.
    pub fn raw(&self) -> vk::Buffer {
        self.buffer.raw()
    }

    /// Its size in bytes.
    pub fn size(&self) -> u64 {
        self.buffer.size()
    }

    /// The buffer as a skinned scalp's source: `vertex_count` vertices of
    /// `format`, `stride` bytes apart.
    pub fn scalp_source(&self, stride: u64, format: vk::Format, vertex_count: u32) -> ScalpSource {
        ScalpSource { buffer: self.raw(), size: self.size(), stride, format, vertex_count }
    }
}
