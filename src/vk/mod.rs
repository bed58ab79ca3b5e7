//! Thin, crate-private wrappers over ash: the device record, buffers, images,
//! staging, barriers, reflection, pipelines and debug names/labels.
//!
//! Parts of this layer exist for the simulation and render stages built on it;
//! until every part has a caller, unused items are allowed here.
#![allow(dead_code)]

pub(crate) mod barrier;
pub(crate) mod buffer;
pub(crate) mod debug;
pub(crate) mod device;
pub(crate) mod image;
pub(crate) mod pipeline;
pub(crate) mod reflect;
pub(crate) mod shaders;
pub(crate) mod staging;

#[cfg(test)]
mod tests;
