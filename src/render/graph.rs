//! The frame's barriers, derived from what each pass declares it reads and writes.
//!
//! A pass (or a step of one) names, before it records, every resource it
//! touches as a [`Use`]: a buffer or image, the [`AccessKind`]s it makes of it
//! and, for an image, the layout it needs. [`FrameGraph::record`] compares each
//! use with the resource's last ones and records one `vkCmdPipelineBarrier2`
//! holding the dependencies they need (one global barrier folding every
//! buffer's together):
//!
//! - a read after a write waits for that write and makes it visible to the
//!   reading kinds (once: a later read of the same kinds needs nothing, until
//!   the next write or layout transition);
//! - a write waits for the last write (its memory) and for every read since
//!   (execution only);
//! - an image whose layout changes is transitioned, from `UNDEFINED` where the
//!   use discards its contents; a discarding first use in the graph is
//!   transitioned from `UNDEFINED` even when it needs the rest layout, so that
//!   a new image needs no transition of its own.
//!
//! Buffer dependencies fold into one global memory barrier; image transitions
//! are image barriers. No pass places a barrier against its neighbour: the
//! smoothing pass does not know the interpolation reads its output, the
//! interpolation declares that it does.
//!
//! A graph lives for one recording entry point ([`super::Renderer::record_prepare`],
//! `record_shadows`, `record_draw`): the host may record anything between them,
//! in any command buffer, so the first use of a resource in an entry point waits
//! for any earlier write and read (the past is unknown) and every image starts in
//! its rest layout (what its [`Use`] names as such: the layout it is in between
//! entry points). [`FrameGraph::settle`] returns the images to those layouts
//! at the end.

use std::collections::HashMap;

use ash::vk;

use crate::vk::barrier::{self, AccessKind, Barriers, KindSet};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::Image;

/// What a use touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Resource {
    Buffer(vk::Buffer),
    Image(vk::Image),
    /// The host's colour and depth attachments, known by their views only:
    /// ordered by memory dependencies, their layouts the host's.
    HostAttachments,
}

/// How a use touches an image.
#[derive(Debug, Clone, Copy)]
struct ImageUse {
    range: vk::ImageSubresourceRange,
    /// The layout the use needs.
    layout: vk::ImageLayout,
    /// The layout the image is in between entry points.
    rest: vk::ImageLayout,
    /// The use overwrites the image without reading what was there.
    discard: bool,
}

/// One resource as a pass uses it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Use {
    resource: Resource,
    kinds: KindSet,
    image: Option<ImageUse>,
}

impl Use {
    /// `buffer` accessed as `kinds`.
    pub(crate) fn buffer(buffer: &Buffer, kinds: &[AccessKind]) -> Use {
        Use::raw_buffer(buffer.raw(), kinds)
    }

    /// Each of `buffers` accessed as `kinds`.
    pub(crate) fn buffers<'a>(buffers: impl IntoIterator<Item = &'a Buffer>, kinds: &[AccessKind]) -> Vec<Use> {
        buffers.into_iter().map(|b| Use::buffer(b, kinds)).collect()
    }

    /// A buffer vkhair may not own (the simulation's, a host's) accessed as `kinds`.
    pub(crate) fn raw_buffer(buffer: vk::Buffer, kinds: &[AccessKind]) -> Use {
        Use { resource: Resource::Buffer(buffer), kinds: KindSet::of(kinds), image: None }
    }

    /// The host's attachments ([`Resource::HostAttachments`]) accessed as `kinds`.
    pub(crate) fn host_attachments(kinds: &[AccessKind]) -> Use {
        Use { resource: Resource::HostAttachments, kinds: KindSet::of(kinds), image: None }
    }

    /// All of `image` accessed as `kinds` in `layout`; between entry points it is in `rest`.
    pub(crate) fn image(image: &Image, kinds: &[AccessKind], layout: vk::ImageLayout, rest: vk::ImageLayout) -> Use {
        Use::subresources(image.raw(), image.full_range(), kinds, (layout, rest))
    }

    /// `range` of an image vkhair may not own (a host's) accessed as `kinds`
    /// in `layouts.0`; between entry points it is in `layouts.1`.
    pub(crate) fn subresources(
        image: vk::Image,
        range: vk::ImageSubresourceRange,
        kinds: &[AccessKind],
        (layout, rest): (vk::ImageLayout, vk::ImageLayout),
    ) -> Use {
        Use {
            resource: Resource::Image(image),
            kinds: KindSet::of(kinds),
            image: Some(ImageUse { range, layout, rest, discard: false }),
        }
    }

    /// The same use, overwriting the whole image without reading it (its
    /// earlier contents may be discarded by the transition).
    pub(crate) fn discarding(mut self) -> Use {
        if let Some(image) = &mut self.image {
            image.discard = true;
        }
        self
    }
}

