//! Tangential sub-models: the shear force's history and its Coulomb cap.
use super::{ShearState, SubModel, TangentialModel};
use crate::diagnostics::ContactDissipation;
use crate::material::ContactModel;

/// The incremental shear spring with a Coulomb cap (paper Eq. 2, 4): one value
/// of history, the spring `Fs` (N) along the current tangent. Each update adds
/// `-ks v_t increment_time` and caps the result at `mu * elastic_normal`; the
/// contact slides exactly when the spring ends at the cap, and the slip's work
/// is the ledger's `friction` entry ([`ShearSpring::slip_work`]).
#[derive(Debug, Clone, Copy)]
pub struct ShearSpring;

impl SubModel for ShearSpring {
    const NAME: &'static str = "incremental shear spring with Coulomb cap";
    const HISTORY: usize = 1;
    const LANES: bool = true;
}

impl ShearSpring {
    /// The energy dissipated by a slip from the spring `before` through the
    /// uncapped `trial` to the `capped` spring: the work of the mean shear
    /// force over the slip minus the spring's energy change, the exact
    /// counterpart of leapfrog's trapezoidal work. The four-pair lanes book
    /// their slips with it too.
    #[inline(always)]
    pub fn slip_work(model: &ContactModel, before: f64, trial: f64, capped: f64) -> f64 {
        0.5 * (before + capped) * (trial - capped) / model.shear_stiffness
    }
}

impl TangentialModel for ShearSpring {
    #[inline(always)]
    fn update(
        model: &ContactModel,
        elastic_normal: f64,
        tangential_velocity: f64,
        increment_time: f64,
        history: &mut [f64],
        dissipation: &mut ContactDissipation,
    ) -> ShearState {
        let spring = &mut history[0];
        let trial = *spring - model.shear_stiffness * tangential_velocity * increment_time;
        let cap = model.friction * elastic_normal;
        let sliding = trial.abs() >= cap;
        if sliding {
            let capped = cap.copysign(trial);
            dissipation.friction += Self::slip_work(model, *spring, trial, capped);
            *spring = capped;
        } else {
            *spring = trial;
        }
        ShearState {
            spring: *spring,
            sliding,
        }
    }
}
