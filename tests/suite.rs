//! The integration tests of the crate, one module per file beside this one
//! (`tests/sim.rs` is `sim::…`), built as one test binary: one link instead of
//! one per file, and tests from every file run side by side. Run one file's
//! tests with `cargo test --test suite sim::`.

#[path = "alembic.rs"]
mod alembic;
#[path = "asset_mutations.rs"]
mod asset_mutations;
#[path = "body.rs"]
mod body;
mod common;
#[path = "context.rs"]
mod context;
#[path = "crowd.rs"]
mod crowd;
#[path = "embed_example.rs"]
mod embed_example;
#[path = "followers.rs"]
mod followers;
#[path = "groom_files.rs"]
mod groom_files;
#[path = "grow.rs"]
mod grow;
#[path = "host_frame.rs"]
mod host_frame;
#[path = "interpolation.rs"]
mod interpolation;
#[path = "layers.rs"]
mod layers;
#[path = "mesh_collider.rs"]
mod mesh_collider;
#[path = "motion.rs"]
mod motion;
#[path = "params_walk.rs"]
mod params_walk;
#[path = "presets.rs"]
mod presets;
#[path = "reader_fuzz.rs"]
mod reader_fuzz;
#[path = "render.rs"]
mod render;
#[path = "scalp.rs"]
mod scalp;
#[path = "schedule.rs"]
mod schedule;
#[path = "sdf.rs"]
mod sdf;
#[path = "sim.rs"]
mod sim;
#[path = "skinned_collider.rs"]
mod skinned_collider;
#[path = "teleport.rs"]
mod teleport;
#[path = "transparency.rs"]
mod transparency;
#[path = "usd.rs"]
mod usd;
#[path = "viewer.rs"]
mod viewer;
#[path = "volume.rs"]
mod volume;
