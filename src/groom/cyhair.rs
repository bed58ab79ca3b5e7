//! Cem Yuksel's binary `.hair` format: read, write, exact round trip.
//!
//! Layout (little-endian): a 128-byte header — `"HAIR"`, u32 hair count,
//! u32 point count, u32 array flags (1 segments, 2 points, 4 thickness,
//! 8 transparency, 16 colors), u32 default segments, f32 default thickness,
//! f32 default transparency, 3×f32 default color, 88-byte info string —
//! then the arrays that are present, in that order: segments as u16 per hair
//! (a hair has segments + 1 points), points as 3×f32 root to tip, thickness
//! and transparency as f32 per point, colors as 3×f32 per point.
//!
//! Hostile input is rejected with typed errors before any large allocation:
//! counts are checked against the limits of [`super`] and against the file size.

use std::path::Path;

use glam::Vec3;

use super::bytes::Reader;
use super::repair::Load;
use super::{Attributes, Groom, Repairs, MAX_POINTS, MAX_STRANDS};
use crate::error::{Error, FileFormat, Result};

const MAGIC: &[u8; 4] = b"HAIR";
const HEADER_SIZE: u64 = 128;
/// Length of the header's info string.
pub const INFO_LEN: usize = 88;

const HAS_SEGMENTS: u32 = 1;
const HAS_POINTS: u32 = 2;
const HAS_THICKNESS: u32 = 4;
const HAS_TRANSPARENCY: u32 = 8;
const HAS_COLORS: u32 = 16;
const KNOWN_FLAGS: u32 = 31;

/// The header and the arrays it announces of the `.hair` file at `path`.
fn read(path: &Path) -> Result<Vec<u8>> {
    crate::files::read_announced(path, HEADER_SIZE, |header| {
        let h = Header::read(&Reader { data: header, format: FileFormat::CyHair })?;
        Ok(HEADER_SIZE + Header::arrays_len(h.hair_count, h.point_count, h.flags))
    })
}

/// What the 128-byte header says, checked against the format and the limits.
struct Header {
    hair_count: u64,
    point_count: u64,
    flags: u32,
    defaults: HairDefaults,
    info: [u8; INFO_LEN],
}

impl Header {
    fn read(r: &Reader<'_>) -> Result<Header> {
        let magic = r.bytes(0, 4, "signature")?;
        if magic != MAGIC {
            return Err(Error::BadMagic {
                format: FileFormat::CyHair,
                reason: format!("signature is {magic:02x?}, expected \"HAIR\""),
            });
        }
        r.bytes(0, HEADER_SIZE, "header")?;
        let hair_count = u64::from(r.u32(4, "hair count")?);
        let point_count = u64::from(r.u32(8, "point count")?);
        let flags = r.u32(12, "array flags")?;
        let defaults = HairDefaults {
            segments: r.u32(16, "default segments")?,
            thickness: r.f32(20, "default thickness")?,
            transparency: r.f32(24, "default transparency")?,
            color: [r.f32(28, "default color")?, r.f32(32, "default color")?, r.f32(36, "default color")?],
        };
        let mut info = [0u8; INFO_LEN];
        info.copy_from_slice(r.bytes(40, INFO_LEN as u64, "info string")?);
        if flags & !KNOWN_FLAGS != 0 {
            return Err(Error::Unsupported {
                format: FileFormat::CyHair,
                reason: format!("unknown array flags {:#x}", flags & !KNOWN_FLAGS),
            });
        }
        if flags & HAS_POINTS == 0 {
            return Err(Error::Unsupported {
                format: FileFormat::CyHair,
                reason: "the file has no points array".into(),
            });
        }
        if hair_count == 0 {
            return Err(Error::EmptyGroom);
        }
        if hair_count > MAX_STRANDS as u64 {
            return Err(Error::TooManyStrands { count: hair_count, max: MAX_STRANDS as u64 });
        }
        if point_count > MAX_POINTS as u64 {
            return Err(Error::TooManyPoints { count: point_count, max: MAX_POINTS as u64 });
        }
        if !defaults.thickness.is_finite()
            || !defaults.transparency.is_finite()
            || !defaults.color.iter().all(|c| c.is_finite())
        {
            return Err(Error::Malformed {
                format: FileFormat::CyHair,
                reason: "a header default is NaN or infinite".into(),
            });
        }
        Ok(Header { hair_count, point_count, flags, defaults, info })
    }

