//! grainlab-core: a 2D disk discrete element engine.
#![warn(missing_docs)]

/// Version of the engine crate.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
