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
//!   its item's size; a dictionary's and a variant selection map's entries
//!   (at least 12 and 8 bytes each: the crate loops over a dictionary's
//!   count, seeking by offsets it reads).
//!
//! Then every index a value holds into the layer's tables — single tokens,
//! strings and asset paths, token and string arrays, token, string and path
//! vectors and list operations — must lie inside its table, and an array may
//! not be marked inlined, nor compressed unless its type's arrays are (the
//! crate indexes and asserts without checking); the crate's own
//! cross-checks of its tables run first (`CrateFile::validate`). The values
//! inside dictionaries, time samples, references and payloads are walked the
//! same way, bounded in depth and number (`groom/usdc_nested.rs`). Then the
//! prims' children lists are checked against the layer's paths
//! (`groom/usdc_children.rs`).

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::usdc_nested::{Tables, ValueRep, Walk};
use crate::error::{Error, FileFormat, Result};

/// Most items (tokens, fields, paths, specs) a compressed byte can decode to:
/// the integer coding's two bits an item at best, times LZ4's best ratio
/// (255), rounded up.
pub const MAX_ITEMS_PER_BYTE: u64 = 1024;
/// Most items a section may count (what the crate's own bound on strings is):
/// a gibibyte of 8-byte values.
pub const MAX_ITEMS: u64 = 1 << 27;

/// Bytes of the file the value checks read at once.
const WINDOW: u64 = 64 << 10;

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
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
        // Time codes are doubles (the crate reads their arrays as it reads floats).
        7..=9 | 56 => version >= (0, 6, 0),
        _ => false,
    }
}

/// Item sizes of the lists a vector or list-op type holds, and whether its
/// value starts with a list-op header byte: `None` for the other types.
fn counted_items(ty: u64) -> Option<(u64, bool)> {
    match ty {
        40 | 41 | 50 => Some((4, false)),          // path, token, string vectors
        31 => Some((12, false)),                   // dictionary: a string key and a value each
        45 => Some((8, false)),                    // variant selections: two strings each
        48 => Some((8, false)),                    // double vector
        49 => Some((16, false)),                   // layer offset vector
        32 | 33 | 34 | 36 | 38 => Some((4, true)), // token, string, path, int, uint list ops
        37 | 39 => Some((8, true)),                // int64, uint64 list ops
        54 => Some((4, true)),                     // unregistered value list ops: string lists
        58 => Some((8, false)),                    // relocates: two paths each
        _ => None,
    }
}

/// Checks the values of the crate file at `path`, `len` bytes long, `version`
/// its crate version, whose structure [`super::usdc_check::check`] passed.
pub fn check(path: &Path, len: u64, version: (u8, u8, u8)) -> Result<()> {
    let io = |source| Error::Io { path: path.into(), source };
    let (reps, tables) = crate::files::read_guarded(|| {
        let file = std::fs::File::open(path).map_err(|e| format!("{e}"))?;
        let crate_file = openusd::usdc::CrateFile::open(std::io::BufReader::new(file)).map_err(|e| format!("{e:#}"))?;
        // The crate's own cross-checks of its tables (fields' tokens,
        // field sets, specs' paths), which reading a stage does not run.
        crate_file.validate().map_err(|e| format!("{e:#}"))?;
        let tables = Tables {
            tokens: crate_file.tokens.len() as u64,
            strings: crate_file.strings.len() as u64,
            paths: crate_file.paths.len() as u64,
            string_tokens: crate_file.strings.iter().map(|&t| t as u64).collect(),
            // `validate` checked the fields' tokens.
            field_names: crate_file.fields.iter().map(|f| crate_file.tokens[f.token_index].clone()).collect(),
        };
        Ok::<_, String>((crate_file.fields.iter().map(|f| f.value_rep.0).collect::<Vec<u64>>(), tables))
    })
    .unwrap_or_else(|what| Err(format!("the USD reader stopped: {what}")))
    .map_err(|why| malformed(format!("its structure cannot be read: {why}")))?;
    if let Some((i, &token)) = tables.string_tokens.iter().enumerate().find(|(_, t)| **t >= tables.tokens) {
        return Err(malformed(format!("its string {i} names token {token} of {}", tables.tokens)));
    }
    let mut file = std::fs::File::open(path).map_err(io)?;
    // Reads go through a window of the file, so that the indices of a long
    // vector cost a read a window, not one each.
    let (mut window, mut window_at) = (Vec::new(), 0u64);
    let mut read_at = |at: u64, n: usize| -> Result<u64> {
        let inside = at >= window_at && at + n as u64 <= window_at + window.len() as u64;
        if !inside {
            let size = WINDOW.min(len.saturating_sub(at)) as usize;
            window.resize(size, 0);
            file.seek(SeekFrom::Start(at)).and_then(|_| file.read_exact(&mut window)).map_err(io)?;
            window_at = at;
        }
        let from = (at - window_at) as usize;
        let bytes = window.get(from..from + n).ok_or_else(|| {
            malformed(format!("a value's {n} bytes at byte {at} lie past the file's end ({len} bytes)"))
        })?;
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(bytes);
        Ok(u64::from_le_bytes(b))
    };
    let mut visits = 0u64;
    for (field, rep) in reps.iter().copied().map(ValueRep).enumerate() {
        let mut walk = Walk {
            field,
            tables: &tables,
            version,
            len,
            read_at: &mut read_at,
            visits: &mut visits,
            check: check_value,
        };
        check_value(&mut walk, rep, 0)?;
    }
    super::usdc_children::check(path)
}