/// What the graph knows of one resource.
#[derive(Debug, Clone, Copy)]
struct State {
    /// The kinds of the last write (`AnyWrite` before the first in the entry point).
    write: KindSet,
    /// The kinds the last write was made visible to.
    visible: KindSet,
    /// The kinds that read since the last write.
    readers: KindSet,
    /// The image's layout and rest layout.
    layout: Option<(vk::ImageLayout, vk::ImageLayout, vk::ImageSubresourceRange)>,
}

impl State {
    /// A resource the entry point has not used yet: any earlier write and read may be pending.
    fn unknown(image: Option<ImageUse>) -> State {
        State {
            write: KindSet::of(&[AccessKind::AnyWrite]),
            visible: KindSet::EMPTY,
            readers: KindSet::of(&[AccessKind::AnyRead]),
            layout: image.map(|i| (i.rest, i.rest, i.range)),
        }
    }
}

/// The barriers of one entry point's passes, derived from their [`Use`]s.
#[derive(Debug, Default)]
pub(crate) struct FrameGraph {
    states: HashMap<Resource, State>,
}

impl FrameGraph {
    /// A graph that knows nothing of earlier work.
    pub(crate) fn new() -> FrameGraph {
        FrameGraph::default()
    }

    /// The barriers that order `uses` after every earlier use the graph saw,
    /// and the graph updated as if they were recorded.
    pub(crate) fn derive(&mut self, uses: &[Use]) -> Barriers {
        let (mut src, mut src_stages, mut dst) = (KindSet::EMPTY, KindSet::EMPTY, KindSet::EMPTY);
        let mut images = Vec::new();
        for u in uses {
            let first = !self.states.contains_key(&u.resource);
            let state = self.states.entry(u.resource).or_insert_with(|| State::unknown(u.image));
            let (writes, reads) = (u.kinds.writes(), u.kinds.reads());
            let unseen = !reads.minus(state.visible).is_empty();
            let after_write = !state.write.is_empty() && (!writes.is_empty() || unseen);
            let after_reads = !writes.is_empty() && !state.readers.is_empty();
            let old = state.layout.map(|(layout, _, _)| layout);
            // A discarding first use transitions from UNDEFINED even into the
            // rest layout: the image may be new, its layout never set.
            let transitioned = u.image.filter(|i| Some(i.layout) != old || (first && i.discard));
            match (u.resource, transitioned, old) {
                (Resource::Image(raw), Some(image), Some(old)) => {
                    let old = if image.discard { vk::ImageLayout::UNDEFINED } else { old };
                    images.push(transition(raw, image.range, (old, image.layout), state, u.kinds));
                    state.layout = Some((image.layout, image.rest, image.range));
                }
                _ => {
                    if after_write {
                        // The reads since (a transition among them) chain the write's wait.
                        src = src.union(state.write);
                        src_stages = src_stages.union(state.readers);
                    }
                    if after_reads {
                        src_stages = src_stages.union(state.readers);
                    }
                    if after_write || after_reads {
                        dst = dst.union(u.kinds);
                    }
                }
            }
            if writes.is_empty() && transitioned.is_some() {
                // A transition writes the image: only this use's kinds see it,
                // and earlier readers are ordered before it.
                state.visible = reads;
                state.readers = reads;
            } else if writes.is_empty() {
                if after_write {
                    state.visible = state.visible.union(reads);
                }
                state.readers = state.readers.union(reads);
            } else {
                *state = State { write: writes, visible: KindSet::EMPTY, readers: reads, layout: state.layout };
            }
        }
        let mut memory = Vec::new();
        if !dst.is_empty() {
            memory.push(memory_barrier(src, src_stages, dst));
        }
        Barriers { memory, images }
    }

