//! Argument groups several commands share: the groom a user gives
//! ([`input::InputArgs`]), the simulation knobs ([`sim::SimArgs`]) and the
//! rendered scene ([`scene::SceneArgs`]).

pub mod input;
pub mod scene;
pub mod sim;
pub mod texture;
