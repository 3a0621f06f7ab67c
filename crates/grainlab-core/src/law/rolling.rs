//! Rolling sub-models: a torque resisting the relative rolling of the two bodies.
use super::{ContactForce, ContactKinematics, RollingModel, SubModel};
use crate::material::ContactModel;

/// The elastic-plastic spring-dashpot rolling law (Ai, Chen, Rotter and Ooi
/// 2011, type C; PFC's rolling linear model without its dashpot), in 2D.
///
/// One value of history: the rolling spring `M_r` (N m), the moment on body
/// `j` (its opposite on `i`). Each update adds `-k_r (omega_j - omega_i)
/// increment_time` and caps the result at `mu_r R* F_n` (`R* = r_i r_j / (r_i
/// + r_j)`, the particle's radius against a wall; `F_n` the elastic normal
/// force, as the Coulomb cap); a capped (plastic) update books its work in the
/// ledger's `rolling` entry as the shear spring books a slip. While elastic, a
/// dashpot `-eta_r 2 sqrt(I_r k_r) (omega_j - omega_i)` acts on top (not
/// stored), its power booked too. `k_r` is the model's `rolling_stiffness`,
/// or when that is 0 the Iwashita-Oda rule `2.25 k_n mu_r^2 R*^2`.
///
/// With `rolling_friction` 0 (the default) it does nothing: no torque, no
/// dissipation, its slot of the record left as it is (so the paper's law keeps
/// its bits). The four-pair lanes (`pipeline/pair_lanes.rs`, `law_by_four`)
/// evaluate it with the same bits, compiled in only for a table with rolling
/// resistance.
#[derive(Debug, Clone, Copy)]
pub struct RollingSpring;

impl SubModel for RollingSpring {
    const NAME: &'static str = "elastic-plastic rolling spring with dashpot";
    const HISTORY: usize = 1;
    /// The lanes evaluate it, its dashpot included (with rolling resistance in
    /// some model, [`crate::material::MaterialTable::rolling`]; without, they
    /// leave its slot as it is).
    const LANES: bool = true;
}

impl RollingSpring {
    /// The contact's effective radius `R*` (m): `r_i r_j / (r_i + r_j)`, or
    /// `r_j` against a wall (`r_i` = 0).
    #[inline(always)]
    pub fn effective_radius(kinematics: &ContactKinematics) -> f64 {
        let (ri, rj) = (kinematics.radius_i, kinematics.radius_j);
        if ri == 0.0 {
            rj
        } else {
            ri * rj / (ri + rj)
        }
    }

    /// The rolling stiffness `k_r` (N m/rad) of `model` at a contact of
    /// effective radius `r_star` and normal tangent stiffness `normal_stiffness`
    /// (the law's `k_n`): the given one, or the rule `2.25 k_n mu_r^2 R*^2`.
    #[inline(always)]
    pub fn stiffness(model: &ContactModel, normal_stiffness: f64, r_star: f64) -> f64 {
        if model.rolling_stiffness > 0.0 {
            model.rolling_stiffness
        } else {
            let mu_r = model.rolling_friction;
            2.25 * normal_stiffness * mu_r * mu_r * r_star * r_star
        }
    }

    /// The energy dissipated by a plastic update from the spring `before`
    /// through the uncapped `trial` to the `capped` spring, as
    /// [`super::tangential::ShearSpring::slip_work`]: the mean moment times the
    /// plastic rotation `(trial - capped) / k_r`.
    #[inline(always)]
    pub fn plastic_work(stiffness: f64, before: f64, trial: f64, capped: f64) -> f64 {
        0.5 * (before + capped) * (trial - capped) / stiffness
    }
}

impl RollingModel for RollingSpring {
    #[inline(always)]
    fn apply(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        dt: f64,
        increment_time: f64,
        history: &mut [f64],
        force: &mut ContactForce,
    ) {
        let mu_r = model.rolling_friction;
        if mu_r == 0.0 {
            return;
        }
        let r_star = Self::effective_radius(kinematics);
        let k_r = Self::stiffness(model, force.normal_stiffness, r_star);
        let w = kinematics.rolling_velocity;
        let spring = &mut history[0];
        let trial = *spring - k_r * w * increment_time;
        let cap = mu_r * r_star * force.elastic_normal;
        let plastic = trial.abs() >= cap;
        let mut moment = if plastic {
            let capped = cap.copysign(trial);
            force.dissipation.rolling += Self::plastic_work(k_r, *spring, trial, capped);
            capped
        } else {
            trial
        };
        *spring = moment;
        force.rolling_spring = moment;
        force.rolling_energy = 0.5 * moment * moment / k_r;
        if !plastic && model.rolling_damping_ratio > 0.0 {
            let c_r = 2.0 * model.rolling_damping_ratio * (kinematics.rolling_inertia * k_r).sqrt();
            moment -= c_r * w;
            force.dissipation.rolling += c_r * w * w * dt;
        }
        force.rolling_moment = moment;
        force.torque_i -= moment;
        force.torque_j += moment;
    }
}
