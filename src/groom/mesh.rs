//! Triangle meshes (Wavefront OBJ through `tobj`) used as scalps and heads.

use std::path::Path;

use glam::Vec3;

use crate::error::{Error, FileFormat, Result};

/// Most triangles a mesh may have (16,777,216).
pub const MAX_TRIANGLES: usize = 1 << 24;

/// The most vkhair reads of an OBJ file unless [`crate::files::MAX_INPUT_ENV`]
/// says otherwise: 256 MiB (a head mesh is a few MiB).
pub const MAX_OBJ_BYTES: u64 = 256 << 20;

/// An indexed triangle mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Counter-clockwise triangles (outward normals by the right-hand rule).
    pub triangles: Vec<[u32; 3]>,
}

/// `triangles` (indices into `positions`) as their own mesh, each used vertex
/// once in the order first met, and per vertex of the result its index in
/// `positions`; `None` when there are no triangles.
pub(crate) fn compact(
    positions: &[Vec3],
    triangles: impl Iterator<Item = [u32; 3]>,
) -> Result<Option<(TriMesh, Vec<usize>)>> {
    let mut index = vec![u32::MAX; positions.len()];
    let (mut vertices, mut kept) = (Vec::new(), Vec::new());
    for t in triangles {
        kept.push(t.map(|v| {
            let v = v as usize;
            if index[v] == u32::MAX {
                index[v] = vertices.len() as u32;
                vertices.push(v);
            }
            index[v]
        }));
    }
    if kept.is_empty() {
        return Ok(None);
    }
    let mesh = TriMesh::new(vertices.iter().map(|&v| positions[v]).collect(), kept)?;
    Ok(Some((mesh, vertices)))
}

impl TriMesh {
    /// A mesh from positions and triangles, validated (finite positions, indices in
    /// range, at least one triangle).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        let malformed = |reason: String| Error::Malformed { format: FileFormat::Obj, reason };
        if triangles.is_empty() {
            return Err(malformed("the mesh has no triangles".into()));
        }
        if triangles.len() > MAX_TRIANGLES {
            return Err(malformed(format!("{} triangles exceed the limit of {MAX_TRIANGLES}", triangles.len())));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(malformed(format!("vertex {i} is not finite")));
        }
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&i| i as usize >= positions.len())) {
            return Err(malformed(format!("triangle {t} indexes past the {} vertices", positions.len())));
        }
        Ok(TriMesh { positions, triangles })
    }

    /// Loads every object of an OBJ file into one mesh (faces are triangulated);
    /// a file over [`MAX_OBJ_BYTES`] (or [`crate::files::MAX_INPUT_ENV`]'s cap)
    /// is refused before reading.
    pub fn load_obj(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let data = crate::files::read_capped(path, crate::files::input_cap(MAX_OBJ_BYTES)?, "an OBJ mesh")?;
        Self::parse_obj(&data).map_err(|e| e.in_asset(path))
    }

    /// Parses OBJ text (materials are ignored). A file without faces (only
    /// points or polylines) is refused, and a vertex that is not finite is
    /// named by its number in the file (counting from 1, as faces do) and line.
    pub fn parse_obj(data: &[u8]) -> Result<Self> {
        // A glTF document given as a mesh is named as what it is, not as a
        // malformed OBJ.
        let json_gltf = data.trim_ascii_start().starts_with(b"{") && data.windows(7).any(|w| w == b"\"asset\"");
        if data.starts_with(b"glTF") || json_gltf {
            return Err(Error::Unsupported {
                format: FileFormat::Obj,
                reason: "this is a glTF document, not an OBJ mesh: read it as a character (glTF)".into(),
            });
        }
        let text = match std::str::from_utf8(data) {
            Ok(text) => text,
            Err(e) => {
                let line = 1 + data[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count();
                return Err(Error::Malformed {
                    format: FileFormat::Obj,
                    reason: format!("line {line} is not UTF-8 text (an OBJ file is text; is this a binary file?)"),
                });
            }
        };
        check_obj_statements(text)?;
        let options =
            tobj::LoadOptions { single_index: false, triangulate: true, ignore_points: true, ignore_lines: true };
        let mut reader = std::io::BufReader::new(data);
        let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::GenericFailure))
            .map_err(|e| Error::Malformed { format: FileFormat::Obj, reason: e.to_string() })?;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for model in models {
            let m = model.mesh;
            let base = positions.len() as u32;
            positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
            triangles.extend(m.indices.chunks_exact(3).map(|c| [base + c[0], base + c[1], base + c[2]]));
        }
        Self::new(positions, triangles)
    }

    /// A UV sphere of `stacks` × `slices` quads (each ≥ 3), outward-facing.
    pub fn uv_sphere(center: Vec3, radius: f32, stacks: u32, slices: u32) -> Result<Self> {
        if !(center.is_finite() && radius.is_finite() && radius > 0.0)
            || stacks < 3
            || slices < 3
            || stacks * slices > 1 << 20
        {
            return Err(Error::param(
                "sphere",
                format!("centre {center}, radius {radius}, {stacks}×{slices}"),
                "finite centre, radius > 0, at least 3×3 and at most 2²⁰ quads",
            ));
        }
        let mut positions = Vec::new();
        for i in 0..=stacks {
            let theta = std::f32::consts::PI * i as f32 / stacks as f32;
            for j in 0..=slices {
                let phi = std::f32::consts::TAU * j as f32 / slices as f32;
                positions
                    .push(center + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
            }
        }
        let row = slices + 1;
        let mut triangles = Vec::new();
        for i in 0..stacks {
            for j in 0..slices {
                let (a, b, c, d) = (i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1);
                triangles.push([a, b, c]);
                triangles.push([b, d, c]);
            }
        }
        Self::new(positions, triangles)
    }

    /// Axis-aligned bounding box (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        super::bounding_box(self.positions.iter().copied())
    }

    /// Corners of triangle `i`.
    pub fn corners(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// Area-weighted (unnormalised) normal of triangle `i`: its length is twice the area.
    pub fn scaled_normal(&self, i: usize) -> Vec3 {
        let [a, b, c] = self.corners(i);
        (b - a).cross(c - a)
    }
}

/// What `tobj` does not say about an OBJ text: a vertex that is not finite
/// (by its number in the file and its line) and a file with no face.
fn check_obj_statements(text: &str) -> Result<()> {
    let malformed = |reason: String| Error::Malformed { format: FileFormat::Obj, reason };
    let (mut vertices, mut faces) = (0usize, 0usize);
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                vertices += 1;
                let coords: Vec<&str> = words.take(3).collect();
                let finite = coords.len() == 3 && coords.iter().all(|w| w.parse::<f32>().is_ok_and(f32::is_finite));
                if !finite {
                    return Err(malformed(format!(
                        "vertex {vertices} (line {}) is not three finite numbers",
                        number + 1
                    )));
                }
            }
            Some("f") => faces += 1,
            _ => {}
        }
    }
    if faces == 0 {
        return Err(malformed(format!(
            "no face (`f`) in {vertices} vertices: a mesh needs triangles, and points and polylines are not surfaces"
        )));
    }
    Ok(())
}
