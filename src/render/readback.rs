//! What tests and tools read back from the renderer (each call submits and waits).

use glam::Vec4;

use super::Renderer;
use crate::error::Result;

/// Read-backs for tests and tools (each submits and waits).
impl Renderer {
    /// Reads the smoothed positions and unit tangents back, strand after strand
    /// ([`Renderer::smoothed_vertices_per_strand`] each; this submits and waits).
    pub fn read_smoothed(&self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        self.smooth.read(self.strands as usize * self.smoothed_vertices_per_strand() as usize)
    }

    /// Reads the interpolated hairs back: positions and (tangent, t along the hair),
    /// hair after hair ([`Renderer::hair_counts`]; this submits and waits).
    pub fn read_hairs(&self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let (hairs, per_hair) = self.hair_counts();
        self.interpolate.read(hairs as usize * per_hair as usize)
    }

    /// Reads the interpolated hairs back as [`super::reference::CompositeScene::hairs`]
    /// takes them: per hair its vertices root to tip, xyz the position and w the
    /// t along the hair (this submits and waits).
    pub fn read_strands(&self) -> Result<Vec<Vec<Vec4>>> {
        let (positions, tangents) = self.read_hairs()?;
        let per_hair = self.hair_counts().1.max(1) as usize;
        Ok(positions
            .chunks_exact(per_hair)
            .zip(tangents.chunks_exact(per_hair))
            .map(|(p, t)| p.iter().zip(t).map(|(p, t)| p.truncate().extend(t.w)).collect())
            .collect())
    }

    /// The key hairs' reference vectors (rest-plane normals, head frame).
    pub fn reference_vectors(&self) -> Result<Vec<Vec4>> {
        self.interpolate.read_reference(self.strands as usize)
    }

    /// Builds the Marschner tables for the current material and reads them back
    /// (M indexed by sin θi, sin θo; N by cos φ, cos θd; rows of
    /// [`super::marschner::TABLE_SIZE`] texels) — for tests and tools (submits and waits).
    pub fn read_marschner_tables(&mut self) -> Result<(Vec<Vec4>, Vec<Vec4>)> {
        let params = self.material.marschner;
        self.draw.read_marschner_tables(&params)
    }
}