    /// Bytes of the arrays after the header.
    fn arrays_len(hair_count: u64, point_count: u64, flags: u32) -> u64 {
        let per_point = 12
            + if flags & HAS_THICKNESS != 0 { 4 } else { 0 }
            + if flags & HAS_TRANSPARENCY != 0 { 4 } else { 0 }
            + if flags & HAS_COLORS != 0 { 12 } else { 0 };
        let segments_bytes = if flags & HAS_SEGMENTS != 0 { 2 * hair_count } else { 0 };
        segments_bytes + per_point * point_count
    }
}

/// Header defaults that apply where an array is absent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairDefaults {
    /// Segments per hair when the segments array is absent.
    pub segments: u32,
    /// Thickness of every point when the thickness array is absent.
    pub thickness: f32,
    /// Transparency of every point when the transparency array is absent.
    pub transparency: f32,
    /// Color of every point when the color array is absent.
    pub color: [f32; 3],
}

impl Default for HairDefaults {
    fn default() -> Self {
        HairDefaults { segments: 0, thickness: 1.0, transparency: 0.0, color: [1.0, 1.0, 1.0] }
    }
}

/// A `.hair` file: the groom plus the header fields that are not strand data.
#[derive(Debug, Clone, PartialEq)]
pub struct HairFile {
    /// The strands and their per-point arrays.
    pub groom: Groom,
    /// Header defaults.
    pub defaults: HairDefaults,
    /// The 88-byte info string (NUL-padded).
    pub info: [u8; INFO_LEN],
    /// Whether the file stores a segments array (otherwise every hair has
    /// `defaults.segments` segments). Written back as read when possible.
    pub has_segments_array: bool,
}

impl HairFile {
    /// Wraps a groom with default header fields and `info` (truncated to 88 bytes).
    pub fn new(groom: Groom, info: &str) -> Self {
        let mut bytes = [0u8; INFO_LEN];
        let src = info.as_bytes();
        let n = src.len().min(INFO_LEN - 1);
        bytes[..n].copy_from_slice(&src[..n]);
        let uniform = groom.uniform_points_per_strand();
        HairFile {
            defaults: HairDefaults { segments: uniform.map_or(0, |n| n as u32 - 1), ..HairDefaults::default() },
            groom,
            info: bytes,
            has_segments_array: uniform.is_none(),
        }
    }

    /// The info string up to its first NUL.
    pub fn info_str(&self) -> String {
        let end = self.info.iter().position(|&b| b == 0).unwrap_or(INFO_LEN);
        String::from_utf8_lossy(&self.info[..end]).into_owned()
    }

