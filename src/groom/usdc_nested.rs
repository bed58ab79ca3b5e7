//! Values that hold other values in a USD binary layer, walked before the
//! `openusd` crate reads them: a dictionary (its entries' values reached by
//! offsets the file gives), time samples (a times value and a list of values,
//! by offsets too), and the references and payloads of a list operation (each
//! an asset path, a prim path, a layer offset and, for a reference, a
//! dictionary of custom data). The crate follows each offset and reads each
//! nested value as it reads a field's own, allocating by counts the file
//! gives and recursing without a limit (a dictionary whose entry points back
//! at itself recursed until the stack ended). [`check`] walks the same
//! offsets and checks every nested value as `usdc_values` checks a
//! field's (counts against the room the file has, indices against their
//! tables), at most [`MAX_VALUE_NESTING`] deep and [`MAX_NESTED_VALUES`] in
//! all.

use crate::error::{Error, FileFormat, Result};

/// Deepest a value may lie inside others (dictionaries in dictionaries, time
/// samples of dictionaries): far beyond what a real layer's metadata needs.
pub const MAX_VALUE_NESTING: u32 = 64;

/// Most values a layer may nest inside others, all together: the walk (and
/// the crate's reading) visits each, however often the file points at it.
pub const MAX_NESTED_VALUES: u64 = 1 << 20;

/// Smallest a dictionary entry may be: a key's string index, an offset and
/// the value's representation.
const ENTRY_BYTES: u64 = 4 + 8 + 8;

/// A field's value representation, as the crate format packs it in 64 bits.
#[derive(Clone, Copy)]
pub(super) struct ValueRep(pub(super) u64);

impl ValueRep {
    pub(super) fn ty(self) -> u64 {
        (self.0 >> 48) & 0xFF
    }
    pub(super) fn payload(self) -> u64 {
        self.0 & ((1 << 48) - 1)
    }
    pub(super) fn is_array(self) -> bool {
        self.0 & (1 << 63) != 0
    }
    pub(super) fn is_inlined(self) -> bool {
        self.0 & (1 << 62) != 0
    }
    pub(super) fn is_compressed(self) -> bool {
        self.0 & (1 << 61) != 0
    }
}

/// One field's value being checked, and what the walk of values nested in
/// others needs ([`super::usdc_nested`]).
pub(super) struct Walk<'a> {
    /// The field whose value (or a value nested in it) is checked.
    pub field: usize,
    pub tables: &'a Tables,
    pub version: (u8, u8, u8),
    /// The file's length.
    pub len: u64,
    /// Up to 8 bytes of the file at a byte offset, little-endian.
    pub read_at: &'a mut dyn FnMut(u64, usize) -> Result<u64>,
    /// Values visited so far over the whole layer (nested ones included).
    pub visits: &'a mut u64,
    /// What checks a value (and, through this walk, what it holds):
    /// `usdc_values::check_value`.
    pub check: fn(&mut Walk<'_>, ValueRep, u32) -> Result<()>,
}

/// The sizes of the tables a value's indices point into.
pub(super) struct Tables {
    pub tokens: u64,
    pub strings: u64,
    pub paths: u64,
    /// Each string's token.
    pub string_tokens: Vec<u64>,
    /// Each field's name.
    pub field_names: Vec<String>,
}

impl Tables {
    /// Field `field` as an error names it: its index and name.
    pub(super) fn field(&self, field: usize) -> String {
        let name = self.field_names.get(field).map_or("", String::as_str);
        format!("field {field} ({name:?})")
    }
}

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// Checks the values `rep` (of `walk`'s field, `depth` deep) holds.
pub(super) fn check(walk: &mut Walk<'_>, rep: ValueRep, depth: u32) -> Result<()> {
    let at = rep.payload();
    match rep.ty() {
        31 if !rep.is_inlined() => dictionary(walk, at, depth).map(drop),
        35 => list_op(walk, rep, depth, Item::Reference),
        55 => list_op(walk, rep, depth, Item::Payload),
        47 if !rep.is_inlined() => item(walk, at, depth, Item::Payload).map(drop),
        46 => time_samples(walk, at, depth),
        _ => Ok(()),
    }
}

/// What a list operation of references or payloads holds.
#[derive(Clone, Copy)]
enum Item {
    Reference,
    Payload,
}

/// `what` said of `walk`'s field.
fn refused(walk: &Walk<'_>, what: String) -> Error {
    malformed(format!("{}'s value {what}", walk.tables.field(walk.field)))
}

/// Counts one more nested value at `depth`, refusing one too deep or too many.
fn visit(walk: &mut Walk<'_>, depth: u32) -> Result<()> {
    *walk.visits += 1;
    if depth > MAX_VALUE_NESTING {
        return Err(refused(walk, format!("nests values more than {MAX_VALUE_NESTING} deep")));
    }
    if *walk.visits > MAX_NESTED_VALUES {
        return Err(refused(walk, format!("takes the layer past {MAX_NESTED_VALUES} nested values")));
    }
    Ok(())
}

