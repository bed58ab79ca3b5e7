//! One folder per command; no command imports another (`tests/layers.rs`
//! checks), what several need lives in `args/`, `scene/` and the files beside
//! `commands/`.

pub mod bench;
pub mod config;
pub mod convert;
pub mod devices;
pub mod grow;
pub mod inspect;
pub mod plot;
pub mod render;
pub mod simulate;