/// Checks value `rep` of `walk`'s field (at nesting `depth`): an array's
/// bits, every count against the room the file has, every index against its
/// table, and what values it holds ([`super::usdc_nested`]).
pub(super) fn check_value(walk: &mut Walk<'_>, rep: ValueRep, depth: u32) -> Result<()> {
    check_counts(walk, rep)?;
    check_indices(walk.field, rep, walk.tables, walk.version, walk.read_at)?;
    super::usdc_nested::check(walk, rep, depth)
}

/// The counts of value `rep` against the room the file has (nothing for a
/// value the crate does not read at its payload).
fn check_counts(walk: &mut Walk<'_>, rep: ValueRep) -> Result<()> {
    let (field, tables, version, len) = (walk.field, walk.tables, walk.version, walk.len);
    let read_at = &mut *walk.read_at;
    // The crate asserts what an array's bits may be: never inlined, and
    // compressed only where its type's arrays are (integers from 0.5.0,
    // floating point from 0.6.0).
    if rep.is_array() && (rep.is_inlined() || (rep.is_compressed() && !compressible(rep.ty(), version))) {
        let bits = if rep.is_inlined() { "inlined" } else { "compressed" };
        return Err(malformed(format!(
            "{}'s value (type {}) is an array marked {bits}",
            tables.field(field),
            rep.ty()
        )));
    }
    // The crate reads a vector or list operation by its type whatever its
    // array bit says, and arrays and those at their payload whatever the
    // inlined bit says: only other inlined values are skipped.
    let counted = rep.is_array() || counted_items(rep.ty()).is_some();
    // (An inlined dictionary is an empty one: nothing to read.)
    let empty_dictionary = rep.ty() == 31 && rep.is_inlined();
    if (rep.is_inlined() && !counted) || (rep.is_array() && rep.payload() == 0) || empty_dictionary {
        return Ok(());
    }
    let what = |detail: String| malformed(format!("{}'s value (type {}) {detail}", tables.field(field), rep.ty()));
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
        if compressed {
            check_compressed_block(read_at, pos, len, rep.ty(), count).map_err(what)?;
        }
    } else if at >= len {
        return Err(what(format!("starts at byte {at}, past the file's end ({len} bytes)")));
    }
    Ok(())
}

