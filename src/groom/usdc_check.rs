//! What a USD binary (crate) layer must satisfy before the `openusd` crate
//! reads it, which trusts its bootstrap, table of contents and structure:
//! [`check`] reads those without the crate, and refuses
//!
//! - a bootstrap that is not `PXR-USDC` or is cut short;
//! - a crate version the reader cannot read: before 0.4.0 (the crate stops
//!   on those with a panic) or after [`NEWEST`];
//! - a table of contents outside the file, of no section or more than
//!   [`MAX_SECTIONS`], or whose sections reach past the file's end;
//! - in the sections the crate reads first (`TOKENS`, `STRINGS`, `FIELDS`,
//!   `FIELDSETS`, `PATHS`, `SPECS`), a count or a compressed block that its
//!   section cannot hold: the crate allocates what a count asks for before
//!   it decompresses (a changed byte asked for 5 × 10¹⁸ bytes and aborted the
//!   process), so each count is bounded by what its compressed blocks can
//!   decode to ([`MAX_ITEMS_PER_BYTE`] a byte, at most [`MAX_ITEMS`]) and
//!   every block must lie inside its section;
//! - in those sections' compressed blocks, decoded as the crate decodes them
//!   (`groom/usdc_blocks.rs`): chunked or undecodable LZ4 data, integer
//!   blocks shorter than their counts, value representations fewer than the
//!   fields, and a path tree whose tokens, path indices or jumps leave their
//!   tables or reach an entry twice.
//!
//! Each error names the value found (and, for a bound of the file, its
//! length). Then the values
//! the fields point at are checked (`groom/usdc_values.rs`).

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::{Error, FileFormat, Result};

/// The bootstrap: magic, version (major, minor, patch, five unused), the
/// table of contents' offset, eight unused bytes.
const BOOTSTRAP: usize = 32;
/// One section's entry: a 16-byte name, its start and its size.
const SECTION: u64 = 32;
/// Most sections a table of contents may list (the reader's own bound).
pub const MAX_SECTIONS: u64 = 63;
/// The oldest crate version read.
pub const OLDEST: (u8, u8, u8) = (0, 4, 0);
/// The newest crate version read.
pub const NEWEST: (u8, u8, u8) = (0, 12, 0);

pub use super::usdc_values::{MAX_ITEMS, MAX_ITEMS_PER_BYTE};

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[at..at + 8]);
    u64::from_le_bytes(b)
}

/// Checks the crate file at `path`, `len` bytes long.
pub fn check(path: &Path, len: u64) -> Result<()> {
    let io = |source| Error::Io { path: path.into(), source };
    let mut file = std::fs::File::open(path).map_err(io)?;
    // Reads `n` bytes at `at`, which the caller has checked lie in the file.
    let mut read_at = |at: u64, n: usize| -> Result<Vec<u8>> {
        let mut b = vec![0u8; n];
        file.seek(SeekFrom::Start(at)).and_then(|_| file.read_exact(&mut b)).map_err(io)?;
        Ok(b)
    };
    if len < BOOTSTRAP as u64 {
        return Err(malformed(format!("a binary layer of {len} bytes without a whole PXR-USDC bootstrap")));
    }
    let bytes = read_at(0, BOOTSTRAP)?;
    if &bytes[..8] != b"PXR-USDC" {
        return Err(malformed(format!("a binary layer of {len} bytes without a whole PXR-USDC bootstrap")));
    }
    let version = (bytes[8], bytes[9], bytes[10]);
    if version < OLDEST || version > NEWEST {
        let (a, b, c) = version;
        return Err(Error::Unsupported {
            format: FileFormat::Usd,
            reason: format!(
                "crate version {a}.{b}.{c} (versions {}.{}.{} to {}.{}.{} are read)",
                OLDEST.0, OLDEST.1, OLDEST.2, NEWEST.0, NEWEST.1, NEWEST.2
            ),
        });
    }
    let toc = u64_at(&bytes, 16);
    if toc < BOOTSTRAP as u64 || toc.saturating_add(8) > len {
        return Err(malformed(format!("its table of contents is at byte {toc}, outside the file ({len} bytes)")));
    }
    let count = u64_at(&read_at(toc, 8)?, 0);
    if !(1..=MAX_SECTIONS).contains(&count) {
        return Err(malformed(format!("its table of contents lists {count} sections (1 to {MAX_SECTIONS} are read)")));
    }
    let end = toc.saturating_add(8).saturating_add(count * SECTION);
    if end > len {
        return Err(malformed(format!(
            "its table of contents of {count} sections ends at byte {end}, past the file's end ({len} bytes)"
        )));
    }
    let table = read_at(toc + 8, (count * SECTION) as usize)?;
    let mut sections = Vec::new();
    for entry in table.chunks_exact(SECTION as usize) {
        let name: String = entry[..16].iter().take_while(|&&b| b != 0).map(|&b| char::from(b)).collect();
        let (start, size) = (u64_at(entry, 16), u64_at(entry, 24));
        match start.checked_add(size) {
            Some(stop) if stop <= len && start >= BOOTSTRAP as u64 => {}
            _ => {
                return Err(malformed(format!(
                    "its section {name:?} of {size} bytes at byte {start} lies outside the file ({len} bytes)"
                )));
            }
        }
        sections.push((name, start, size));
    }
    // The token count the paths are checked against (the crate reads the
    // tokens first, whatever the table's order).
    let tokens = match sections.iter().find(|s| s.0 == "TOKENS") {
        Some(&(_, start, size)) if size >= 8 => u64_at(&read_at(start, 8)?, 0),
        _ => 0,
    };
    for (name, start, size) in sections {
        let mut section = Section { name: &name, at: start, end: start + size, tokens, read_at: &mut read_at };
        section.check()?;
    }
    super::usdc_values::check(path, len, version)
}

