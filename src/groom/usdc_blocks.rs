//! The compressed blocks of a USD binary (crate) layer's structure sections,
//! decoded as the `openusd` crate decodes them and checked before it does
//! ([`super::usdc_check`] calls these): the crate indexes and slices what it
//! decodes without checking, so a changed byte stopped it with a panic. A
//! block is refused where
//!
//! - its LZ4 data is chunked (the crate has no reader for it) or does not
//!   decompress into the room the crate gives it;
//! - it decodes to fewer integers than its section counts (the crate slices
//!   past the decoded bytes), or a block of value representations to fewer
//!   than the fields;
//! - a path names a token past the table, or a path index past the paths, or
//!   the walk of the path tree leaves the encoded paths or reaches one twice
//!   (whose repeats would compound).

use crate::error::{Error, FileFormat, Result};

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// Bytes the crate gives the decoded block of `count` integers of `width`
/// bytes: the common value, two bits a code, and at most `width` bytes an
/// integer.
pub(super) fn encoded_room(count: u64, width: u64) -> u64 {
    if count == 0 {
        0
    } else {
        width.saturating_add(count.saturating_mul(2).div_ceil(8)).saturating_add(width.saturating_mul(count))
    }
}

/// Decompresses an LZ4 `block` (the crate's one-byte chunk count, then the
/// data) into at most `room` bytes: the decoded size is found first by
/// walking the block's sequences, so that nothing larger than the block
/// decodes to is allocated.
pub(super) fn decompress(block: &[u8], room: u64, what: &str) -> Result<Vec<u8>> {
    let Some((&chunks, data)) = block.split_first() else {
        return Err(malformed(format!("{what}: an empty compressed block")));
    };
    if chunks != 0 {
        return Err(malformed(format!("{what}: a compressed block of {chunks} chunks (only whole blocks are read)")));
    }
    let refuse = |why: &str| malformed(format!("{what}: a compressed block that does not decompress: {why}"));
    let size = lz4_size(data).ok_or_else(|| refuse("its sequences run past its end or back before its start"))?;
    if size > room {
        return Err(refuse(&format!("it decodes to {size} bytes, more than the {room} the reader gives it")));
    }
    let mut out = vec![0u8; size as usize];
    let written = lz4_flex::block::decompress_into(data, &mut out).map_err(|e| refuse(&e.to_string()))?;
    out.truncate(written);
    Ok(out)
}

/// The size an LZ4 block decodes to, from its sequences' lengths (a literal
/// run, then a match of at least 4 bytes at an offset back into what was
/// decoded, the last sequence without one); `None` where a length or a
/// literal run passes the block's end or a match reaches before the start.
fn lz4_size(data: &[u8]) -> Option<u64> {
    let (mut at, mut size) = (0usize, 0u64);
    // A length: the nibble, and while it (then each added byte) is at its
    // largest, the next byte added.
    let length = |at: &mut usize, nibble: u8| -> Option<u64> {
        let mut n = u64::from(nibble);
        if nibble == 15 {
            loop {
                let b = *data.get(*at)?;
                *at += 1;
                n += u64::from(b);
                if b != 255 {
                    break;
                }
            }
        }
        Some(n)
    };
    while at < data.len() {
        let token = data[at];
        at += 1;
        let literals = length(&mut at, token >> 4)?;
        at = at.checked_add(usize::try_from(literals).ok()?).filter(|&end| end <= data.len())?;
        size += literals;
        if at == data.len() {
            return Some(size);
        }
        let offset = u64::from(u16::from_le_bytes([*data.get(at)?, *data.get(at + 1)?]));
        at += 2;
        if offset == 0 || offset > size {
            return None;
        }
        size += length(&mut at, token & 15)? + 4;
    }
    Some(size)
}

/// `count` 32-bit integers decoded from `data` as the crate's integer coding
/// stores them (a common value, two bits a code for each integer — common,
/// small, medium, large — then the deltas), kept as the crate keeps them
/// (wrapped to 32 bits): the structure's tables are all of 32-bit integers.
pub(super) fn decode_ints(data: &[u8], count: u64, what: &str) -> Result<Vec<i32>> {
    decode_ints_of(data, count, 4, what).map(|v| v.into_iter().map(|i| i as i32).collect())
}

