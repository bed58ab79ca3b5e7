//! What tools, tests and examples use to stand in for a host.
//!
//! A real host records vkhair's passes into its own command buffers, submits
//! them with its own synchronisation and draws into its own images. Without a
//! host, these helpers do that part:
//!
//! - [`Submit`]: record into a fresh command buffer, submit to the context's
//!   graphics queue and wait ([`Submit::run_commands`], [`Submit::run_frame`]);
//! - [`Offscreen`]: a colour + depth target in place of a swapchain image,
//!   read back as RGBA8;
//! - [`MeshDrawer`]: the head mesh drawn the way a host draws its geometry,
//!   optionally shadowed by the hair;
//! - [`HostBuffer`]: a storage buffer filled from the CPU in place of a
//!   host's GPU buffer (skinned scalp vertices);
//! - [`coverage`]: how much of a region of the picture (a character's face)
//!   the hair hides.
//!
//! ```
//! use vkhair::headless::{Offscreen, Submit};
//! use vkhair::{ContextOptions, GpuContext, ValidationLog};
//!
//! let log = ValidationLog::new();
//! {
//!     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
//!     let target = Offscreen::new(&ctx, 64, 64)?;
//!     ctx.run_commands("clear", |cmd| {
//!         // SAFETY: a recording command buffer of the context's device.
//!         unsafe { target.record_clear(cmd, glam::Vec3::new(0.0, 1.0, 0.0)) }
//!     })?;
//!     let pixels = target.read_rgba8()?;
//!     assert_eq!(pixels.len(), 64 * 64 * 4);
//!     assert_eq!(&pixels[..4], &[0, 255, 0, 255]);
//! }
//! log.assert_clean();
//! # Ok::<(), vkhair::Error>(())
//! ```

pub mod coverage;
mod host_buffer;
mod mesh;
mod offscreen;
mod texels;

use ash::vk;

pub use host_buffer::HostBuffer;
pub use mesh::MeshDrawer;
pub use offscreen::{Offscreen, OFFSCREEN_COLOR, OFFSCREEN_COLOR_FORMATS, OFFSCREEN_DEPTH};

use crate::context::GpuContext;
use crate::error::Result;
use crate::schedule::FrameSync;

/// Submit-and-wait on a context's graphics queue, for code without a host.
pub trait Submit {
    /// Records `record` into a fresh command buffer, submits it to the graphics
    /// queue and waits.
    fn run_commands(&self, name: &str, record: impl FnOnce(vk::CommandBuffer)) -> Result<()>;

    /// Records one frame into a fresh command buffer — `record` returns what the
    /// submission must wait on ([`crate::schedule::FrameScheduler::record_frame`]'s
    /// [`FrameSync`]) — submits it to the graphics queue with those waits and waits
    /// for it.
    fn run_frame(&self, name: &str, record: impl FnOnce(vk::CommandBuffer) -> Result<FrameSync>) -> Result<()>;

    /// Waits until the graphics queue is idle.
    fn wait_idle(&self) -> Result<()>;
}

impl Submit for GpuContext {
    fn run_commands(&self, name: &str, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        self.device.submit_once(name, record)
    }

    fn run_frame(&self, name: &str, record: impl FnOnce(vk::CommandBuffer) -> Result<FrameSync>) -> Result<()> {
        let mut result = Ok(());
        self.device.submit_once_waiting(name, |cmd| match record(cmd) {
            Ok(sync) => sync.wait_infos(),
            Err(e) => {
                result = Err(e);
                Vec::new()
            }
        })?;
        result
    }

    fn wait_idle(&self) -> Result<()> {
        self.device.wait_idle()
    }
}
