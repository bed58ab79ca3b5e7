//! The Ogawa container under Alembic files: a tree of groups and data blocks.
//!
//! A 16-byte header — the bytes `Ogawa`, a byte 0xff once the writer has
//! finished, a big-endian u16 version (1), then the little-endian u64
//! position of the root group. A group at position `p` is a u64 child count
//! `n` and `n` u64 child positions; a child whose high bit is set is a data
//! block at the position in its low 63 bits, any other a group (position 0:
//! an empty group or, with the high bit, an empty block). A data block is a
//! u64 byte count and the bytes. Every position and length is checked against
//! the file before it is used, and what decoding the file allocates is
//! charged to one budget ([`Ogawa::charge`], [`super::MAX_ABC_DECODED`]): a
//! group read many times, metadata repeated, narrow numbers widened all count.

use std::cell::Cell;

use crate::error::{Error, FileFormat, Result};

/// The header's length, bytes.
pub(crate) const HEADER_LEN: usize = 16;
const DATA_BIT: u64 = 1 << 63;

/// A child of a group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Child {
    /// A group at this position (0: empty).
    Group(u64),
    /// A data block at this position (0: empty).
    Data(u64),
}

/// An Ogawa file held in memory.
pub(crate) struct Ogawa<'a> {
    bytes: &'a [u8],
    /// Bytes decoding has allocated so far.
    decoded: Cell<u64>,
}

pub(crate) fn malformed(reason: impl Into<String>) -> Error {
    Error::Malformed { format: FileFormat::Alembic, reason: reason.into() }
}

impl<'a> Ogawa<'a> {
    /// The file's container and the position of its root group.
    pub fn new(bytes: &'a [u8]) -> Result<(Self, u64)> {
        if bytes.len() < HEADER_LEN {
            return Err(Error::Truncated {
                format: FileFormat::Alembic,
                what: "Ogawa header",
                needed: HEADER_LEN as u64,
                available: bytes.len() as u64,
            });
        }
        if &bytes[..5] != b"Ogawa" {
            let reason = if bytes.starts_with(&[0x89, b'H', b'D', b'F']) {
                "an HDF5 Alembic file (only the Ogawa container is read; re-export it as Ogawa)".to_owned()
            } else {
                "it does not start with \"Ogawa\"".to_owned()
            };
            return Err(Error::BadMagic { format: FileFormat::Alembic, reason });
        }
        if bytes[5] != 0xff {
            return Err(malformed("the writer did not finish the file (its frozen flag is not set)"));
        }
        let version = u16::from_be_bytes([bytes[6], bytes[7]]);
        if version != 1 {
            return Err(Error::Unsupported { format: FileFormat::Alembic, reason: format!("Ogawa version {version}") });
        }
        let file = Ogawa { bytes, decoded: Cell::new(0) };
        let root = file.u64_at(8, "root group position")?;
        Ok((file, root))
    }

    /// The file's length, bytes.
    pub fn len(&self) -> u64 {
        self.bytes.len() as u64
    }

    /// Charges `bytes` that decoding `what` allocates to the file's budget,
    /// refusing the file past [`super::MAX_ABC_DECODED`] in all.
    pub fn charge(&self, bytes: u64, what: &str) -> Result<()> {
        let total = self.decoded.get().saturating_add(bytes);
        if total > super::MAX_ABC_DECODED {
            return Err(malformed(format!(
                "decoding it takes more than {} MiB (at {what}): its groups, metadata or values are read over \
                 and over or widened past what a groom of its size needs",
                super::MAX_ABC_DECODED >> 20
            )));
        }
        self.decoded.set(total);
        Ok(())
    }

    fn u64_at(&self, at: u64, what: &'static str) -> Result<u64> {
        let b = self.slice(at, 8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }

    fn slice(&self, at: u64, len: u64, what: &'static str) -> Result<&'a [u8]> {
        let available = self.len().saturating_sub(at);
        if len > available {
            return Err(Error::Truncated { format: FileFormat::Alembic, what, needed: len, available });
        }
        Ok(&self.bytes[at as usize..(at + len) as usize])
    }

    /// The children of the group at `at` (none for an empty group).
    pub fn group(&self, at: u64) -> Result<Vec<Child>> {
        if at == 0 {
            return Ok(Vec::new());
        }
        let n = self.u64_at(at, "group child count")?;
        // Checked before allocating: the children must fit in the file.
        let bytes = n.checked_mul(8).filter(|&b| b <= self.len()).ok_or_else(|| {
            malformed(format!("a group at byte {at} claims {n} children, more than the file can hold"))
        })?;
        let raw = self.slice(at + 8, bytes, "group children")?;
        self.charge(n.saturating_mul(std::mem::size_of::<Child>() as u64), "a group's children")?;
        Ok(raw
            .chunks_exact(8)
            .map(|c| {
                let mut a = [0u8; 8];
                a.copy_from_slice(c);
                let v = u64::from_le_bytes(a);
                if v & DATA_BIT != 0 {
                    Child::Data(v & !DATA_BIT)
                } else {
                    Child::Group(v)
                }
            })
            .collect())
    }

    /// The bytes of the data block at `at` (none for an empty block).
    pub fn data(&self, at: u64) -> Result<&'a [u8]> {
        if at == 0 {
            return Ok(&[]);
        }
        let n = self.u64_at(at, "data block size")?;
        self.slice(at + 8, n, "data block")
    }

    /// The group at `child`, refusing a data block where a group belongs.
    pub fn group_of(&self, child: Child, what: &str) -> Result<Vec<Child>> {
        match child {
            Child::Group(at) => self.group(at),
            Child::Data(_) => Err(malformed(format!("{what} is a data block where a group belongs"))),
        }
    }

    /// The data at `child`, refusing a group where a data block belongs.
    pub fn data_of(&self, child: Child, what: &str) -> Result<&'a [u8]> {
        match child {
            Child::Data(at) => self.data(at),
            Child::Group(_) => Err(malformed(format!("{what} is a group where a data block belongs"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file whose root group has `n` empty children.
    fn file(n: u64) -> Vec<u8> {
        let mut f = b"Ogawa\xff\x00\x01".to_vec();
        f.extend_from_slice(&16u64.to_le_bytes());
        f.extend_from_slice(&n.to_le_bytes());
        f.extend(std::iter::repeat_n(0u8, 8 * n as usize));
        f
    }

    /// Every read of a group charges its child list to the budget, and the
    /// budget refuses the file past MAX_ABC_DECODED, naming what it was
    /// decoding.
    #[test]
    fn decoding_is_charged_and_refused_past_the_budget() {
        let bytes = file(1000);
        let (ogawa, root) = Ogawa::new(&bytes).expect("file");
        for _ in 0..3 {
            assert_eq!(ogawa.group(root).expect("group").len(), 1000);
        }
        assert_eq!(ogawa.decoded.get(), 3 * 1000 * std::mem::size_of::<Child>() as u64);
        let left = super::super::MAX_ABC_DECODED - ogawa.decoded.get();
        ogawa.charge(left, "the rest").expect("up to the budget");
        let e = ogawa.group(root).expect_err("past the budget").to_string();
        assert!(e.contains("decoding it takes more than 2048 MiB (at a group's children)"), "{e}");
    }
}