/// `count` integers of `width` bytes (4 or 8) decoded from `data` as the
/// crate's integer coding stores them (see [`decode_ints`]), each as an
/// `i64` (a 32-bit one wrapped to 32 bits first, as the crate keeps it).
pub(super) fn decode_ints_of(data: &[u8], count: u64, width: u64, what: &str) -> Result<Vec<i64>> {
    if count == 0 {
        return Ok(Vec::new());
    }
    let codes = count.saturating_mul(2).div_ceil(8);
    let short = || malformed(format!("{what}: {} decoded bytes cannot hold {count} integers", data.len()));
    let start = width.checked_add(codes).filter(|&s| s <= data.len() as u64).ok_or_else(short)? as usize;
    let signed = |bytes: &[u8]| -> i64 {
        match bytes.len() {
            1 => i64::from(bytes[0] as i8),
            2 => i64::from(i16::from_le_bytes([bytes[0], bytes[1]])),
            4 => i64::from(i32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
            _ => i64::from_le_bytes(bytes.try_into().unwrap_or([0; 8])),
        }
    };
    let common = signed(&data[..width as usize]);
    let (mut at, mut prev) = (start, 0i64);
    // At most four integers a code byte, and the code bytes are inside `data`.
    let mut out = Vec::with_capacity(count.min(data.len() as u64 * 4) as usize);
    for k in 0..count {
        let code = (data[width as usize + (k / 4) as usize] >> (2 * (k % 4))) & 3;
        let size = match code {
            0 => 0,
            1 => width / 4,
            2 => width / 2,
            _ => width,
        } as usize;
        let delta = match size {
            0 => common,
            n => signed(data.get(at..at + n).ok_or_else(short)?),
        };
        at += size;
        prev = prev.wrapping_add(delta);
        out.push(if width == 4 { i64::from(prev as i32) } else { prev });
    }
    Ok(out)
}

/// The PATHS section's three decoded arrays, as the crate builds its paths
/// from them: every visited entry's path index below `paths`, its element's
/// token below `tokens`, the child and sibling jumps inside the entries, no
/// entry visited twice.
pub(super) fn check_paths(
    (path_indexes, element_tokens, jumps): (&[i32], &[i32], &[i32]),
    paths: u64,
    tokens: u64,
) -> Result<()> {
    let count = path_indexes.len();
    if count == 0 {
        return Ok(());
    }
    let refuse = |what: String| Err(malformed(format!("its section \"PATHS\": {what}")));
    let mut visited = vec![false; count];
    // (entry, whether its parent is the root still to be made)
    let mut pending = vec![(0usize, true)];
    while let Some((mut current, mut root)) = pending.pop() {
        loop {
            let index = current;
            current += 1;
            if index >= count {
                return refuse(format!("the path tree leads to entry {index} of {count}"));
            }
            if std::mem::replace(&mut visited[index], true) {
                return refuse(format!("the path tree reaches entry {index} twice"));
            }
            // Path indices are unsigned.
            let path = u64::from(path_indexes[index] as u32);
            if path >= paths || (root && index as u64 >= paths) {
                return refuse(format!("entry {index} names path {path} of {paths}"));
            }
            if !root && u64::from(element_tokens[index].unsigned_abs()) >= tokens {
                return refuse(format!("entry {index} names token {} of {tokens}", element_tokens[index]));
            }
            root = false;
            let jump = jumps[index];
            let (child, sibling) = (jump > 0 || jump == -1, jump >= 0);
            if child && sibling {
                let to = index as i64 + i64::from(jump);
                if to >= count as i64 {
                    return refuse(format!("entry {index}'s sibling jump {jump} leaves the {count} entries"));
                }
                pending.push((to as usize, false));
            }
            if !child && !sibling {
                break;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_decode_as_the_crates_coding_stores_them() {
        // Common value 1; codes: common, small (+5), medium (−300), large (70000).
        let mut data = 1i32.to_le_bytes().to_vec();
        data.push(0b11_10_01_00);
        data.push(5);
        data.extend_from_slice(&(-300i16).to_le_bytes());
        data.extend_from_slice(&70000i32.to_le_bytes());
        let ints = decode_ints(&data, 4, "test").expect("decodes");
        assert_eq!(ints, [1, 6, -294, 69706]);
        // One byte short of the last delta: refused, not sliced past.
        assert!(decode_ints(&data[..data.len() - 1], 4, "test").is_err());
        assert!(decode_ints(&data[..3], 4, "test").is_err());
    }

    #[test]
    fn an_lz4_block_is_sized_by_its_sequences_before_it_is_decompressed() {
        let raw: Vec<u8> = (0..300u32).map(|i| (i % 7) as u8).collect();
        let mut block = vec![0u8];
        block.extend(lz4_flex::block::compress(&raw));
        assert_eq!(lz4_size(&block[1..]), Some(300));
        assert_eq!(decompress(&block, 300, "test").expect("decompresses"), raw);
        assert!(decompress(&block, 299, "test").is_err(), "less room than it decodes to");
        let mut chunked = block.clone();
        chunked[0] = 2;
        assert!(decompress(&chunked, 300, "test").is_err(), "a chunked block");
        assert!(
            lz4_size(&block[1..block.len() - 3]).is_none()
                || decompress(&block[..block.len() - 3], 300, "test").is_err()
        );
    }

    #[test]
    fn a_path_tree_is_walked_once_inside_its_tables() {
        // Root, then /a with a child /a/b and a sibling /c.
        let (indexes, tokens, jumps) = ([0, 1, 2, 3], [0, 1, 2, 3], [-1, 2, -2, -2]);
        assert!(check_paths((&indexes, &tokens, &jumps), 4, 4).is_ok());
        assert!(check_paths((&indexes, &[0, 1, 9, 3], &jumps), 4, 4).is_err(), "a token past the table");
        assert!(check_paths((&[0, 1, 7, 3], &tokens, &jumps), 4, 4).is_err(), "a path past the paths");
        assert!(check_paths((&indexes, &tokens, &[-1, 9, -2, -2]), 4, 4).is_err(), "a jump past the entries");
        // Entry 1's sibling jump lands on its own child: reached twice.
        assert!(check_paths((&indexes, &tokens, &[-1, 1, -2, -2]), 4, 4).is_err(), "an entry reached twice");
    }
}
