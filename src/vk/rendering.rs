//! Dynamic rendering: attachments, rendering instances, viewport and scissor.

use ash::vk;

use super::device::Device;

/// What a rendering instance does with an attachment's earlier contents. The
/// contents are always stored.
#[derive(Clone, Copy)]
pub(crate) enum Load {
    /// Keep them (the host's colour and depth, a map drawn in an earlier pass).
    Keep,
    /// Clear to this value.
    Clear(vk::ClearValue),
}

impl Load {
    /// Clear colour to `rgba`.
    pub(crate) fn color(rgba: [f32; 4]) -> Load {
        Load::Clear(vk::ClearValue { color: vk::ClearColorValue { float32: rgba } })
    }

    /// Clear depth to `depth` (stencil 0).
    pub(crate) fn depth(depth: f32) -> Load {
        Load::Clear(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth, stencil: 0 } })
    }
}

/// An attachment of `view` in `layout`, loaded as `load` and stored.
fn attachment(view: vk::ImageView, layout: vk::ImageLayout, load: Load) -> vk::RenderingAttachmentInfo<'static> {
    let info = vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(layout)
        .store_op(vk::AttachmentStoreOp::STORE);
    match load {
        Load::Keep => info.load_op(vk::AttachmentLoadOp::LOAD),
        Load::Clear(value) => info.load_op(vk::AttachmentLoadOp::CLEAR).clear_value(value),
    }
}

/// A colour attachment in `COLOR_ATTACHMENT_OPTIMAL`.
pub(crate) fn color(view: vk::ImageView, load: Load) -> vk::RenderingAttachmentInfo<'static> {
    attachment(view, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, load)
}

/// A depth attachment in `DEPTH_ATTACHMENT_OPTIMAL`.
pub(crate) fn depth(view: vk::ImageView, load: Load) -> vk::RenderingAttachmentInfo<'static> {
    attachment(view, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL, load)
}

/// A one-layer rendering instance over `extent` from the origin, with `colors`
/// and an optional depth attachment.
pub(crate) fn info<'a>(
    extent: vk::Extent2D,
    colors: &'a [vk::RenderingAttachmentInfo<'a>],
    depth: Option<&'a vk::RenderingAttachmentInfo<'a>>,
) -> vk::RenderingInfo<'a> {
    let info = vk::RenderingInfo::default()
        .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
        .layer_count(1)
        .color_attachments(colors);
    match depth {
        Some(depth) => info.depth_attachment(depth),
        None => info,
    }
}

impl Device {
    /// Sets a viewport (depth 0..1) and a scissor covering `extent` from the origin.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of this device.
    pub(crate) unsafe fn cmd_set_full_viewport(&self, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.width as f32,
            height: extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: guaranteed by the caller.
        unsafe {
            self.raw.cmd_set_viewport(cmd, 0, &[viewport]);
            self.raw.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
        }
    }
}