    /// Records the barriers [`FrameGraph::derive`] finds for `uses` (nothing when none are needed).
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device` outside a render pass;
    /// the resources belong to it; every command recorded since the graph was
    /// made that touches them was declared to it.
    pub(crate) unsafe fn record(&mut self, device: &Device, cmd: vk::CommandBuffer, uses: &[Use]) {
        let barriers = self.derive(uses);
        // SAFETY: guaranteed by the caller.
        unsafe { record_any(device, cmd, &barriers) };
    }

    /// The transitions that return every image the graph moved to its rest
    /// layout, made ready for any later access; the graph then knows nothing.
    pub(crate) fn settle_barriers(&mut self) -> Barriers {
        let mut images = Vec::new();
        for (resource, state) in &self.states {
            let (Resource::Image(raw), Some((layout, rest, range))) = (resource, state.layout) else { continue };
            if layout != rest {
                images.push(transition(*raw, range, (layout, rest), state, KindSet::of(barrier::ANY)));
            }
        }
        self.states.clear();
        Barriers { memory: Vec::new(), images }
    }

    /// Records [`FrameGraph::settle_barriers`] (nothing when every image is at rest).
    ///
    /// # Safety
    /// As for [`FrameGraph::record`].
    pub(crate) unsafe fn settle(&mut self, device: &Device, cmd: vk::CommandBuffer) {
        let barriers = self.settle_barriers();
        // SAFETY: guaranteed by the caller.
        unsafe { record_any(device, cmd, &barriers) };
    }
}

/// Records `barriers` unless there are none.
///
/// # Safety
/// As for [`FrameGraph::record`].
unsafe fn record_any(device: &Device, cmd: vk::CommandBuffer, barriers: &Barriers) {
    if !barriers.memory.is_empty() || !barriers.images.is_empty() {
        // SAFETY: guaranteed by the caller.
        unsafe { device.cmd_barriers(cmd, barriers) };
    }
}

/// A global barrier from the writes `src` and the reads `src_stages` (their
/// stages only) to `dst`.
fn memory_barrier(src: KindSet, src_stages: KindSet, dst: KindSet) -> vk::MemoryBarrier2<'static> {
    let (stage, access) = src.mask();
    let (readers, _) = src_stages.mask();
    let (dst_stage, dst_access) = dst.mask();
    vk::MemoryBarrier2::default()
        .src_stage_mask(stage | readers)
        .src_access_mask(access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
}

/// The transition of `range` of `raw` between `layouts` (old, new), after
/// `state`'s last write and reads, before `dst`.
fn transition(
    raw: vk::Image,
    range: vk::ImageSubresourceRange,
    (old, new): (vk::ImageLayout, vk::ImageLayout),
    state: &State,
    dst: KindSet,
) -> vk::ImageMemoryBarrier2<'static> {
    let dependency = memory_barrier(state.write, state.readers, dst);
    barrier::subresources(raw, range, &[], &[], old, new)
        .src_stage_mask(dependency.src_stage_mask)
        .src_access_mask(dependency.src_access_mask)
        .dst_stage_mask(dependency.dst_stage_mask)
        .dst_access_mask(dependency.dst_access_mask)
}

#[cfg(test)]
#[path = "graph_tests.rs"]
mod tests;
