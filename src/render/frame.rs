//! What the latest prepared frame holds: its detail, hair counts and
//! spacing, and the push constants of the geometry passes.

use super::{Detail, InterpolationMode, Renderer};
use crate::gpu_types::{InterpolatePush, SmoothPush};

/// What the latest prepared frame holds.
impl Renderer {
    /// Smoothed vertices per key hair at the detail of the latest prepared frame.
    pub fn smoothed_vertices_per_strand(&self) -> u32 {
        (self.points - 1) * self.detail.smoothing_level + 1
    }

    /// The detail of the latest prepared frame.
    pub fn detail(&self) -> Detail {
        self.detail
    }

    /// Scalp triangles between key-hair roots (barycentric mode).
    pub fn scalp_triangle_count(&self) -> u32 {
        self.interpolate.triangles()
    }

    /// Key hairs, or scalp triangles in barycentric mode: what hairs are grown from.
    pub(super) fn interpolation_units(&self) -> u32 {
        self.units_of(self.params.interpolation)
    }

    /// Key hairs, or scalp triangles: what `mode` grows hairs from.
    pub(super) fn units_of(&self, mode: InterpolationMode) -> u32 {
        self.interpolate.units(mode, self.strands)
    }

    /// Real hairs each hair drawn in the latest prepared frame stands for:
    /// [`super::HairMaterial::represented_hairs`] at full detail, more where level of
    /// detail draws fewer hairs (× full `hairs_per_key` / the frame's).
    pub fn strand_hairs(&self) -> f32 {
        self.material.represented_hairs * self.params.hairs_per_key as f32 / self.detail.hairs_per_key.max(1) as f32
    }

    /// Spacing of the hairs drawn in the latest prepared frame at the root and
    /// at the tip, meters: in single-strand mode the side of each one's share
    /// of its clump's disk (clump radius × √(π / hairs_per_key) at the
    /// frame's detail), in barycentric mode of its share of a mean scalp
    /// triangle (√(area / hairs_per_key)). A transparent strand standing for
    /// several hairs spreads over part of it ([`super::reference::strand_band`]).
    /// With followers, the spacing of their roots (×√ of the share level of
    /// detail leaves out).
    pub fn strand_spacing(&self) -> (f32, f32) {
        let hairs = self.detail.hairs_per_key.max(1) as f32;
        let p = &self.params;
        if let Some(f) = self.followers {
            let side = f.root_spacing * (f.count as f32 / self.hair_counts().0.max(1) as f32).sqrt();
            return (side, side);
        }
        match p.interpolation {
            InterpolationMode::SingleStrand => {
                let share = (std::f32::consts::PI / hairs).sqrt() * p.clump_width;
                (share * p.root_width, share * p.tip_width)
            }
            InterpolationMode::Barycentric => {
                let side = (self.interpolate.mean_triangle_area() / hairs).sqrt();
                (side, side)
            }
        }
    }

    /// Interpolated hairs (or followers) and vertices per hair of the latest
    /// prepared frame.
    pub fn hair_counts(&self) -> (u32, u32) {
        match self.followers {
            Some(f) => {
                let share = self.detail.hairs_per_key as f32 / self.params.hairs_per_key.max(1) as f32;
                (((f.count as f32 * share).round() as u32).clamp(1, f.count), f.points)
            }
            None => (self.interpolation_units() * self.detail.hairs_per_key, self.smoothed_vertices_per_strand()),
        }
    }

    /// Followers drawn instead of grown hairs (0 without).
    pub fn follower_count(&self) -> u32 {
        self.followers.map_or(0, |f| f.count)
    }

    /// Segments of the latest prepared frame's hairs: a ribbon (two
    /// triangles) or a line each.
    pub(super) fn draw_segments(&self) -> u32 {
        let (hairs, per_hair) = self.hair_counts();
        hairs * (per_hair - 1)
    }

    /// Radius around the rest bounds' centre that the hair can reach.
    #[cfg(test)]
    pub(crate) fn bounds_radius(&self) -> f32 {
        self.placement.bound_radius
    }

    pub(super) fn smooth_push(&self, alpha: f32) -> SmoothPush {
        SmoothPush {
            strands: self.strands,
            points: self.points,
            level: self.detail.smoothing_level,
            stride: self.smoothed_vertices_per_strand(),
            alpha,
        }
    }

    pub(super) fn interpolate_push(&self) -> InterpolatePush {
        if let Some(f) = self.followers {
            return InterpolatePush {
                head_rotation: self.placement.head_rotation.to_array(),
                strands: self.hair_counts().0,
                points: f.points,
                level: 1,
                stride: self.smoothed_vertices_per_strand(),
                hairs: 1,
                clump_width: 0.0,
                root_width: 0.0,
                tip_width: 0.0,
            };
        }
        InterpolatePush {
            head_rotation: self.placement.head_rotation.to_array(),
            strands: self.interpolation_units(),
            points: self.points,
            level: self.detail.smoothing_level,
            stride: self.smoothed_vertices_per_strand(),
            hairs: self.detail.hairs_per_key,
            clump_width: self.params.clump_width,
            root_width: self.params.root_width,
            tip_width: self.params.tip_width,
        }
    }
}