    /// Reads a `.hair` file from disk, refusing any defect. Only the header and
    /// the arrays it announces are read (at most [`HairFile::MAX_FILE_BYTES`]).
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read(path)?).map_err(|e| e.in_asset(path))
    }

    /// Reads a `.hair` file from disk, repairing what can be repaired (see
    /// [`Groom::repaired`]).
    pub fn open_repairing(path: impl AsRef<Path>) -> Result<(Self, Repairs)> {
        let path = path.as_ref();
        Self::parse_repairing(&read(path)?).map_err(|e| e.in_asset(path))
    }

    /// The largest `.hair` file the limits allow ([`MAX_STRANDS`] hairs of a
    /// segments array, [`MAX_POINTS`] points of every array): what vkhair
    /// reads of one at most.
    pub const MAX_FILE_BYTES: u64 = HEADER_SIZE + 2 * MAX_STRANDS as u64 + 32 * MAX_POINTS as u64;

    /// Parses `.hair` bytes, repairing what can be repaired (see
    /// [`Groom::repaired`]).
    pub fn parse_repairing(data: &[u8]) -> Result<(Self, Repairs)> {
        let (file, repairs) = Self::parse_as(data, Load::Repair)?;
        Ok((file, repairs.unwrap_or_default()))
    }

    /// Writes a `.hair` file to disk.
    /// The file appears whole or not at all: the bytes go to a temporary file in
    /// the same folder, which then replaces `path` (a failed write, a full disk or
    /// a kill never leaves a truncated file behind).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        crate::files::write_atomic(path.as_ref(), &self.to_bytes())
    }

    /// Parses `.hair` bytes, refusing any defect. Bytes after the last array are
    /// ignored.
    pub fn parse(data: &[u8]) -> Result<Self> {
        Self::parse_as(data, Load::Strict).map(|(file, _)| file)
    }

    fn parse_as(data: &[u8], load: Load) -> Result<(Self, Option<Repairs>)> {
        let r = Reader { data, format: FileFormat::CyHair };
        let Header { hair_count, point_count, flags, defaults, info } = Header::read(&r)?;
        let malformed = |reason: String| Error::Malformed { format: FileFormat::CyHair, reason };
        // Size check of everything the header announces, before allocating.
        let segments_bytes = if flags & HAS_SEGMENTS != 0 { 2 * hair_count } else { 0 };
        r.bytes(HEADER_SIZE, Header::arrays_len(hair_count, point_count, flags), "arrays announced by the header")?;

        let mut offset = HEADER_SIZE;
        let counts: Vec<u32> = if flags & HAS_SEGMENTS != 0 {
            let segments = r.u16s(offset, hair_count, "segments array")?;
            offset += segments_bytes;
            segments.iter().map(|&s| u32::from(s) + 1).collect()
        } else {
            if defaults.segments == 0 || defaults.segments > u32::from(u16::MAX) {
                return Err(malformed(format!(
                    "no segments array and default segments {} is outside 1..=65535",
                    defaults.segments
                )));
            }
            vec![defaults.segments + 1; hair_count as usize]
        };
        let sum: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        if sum != point_count {
            return Err(malformed(format!(
                "the hairs' segments add up to {sum} points but the header says {point_count}"
            )));
        }
        let mut vec3s = |what| -> Result<Vec<Vec3>> {
            let v = r.f32s(offset, 3 * point_count, what)?;
            offset += 12 * point_count;
            Ok(v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
        };
        let positions = vec3s("points array")?;
        let mut scalars = |present: bool, what| -> Result<Option<Vec<f32>>> {
            if !present {
                return Ok(None);
            }
            let v = r.f32s(offset, point_count, what)?;
            offset += 4 * point_count;
            Ok(Some(v))
        };
        let thickness = scalars(flags & HAS_THICKNESS != 0, "thickness array")?;
        let transparency = scalars(flags & HAS_TRANSPARENCY != 0, "transparency array")?;
        let colors = if flags & HAS_COLORS != 0 {
            let v = r.f32s(offset, 3 * point_count, "color array")?;
            Some(v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
        } else {
            None
        };
        let (groom, repairs) = load.build(positions, &counts, Attributes { thickness, transparency, colors })?;
        // A repaired groom may have lost the uniform point count a file without a
        // segments array implies.
        let has_segments_array = flags & HAS_SEGMENTS != 0 || groom.uniform_points_per_strand().is_none();
        Ok((HairFile { groom, defaults, info, has_segments_array }, repairs))
    }

    /// Serialises to `.hair` bytes. The segments array is written when the file had
    /// one or when strands differ in point count.
    pub fn to_bytes(&self) -> Vec<u8> {
        let g = &self.groom;
        let uniform = g.uniform_points_per_strand();
        let write_segments = self.has_segments_array || uniform.is_none();
        let mut flags = HAS_POINTS;
        flags |= if write_segments { HAS_SEGMENTS } else { 0 };
        flags |= if g.thickness().is_some() { HAS_THICKNESS } else { 0 };
        flags |= if g.transparency().is_some() { HAS_TRANSPARENCY } else { 0 };
        flags |= if g.colors().is_some() { HAS_COLORS } else { 0 };
        let default_segments = match (write_segments, uniform) {
            (false, Some(n)) => n as u32 - 1,
            _ => self.defaults.segments,
        };
        let mut out = Vec::with_capacity(HEADER_SIZE as usize + g.point_count() * 32);
        out.extend_from_slice(MAGIC);
        for v in [g.strand_count() as u32, g.point_count() as u32, flags, default_segments] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let d = &self.defaults;
        for v in [d.thickness, d.transparency, d.color[0], d.color[1], d.color[2]] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.info);
        if write_segments {
            for i in 0..g.strand_count() {
                out.extend_from_slice(&((g.strand_len(i) - 1) as u16).to_le_bytes());
            }
        }
        let mut put =
            |values: &mut dyn Iterator<Item = f32>| values.for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        put(&mut g.positions().iter().flat_map(|p| p.to_array()));
        if let Some(t) = g.thickness() {
            put(&mut t.iter().copied());
        }
        if let Some(t) = g.transparency() {
            put(&mut t.iter().copied());
        }
        if let Some(c) = g.colors() {
            put(&mut c.iter().flat_map(|p| p.to_array()));
        }
        out
    }
}
