//! AMD TressFX binary `.tfx` files (the layout of TressFX 3.x and 4.x).
//!
//! A 160-byte header — f32 version, u32 strand count, u32 vertices per
//! strand, then u32 byte offsets of the vertex positions (float4 per vertex,
//! w = inverse mass), strand UVs (float2 per strand), vertex UVs (float2 per
//! vertex), strand thickness (f32 per strand) and vertex colors (float4 per
//! vertex), an offset of 0 meaning absent, then 32 reserved u32 — followed by
//! the arrays at their offsets. Every strand has the same vertex count.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::bytes::Reader;
use super::repair::Load;
use super::{Attributes, Groom, Repairs, MAX_POINTS, MAX_POINTS_PER_STRAND, MAX_STRANDS};
use crate::error::{Error, FileFormat, Result};

const HEADER_SIZE: u64 = 160;

/// The header and the arrays it points at of the `.tfx` file at `path`.
fn read(path: &Path) -> Result<Vec<u8>> {
    crate::files::read_announced(path, HEADER_SIZE, |header| {
        Header::read(&Reader { data: header, format: FileFormat::TressFx }).map(|h| h.len())
    })
}

/// Names of the arrays in the order of the header's offsets.
const ARRAYS: [&str; 5] = ["vertex positions", "strand UVs", "vertex UVs", "strand thickness", "vertex colors"];

/// What the 160-byte header says, checked against the format and the limits.
struct Header {
    version: f32,
    strands: u64,
    per_strand: u64,
    /// Byte offsets of the arrays in [`ARRAYS`] order, 0 for absent ones.
    offsets: [u64; 5],
}

impl Header {
    fn read(r: &Reader<'_>) -> Result<Header> {
        r.bytes(0, HEADER_SIZE, "header")?;
        let version = r.f32(0, "version")?;
        if !(version.is_finite() && (3.0..5.0).contains(&version)) {
            return Err(Error::BadMagic {
                format: FileFormat::TressFx,
                reason: format!("version {version} is not 3.x or 4.x"),
            });
        }
        let strands = u64::from(r.u32(4, "strand count")?);
        let per_strand = u64::from(r.u32(8, "vertices per strand")?);
        let mut offsets = [0u64; 5];
        for (i, offset) in offsets.iter_mut().enumerate() {
            *offset = u64::from(r.u32(12 + 4 * i as u64, "array offset")?);
        }
        if strands == 0 {
            return Err(Error::EmptyGroom);
        }
        if strands > MAX_STRANDS as u64 {
            return Err(Error::TooManyStrands { count: strands, max: MAX_STRANDS as u64 });
        }
        if !(2..=MAX_POINTS_PER_STRAND as u64).contains(&per_strand) {
            return Err(Error::StrandPointCount { strand: 0, points: per_strand, max: MAX_POINTS_PER_STRAND as u64 });
        }
        let points = strands * per_strand;
        if points > MAX_POINTS as u64 {
            return Err(Error::TooManyPoints { count: points, max: MAX_POINTS as u64 });
        }
        if offsets[0] == 0 {
            return Err(Error::Malformed {
                format: FileFormat::TressFx,
                reason: "the file has no vertex positions".into(),
            });
        }
        for (name, &offset) in ARRAYS.iter().zip(&offsets) {
            if offset != 0 && offset < HEADER_SIZE {
                return Err(Error::Malformed {
                    format: FileFormat::TressFx,
                    reason: format!("the {name} start at byte {offset}, inside the {HEADER_SIZE}-byte header"),
                });
            }
        }
        Ok(Header { version, strands, per_strand, offsets })
    }

    /// Bytes of each array in [`ARRAYS`] order.
    fn array_lens(&self) -> [u64; 5] {
        let points = self.strands * self.per_strand;
        [16 * points, 8 * self.strands, 8 * points, 4 * self.strands, 16 * points]
    }

    /// Bytes to the end of the last array present.
    fn len(&self) -> u64 {
        let ends = self.offsets.iter().zip(self.array_lens()).map(|(&at, len)| if at == 0 { 0 } else { at + len });
        ends.fold(HEADER_SIZE, u64::max)
    }
}

