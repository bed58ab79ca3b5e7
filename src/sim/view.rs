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
#[derive(Clone, Copy)]
pub struct KeyHairs<'a> {
    pub(crate) device: &'a Arc<Device>,
    /// Rest shape (head frame) and rest lengths.
    pub(crate) rest: &'a SimState,
    /// Both halves of the positions double buffer (vec4 per particle).
    pub(crate) halves: [&'a Buffer; 2],
    /// The half holding the latest state.
    pub(crate) current: usize,
    /// The head transform of that state.
    pub(crate) head: RigidTransform,
    /// The volume grid and the density buffer (one vec4 per cell), when present.
    pub(crate) volume: Option<(VolumeGrid, &'a Buffer)>,
}

impl std::fmt::Debug for KeyHairs<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KeyHairs")
            .field("strands", &self.rest.strands)
            .field("points", &self.rest.points)
            .field("current", &self.current)
            .field("head", &self.head)
            .field("volume", &self.volume.as_ref().map(|(g, _)| g))
            .finish()
    }
}

impl KeyHairs<'_> {
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
    pub(crate) fn bound_buffers(&self) -> [vk::Buffer; 2] {
        [self.halves[0].raw(), self.halves[1].raw()]
    }
}

impl<'a> From<&'a HairSim> for KeyHairs<'a> {
    fn from(sim: &'a HairSim) -> Self {
        sim.key_hairs()
    }
}
