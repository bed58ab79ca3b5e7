//! Alembic's layout on Ogawa: the archive, its objects and their properties.
//!
//! - The root group holds, in order: the archive version and the library
//!   version (data), the top object (group), the archive's metadata, its time
//!   samplings and its indexed metadata (data).
//! - An object group holds its top compound property (group 0), its child
//!   objects (groups 1..n) and, last, the headers of those children (data:
//!   per child a u32 name length, the name, a u8 metadata index — 0xff: a u32
//!   length and the metadata inline — then 32 bytes of hashes at the end).
//! - A compound property group holds its properties (group i for property i)
//!   and, last, their headers (data: a u32 of bit fields — kind, POD type,
//!   extent, metadata index, size hint of the numbers that follow, whether
//!   samples repeat — then sample counts, the name and maybe metadata).
//! - An array property's sample `i` is stored as data `2i` (16 bytes of key,
//!   then the values) and data `2i + 1` (its dimensions, u64 each; empty for
//!   one dimension); a scalar property's sample `i` as data `i`.
//!
//! Only the first sample of a property is read. Metadata is `key=value`
//! pairs separated by `;`.

use super::ogawa::{malformed, Child, Ogawa};
use crate::error::{Error, FileFormat, Result};

/// The plain old data types of Alembic's properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pod {
    Bool,
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F16,
    F32,
    F64,
    String,
    WString,
}

impl Pod {
    fn from_code(code: u32) -> Option<Pod> {
        use Pod::*;
        [Bool, U8, I8, U16, I16, U32, I32, U64, I64, F16, F32, F64, String, WString].get(code as usize).copied()
    }

    /// Bytes per value (0 for strings).
    fn size(self) -> usize {
        match self {
            Pod::Bool | Pod::U8 | Pod::I8 => 1,
            Pod::U16 | Pod::I16 | Pod::F16 => 2,
            Pod::U32 | Pod::I32 | Pod::F32 => 4,
            Pod::U64 | Pod::I64 | Pod::F64 => 8,
            Pod::String | Pod::WString => 0,
        }
    }
}

/// What kind of property a header describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Compound,
    Scalar,
    Array,
}

/// A property's header.
#[derive(Debug, Clone)]
pub(crate) struct PropertyHeader {
    pub name: String,
    pub kind: Kind,
    pub pod: Pod,
    pub extent: u8,
    /// Samples written.
    pub samples: u32,
    pub metadata: String,
}

/// An object's header, as its parent lists it.
#[derive(Debug, Clone)]
pub(crate) struct ObjectHeader {
    pub name: String,
    pub metadata: String,
}

/// The value of `key` in `key=value;…` metadata.
pub(crate) fn meta<'m>(metadata: &'m str, key: &str) -> Option<&'m str> {
    metadata.split(';').filter_map(|kv| kv.split_once('=')).find(|(k, _)| *k == key).map(|(_, v)| v)
}

/// The first sample of a scalar or array property: its values' bytes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample<'a> {
    pub pod: Pod,
    pub extent: usize,
    pub bytes: &'a [u8],
}

impl Sample<'_> {
    /// Values (not elements: an extent-3 property has 3 per element).
    pub fn len(&self) -> usize {
        self.bytes.len().checked_div(self.pod.size()).unwrap_or(0)
    }

    /// Every value as f64 (numbers only; `None` for strings and halves).
    pub fn numbers(&self) -> Option<Vec<f64>> {
        let b = self.bytes;
        let n = self.len();
        let le = |i: usize, k: usize| {
            let mut a = [0u8; 8];
            a[..k].copy_from_slice(&b[i * k..(i + 1) * k]);
            u64::from_le_bytes(a)
        };
        let v: Vec<f64> = match self.pod {
            Pod::Bool | Pod::U8 => (0..n).map(|i| f64::from(b[i])).collect(),
            Pod::I8 => (0..n).map(|i| f64::from(b[i] as i8)).collect(),
            Pod::U16 => (0..n).map(|i| le(i, 2) as u16 as f64).collect(),
            Pod::I16 => (0..n).map(|i| le(i, 2) as u16 as i16 as f64).collect(),
            Pod::U32 => (0..n).map(|i| le(i, 4) as u32 as f64).collect(),
            Pod::I32 => (0..n).map(|i| le(i, 4) as u32 as i32 as f64).collect(),
            Pod::U64 => (0..n).map(|i| le(i, 8) as f64).collect(),
            Pod::I64 => (0..n).map(|i| le(i, 8) as i64 as f64).collect(),
            Pod::F32 => (0..n).map(|i| f64::from(f32::from_bits(le(i, 4) as u32))).collect(),
            Pod::F64 => (0..n).map(|i| f64::from_bits(le(i, 8))).collect(),
            Pod::F16 | Pod::String | Pod::WString => return None,
        };
        Some(v)
    }
}

