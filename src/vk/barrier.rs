//! Synchronization2 barriers written with access kinds.
//!
//! Every barrier in the crate names what came before and what comes after as a
//! list of [`AccessKind`]s (a pipeline stage together with the accesses made
//! there, as `vk-sync` does); [`AccessKind::mask`] maps a list to the stage and
//! access masks. No call site writes mask literals.

use ash::vk;

use super::buffer::Buffer;
use super::device::Device;
use super::image::Image;

type Stage = vk::PipelineStageFlags2;
type Acc = vk::AccessFlags2;

/// Both fragment-test stages (depth attachments are read and written in either).
const FRAGMENT_TESTS: Stage =
    Stage::from_raw(Stage::EARLY_FRAGMENT_TESTS.as_raw() | Stage::LATE_FRAGMENT_TESTS.as_raw());

/// Defines [`AccessKind`], its list and its stage and access masks from one
/// table: each kind once, with its documentation and its parts.
macro_rules! access_kinds {
    ($($(#[$doc:meta])* $kind:ident => $parts:expr,)*) => {
        /// One kind of access: a pipeline stage and what it does to memory there.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub(crate) enum AccessKind {
            $($(#[$doc])* $kind,)*
        }

        impl AccessKind {
            /// Every kind, in declaration order (its index is its bit in a [`KindSet`]).
            pub(crate) const ALL: &'static [AccessKind] = &[$(AccessKind::$kind),*];

            /// The stage and access of this kind.
            const fn parts(self) -> (Stage, Acc) {
                match self {
                    $(AccessKind::$kind => $parts,)*
                }
            }
        }
    };
}

access_kinds! {
    /// Storage-buffer or storage-image reads in compute shaders.
    ComputeRead => (Stage::COMPUTE_SHADER, Acc::SHADER_STORAGE_READ),
    /// Storage writes in compute shaders.
    ComputeWrite => (Stage::COMPUTE_SHADER, Acc::SHADER_STORAGE_WRITE),
    /// Uniform-buffer reads in compute shaders.
    ComputeUniformRead => (Stage::COMPUTE_SHADER, Acc::UNIFORM_READ),
    /// Indirect dispatch or draw arguments.
    IndirectRead => (Stage::DRAW_INDIRECT, Acc::INDIRECT_COMMAND_READ),
    /// Storage reads in vertex shaders.
    VertexRead => (Stage::VERTEX_SHADER, Acc::SHADER_STORAGE_READ),
    /// Uniform reads in vertex shaders.
    VertexUniformRead => (Stage::VERTEX_SHADER, Acc::UNIFORM_READ),
    /// Storage reads in tessellation evaluation shaders.
    TessellationRead => (Stage::TESSELLATION_EVALUATION_SHADER, Acc::SHADER_STORAGE_READ),
    /// Storage writes in tessellation evaluation shaders (the capture passes).
    TessellationWrite => (Stage::TESSELLATION_EVALUATION_SHADER, Acc::SHADER_STORAGE_WRITE),
    /// Storage reads in fragment shaders.
    FragmentRead => (Stage::FRAGMENT_SHADER, Acc::SHADER_STORAGE_READ),
    /// Storage writes in fragment shaders.
    FragmentWrite => (Stage::FRAGMENT_SHADER, Acc::SHADER_STORAGE_WRITE),
    /// Uniform reads in fragment shaders.
    FragmentUniformRead => (Stage::FRAGMENT_SHADER, Acc::UNIFORM_READ),
    /// Sampled-image reads in fragment shaders.
    FragmentSampledRead => (Stage::FRAGMENT_SHADER, Acc::SHADER_SAMPLED_READ),
    /// Sampled-image reads in compute shaders.
    ComputeSampledRead => (Stage::COMPUTE_SHADER, Acc::SHADER_SAMPLED_READ),
    /// Colour attachment reads (blending, load).
    ColorAttachmentRead => (Stage::COLOR_ATTACHMENT_OUTPUT, Acc::COLOR_ATTACHMENT_READ),
    /// Colour attachment writes.
    ColorAttachmentWrite => (Stage::COLOR_ATTACHMENT_OUTPUT, Acc::COLOR_ATTACHMENT_WRITE),
    /// Depth attachment reads (tests, load).
    DepthAttachmentRead => (FRAGMENT_TESTS, Acc::DEPTH_STENCIL_ATTACHMENT_READ),
    /// Depth attachment writes.
    DepthAttachmentWrite => (FRAGMENT_TESTS, Acc::DEPTH_STENCIL_ATTACHMENT_WRITE),
    /// Copy sources.
    TransferRead => (Stage::COPY, Acc::TRANSFER_READ),
    /// Copy destinations.
    TransferWrite => (Stage::COPY, Acc::TRANSFER_WRITE),
    /// Clear destinations (`vkCmdClear*Image`, `vkCmdFillBuffer`, `vkCmdUpdateBuffer`).
    ClearWrite => (Stage::CLEAR, Acc::TRANSFER_WRITE),
    /// Writes by any transfer command (copies, clears, updates, blits).
    AnyTransferWrite => (Stage::ALL_TRANSFER, Acc::TRANSFER_WRITE),
    /// Host reads of mapped memory.
    HostRead => (Stage::HOST, Acc::HOST_READ),
    /// Every earlier write, for one-shot submissions that know nothing of prior use.
    AnyWrite => (Stage::ALL_COMMANDS, Acc::MEMORY_WRITE),
    /// Every later read, for one-shot submissions that know nothing of later use.
    AnyRead => (Stage::ALL_COMMANDS, Acc::MEMORY_READ),
}

impl AccessKind {
    /// Whether the kind writes memory (a later access of any kind waits for it).
    pub(crate) const fn writes(self) -> bool {
        self.parts().1.as_raw() & WRITE_ACCESS.as_raw() != 0
    }

    /// The stage and access masks of `kinds` together (none for an empty list).
    pub(crate) const fn mask(kinds: &[AccessKind]) -> (Stage, Acc) {
        let (mut stage, mut access) = (0u64, 0u64);
        let mut i = 0;
        while i < kinds.len() {
            let (s, a) = kinds[i].parts();
            stage |= s.as_raw();
            access |= a.as_raw();
            i += 1;
        }
        (Stage::from_raw(stage), Acc::from_raw(access))
    }
}

/// Every access flag that writes memory.
const WRITE_ACCESS: Acc = Acc::from_raw(
    Acc::SHADER_STORAGE_WRITE.as_raw()
        | Acc::COLOR_ATTACHMENT_WRITE.as_raw()
        | Acc::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
        | Acc::TRANSFER_WRITE.as_raw()
        | Acc::MEMORY_WRITE.as_raw(),
);

/// A set of [`AccessKind`]s, one bit each (its index in [`AccessKind::ALL`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct KindSet(u32);

impl KindSet {
    /// No kind.
    pub(crate) const EMPTY: KindSet = KindSet(0);

    /// The set of `kinds`.
    pub(crate) fn of(kinds: &[AccessKind]) -> KindSet {
        kinds.iter().copied().collect()
    }

    /// Whether no kind is in the set.
    pub(crate) fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The kinds of both sets.
    pub(crate) fn union(self, other: KindSet) -> KindSet {
        KindSet(self.0 | other.0)
    }

    /// The kinds of this set not in `other`.
    pub(crate) fn minus(self, other: KindSet) -> KindSet {
        KindSet(self.0 & !other.0)
    }

    /// The kinds of the set that write.
    pub(crate) fn writes(self) -> KindSet {
        self.kinds().filter(|k| k.writes()).collect()
    }

    /// The kinds of the set that only read.
    pub(crate) fn reads(self) -> KindSet {
        self.minus(self.writes())
    }

    /// The kinds in the set.
    pub(crate) fn kinds(self) -> impl Iterator<Item = AccessKind> {
        AccessKind::ALL.iter().copied().filter(move |&k| self.0 & 1 << k as u32 != 0)
    }

    /// The stage and access masks of the set's kinds.
    pub(crate) fn mask(self) -> (Stage, Acc) {
        self.kinds().fold((Stage::NONE, Acc::NONE), |(stage, access), kind| {
            let (s, a) = kind.parts();
            (stage | s, access | a)
        })
    }
}

impl FromIterator<AccessKind> for KindSet {
    fn from_iter<I: IntoIterator<Item = AccessKind>>(kinds: I) -> KindSet {
        KindSet(kinds.into_iter().fold(0, |bits, k| bits | 1 << k as u32))
    }
}

/// Nothing before or after (ownership releases and acquires, first uses).
pub(crate) const NOTHING: &[AccessKind] = &[];
/// Colour and depth attachment reads and writes: a rendering instance that loads.
pub(crate) const ATTACHMENTS: &[AccessKind] = &[
    AccessKind::ColorAttachmentRead,
    AccessKind::ColorAttachmentWrite,
    AccessKind::DepthAttachmentRead,
    AccessKind::DepthAttachmentWrite,
];
/// Colour attachment reads and writes.
pub(crate) const COLOR_ATTACHMENT: &[AccessKind] = &[AccessKind::ColorAttachmentRead, AccessKind::ColorAttachmentWrite];
/// Depth attachment reads and writes.
pub(crate) const DEPTH_ATTACHMENT: &[AccessKind] = &[AccessKind::DepthAttachmentRead, AccessKind::DepthAttachmentWrite];
/// Compute-shader storage reads and writes.
pub(crate) const COMPUTE_READ_WRITE: &[AccessKind] = &[AccessKind::ComputeRead, AccessKind::ComputeWrite];
/// Any later access.
pub(crate) const ANY: &[AccessKind] = &[AccessKind::AnyRead, AccessKind::AnyWrite];

/// A barrier on a whole buffer.
pub(crate) fn buffer(buffer: &Buffer, src: &[AccessKind], dst: &[AccessKind]) -> vk::BufferMemoryBarrier2<'static> {
    ownership(buffer.raw(), src, dst, vk::QUEUE_FAMILY_IGNORED, vk::QUEUE_FAMILY_IGNORED)
}

/// A barrier on a whole buffer that also moves it from queue family `from` to `to`
/// (a release on the `from` side, an acquire on the `to` side; `VK_QUEUE_FAMILY_EXTERNAL`
/// for memory shared with another device).
pub(crate) fn ownership(
    buffer: vk::Buffer,
    src: &[AccessKind],
    dst: &[AccessKind],
    from: u32,
    to: u32,
) -> vk::BufferMemoryBarrier2<'static> {
    let ((src_stage, src_access), (dst_stage, dst_access)) = (AccessKind::mask(src), AccessKind::mask(dst));
    vk::BufferMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .src_queue_family_index(from)
        .dst_queue_family_index(to)
        .buffer(buffer)
        .offset(0)
        .size(vk::WHOLE_SIZE)
}

/// A barrier and layout transition on a whole image.
pub(crate) fn image(
    image: &Image,
    src: &[AccessKind],
    dst: &[AccessKind],
    old: vk::ImageLayout,
    new: vk::ImageLayout,
) -> vk::ImageMemoryBarrier2<'static> {
    subresources(image.raw(), image.full_range(), src, dst, old, new)
}