/// Bytes `n` at `at` (little-endian), refused past the file's end.
fn read(walk: &mut Walk<'_>, at: u64, n: usize) -> Result<u64> {
    if at.checked_add(n as u64).is_none_or(|end| end > walk.len) {
        return Err(refused(walk, format!("reads {n} bytes at byte {at}, past the file's end ({} bytes)", walk.len)));
    }
    (walk.read_at)(at, n)
}

/// Where an offset at byte `at` leads: `at` plus the signed offset it holds
/// (the crate seeks from before the offset), within the file.
fn follow(walk: &mut Walk<'_>, at: u64) -> Result<u64> {
    let offset = read(walk, at, 8)? as i64;
    let to = i128::from(at) + i128::from(offset);
    if to < 0 || to + 8 > i128::from(walk.len) {
        return Err(refused(walk, format!("has an offset at byte {at} leading out of the file ({to})")));
    }
    Ok(to as u64)
}

/// A string index at `at`, within the string table.
fn string(walk: &mut Walk<'_>, at: u64) -> Result<()> {
    let index = read(walk, at, 4)?;
    if index >= walk.tables.strings {
        return Err(refused(walk, format!("names string {index} of {}", walk.tables.strings)));
    }
    Ok(())
}

/// A path index at `at`, within the path table.
fn path(walk: &mut Walk<'_>, at: u64) -> Result<()> {
    let index = read(walk, at, 4)?;
    if index >= walk.tables.paths {
        return Err(refused(walk, format!("names path {index} of {}", walk.tables.paths)));
    }
    Ok(())
}

/// A count at `at` of items at least `item` bytes each, bounded by the room
/// after it.
fn count(walk: &mut Walk<'_>, at: u64, item: u64) -> Result<u64> {
    let count = read(walk, at, 8)?;
    if count > walk.len.saturating_sub(at + 8) / item {
        return Err(refused(walk, format!("counts {count} items at byte {at}, more than the file holds")));
    }
    Ok(count)
}

/// The dictionary at `at` (`depth` deep): every key and entry value; returns
/// where the crate's reading of it ends.
fn dictionary(walk: &mut Walk<'_>, at: u64, depth: u32) -> Result<u64> {
    visit(walk, depth)?;
    let entries = count(walk, at, ENTRY_BYTES)?;
    let mut pos = at + 8;
    for _ in 0..entries {
        string(walk, pos)?;
        let rep_at = follow(walk, pos + 4)?;
        let rep = ValueRep(read(walk, rep_at, 8)?);
        if rep.ty() == 0 {
            return Err(refused(walk, format!("holds an entry of no type at byte {rep_at}")));
        }
        visit(walk, depth + 1)?;
        (walk.check)(walk, rep, depth + 1)?;
        pos = rep_at + 8;
    }
    Ok(pos)
}

/// A reference or payload at `at`: its asset path, prim path, layer offset
/// and a reference's custom data; returns where it ends.
fn item(walk: &mut Walk<'_>, at: u64, depth: u32, kind: Item) -> Result<u64> {
    string(walk, at)?;
    path(walk, at + 4)?;
    match kind {
        Item::Reference => dictionary(walk, at + 8 + 16, depth + 1),
        // Layer offsets came to payloads with crate version 0.8.0.
        Item::Payload if walk.version >= (0, 8, 0) => Ok(at + 8 + 16),
        Item::Payload => Ok(at + 8),
    }
}

/// A list operation of references or payloads: its header, then per list a
/// count and the items.
fn list_op(walk: &mut Walk<'_>, rep: ValueRep, depth: u32, kind: Item) -> Result<()> {
    let at = rep.payload();
    let header = read(walk, at, 1)? as u8;
    let mut pos = at + 1;
    let least = match kind {
        Item::Reference => 8 + 16 + 8,
        Item::Payload if walk.version >= (0, 8, 0) => 8 + 16,
        Item::Payload => 8,
    };
    for _ in 0..((header >> 1) & 0x3F).count_ones() {
        let items = count(walk, pos, least)?;
        pos += 8;
        for _ in 0..items {
            visit(walk, depth + 1)?;
            pos = item(walk, pos, depth + 1, kind)?;
        }
    }
    Ok(())
}

/// Time samples at `at`: the times (a double vector or array) by an offset,
/// then by another the count and the samples' value representations.
fn time_samples(walk: &mut Walk<'_>, at: u64, depth: u32) -> Result<()> {
    visit(walk, depth)?;
    let times_at = follow(walk, at)?;
    let times = ValueRep(read(walk, times_at, 8)?);
    if !(times.ty() == 48 || (times.ty() == 9 && times.is_array())) {
        return Err(refused(walk, format!("has times of type {} (not doubles) at byte {times_at}", times.ty())));
    }
    (walk.check)(walk, times, depth + 1)?;
    let count_at = follow(walk, times_at + 8)?;
    let samples = count(walk, count_at, 8)?;
    for k in 0..samples {
        let rep = ValueRep(read(walk, count_at + 8 + 8 * k, 8)?);
        visit(walk, depth + 1)?;
        (walk.check)(walk, rep, depth + 1)?;
    }
    Ok(())
}