/// An Alembic archive on an Ogawa file.
pub(crate) struct Archive<'a> {
    pub file: Ogawa<'a>,
    /// The archive's indexed metadata (index 0: empty).
    indexed: Vec<String>,
    /// The top object's group.
    pub top: Vec<Child>,
}

/// A little-endian reader over a header block.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
    what: &'static str,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.b.len());
        let end = end.ok_or_else(|| malformed(format!("the {} end inside a field", self.what)))?;
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    fn u32(&mut self) -> Result<u32> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    /// A u32 stored in 1, 2 or 4 bytes as `hint` (0, 1, 2) says.
    fn hinted(&mut self, hint: u32) -> Result<u32> {
        match hint {
            0 => self.u8().map(u32::from),
            1 => {
                let s = self.take(2)?;
                Ok(u32::from(u16::from_le_bytes([s[0], s[1]])))
            }
            2 => self.u32(),
            _ => Err(malformed(format!("the {} use size hint {hint}", self.what))),
        }
    }

    fn text(&mut self, n: usize) -> Result<String> {
        let what = self.what;
        String::from_utf8(self.take(n)?.to_vec())
            .map_err(|_| malformed(format!("the {what} hold text that is not UTF-8")))
    }
}

impl<'a> Archive<'a> {
    pub fn open(bytes: &'a [u8]) -> Result<Self> {
        let (file, root) = Ogawa::new(bytes)?;
        let root = file.group(root)?;
        let shape = [Child::Data(0), Child::Data(0), Child::Group(0), Child::Data(0), Child::Data(0), Child::Data(0)];
        let fits = root.len() >= 6
            && root
                .iter()
                .zip(shape)
                .all(|(c, s)| matches!((c, s), (Child::Data(_), Child::Data(_)) | (Child::Group(_), Child::Group(_))));
        if !fits {
            return Err(malformed("the root group is not an Alembic archive's (versions, top object, metadata)"));
        }
        let top = file.group_of(root[2], "the top object")?;
        let indexed = read_indexed(file.data_of(root[5], "the indexed metadata")?)?;
        Ok(Archive { file, indexed, top })
    }

    fn indexed(&self, index: u32, what: &str) -> Result<String> {
        let text = self.indexed.get(index as usize).ok_or_else(|| {
            malformed(format!("{what} refers to metadata {index}, past the archive's {}", self.indexed.len()))
        })?;
        // Each object or property naming it takes a copy.
        self.file.charge(text.len() as u64, what)?;
        Ok(text.clone())
    }

    /// The child objects of an object group: header, group position and
    /// group each.
    pub fn children(&self, object: &[Child]) -> Result<Vec<(ObjectHeader, u64, Vec<Child>)>> {
        let (at, groups) = match object.split_last() {
            None => return Ok(Vec::new()),
            Some((&Child::Data(at), groups)) => (at, groups),
            // The headers' place holds a group: the children it names would
            // be dropped without a word (a changed offset did that).
            Some((&Child::Group(at), _)) => {
                return Err(malformed(format!(
                    "its child objects' headers are a group (byte {at}) where a data block belongs"
                )));
            }
        };
        let block = self.file.data(at)?;
        // Their names and metadata are copied out: a block many objects
        // share is charged each time.
        self.file.charge(block.len() as u64, "object headers")?;
        if !block.is_empty() && block.len() < 32 {
            return Err(malformed(format!("object headers of {} bytes, shorter than their hashes", block.len())));
        }
        // The last 32 bytes are the object's hashes.
        let headers = &block[..block.len().saturating_sub(32)];
        let mut c = Cursor { b: headers, at: 0, what: "object headers" };
        let mut out: Vec<(ObjectHeader, u64, Vec<Child>)> = Vec::new();
        // The groups of the children so far (a set: a list searched once per
        // child made 100,000 children take 12 s).
        let mut seen: std::collections::HashSet<u64> = std::collections::HashSet::new();
        while c.at < headers.len() {
            let n = c.u32()? as usize;
            if n == 0 {
                return Err(malformed("an object header has an empty name"));
            }
            let name = c.text(n)?;
            let index = c.u8()?;
            let metadata = if index == 0xff {
                let m = c.u32()? as usize;
                c.text(m)?
            } else {
                self.indexed(u32::from(index), &format!("object {name}"))?
            };
            // Child i is group i + 1 (group 0 holds the properties).
            let child =
                groups.get(out.len() + 1).copied().ok_or_else(|| malformed(format!("object {name} has no group")))?;
            let (Child::Group(at) | Child::Data(at)) = child;
            // Two children in one group are a cycle (or a fan-out) refused
            // before their group is read again.
            if at != 0 && !seen.insert(at) {
                return Err(malformed(format!("object {name}'s group belongs to another object too")));
            }
            let group = self.file.group_of(child, &format!("object {name}"))?;
            out.push((ObjectHeader { name, metadata }, at, group));
        }
        // Every child group has its header (group 0 holds the properties).
        let named = out.len();
        if named + 1 < groups.len() {
            return Err(malformed(format!(
                "it has {} child object groups but headers for {named}: the others would be dropped",
                groups.len() - 1
            )));
        }
        Ok(out)
    }

