//! The graph's derivations, checked against the barriers written out by hand.

use ash::vk::{self, AccessFlags2 as A, Handle, ImageLayout as L, PipelineStageFlags2 as S};

use super::{FrameGraph, Use};
use crate::vk::barrier::AccessKind::*;

fn buffer(n: u64) -> vk::Buffer {
    vk::Buffer::from_raw(n)
}

fn image(n: u64, kinds: &[crate::vk::barrier::AccessKind], layout: L, rest: L) -> Use {
    let range = vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    };
    Use::subresources(vk::Image::from_raw(n), range, kinds, (layout, rest))
}

/// The single memory barrier of `uses` as (src stage, src access, dst stage, dst access), or None.
fn memory(graph: &mut FrameGraph, uses: &[Use]) -> Option<(S, A, S, A)> {
    let b = graph.derive(uses);
    assert!(b.images.is_empty(), "no transitions expected");
    assert!(b.memory.len() <= 1, "one global barrier at most");
    b.memory.first().map(|m| (m.src_stage_mask, m.src_access_mask, m.dst_stage_mask, m.dst_access_mask))
}

#[test]
fn the_first_use_in_an_entry_point_waits_for_any_earlier_work() {
    let mut g = FrameGraph::new();
    let read = memory(&mut g, &[Use::raw_buffer(buffer(1), &[VertexRead])]);
    assert_eq!(read, Some((S::ALL_COMMANDS, A::MEMORY_WRITE, S::VERTEX_SHADER, A::SHADER_STORAGE_READ)));
    let write = memory(&mut g, &[Use::raw_buffer(buffer(2), &[TessellationWrite])]);
    assert_eq!(
        write,
        Some((S::ALL_COMMANDS, A::MEMORY_WRITE, S::TESSELLATION_EVALUATION_SHADER, A::SHADER_STORAGE_WRITE))
    );
}

#[test]
fn a_read_waits_for_the_write_once_and_a_write_for_the_reads() {
    let mut g = FrameGraph::new();
    let b = buffer(7);
    memory(&mut g, &[Use::raw_buffer(b, &[TessellationWrite])]);
    // Read after write: the writer's stage and access to the reader's.
    let raw = memory(&mut g, &[Use::raw_buffer(b, &[TessellationRead])]);
    assert_eq!(
        raw,
        Some((
            S::TESSELLATION_EVALUATION_SHADER,
            A::SHADER_STORAGE_WRITE,
            S::TESSELLATION_EVALUATION_SHADER,
            A::SHADER_STORAGE_READ
        ))
    );
    // The same kind again: already visible, nothing.
    assert_eq!(memory(&mut g, &[Use::raw_buffer(b, &[TessellationRead])]), None);
    // Another kind: its own visibility (the earlier reads' stage chained in).
    let compute = memory(&mut g, &[Use::raw_buffer(b, &[ComputeRead])]);
    assert_eq!(
        compute,
        Some((S::TESSELLATION_EVALUATION_SHADER, A::SHADER_STORAGE_WRITE, S::COMPUTE_SHADER, A::SHADER_STORAGE_READ))
    );
    // Write after the reads: waits for both readers' stages (execution only)
    // and for the last write's memory.
    let war = memory(&mut g, &[Use::raw_buffer(b, &[ClearWrite])]);
    assert_eq!(
        war,
        Some((
            S::TESSELLATION_EVALUATION_SHADER | S::COMPUTE_SHADER,
            A::SHADER_STORAGE_WRITE,
            S::CLEAR,
            A::TRANSFER_WRITE
        ))
    );
    // Write after write.
    let waw = memory(&mut g, &[Use::raw_buffer(b, &[ComputeRead, ComputeWrite])]);
    assert_eq!(
        waw,
        Some((S::CLEAR, A::TRANSFER_WRITE, S::COMPUTE_SHADER, A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE))
    );
    // A read-write use's own reads are not visible to the next read-write.
    let again = memory(&mut g, &[Use::raw_buffer(b, &[ComputeRead, ComputeWrite])]);
    assert!(again.is_some(), "two storage read-writes in a row need a barrier");
}

