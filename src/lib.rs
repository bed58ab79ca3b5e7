//! # vkhair — real-time strand hair for Vulkan renderers
//!
//! `vkhair` simulates key hairs (guide strands) on the GPU and renders a full
//! head of hair from them, recording its work into a host renderer's command
//! buffers. It is written against raw Vulkan through `ash`; shaders are GLSL
//! compiled at build time and their interfaces are checked against the Rust
//! side by SPIR-V reflection.
//!
//! ## Layers
//!
//! - `vk` (crate-private): thin wrappers over ash — device record, buffers,
//!   images, staging, barriers, reflection, pipelines, debug names and labels.
//! - [`render`]: drawing hair from the simulated key hairs ([`render::Renderer`]).
//! - [`sim`]: the GPU simulation ([`sim::HairSim`]) and its CPU reference.
//! - [`crowd`]: many characters' key hairs in one simulation, drawn by one
//!   renderer ([`crowd::Crowd`]).
//! - [`schedule`]: where the simulation runs — in order on one queue, on an async
//!   compute queue, or on a second device with a worker thread — and the per-frame
//!   hand-off to rendering ([`schedule::FrameScheduler`]).
//! - [`groom`]: key-hair data — the [`Groom`] type, `.hair` and `.tfx` files,
//!   procedural growth from a scalp, resampling and key-hair selection.
//! - The public GPU API: [`GpuContext`] (owned headless device, or borrowed from a
//!   host through [`GpuContext::from_host`]), [`requirements()`] (what the host
//!   must enable), [`GpuProfiler`] (per-pass GPU timings) and [`ValidationLog`].
//!
//! ## Embedding
//!
//! A host creates its device with everything [`requirements()`] lists, wraps it
//! with the `unsafe` [`GpuContext::from_host`] (nothing the host owns is ever
//! destroyed by vkhair), and records vkhair's passes into its own command buffers.
//! A headless context ([`GpuContext::headless`]) owns its instance and device and
//! is what tools and tests use; on machines without a GPU it runs on lavapipe.
//! [`headless`] stands in for the rest of a host (submission, an offscreen
//! target); `examples/embed_minimal/` shows a host that owns everything.
//!
//! ## A frame, headless
//!
//! Key hairs grown on the thesis scalp are simulated for one step and drawn
//! into an offscreen target; validation is on and must stay silent.
//!
//! ```
//! use glam::Vec3;
//! use vkhair::headless::{Offscreen, Submit};
//! use vkhair::render::{Camera, Light, RenderParams, Renderer};
//! use vkhair::sim::{HairSim, RigidTransform, SimParams};
//! use vkhair::{groom, ContextOptions, GpuContext, ValidationLog};
//!
//! let log = ValidationLog::new();
//! {
//!     let ctx = GpuContext::headless(&ContextOptions::validated(&log))?;
//!     let params = groom::grow::GrowParams { strands: 64, points_per_strand: 6, ..Default::default() };
//!     let groom = groom::grow::grow(&groom::scenes::thesis_scalp(), &params)?;
//!     let head = RigidTransform::default();
//!     let mut sim = HairSim::new(&ctx, &groom, &SimParams::default(), &head)?;
//!     let mut renderer = Renderer::new(&ctx, &sim, &RenderParams::default())?;
//!     renderer.set_lights(&[Light::Directional { direction: Vec3::NEG_Y, color: Vec3::ONE }])?;
//!     let target = Offscreen::new(&ctx, 64, 64)?;
//!     let eye = Vec3::new(0.0, 1.6, 0.6);
//!     let camera = Camera::look_at(eye, Vec3::new(0.0, 1.6, 0.0), 0.8, 1.0, 0.01, 10.0)?;
//!     let mut result = Ok(());
//!     ctx.run_commands("frame", |cmd| {
//!         // SAFETY: a recording command buffer of `ctx`'s device; everything
//!         // recorded belongs to it, and the frame is waited for before reuse.
//!         result = unsafe {
//!             target.record_clear(cmd, Vec3::ZERO);
//!             sim.record_step(cmd, &head, None)
//!                 .and_then(|_| renderer.record_prepare(cmd, &sim, Some(&camera), None))
//!                 .and_then(|_| renderer.record_shadows(cmd, &sim, None))
//!                 .and_then(|_| renderer.record_draw(cmd, 0, &target.target(), &camera, None))
//!         };
//!     })?;
//!     result?;
//!     let pixels = target.read_rgba8()?;
//!     assert!(pixels.chunks(4).any(|p| p[0] > 0), "hair was drawn");
//! }
//! log.assert_clean(); // after everything was dropped: no message, no leak
//! # Ok::<(), vkhair::Error>(())
//! ```

#![deny(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod character;
pub(crate) mod codes;
pub mod config;
mod context;
pub mod crowd;
mod error;
pub mod files;
pub(crate) mod gpu_types;
pub mod groom;
mod hash;
pub mod headless;
pub(crate) mod limits;
mod profiler;
pub mod render;
mod requirements;
pub mod schedule;
pub mod sim;
pub(crate) mod vk;

pub use context::{
    list_devices, ContextOptions, DeviceReport, GpuContext, HostDevice, HostQueue, DEVICE_ENV, VALIDATION_ENV,
};
pub use error::{Error, FileFormat, Result};
pub use groom::Groom;
pub use profiler::{Clock, GpuProfiler, PassTiming, ProfileReport, ScopeId};
pub use requirements::{requirements, RequiredFeatures, Requirements, API_VERSION};
pub use vk::counters::{DispatchRecord, RecordedWork};
pub use vk::device::DeviceInfo;
pub use vk::validation::{Severity, ValidationLog, ValidationMessage};

/// Re-export of the `ash` crate vkhair's public API is written against.
pub use ash;
/// Re-export of the `gpu_allocator` crate whose allocator a host may share.
pub use gpu_allocator;
