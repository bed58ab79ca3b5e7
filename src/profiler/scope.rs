//! One helper for every pass and stage: a debug label, and a timestamp pair
//! when a profiler records the frame.

use ash::vk;

use super::{ScopeId, Timing};
use crate::vk::debug::LabelColor;
use crate::vk::device::Device;

/// Stage of both timestamps of every scope: `ALL_COMMANDS`, the opening one
/// once every earlier command has finished (a pass's time never includes its
/// predecessor's), the closing one once the pass's own commands have. A
/// narrower closing stage (`COMPUTE_SHADER` for a compute pass) would not wait
/// for earlier work of other stages, so the end could be stamped before the
/// start.
pub(crate) const TIMESTAMP_STAGE: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::ALL_COMMANDS;

/// An open pass: a timestamp scope of the frame's profiler (which also opens the
/// label), or just the label without a profiler.
#[must_use = "a pass scope must be closed"]
pub(crate) struct PassScope {
    id: Option<ScopeId>,
}

impl PassScope {
    /// Opens `label` as a `kind` pass.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of `device`; with a profiler, its frame
    /// was begun in this command buffer's submission order.
    pub(crate) unsafe fn open(
        device: &Device,
        cmd: vk::CommandBuffer,
        timing: Timing<'_>,
        label: &str,
        kind: LabelColor,
    ) -> PassScope {
        // SAFETY: guaranteed by the caller.
        unsafe {
            match timing.profiler() {
                Some(p) => PassScope { id: Some(p.begin_scope_as(cmd, label, kind)) },
                None => {
                    device.cmd_begin_label(cmd, label, kind);
                    PassScope { id: None }
                }
            }
        }
    }

    /// Closes the scope.
    ///
    /// # Safety
    /// As for [`PassScope::open`], in the same command buffer and with the same
    /// profiler, scopes closed innermost first.
    pub(crate) unsafe fn close(self, device: &Device, cmd: vk::CommandBuffer, timing: Timing<'_>) {
        // SAFETY: guaranteed by the caller.
        unsafe {
            match (timing.profiler(), self.id) {
                (Some(p), Some(id)) => p.end_scope_shared(cmd, id),
                _ => device.cmd_end_label(cmd),
            }
        }
    }

    /// Records `body` inside a `kind` scope named `label`.
    ///
    /// # Safety
    /// As for [`PassScope::open`]; `body` records only valid commands into `cmd`.
    pub(crate) unsafe fn record<T>(
        device: &Device,
        cmd: vk::CommandBuffer,
        timing: Timing<'_>,
        label: &str,
        kind: LabelColor,
        body: impl FnOnce() -> T,
    ) -> T {
        // SAFETY: guaranteed by the caller.
        unsafe {
            let scope = PassScope::open(device, cmd, timing, label, kind);
            let out = body();
            scope.close(device, cmd, timing);
            out
        }
    }
}
