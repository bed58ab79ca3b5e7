//! [`KeyHairs`]: what a renderer reads of the simulated key hairs.

use std::sync::Arc;

use ash::vk;

use super::{HairSim, RigidTransform, SimState, VolumeGrid};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;

/// The latest key-hair state on one device, as the renderer reads it: either a
/// [`HairSim`]'s own double buffer (`(&sim).into()`) or the hand-off copy kept by a
/// [`crate::schedule::FrameScheduler`] ([`crate::schedule::FrameScheduler::key_hairs`]).
///
/// A renderer is bound to the buffers of the view it was created from; later
/// views must come from the same source.
///
/// The view also holds the state before the latest step. Drawn as it is, it shows
/// the latest state; [`KeyHairs::blended`] draws between the two by the
/// fixed-step driver's [`crate::sim::StepPlan::alpha`], so a host that renders
/// faster than the simulation steps sees smooth motion, not a jump every step:
///
/// ```
/// use glam::Vec3;
/// use vkhair::render::{RenderParams, Renderer};
/// use vkhair::sim::{FixedStepDriver, HairSim, RigidTransform, SimParams};
/// use vkhair::{ContextOptions, GpuContext, Groom, ValidationLog};
///
/// let log = ValidationLog::new();
/// {
///     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
///     let strand: Vec<Vec3> = (0..6).map(|i| Vec3::new(0.02 * i as f32, 0.0, 0.0)).collect();
///     let head = RigidTransform::default();
///     let mut sim = HairSim::new(&ctx, &Groom::from_strands(&[strand])?, &SimParams::default(), &head)?;
///     let mut renderer = Renderer::new(&ctx, &sim, &RenderParams::default())?;
///     // Frames at 144 Hz over a 60 Hz simulation.
///     let mut driver = FixedStepDriver::new(1.0 / 60.0, 4)?;
///     for _ in 0..5 {
///         let plan = driver.advance(1.0 / 144.0);
///         sim.run(plan.steps as usize, |_| head, None)?;
///         // A host records this into its frame with record_prepare.
///         renderer.prepare_now(sim.key_hairs().blended(plan.alpha)?, None)?;
///     }
/// }
/// log.assert_clean();
/// # Ok::<(), vkhair::Error>(())
/// ```
#[derive(Clone, Copy)]
pub struct KeyHairs<'a> {
    pub(crate) device: &'a Arc<Device>,
    /// Rest shape (head frame) and rest lengths.
    pub(crate) rest: &'a SimState,
    /// Both halves of the positions double buffer (vec4 per particle).
    pub(crate) halves: [&'a Buffer; 2],
    /// The half holding the latest state.
    pub(crate) current: usize,
    /// Per half: the positions before the step that produced that half's state.
    pub(crate) before: [&'a Buffer; 2],
    /// Where between the state before the latest step (0) and the latest (1) the
    /// view is drawn.
    pub(crate) alpha: f32,
    /// The head transform of that state.
    pub(crate) head: RigidTransform,
    /// The volume grid and the density buffer (one vec4 per cell), when present.
    pub(crate) volume: Option<(VolumeGrid, &'a Buffer)>,
    /// A sphere (world centre, radius) holding every key hair, when the source
    /// knows one better than the rest shape placed by the head
    /// ([`KeyHairs::with_bounds`]).
    pub(crate) bounds: Option<(glam::Vec3, f32)>,
}

impl std::fmt::Debug for KeyHairs<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KeyHairs")
            .field("strands", &self.rest.strands)
            .field("points", &self.rest.points)
            .field("current", &self.current)
            .field("alpha", &self.alpha)
            .field("head", &self.head)
            .field("volume", &self.volume.as_ref().map(|(g, _)| g))
            .field("bounds", &self.bounds)
            .finish()
    }
}

impl KeyHairs<'_> {
    /// The view drawn at `alpha` between the state before the latest step (0)
    /// and the latest state (1): positions blended per particle before any
    /// smoothing, `before + (latest − before)·alpha`, exactly the two states at 0
    /// and 1 (bit for bit). The head frame, the reference vectors and the density
    /// volume stay those of the latest state, so the hairs' tangent frames do not
    /// jump. `alpha` is a fraction of one step, as
    /// [`crate::sim::StepPlan::alpha`] gives it.
    pub fn blended(self, alpha: f32) -> crate::error::Result<Self> {
        if !(0.0..=1.0).contains(&alpha) {
            return Err(crate::error::Error::param("alpha", alpha, "0..=1 (a fraction of one step)"));
        }
        Ok(KeyHairs { alpha, ..self })
    }

    /// The view with the hair known to lie within the sphere of `centre`
    /// (world) and `radius` (meters): a renderer then fits its shadow maps to
    /// that sphere and picks the level of detail by the camera's distance from
    /// `centre`, instead of using the rest shape's bounds placed by the head.
    /// For key hairs that do not ride the head rigidly (a [`crate::crowd::Crowd`]
    /// of characters, a skinned scalp walking away from the head transform).
    /// Refuses a centre that is not finite or a radius that is not finite and
    /// above 0.
    pub fn with_bounds(self, centre: glam::Vec3, radius: f32) -> crate::error::Result<Self> {
        if !centre.is_finite() {
            return Err(crate::error::Error::param("bounds centre", centre, "finite"));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(crate::error::Error::param("bounds radius", radius, "finite and above 0 (meters)"));
        }
        Ok(KeyHairs { bounds: Some((centre, radius)), ..self })
    }

    /// The sphere (world centre, radius) given by [`KeyHairs::with_bounds`].
    pub fn bounds(&self) -> Option<(glam::Vec3, f32)> {
        self.bounds
    }

    /// Where between the two states the view is drawn (1: the latest).
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// Key hairs and points per key hair.
    pub fn size(&self) -> (usize, usize) {
        (self.rest.strands, self.rest.points)
    }

    /// The head transform of the state.
    pub fn head(&self) -> RigidTransform {
        self.head
    }

    /// The volume grid as placed for the state, when a density volume comes with it.
    pub fn volume_grid(&self) -> Option<VolumeGrid> {
        self.volume.as_ref().map(|(g, _)| *g)
    }

    /// The positions buffer holding the state (vec4 per particle, w = inverse mass).
    pub fn positions_buffer(&self) -> vk::Buffer {
        self.halves[self.current].raw()
    }

    /// The raw buffers of both halves, for checking that a view comes from the
    /// source a renderer was bound to.
    pub(crate) fn bound_buffers(&self) -> [vk::Buffer; 4] {
        [self.halves[0].raw(), self.halves[1].raw(), self.before[0].raw(), self.before[1].raw()]
    }
}

impl<'a> From<&'a HairSim> for KeyHairs<'a> {
    fn from(sim: &'a HairSim) -> Self {
        sim.key_hairs()
    }
}
