//! grainlab-core: a 2D disk discrete element engine (no Python in it).
//!
//! The [`pipeline::Simulation`] owns the state and runs whole blocks of steps;
//! see `pipeline/` for the step order and `law/` for the contact law and its sub-models.
#![warn(missing_docs)]

pub mod analysis;
pub mod body;
pub mod bond;
pub mod boundary;
pub mod cell;
pub mod cement;
pub mod contact;
pub mod contact_list;
pub mod diagnostics;
pub mod error;
pub mod integrate;
mod integrate_lanes;
pub mod law;
pub mod material;
pub mod neighbor;
pub mod parallel;
pub mod pipeline;
mod simd;
pub mod state;
pub mod vec2;
pub mod wall;

pub use cell::PeriodicCell;
pub use error::{EngineError, Result};
pub use material::{ContactLaw, ContactModel};
pub use pipeline::{BodySpec, Simulation, StepParameters};
pub use state::Particles;
pub use wall::{ServoControl, Wall, WallControl, WallShape};

/// Version of the engine crate.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
