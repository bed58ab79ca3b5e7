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

#![deny(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

mod context;
mod error;
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
pub use vk::debug::{Severity, ValidationLog, ValidationMessage};
pub use vk::device::DeviceInfo;

/// Re-export of the `ash` crate vkhair's public API is written against.
pub use ash;
/// Re-export of the `gpu_allocator` crate whose allocator a host may share.
pub use gpu_allocator;