/// The block of a compressed array of crate type `ty` whose elements start
/// at byte `pos` of a file `len` bytes long: the crate allocates its
/// compressed size (and a floating-point array's lookup table) as the file
/// states them before it reads them (a file of another version's layout had
/// it ask for 80 GiB). An integer array is that size and the block; a
/// floating-point one a code byte, then either that (`i`, integers) or a
/// 32-bit table length, the table and that (`t`). Each must fit in the file,
/// and the block must decode as the crate decodes it — LZ4 into the room it
/// gives (sized for 32-bit integers, whatever the type), then `count`
/// integers of the type's width, a table's indices inside it — since the
/// crate slices and indexes what it decodes without checking (a block size
/// changed to 7 stopped it with a panic). `Err` says how it does not.
fn check_compressed_block(
    read_at: &mut dyn FnMut(u64, usize) -> Result<u64>,
    pos: u64,
    len: u64,
    ty: u64,
    count: u64,
) -> std::result::Result<(), String> {
    let room = |from: u64| len.saturating_sub(from);
    let past = || format!("has its compressed block past the file's end ({len} bytes)");
    let io = |e: Error| format!("cannot be read: {e}");
    let mut pos = pos;
    let mut table = None;
    if !(3..=6).contains(&ty) {
        // Floating point: a code byte first.
        if room(pos) < 1 {
            return Err(past());
        }
        let code = read_at(pos, 1).map_err(io)? as u8;
        pos += 1;
        match code {
            b'i' => {}
            b't' => {
                if room(pos) < 4 {
                    return Err(past());
                }
                let values = read_at(pos, 4).map_err(io)?;
                pos += 4;
                let bytes = values.saturating_mul(element_size(ty));
                if bytes > room(pos) {
                    return Err(format!("has a lookup table of {values} values, more than the file holds"));
                }
                pos += bytes;
                table = Some(values);
            }
            other => return Err(format!("has an unknown compression code {other}")),
        }
    }
    if room(pos) < 8 {
        return Err(past());
    }
    let size = read_at(pos, 8).map_err(io)?;
    if size > room(pos + 8) {
        return Err(format!("has a compressed block of {size} bytes, more than the file holds"));
    }
    let mut block = Vec::with_capacity(size as usize);
    for at in (pos + 8..pos + 8 + size).step_by(8) {
        let n = (pos + 8 + size - at).min(8) as usize;
        block.extend_from_slice(&read_at(at, n).map_err(io)?.to_le_bytes()[..n]);
    }
    let reason = |e: Error| match e {
        Error::Malformed { reason, .. } => reason,
        e => e.to_string(),
    };
    let what = "has a compressed block that does not decode";
    let room_bytes = super::usdc_blocks::encoded_room(count, 4);
    let decoded = super::usdc_blocks::decompress(&block, room_bytes, what).map_err(reason)?;
    let width = if matches!(ty, 5 | 6) { 8 } else { 4 };
    let ints = super::usdc_blocks::decode_ints_of(&decoded, count, width, what).map_err(reason)?;
    if let Some(values) = table {
        if let Some(index) = ints.iter().find(|&&i| (i as u32 as u64) >= values) {
            return Err(format!("names value {} of a lookup table of {values}", *index as u32));
        }
    }
    Ok(())
}

/// Which table a value's indices point into.
#[derive(Clone, Copy)]
enum Table {
    Tokens,
    Strings,
    Paths,
}

