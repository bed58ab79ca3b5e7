//! The values a USD binary (crate) layer's fields point at, checked before the
//! `openusd` crate reads them: it takes each array's length and each vector's
//! count from the file and allocates that many elements before it reads them
//! (a changed byte asked for 10¹² bytes and aborted the process). [`check`]
//! reads the layer's structure with the crate (after
//! [`super::usdc_check::check`] has bounded it), then, for every field's
//! value stored out of line, the few bytes that hold its count, and refuses
//! one the rest of the file cannot hold:
//!
//! - an array (`int[]`, `point3f[]`, …): its length times its element's size,
//!   or for a compressed one at most [`MAX_ITEMS_PER_BYTE`] elements a byte
//!   and [`MAX_ITEMS`] in all;
//! - a token, string, path, double or layer-offset vector, and every list of
//!   a list operation of tokens, strings, paths or integers: its count times
//!   its item's size.
//!
//! Values inside dictionaries and time samples are not reached. Then the
//! prims' children lists are checked against the layer's paths
//! (`groom/usdc_children.rs`).

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::{Error, FileFormat, Result};

/// Most items (tokens, fields, paths, specs) a compressed byte can decode to:
/// the integer coding's two bits an item at best, times LZ4's best ratio
/// (255), rounded up.
pub const MAX_ITEMS_PER_BYTE: u64 = 1024;
/// Most items a section may count (what the crate's own bound on strings is):
/// a gibibyte of 8-byte values.
pub const MAX_ITEMS: u64 = 1 << 27;

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// A field's value representation, as the crate format packs it in 64 bits.
#[derive(Clone, Copy)]
struct ValueRep(u64);

impl ValueRep {
    fn ty(self) -> u64 {
        (self.0 >> 48) & 0xFF
    }
    fn payload(self) -> u64 {
        self.0 & ((1 << 48) - 1)
    }
    fn is_array(self) -> bool {
        self.0 & (1 << 63) != 0
    }
    fn is_inlined(self) -> bool {
        self.0 & (1 << 62) != 0
    }
    fn is_compressed(self) -> bool {
        self.0 & (1 << 61) != 0
    }
}

/// Bytes of one element of an array of crate type `ty` (1 for a type this
/// check does not size: a lower bound).
fn element_size(ty: u64) -> u64 {
    match ty {
        1 | 2 => 1,                         // bool, uchar
        7 => 2,                             // half
        3 | 4 | 8 | 10 | 11 | 12 | 57 => 4, // int, uint, float, string, token, asset, path expression
        5 | 6 | 9 | 56 => 8,                // int64, uint64, double, time code
        13 => 32,                           // matrix2d
        14 => 72,                           // matrix3d
        15 => 128,                          // matrix4d
        16 | 27 => 32,                      // quatd, vec4d
        17 | 28 | 30 | 19 => 16,            // quatf, vec4f, vec4i, vec2d
        18 | 29 | 20 | 22 => 8,             // quath, vec4h, vec2f, vec2i
        21 => 4,                            // vec2h
        23 => 24,                           // vec3d
        24 | 26 => 12,                      // vec3f, vec3i
        25 => 6,                            // vec3h
        _ => 1,
    }
}

/// The crate types stored as integers (compressed from version 0.5.0) and as
/// floating point (from 0.6.0).
fn compressible(ty: u64, version: (u8, u8, u8)) -> bool {
    match ty {
        3..=6 => version >= (0, 5, 0),
        7..=9 => version >= (0, 6, 0),
        _ => false,
    }
}

/// Item sizes of the lists a vector or list-op type holds, and whether its
/// value starts with a list-op header byte: `None` for the other types.
fn counted_items(ty: u64) -> Option<(u64, bool)> {
    match ty {
        40 | 41 | 50 => Some((4, false)),          // path, token, string vectors
        48 => Some((8, false)),                    // double vector
        49 => Some((16, false)),                   // layer offset vector
        32 | 33 | 34 | 36 | 38 => Some((4, true)), // token, string, path, int, uint list ops
        37 | 39 => Some((8, true)),                // int64, uint64 list ops
        _ => None,
    }
}

