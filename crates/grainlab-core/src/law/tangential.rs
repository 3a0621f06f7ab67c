//! Tangential sub-models: the shear force's history and its Coulomb cap.
use super::real::Real;
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

/// One update of a spring with a cap (the shear spring's, the rolling
/// spring's), for one contact or four lanes.
#[derive(Debug, Clone, Copy)]
pub struct CappedUpdate<R: Real> {
    /// The spring plus its increment, before the cap.
    pub trial: R,
    /// The cap with the trial's sign.
    pub capped: R,
    /// Where the trial reaches the cap, `|trial| >= cap`: the spring ends there.
    pub at_cap: R::Mask,
    /// The spring after the update: `capped` at the cap, else `trial`.
    pub spring: R,
}

impl<R: Real> CappedUpdate<R> {
    /// The spring `before` plus `increment`, capped at `cap`.
    #[inline(always)]
    pub fn of(before: R, increment: R, cap: R) -> Self {
        let trial = before - increment;
        let at_cap = trial.abs().ge(cap);
        let capped = cap.copysign(trial);
        CappedUpdate {
            trial,
            capped,
            at_cap,
            spring: R::select(at_cap, capped, trial),
        }
    }
}

impl ShearSpring {
    /// The spring's update, of one contact or four lanes: `spring - ks v_t
    /// increment_time`, capped at `mu * elastic_normal`.
    #[inline(always)]
    pub fn advance<R: Real>(
        shear_stiffness: R,
        friction: R,
        elastic_normal: R,
        tangential_velocity: R,
        increment_time: R,
        spring: R,
    ) -> CappedUpdate<R> {
        CappedUpdate::of(
            spring,
            shear_stiffness * tangential_velocity * increment_time,
            friction * elastic_normal,
        )
    }

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
        let update = Self::advance(
            model.shear_stiffness,
            model.friction,
            elastic_normal,
            tangential_velocity,
            increment_time,
            *spring,
        );
        if update.at_cap {
            dissipation.friction += Self::slip_work(model, *spring, update.trial, update.capped);
        }
        *spring = update.spring;
        ShearState {
            spring: update.spring,
            sliding: update.at_cap,
        }
    }
}