/// Refuses a value of field `field` holding a token, string or path index
/// past its table (the crate indexes its tables without checking): single
/// tokens, strings and asset paths, token and string arrays, token, string
/// and path vectors and list operations, relocates. The counts were bounded
/// before ([`check_counts`]); values nested in others are walked by
/// [`super::usdc_nested`].
fn check_indices(
    field: usize,
    rep: ValueRep,
    tables: &Tables,
    version: (u8, u8, u8),
    read_at: &mut dyn FnMut(u64, usize) -> Result<u64>,
) -> Result<()> {
    let size = |table| match table {
        Table::Tokens => tables.tokens,
        Table::Strings => tables.strings,
        Table::Paths => tables.paths,
    };
    let name = |table| match table {
        Table::Tokens => "token",
        Table::Strings => "string",
        Table::Paths => "path",
    };
    let within = |index: u64, table: Table| {
        if index < size(table) {
            Ok(())
        } else {
            Err(malformed(format!(
                "{}'s value (type {}) names {} {index} of {}",
                tables.field(field),
                rep.ty(),
                name(table),
                size(table)
            )))
        }
    };
    // `count` indices of 4 bytes from byte `at`, each within `table`.
    let indices = |read_at: &mut dyn FnMut(u64, usize) -> Result<u64>, at: u64, count: u64, table: Table| {
        for k in 0..count {
            within(read_at(at + 4 * k, 4)?, table)?;
        }
        Ok::<_, Error>(at + 4 * count)
    };
    let at = rep.payload();
    // An inlined value is its payload's low 32 bits; another lies at its payload.
    let single = |read_at: &mut dyn FnMut(u64, usize) -> Result<u64>, bytes: usize| {
        if rep.is_inlined() {
            Ok(at & 0xFFFF_FFFF)
        } else {
            read_at(at, bytes)
        }
    };
    match (rep.ty(), rep.is_array()) {
        (11, false) => within(single(read_at, 8)?, Table::Tokens),
        (10, false) => within(single(read_at, 4)?, Table::Strings),
        (12, false) => within(single(read_at, 4)?, if rep.is_inlined() { Table::Tokens } else { Table::Strings }),
        (11, true) if at != 0 => {
            let start = at + if version < (0, 5, 0) { 4 } else { 0 };
            let wide = version >= (0, 7, 0);
            let count = read_at(start, if wide { 8 } else { 4 })?;
            indices(read_at, start + if wide { 8 } else { 4 }, count, Table::Tokens).map(|_| ())
        }
        (10 | 12, true) | (50, _) if at != 0 => {
            let count = read_at(at, 8)?;
            indices(read_at, at + 8, count, Table::Strings).map(|_| ())
        }
        (40 | 41, _) => {
            let count = read_at(at, 8)?;
            indices(read_at, at + 8, count, if rep.ty() == 40 { Table::Paths } else { Table::Tokens }).map(|_| ())
        }
        (58, _) => {
            // Relocates: pairs of paths.
            let count = read_at(at, 8)?;
            indices(read_at, at + 8, count.saturating_mul(2), Table::Paths).map(|_| ())
        }
        (32..=34 | 54, _) => {
            let table = match rep.ty() {
                32 => Table::Tokens,
                34 => Table::Paths,
                _ => Table::Strings,
            };
            let header = read_at(at, 1)? as u8;
            let mut pos = at + 1;
            for _ in 0..((header >> 1) & 0x3F).count_ones() {
                let count = read_at(pos, 8)?;
                pos = indices(read_at, pos + 8, count, table)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::check_compressed_block;

    /// A compressed array's block as the crate stores it, from byte 0: for a
    /// float type (`ty` 8) the code byte and, with `table`, a lookup table of
    /// that many floats; then the block's size and the block (the chunk
    /// count 0, then LZ4 of `count` integers all the common value `common`:
    /// it, in the type's width, and a code byte of zeros a four).
    fn block(ty: u64, table: Option<u32>, common: i32, count: usize, size: Option<u64>) -> Vec<u8> {
        let mut encoded = match ty {
            5 | 6 => i64::from(common).to_le_bytes().to_vec(),
            _ => common.to_le_bytes().to_vec(),
        };
        encoded.extend(std::iter::repeat_n(0u8, (count * 2).div_ceil(8)));
        let mut lz4 = vec![0u8];
        lz4.extend(lz4_flex::block::compress(&encoded));
        let mut out = Vec::new();
        if ty == 8 {
            match table {
                Some(n) => {
                    out.push(b't');
                    out.extend(n.to_le_bytes());
                    out.extend(std::iter::repeat_n(0u8, 4 * n as usize));
                }
                None => out.push(b'i'),
            }
        }
        out.extend(size.unwrap_or(lz4.len() as u64).to_le_bytes());
        out.extend(lz4);
        out
    }

    fn check(bytes: &[u8], ty: u64, count: u64) -> Result<(), String> {
        let mut read_at = |at: u64, n: usize| -> crate::error::Result<u64> {
            let mut b = [0u8; 8];
            b[..n].copy_from_slice(&bytes[at as usize..at as usize + n]);
            Ok(u64::from_le_bytes(b))
        };
        check_compressed_block(&mut read_at, 0, bytes.len() as u64, ty, count)
    }

    /// Blocks that decode as the crate decodes them pass; a block cut short
    /// (its size changed to 7: the crate sliced past what it decoded and
    /// stopped with a panic), a block past the file and a lookup table's
    /// index past the table are refused, each saying what.
    #[test]
    fn compressed_blocks_are_decoded_before_the_reader_trusts_them() {
        assert_eq!(check(&block(3, None, 1, 400, None), 3, 400), Ok(()));
        assert_eq!(check(&block(5, None, 1, 400, None), 5, 400), Ok(()), "64-bit integers");
        assert_eq!(check(&block(8, None, 1, 400, None), 8, 400), Ok(()), "floats as integers");
        assert_eq!(check(&block(8, Some(4), 0, 400, None), 8, 400), Ok(()), "a lookup table's index 0");
        let cut = block(3, None, 1, 400, Some(7));
        let e = check(&cut, 3, 400).expect_err("cut short");
        assert!(e.contains("does not decode"), "{e}");
        let e = check(&block(3, None, 1, 400, Some(1 << 40)), 3, 400).expect_err("past the file");
        assert!(e.contains("a compressed block of 1099511627776 bytes, more than the file holds"), "{e}");
        let e = check(&block(8, Some(4), 1, 400, None), 8, 400).expect_err("an index past the table");
        assert!(e.contains("names value 4 of a lookup table of 4"), "{e}");
        let e = check(&block(8, None, 1, 400, None)[..1], 8, 400).expect_err("no size");
        assert!(e.contains("past the file's end"), "{e}");
    }
}
