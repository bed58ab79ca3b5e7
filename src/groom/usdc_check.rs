//! What a USD binary (crate) layer must satisfy before the `openusd` crate
//! reads it, which trusts its bootstrap and table of contents: [`check`]
//! reads them, without the crate, and refuses
//!
//! - a bootstrap that is not `PXR-USDC` or is cut short;
//! - a crate version the reader cannot read: before 0.4.0 (the crate stops
//!   on those with a panic) or after [`NEWEST`];
//! - a table of contents outside the file, of no section or more than
//!   [`MAX_SECTIONS`], or whose sections reach past the file's end.
//!
//! Each error names the value found and the file's length.

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

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

fn u64_at(bytes: &[u8], at: u64) -> Option<u64> {
    let at = usize::try_from(at).ok()?;
    let b = bytes.get(at..at.checked_add(8)?)?;
    Some(u64::from_le_bytes(b.try_into().ok()?))
}

/// Checks the crate file `bytes` (a whole layer).
pub fn check(bytes: &[u8]) -> Result<()> {
    let len = bytes.len() as u64;
    if bytes.len() < BOOTSTRAP || &bytes[..8] != b"PXR-USDC" {
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
    let toc = u64_at(bytes, 16).unwrap_or(0);
    let count = u64_at(bytes, toc)
        .filter(|_| toc >= BOOTSTRAP as u64)
        .ok_or_else(|| malformed(format!("its table of contents is at byte {toc}, outside the file ({len} bytes)")))?;
    if !(1..=MAX_SECTIONS).contains(&count) {
        return Err(malformed(format!("its table of contents lists {count} sections (1 to {MAX_SECTIONS} are read)")));
    }
    let end = toc.saturating_add(8).saturating_add(count * SECTION);
    if end > len {
        return Err(malformed(format!(
            "its table of contents of {count} sections ends at byte {end}, past the file's end ({len} bytes)"
        )));
    }
    for i in 0..count {
        let entry = toc + 8 + i * SECTION;
        let name_bytes = &bytes[entry as usize..entry as usize + 16];
        let name: String = name_bytes.iter().take_while(|&&b| b != 0).map(|&b| char::from(b)).collect();
        let (start, size) = (u64_at(bytes, entry + 16).unwrap_or(0), u64_at(bytes, entry + 24).unwrap_or(0));
        match start.checked_add(size) {
            Some(stop) if stop <= len && start >= BOOTSTRAP as u64 => {}
            _ => {
                return Err(malformed(format!(
                    "its section {:?} of {size} bytes at byte {start} lies outside the file ({len} bytes)",
                    name.escape_debug().to_string()
                )));
            }
        }
    }
    Ok(())
}
