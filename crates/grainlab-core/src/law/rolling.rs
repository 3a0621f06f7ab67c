//! Rolling sub-models: a torque resisting the relative rolling of the two bodies.
use super::{ContactForce, ContactKinematics, RollingModel, SubModel};
use crate::material::ContactModel;

/// No rolling resistance (the paper's law): no history, no torque beyond the
/// shear force's, nothing booked in the ledger's `rolling` entry. A rolling
/// sub-model takes its place in [`crate::law::Rolling`] (docs/contact-law.md,
/// "Adding a contact sub-model").
#[derive(Debug, Clone, Copy)]
pub struct NoRolling;

impl SubModel for NoRolling {
    const NAME: &'static str = "no rolling resistance";
    const HISTORY: usize = 0;
    const LANES: bool = true;
}

impl RollingModel for NoRolling {
    #[inline(always)]
    fn apply(
        _model: &ContactModel,
        _kinematics: &ContactKinematics,
        _dt: f64,
        _increment_time: f64,
        _history: &mut [f64],
        _force: &mut ContactForce,
    ) {
    }
}
