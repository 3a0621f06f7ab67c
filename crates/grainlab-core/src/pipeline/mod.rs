//! The simulation and its step, in this order (ARCHITECTURE.md repeats it):
//!
//! 1. **Neighbours**: rebuild the Verlet lists if a contact could otherwise be
//!    missed (wraps particles into the periodic cell, carries contact history over).
//! 2. **Reset**: follower loads of the pressure chains at the current positions;
//!    resultant = external force + gravity + follower load, per stripe of particles.
//! 3. **Particle contacts**: each pair's contact law (linear or Hertz-Mindlin, `law/`),
//!    stripes in parallel, then the cross-stripe pairs. The shear increment is the
//!    displacement since the last force evaluation: none on a step that starts
//!    from full-step velocities (see [`Simulation::catch_up_shear_springs`]).
//! 4. **Bonds**: linear normal and shear springs that carry tension (permanent
//!    bonds), then the cement bonds ([`crate::cement`]), which act beside the
//!    contact law and break at the evaluation where their stress reaches their
//!    strength; the broken ones are logged, booked and removed in bond order
//!    after the integration (8).
//! 5. **Wall contacts**: the same law against walls; walls sum their force.
//!    With a team the forces of 4 and 5 wait in slots, and each stripe's
//!    integration (7) adds its own particles' in the same order (`deferred.rs`).
//! 6. **Servo**: servo-controlled walls set their velocity from this step's force.
//! 7. **Integrate**: leapfrog with local damping, stripe by stripe in parallel; the
//!    periodic cell's affine map is applied to positions; displacements since
//!    the last build are tracked.
//! 8. **Move and book**: walls translate, the cell deforms, the largest
//!    displacements are tracked for the rebuild criterion, the energy ledger
//!    books the step's dissipation and work, a measured step records its
//!    measurements, time advances; the lists are rebuilt if needed, so that
//!    queries between steps see every contact.
//! 9. **Checks**: non-finite state or an overlap beyond the allowed fraction of
//!    the smaller radius stops the run with an error naming the particles.
//!
//! The code follows that split: [`simulation`] holds the state, its setters
//! (every one in the user's particle order, keeping the contact history in
//! step) and queries; `step.rs` the step as a list of named stages;
//! `pair_kernel.rs` the contact law over the pair lists, the reset and the
//! particle-wall contact; `pair_lanes.rs` its undamped loop four pairs at a
//! time (AVX2, the same bits); `deferred.rs` the bond and wall forces added
//! stripe by stripe; `checks.rs` the consistency checks and the errors
//! of an unstable run. The bond law is in [`crate::bond`], the nearest image
//! in [`crate::cell`].
mod bodies;
mod cement_lanes;
mod cement_pass;
mod checks;
mod deferred;
mod pair_kernel;
mod pair_lanes;
pub mod simulation;
mod step;

pub use bodies::BodySpec;
pub use simulation::{Simulation, StepParameters};