/// A barrier and layout transition on `range` of an image this crate may not
/// own (a host's).
pub(crate) fn subresources(
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    src: &[AccessKind],
    dst: &[AccessKind],
    old: vk::ImageLayout,
    new: vk::ImageLayout,
) -> vk::ImageMemoryBarrier2<'static> {
    let ((src_stage, src_access), (dst_stage, dst_access)) = (AccessKind::mask(src), AccessKind::mask(dst));
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old)
        .new_layout(new)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(range)
}

/// A global memory barrier.
pub(crate) fn memory(src: &[AccessKind], dst: &[AccessKind]) -> vk::MemoryBarrier2<'static> {
    let ((src_stage, src_access), (dst_stage, dst_access)) = (AccessKind::mask(src), AccessKind::mask(dst));
    vk::MemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
}

/// Memory barriers and image layout transitions recorded together before a
/// pass (what makes its attachments or inputs ready).
#[derive(Clone, Default)]
pub(crate) struct Barriers {
    pub memory: Vec<vk::MemoryBarrier2<'static>>,
    pub images: Vec<vk::ImageMemoryBarrier2<'static>>,
}

impl Device {
    /// Records `barriers` as one `vkCmdPipelineBarrier2`.
    ///
    /// # Safety
    /// As for [`Device::cmd_barrier`].
    pub(crate) unsafe fn cmd_barriers(&self, cmd: vk::CommandBuffer, barriers: &Barriers) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.cmd_barrier(cmd, &barriers.memory, &[], &barriers.images) };
    }

    /// Records one `vkCmdPipelineBarrier2` with the given barriers.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device; the resources belong to it.
    pub(crate) unsafe fn cmd_barrier(
        &self,
        cmd: vk::CommandBuffer,
        memory: &[vk::MemoryBarrier2<'_>],
        buffers: &[vk::BufferMemoryBarrier2<'_>],
        images: &[vk::ImageMemoryBarrier2<'_>],
    ) {
        let info = vk::DependencyInfo::default()
            .memory_barriers(memory)
            .buffer_memory_barriers(buffers)
            .image_memory_barriers(images);
        self.counters.barrier();
        // SAFETY: guaranteed by the caller.
        unsafe { self.raw.cmd_pipeline_barrier2(cmd, &info) };
    }

    /// Records one barrier and layout transition (`layouts`: old, new) on a whole image.
    ///
    /// # Safety
    /// As for [`Device::cmd_barrier`].
    pub(crate) unsafe fn cmd_transition(
        &self,
        cmd: vk::CommandBuffer,
        image: &Image,
        src: &[AccessKind],
        dst: &[AccessKind],
        layouts: (vk::ImageLayout, vk::ImageLayout),
    ) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.cmd_barrier(cmd, &[], &[], &[self::image(image, src, dst, layouts.0, layouts.1)]) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_its_own_bit_and_writes_are_told_from_reads() {
        for (i, &kind) in AccessKind::ALL.iter().enumerate() {
            assert_eq!(kind as usize, i, "{kind:?} is at its index");
            assert_eq!(KindSet::of(&[kind]).kinds().collect::<Vec<_>>(), [kind]);
        }
        let writes: Vec<AccessKind> = AccessKind::ALL.iter().copied().filter(|k| k.writes()).collect();
        use AccessKind::*;
        assert_eq!(
            writes,
            [
                ComputeWrite,
                TessellationWrite,
                FragmentWrite,
                ColorAttachmentWrite,
                DepthAttachmentWrite,
                TransferWrite,
                ClearWrite,
                AnyTransferWrite,
                AnyWrite
            ]
        );
        let both = KindSet::of(&[ComputeRead, ComputeWrite, ColorAttachmentRead]);
        assert_eq!(both.writes(), KindSet::of(&[ComputeWrite]));
        assert_eq!(both.reads(), KindSet::of(&[ComputeRead, ColorAttachmentRead]));
        assert_eq!(both.mask(), AccessKind::mask(&[ComputeRead, ComputeWrite, ColorAttachmentRead]));
    }

    #[test]
    fn kinds_combine_into_masks() {
        let (stage, access) = AccessKind::mask(&[AccessKind::TransferWrite, AccessKind::ComputeRead]);
        assert_eq!(stage, Stage::COPY | Stage::COMPUTE_SHADER);
        assert_eq!(access, Acc::TRANSFER_WRITE | Acc::SHADER_STORAGE_READ);
        assert_eq!(AccessKind::mask(NOTHING), (Stage::NONE, Acc::NONE));
        let (stage, access) = AccessKind::mask(ATTACHMENTS);
        assert_eq!(stage, Stage::COLOR_ATTACHMENT_OUTPUT | Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS);
        assert_eq!(
            access,
            Acc::COLOR_ATTACHMENT_READ
                | Acc::COLOR_ATTACHMENT_WRITE
                | Acc::DEPTH_STENCIL_ATTACHMENT_READ
                | Acc::DEPTH_STENCIL_ATTACHMENT_WRITE
        );
    }
}