/// A `.tfx` file: the groom plus what TressFX stores beside the strands.
#[derive(Debug, Clone, PartialEq)]
pub struct TfxFile {
    /// Header version (3.x or 4.x).
    pub version: f32,
    /// Positions as the groom; strand thickness (when present) as per-point
    /// thickness, vertex colors (when present) as per-point RGB.
    pub groom: Groom,
    /// Per-vertex inverse mass from the positions' w (0 marks pinned vertices).
    pub inverse_mass: Vec<f32>,
    /// Per-strand UVs, when present.
    pub strand_uvs: Option<Vec<Vec2>>,
}

impl TfxFile {
    /// Reads a `.tfx` file from disk, refusing any defect. Only the header and
    /// the arrays it points at are read.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read(path)?).map_err(|e| e.in_asset(path))
    }

    /// Reads a `.tfx` file from disk, repairing what can be repaired (see
    /// [`Groom::repaired`]; a strand whose inverse mass is NaN, infinite or
    /// negative counts as non-finite).
    pub fn open_repairing(path: impl AsRef<Path>) -> Result<(Self, Repairs)> {
        let path = path.as_ref();
        Self::parse_repairing(&read(path)?).map_err(|e| e.in_asset(path))
    }

    /// Parses `.tfx` bytes, refusing any defect.
    pub fn parse(data: &[u8]) -> Result<Self> {
        Self::parse_as(data, Load::Strict).map(|(file, _)| file)
    }

    /// Parses `.tfx` bytes, repairing what can be repaired (see
    /// [`TfxFile::open_repairing`]).
    pub fn parse_repairing(data: &[u8]) -> Result<(Self, Repairs)> {
        let (file, repairs) = Self::parse_as(data, Load::Repair)?;
        Ok((file, repairs.unwrap_or_default()))
    }

    fn parse_as(data: &[u8], load: Load) -> Result<(Self, Option<Repairs>)> {
        let r = Reader { data, format: FileFormat::TressFx };
        let Header { version, strands, per_strand, offsets } = Header::read(&r)?;
        let [positions_at, strand_uv_at, _vertex_uv_at, thickness_at, colors_at] = offsets;
        let points = strands * per_strand;
        let raw = r.f32s(positions_at, 4 * points, "vertex positions")?;
        let mut positions: Vec<Vec3> = raw.chunks_exact(4).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
        let inverse_mass: Vec<f32> = raw.chunks_exact(4).map(|c| c[3]).collect();
        let per = per_strand as usize;
        for i in (0..inverse_mass.len()).filter(|&i| !inverse_mass[i].is_finite() || inverse_mass[i] < 0.0) {
            if load == Load::Strict {
                return Err(Error::NonFinite { strand: i / per, point: i % per, what: "inverse mass" });
            }
            // Repairing: the strand goes as one with a non-finite value.
            positions[i] = Vec3::NAN;
        }
        let strand_uvs = (strand_uv_at != 0)
            .then(|| r.f32s(strand_uv_at, 2 * strands, "strand UVs"))
            .transpose()?
            .map(|v| v.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect());
        let thickness = (thickness_at != 0)
            .then(|| r.f32s(thickness_at, strands, "strand thickness"))
            .transpose()?
            .map(|t| t.iter().flat_map(|&v| std::iter::repeat_n(v, per_strand as usize)).collect());
        let colors = (colors_at != 0)
            .then(|| r.f32s(colors_at, 4 * points, "vertex colors"))
            .transpose()?
            .map(|v| v.chunks_exact(4).map(|c| Vec3::new(c[0], c[1], c[2])).collect());
        let counts = vec![per_strand as u32; strands as usize];
        let attributes = Attributes { thickness, transparency: None, colors };
        let (groom, repairs) = load.build(positions, &counts, attributes)?;
        let (inverse_mass, strand_uvs) = match &repairs {
            Some(r) => (
                r.kept_points().iter().map(|&i| inverse_mass[i]).collect(),
                strand_uvs.map(|uvs: Vec<Vec2>| r.kept_strands().iter().map(|&s| uvs[s]).collect()),
            ),
            None => (inverse_mass, strand_uvs),
        };
        Ok((TfxFile { version, groom, inverse_mass, strand_uvs }, repairs))
    }
}
