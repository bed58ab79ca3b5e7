//! Where the hair is drawn (the host's target) and where it is (its bounds and
//! the head pose of the latest prepared frame).

use ash::vk;
use glam::{Quat, Vec3};

use crate::sim::SimState;

/// The host's images the hair is drawn into.
#[derive(Debug, Clone, Copy)]
pub struct RenderTarget {
    /// Color attachment view, in `COLOR_ATTACHMENT_OPTIMAL`.
    pub color: vk::ImageView,
    /// Its format.
    pub color_format: vk::Format,
    /// Depth attachment view (in `DEPTH_ATTACHMENT_OPTIMAL`), or null for none.
    pub depth: vk::ImageView,
    /// Its format (`UNDEFINED` for none).
    pub depth_format: vk::Format,
    /// The image behind `depth` (its mip level 0 and array layer 0 are the ones
    /// the view shows; a depth-only format: `D32_SFLOAT`, `X8_D24_UNORM_PACK32`
    /// or `D16_UNORM`), created with `TRANSFER_SRC` usage, or null. The compute
    /// rasterisers ([`super::Raster::Compute`], [`super::Raster::Tiles`]) copy the host's depth out of
    /// it to test each hair fragment against (its depth aspect passes through
    /// `TRANSFER_SRC_OPTIMAL` and is back in `DEPTH_ATTACHMENT_OPTIMAL` before
    /// the draw returns); with a depth view and a null image, they refuse the
    /// target. The hardware raster pipeline never reads it.
    pub depth_image: vk::Image,
    /// Velocity image view (in `COLOR_ATTACHMENT_OPTIMAL`; created with
    /// `COLOR_ATTACHMENT` usage, as large as the colour image), or null for
    /// none. Where given, each pixel the hair covers gets its motion since the
    /// previous frame ([`super::MotionParams`]: which hair, the units, the
    /// sign), the jitter excluded; every other pixel keeps what the host wrote.
    /// Written in every transparency mode; the target must be single-sample.
    /// One draw a frame writes motion vectors: the renderer keeps that draw's
    /// camera and drawn positions for the next (a second view of the same
    /// frame would move the history). The motion is kept as half floats
    /// whatever the image's format.
    pub velocity: vk::ImageView,
    /// Its format: `R16G16_SFLOAT` or `R32G32_SFLOAT` (`UNDEFINED` for none).
    pub velocity_format: vk::Format,
    /// Extent of all three.
    pub extent: vk::Extent2D,
    /// Sample count of all three (1 where there is a velocity image).
    pub samples: vk::SampleCountFlags,
}

/// Where the hair is, for the level of detail and the shadow maps' fit.
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    /// Centre of the rest shape's bounds, head frame.
    pub(super) rest_center: Vec3,
    /// Radius around `rest_center` that the hair can reach (roots plus strand length).
    pub(super) rest_radius: f32,
    /// Radius around `head_center` of the latest prepared frame: `rest_radius`,
    /// or the key hairs' own bounds ([`crate::sim::KeyHairs::with_bounds`]).
    pub(super) bound_radius: f32,
    /// Head rotation of the latest prepared frame.
    pub(super) head_rotation: Quat,
    /// `rest_center` in the world at the latest prepared frame, or the centre
    /// of the key hairs' own bounds.
    pub(super) head_center: Vec3,
}

impl Placement {
    pub(super) fn of(rest: &SimState, head_rotation: Quat) -> Placement {
        let (lo, hi) = rest.rest.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| {
            (lo.min(p.truncate()), hi.max(p.truncate()))
        });
        let rest_center = 0.5 * (lo + hi);
        let bound_radius = (0..rest.strands)
            .map(|s| (rest.rest[s * rest.points].truncate() - rest_center).length() + rest.rest_strand_length(s))
            .fold(0.0f32, f32::max);
        Placement { rest_center, rest_radius: bound_radius, bound_radius, head_rotation, head_center: rest_center }
    }

    /// Places the hair for a frame of `sim`: by its own bounds when it has
    /// them, else the rest bounds moved by its head.
    pub(super) fn update(&mut self, sim: &crate::sim::KeyHairs<'_>) {
        let head = sim.head();
        self.head_rotation = head.rotation.normalize();
        (self.head_center, self.bound_radius) = match sim.bounds() {
            Some(bounds) => bounds,
            None => (head.matrix().transform_point3(self.rest_center), self.rest_radius),
        };
    }
}
