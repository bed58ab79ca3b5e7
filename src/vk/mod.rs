//! Thin, crate-private wrappers over ash: the device record, buffers, images,
//! staging, barriers, reflection, pipelines and debug names/labels.

pub(crate) mod barrier;
pub(crate) mod buffer;
pub(crate) mod counters;
pub(crate) mod debug;
pub(crate) mod device;
pub(crate) mod external;
pub(crate) mod image;
pub(crate) mod pipeline;
pub(crate) mod reflect;
pub(crate) mod rendering;
pub(crate) mod shaders;
pub(crate) mod staging;
pub(crate) mod submit;
pub(crate) mod validation;

#[cfg(test)]
pub(crate) mod tests;