/// Checks the values of the crate file at `path`, `len` bytes long, `version`
/// its crate version, whose structure [`super::usdc_check::check`] passed.
pub fn check(path: &Path, len: u64, version: (u8, u8, u8)) -> Result<()> {
    let io = |source| Error::Io { path: path.into(), source };
    let reps = crate::files::read_guarded(|| {
        let file = std::fs::File::open(path).map_err(|e| format!("{e}"))?;
        let crate_file = openusd::usdc::CrateFile::open(std::io::BufReader::new(file)).map_err(|e| format!("{e:#}"))?;
        Ok::<_, String>(crate_file.fields.iter().map(|f| f.value_rep.0).collect::<Vec<u64>>())
    })
    .unwrap_or_else(|what| Err(format!("the USD reader stopped: {what}")))
    .map_err(|why| malformed(format!("its structure cannot be read: {why}")))?;
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut read_at = |at: u64, n: usize| -> Result<u64> {
        let mut b = [0u8; 8];
        file.seek(SeekFrom::Start(at)).and_then(|_| file.read_exact(&mut b[..n])).map_err(io)?;
        Ok(u64::from_le_bytes(b))
    };
    for (field, rep) in reps.into_iter().map(ValueRep).enumerate() {
        // The crate reads a vector or list operation by its type whatever its
        // array bit says, and arrays and those at their payload whatever the
        // inlined bit says: only other inlined values are skipped.
        let counted = rep.is_array() || counted_items(rep.ty()).is_some();
        if (rep.is_inlined() && !counted) || (rep.is_array() && rep.payload() == 0) {
            continue;
        }
        let what = |detail: String| malformed(format!("field {field}'s value (type {}) {detail}", rep.ty()));
        let at = rep.payload();
        let room = |from: u64| len.saturating_sub(from);
        if let Some((item, list_op)) = counted_items(rep.ty()) {
            let mut pos = at;
            let lists = if list_op {
                if pos + 1 > len {
                    return Err(what(format!("starts at byte {at}, past the file's end ({len} bytes)")));
                }
                let header = read_at(pos, 1)? as u8;
                pos += 1;
                // One list for each of the header's bits after the first.
                ((header >> 1) & 0x3F).count_ones()
            } else {
                1
            };
            for _ in 0..lists {
                if pos + 8 > len {
                    return Err(what(format!("has a count past the file's end ({len} bytes)")));
                }
                let count = read_at(pos, 8)?;
                pos += 8;
                if count > room(pos) / item {
                    return Err(what(format!("counts {count} items at byte {at}, more than the file holds")));
                }
                pos += count * item;
            }
        } else if rep.is_array() && (rep.ty() <= 30 || matches!(rep.ty(), 56 | 57)) {
            let mut pos = at + if version < (0, 5, 0) { 4 } else { 0 };
            let wide = version >= (0, 7, 0);
            if pos + if wide { 8 } else { 4 } > len {
                return Err(what(format!("starts at byte {at}, past the file's end ({len} bytes)")));
            }
            let count = read_at(pos, if wide { 8 } else { 4 })?;
            pos += if wide { 8 } else { 4 };
            let compressed = rep.is_compressed() && count >= 4 && compressible(rep.ty(), version);
            let most = if compressed {
                room(pos).saturating_mul(MAX_ITEMS_PER_BYTE).min(MAX_ITEMS)
            } else {
                room(pos) / element_size(rep.ty())
            };
            if count > most {
                return Err(what(format!(
                    "is an array of {count} elements at byte {at}, more than the file holds (at most {most})"
                )));
            }
        } else if at >= len {
            return Err(what(format!("starts at byte {at}, past the file's end ({len} bytes)")));
        }
    }
    super::usdc_children::check(path, version)
}