/// One section's bytes as the crate reads them, front to back.
struct Section<'a, F: FnMut(u64, usize) -> Result<Vec<u8>>> {
    name: &'a str,
    /// The next byte to read.
    at: u64,
    /// Its end.
    end: u64,
    /// Tokens in the layer's table.
    tokens: u64,
    read_at: &'a mut F,
}

impl<F: FnMut(u64, usize) -> Result<Vec<u8>>> Section<'_, F> {
    fn refuse(&self, what: String) -> Error {
        malformed(format!("its section {:?}: {what}", self.name))
    }

    /// The next eight bytes, `what` they hold.
    fn u64(&mut self, what: &str) -> Result<u64> {
        if self.at + 8 > self.end {
            return Err(self.refuse(format!("{what} would lie past the section's end (byte {})", self.end)));
        }
        let value = u64_at(&(self.read_at)(self.at, 8)?, 0);
        self.at += 8;
        Ok(value)
    }

    /// A compressed block (its size, then its bytes): its bytes.
    fn block(&mut self) -> Result<Vec<u8>> {
        let size = self.u64("a compressed block's size")?;
        if size > self.end - self.at {
            return Err(self.refuse(format!(
                "a compressed block of {size} bytes at byte {} reaches past the section's end (byte {})",
                self.at, self.end
            )));
        }
        let bytes = (self.read_at)(self.at, size as usize)?;
        self.at += size;
        Ok(bytes)
    }

    /// A compressed `block`, decompressed into at most `room` bytes.
    fn decompressed(&self, block: &[u8], room: u64) -> Result<Vec<u8>> {
        super::usdc_blocks::decompress(block, room, &format!("its section {:?}", self.name))
    }

    /// A `block` of `count` 32-bit integers in the crate's coding, decoded.
    fn ints(&self, block: &[u8], count: u64) -> Result<Vec<i32>> {
        let data = self.decompressed(block, super::usdc_blocks::encoded_room(count, 4))?;
        super::usdc_blocks::decode_ints(&data, count, &format!("its section {:?}", self.name))
    }

    /// `count` items `what`, decoded from compressed blocks of `bytes` bytes.
    fn bound(&self, count: u64, what: &str, bytes: u64) -> Result<()> {
        let most = bytes.saturating_add(16).saturating_mul(MAX_ITEMS_PER_BYTE).min(MAX_ITEMS);
        if count > most {
            return Err(self
                .refuse(format!("{count} {what}, more than its {bytes} compressed bytes can hold (at most {most})")));
        }
        Ok(())
    }

    /// The section's counts and blocks, by its name (other sections pass).
    fn check(&mut self) -> Result<()> {
        match self.name {
            "TOKENS" => {
                let count = self.u64("the token count")?;
                let decoded = self.u64("the tokens' decoded size")?;
                let block = self.block()?;
                self.bound(decoded, "bytes of tokens", block.len() as u64)?;
                self.decompressed(&block, decoded)?;
                if count > decoded {
                    return Err(self.refuse(format!("{count} tokens in {decoded} bytes")));
                }
            }
            "STRINGS" => {
                let count = self.u64("the string count")?;
                if count.saturating_mul(4) > self.end - self.at || count > MAX_ITEMS {
                    return Err(
                        self.refuse(format!("{count} strings, more than its {} bytes hold", self.end - self.at))
                    );
                }
            }
            "FIELDS" => {
                let count = self.u64("the field count")?;
                let (indices, reps) = (self.block()?, self.block()?);
                self.bound(count, "fields", indices.len().min(reps.len()) as u64)?;
                self.ints(&indices, count)?;
                let reps = self.decompressed(&reps, count.saturating_mul(8))?;
                if (reps.len() as u64) < count * 8 {
                    return Err(
                        self.refuse(format!("{} bytes of value representations for {count} fields", reps.len()))
                    );
                }
            }
            "FIELDSETS" => {
                let count = self.u64("the field set count")?;
                let block = self.block()?;
                self.bound(count, "field set entries", block.len() as u64)?;
                self.ints(&block, count)?;
            }
            "PATHS" => {
                let paths = self.u64("the path count")?;
                let encoded = self.u64("the encoded path count")?;
                let blocks = [self.block()?, self.block()?, self.block()?];
                let least = blocks.iter().map(Vec::len).min().unwrap_or(0) as u64;
                self.bound(paths, "paths", least)?;
                self.bound(encoded, "encoded paths", least)?;
                let [indexes, tokens, jumps] = &blocks;
                let arrays = [self.ints(indexes, encoded)?, self.ints(tokens, encoded)?, self.ints(jumps, encoded)?];
                super::usdc_blocks::check_paths((&arrays[0], &arrays[1], &arrays[2]), paths, self.tokens)?;
            }
            "SPECS" => {
                let count = self.u64("the spec count")?;
                let blocks = [self.block()?, self.block()?, self.block()?];
                self.bound(count, "specs", blocks.iter().map(Vec::len).min().unwrap_or(0) as u64)?;
                for block in &blocks {
                    self.ints(block, count)?;
                }
            }
            _ => {}
        }
        Ok(())
    }
}