    /// The top compound property of an object group.
    pub fn object_properties(&self, object: &[Child]) -> Result<Vec<(PropertyHeader, Child)>> {
        match object.first() {
            Some(&Child::Group(at)) => self.properties(&self.file.group(at)?),
            _ => Ok(Vec::new()),
        }
    }

    /// The properties of a compound property group: header and group each.
    pub fn properties(&self, compound: &[Child]) -> Result<Vec<(PropertyHeader, Child)>> {
        let Some((&Child::Data(at), groups)) = compound.split_last() else { return Ok(Vec::new()) };
        let block = self.file.data(at)?;
        self.file.charge(block.len() as u64, "property headers")?;
        let mut c = Cursor { b: block, at: 0, what: "property headers" };
        let mut out = Vec::new();
        while c.at < block.len() {
            let info = c.u32()?;
            let kind = match info & 0x3 {
                0 => Kind::Compound,
                1 => Kind::Scalar,
                _ => Kind::Array,
            };
            let hint = (info & 0xc) >> 2;
            let (mut pod, mut extent, mut samples) = (Pod::U8, 0u8, 0u32);
            if kind != Kind::Compound {
                let code = (info & 0xf0) >> 4;
                pod = Pod::from_code(code).ok_or_else(|| malformed(format!("a property has POD type {code}")))?;
                extent = ((info & 0xff000) >> 12) as u8;
                samples = c.hinted(hint)?;
                if info & 0x200 != 0 {
                    c.hinted(hint)?; // first changed sample
                    c.hinted(hint)?; // last changed sample
                }
                if info & 0x100 != 0 {
                    c.hinted(hint)?; // time sampling index
                }
            }
            let n = c.hinted(hint)? as usize;
            if n == 0 {
                return Err(malformed("a property header has an empty name"));
            }
            let name = c.text(n)?;
            let index = (info & 0xff0_0000) >> 20;
            let metadata = if index == 0xff {
                let m = c.hinted(hint)? as usize;
                c.text(m)?
            } else {
                self.indexed(index, &format!("property {name}"))?
            };
            let group =
                groups.get(out.len()).copied().ok_or_else(|| malformed(format!("property {name} has no group")))?;
            out.push((PropertyHeader { name, kind, pod, extent, samples, metadata }, group));
        }
        Ok(out)
    }

    /// The first sample of a scalar or array property (`None` without samples).
    pub fn first_sample(&self, header: &PropertyHeader, group: Child) -> Result<Option<Sample<'a>>> {
        let name = &header.name;
        if header.kind == Kind::Compound {
            return Err(malformed(format!("property {name} is a compound, not values")));
        }
        if header.samples == 0 {
            return Ok(None);
        }
        let children = self.file.group_of(group, &format!("property {name}"))?;
        let Some(&first) = children.first() else { return Ok(None) };
        let block = self.file.data_of(first, &format!("property {name}'s first sample"))?;
        if block.is_empty() {
            return Ok(Some(Sample { pod: header.pod, extent: usize::from(header.extent.max(1)), bytes: &[] }));
        }
        if block.len() < 16 {
            return Err(malformed(format!(
                "property {name}'s first sample is {} bytes, shorter than its key",
                block.len()
            )));
        }
        let bytes = &block[16..];
        let size = header.pod.size();
        if size == 0 || header.pod == Pod::F16 {
            return Err(Error::Unsupported {
                format: FileFormat::Alembic,
                reason: format!(
                    "property {name} holds {:?} values (numbers of 8, 16, 32 and 64 bits are read)",
                    header.pod
                ),
            });
        }
        let extent = usize::from(header.extent.max(1));
        if bytes.len() % (size * extent) != 0 {
            return Err(malformed(format!(
                "property {name}'s first sample has {} bytes, not a whole number of {}-byte elements",
                bytes.len(),
                size * extent
            )));
        }
        Ok(Some(Sample { pod: header.pod, extent, bytes }))
    }
}

/// The archive's indexed metadata: index 0 is empty, then a u8 length and the
/// text each.
fn read_indexed(block: &[u8]) -> Result<Vec<String>> {
    let mut out = vec![String::new()];
    let mut c = Cursor { b: block, at: 0, what: "indexed metadata" };
    while c.at < block.len() {
        let n = usize::from(c.u8()?);
        out.push(c.text(n)?);
    }
    Ok(out)
}