#[test]
fn uses_of_one_pass_fold_into_one_barrier_and_untouched_resources_add_nothing() {
    let mut g = FrameGraph::new();
    let (a, b, c) = (buffer(1), buffer(2), buffer(3));
    memory(&mut g, &[Use::raw_buffer(a, &[ComputeWrite]), Use::raw_buffer(b, &[TransferWrite])]);
    let both = memory(&mut g, &[Use::raw_buffer(a, &[FragmentRead]), Use::raw_buffer(b, &[VertexUniformRead])]);
    assert_eq!(
        both,
        Some((
            S::COMPUTE_SHADER | S::COPY,
            A::SHADER_STORAGE_WRITE | A::TRANSFER_WRITE,
            S::FRAGMENT_SHADER | S::VERTEX_SHADER,
            A::SHADER_STORAGE_READ | A::UNIFORM_READ
        ))
    );
    // Reading what is visible next to a first use: only the first use's wait.
    let first = memory(&mut g, &[Use::raw_buffer(a, &[FragmentRead]), Use::raw_buffer(c, &[FragmentRead])]);
    assert_eq!(first, Some((S::ALL_COMMANDS, A::MEMORY_WRITE, S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ)));
}

#[test]
fn images_change_layout_by_transitions_and_settle_at_rest() {
    let mut g = FrameGraph::new();
    let rest = L::SHADER_READ_ONLY_OPTIMAL;
    // Drawn into, discarding: UNDEFINED to the attachment layout, after any earlier work.
    let drawn = image(5, &[ColorAttachmentRead, ColorAttachmentWrite], L::COLOR_ATTACHMENT_OPTIMAL, rest);
    let b = g.derive(&[drawn.discarding()]);
    assert!(b.memory.is_empty());
    let t = &b.images[0];
    assert_eq!((t.old_layout, t.new_layout), (L::UNDEFINED, L::COLOR_ATTACHMENT_OPTIMAL));
    assert_eq!((t.src_stage_mask, t.src_access_mask), (S::ALL_COMMANDS, A::MEMORY_WRITE));
    assert_eq!(t.dst_stage_mask, S::COLOR_ATTACHMENT_OUTPUT);
    // Sampled: the attachment writes to the sampling, kept contents.
    let b = g.derive(&[image(5, &[FragmentSampledRead], rest, rest)]);
    let t = &b.images[0];
    assert_eq!((t.old_layout, t.new_layout), (L::COLOR_ATTACHMENT_OPTIMAL, rest));
    assert_eq!(
        (t.src_stage_mask, t.src_access_mask, t.dst_stage_mask, t.dst_access_mask),
        (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE, S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ)
    );
    // Sampled again by the same kind: nothing.
    assert!(g.derive(&[image(5, &[FragmentSampledRead], rest, rest)]).images.is_empty());
    // A discarding first use in the rest layout still leaves UNDEFINED (a new image).
    let depth = image(9, &[DepthAttachmentWrite], L::DEPTH_ATTACHMENT_OPTIMAL, L::DEPTH_ATTACHMENT_OPTIMAL);
    let b = g.derive(&[depth.discarding()]);
    assert_eq!((b.images[0].old_layout, b.images[0].new_layout), (L::UNDEFINED, L::DEPTH_ATTACHMENT_OPTIMAL));
    // Then, in the same layout: a memory dependency, no transition.
    assert!(g.derive(&[depth.discarding()]).images.is_empty());
    // At rest already: settling adds nothing.
    assert!(g.settle_barriers().images.is_empty());
    // Written, read in one layout, transitioned for another reader, then
    // transitioned back and read by the first kind: each transition is a
    // write, waited for again.
    let mut g = FrameGraph::new();
    g.derive(&[image(8, &[ComputeWrite], L::GENERAL, rest).discarding()]);
    assert!(!g.derive(&[image(8, &[ComputeRead], L::GENERAL, rest)]).memory.is_empty());
    assert_eq!(g.derive(&[image(8, &[FragmentSampledRead], rest, rest)]).images.len(), 1);
    assert_eq!(g.derive(&[image(8, &[ComputeRead], L::GENERAL, rest)]).images.len(), 1);
    // Read by the fragment stage in GENERAL now: the transition back was not
    // made visible to it, so it waits, though it read the image before.
    let b = g.derive(&[image(8, &[FragmentSampledRead], L::GENERAL, rest)]);
    assert_eq!(b.memory.len(), 1, "the fragment read waits for the transition");
    assert_eq!(b.memory[0].dst_stage_mask, S::FRAGMENT_SHADER);
    // A second read of the same kind in the same layout: nothing.
    assert!(g.derive(&[image(8, &[FragmentSampledRead], L::GENERAL, rest)]).memory.is_empty());
    // Left in another layout: settling returns it.
    let mut g = FrameGraph::new();
    g.derive(&[image(6, &[ComputeWrite], L::GENERAL, rest).discarding()]);
    let b = g.settle_barriers();
    let t = &b.images[0];
    assert_eq!((t.old_layout, t.new_layout), (L::GENERAL, rest));
    assert_eq!((t.src_stage_mask, t.src_access_mask), (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE));
    assert!(g.settle_barriers().images.is_empty(), "a settled graph knows nothing more");
}
