//! Debug names and command-buffer labels.

use std::ffi::CString;

use ash::vk;

use super::device::Device;

/// What a labelled pass's commands are; picks the label's colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LabelColor {
    /// Compute dispatches (the simulation's stages, the volume step, lookup tables).
    Compute,
    /// Draws (the render passes).
    Graphics,
    /// Copies and clears (the hand-off to rendering).
    Transfer,
    /// A host's own scope through `GpuProfiler::begin_scope`: anything.
    Host,
}

impl LabelColor {
    fn rgba(self) -> [f32; 4] {
        match self {
            LabelColor::Compute => [0.35, 0.65, 1.0, 1.0],
            LabelColor::Graphics => [1.0, 0.6, 0.2, 1.0],
            LabelColor::Transfer => [0.5, 0.85, 0.4, 1.0],
            LabelColor::Host => [0.8, 0.8, 0.8, 1.0],
        }
    }
}

impl Device {
    /// Gives `handle` a debug name (no-op without `VK_EXT_debug_utils`).
    pub(crate) fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(utils) = &self.debug_utils else { return };
        let Ok(name) = CString::new(name.replace('\0', " ")) else { return };
        let info = vk::DebugUtilsObjectNameInfoEXT::default().object_handle(handle).object_name(&name);
        // SAFETY: the handle belongs to this device; naming failures are not fatal.
        let _ = unsafe { utils.set_debug_utils_object_name(&info) };
    }

    /// Opens a debug label region in `cmd` (RenderDoc/Nsight show it as a named pass).
    ///
    /// # Safety
    /// `cmd` is a command buffer of this device in the recording state.
    pub(crate) unsafe fn cmd_begin_label(&self, cmd: vk::CommandBuffer, name: &str, color: LabelColor) {
        let Some(utils) = &self.debug_utils else { return };
        let Ok(name) = CString::new(name.replace('\0', " ")) else { return };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name).color(color.rgba());
        // SAFETY: the caller guarantees `cmd` is recording.
        unsafe { utils.cmd_begin_debug_utils_label(cmd, &label) };
    }

    /// Closes the innermost label region opened by [`Device::cmd_begin_label`].
    ///
    /// # Safety
    /// `cmd` is recording and has an open label region.
    pub(crate) unsafe fn cmd_end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(utils) = &self.debug_utils {
            // SAFETY: the caller guarantees a matching begin in `cmd`.
            unsafe { utils.cmd_end_debug_utils_label(cmd) };
        }
    }
}
