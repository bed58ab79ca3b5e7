//! Bounds-checked little-endian reads for the binary hair formats.

use crate::error::{Error, FileFormat, Result};

pub(crate) struct Reader<'a> {
    pub data: &'a [u8],
    pub format: FileFormat,
}

impl<'a> Reader<'a> {
    /// `len` bytes at `offset`, or a `Truncated` error naming `what`.
    pub fn bytes(&self, offset: u64, len: u64, what: &'static str) -> Result<&'a [u8]> {
        let available = (self.data.len() as u64).saturating_sub(offset);
        if len > available {
            return Err(Error::Truncated { format: self.format, what, needed: len, available });
        }
        // Both fit in usize: they are bounded by data.len().
        Ok(&self.data[offset as usize..(offset + len) as usize])
    }

    pub fn u32(&self, offset: u64, what: &'static str) -> Result<u32> {
        let b = self.bytes(offset, 4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub fn f32(&self, offset: u64, what: &'static str) -> Result<f32> {
        self.u32(offset, what).map(f32::from_bits)
    }

    /// `count` f32 values at `offset`; the length is checked before allocating.
    pub fn f32s(&self, offset: u64, count: u64, what: &'static str) -> Result<Vec<f32>> {
        let len = count.checked_mul(4).ok_or(Error::Truncated {
            format: self.format,
            what,
            needed: u64::MAX,
            available: self.data.len() as u64,
        })?;
        let b = self.bytes(offset, len, what)?;
        Ok(b.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }

    /// `count` u16 values at `offset`; the length is checked before allocating.
    pub fn u16s(&self, offset: u64, count: u64, what: &'static str) -> Result<Vec<u16>> {
        let b = self.bytes(offset, count.saturating_mul(2), what)?;
        Ok(b.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect())
    }
}
