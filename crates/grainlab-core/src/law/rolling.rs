//! Rolling sub-models: a torque resisting the relative rolling of the two bodies.
use super::real::Real;
use super::tangential::CappedUpdate;
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

/// One update of the rolling sub-model, for one contact or four lanes
/// ([`RollingSpring::advance`]).
#[derive(Debug, Clone, Copy)]
pub struct RollingUpdate<R: Real> {
    /// The rolling stiffness `k_r` (N m/rad).
    pub stiffness: R,
    /// The rolling spring's update and cap (N m).
    pub spring: CappedUpdate<R>,
    /// The spring's elastic energy `M_r^2 / (2 k_r)` (J).
    pub energy: R,
    /// The moment on `j`: the spring, with the dashpot on top where it acts (N m).
    pub moment: R,
    /// Where the dashpot acts: below the cap, `eta_r > 0`.
    pub damped: R::Mask,
    /// The dashpot's power `c_r w^2 dt` where it acts (J; +0 elsewhere, and
    /// everywhere without `DASHPOT`).
    pub power: R,
}

impl RollingSpring {
    /// The contact's effective radius `R*` (m): `r_i r_j / (r_i + r_j)`, or
    /// `r_j` against a wall (`r_i` = 0).
    #[inline(always)]
    pub fn effective_radius(kinematics: &ContactKinematics) -> f64 {
        Self::effective_radius_of(kinematics.radius_i, kinematics.radius_j)
    }

    /// [`RollingSpring::effective_radius`] of the radii, for one contact or four lanes.
    #[inline(always)]
    pub fn effective_radius_of<R: Real>(radius_i: R, radius_j: R) -> R {
        R::select(
            radius_i.eq(R::splat(0.0)),
            radius_j,
            radius_i * radius_j / (radius_i + radius_j),
        )
    }

    /// The rolling stiffness `k_r` (N m/rad) of `model` at a contact of
    /// effective radius `r_star` and normal tangent stiffness `normal_stiffness`
    /// (the law's `k_n`): the given one, or the rule `2.25 k_n mu_r^2 R*^2`.
    #[inline(always)]
    pub fn stiffness(model: &ContactModel, normal_stiffness: f64, r_star: f64) -> f64 {
        Self::stiffness_of(
            model.rolling_stiffness,
            model.rolling_friction,
            normal_stiffness,
            r_star,
        )
    }

    /// [`RollingSpring::stiffness`] from the `given` stiffness (0: the rule)
    /// and `mu_r`, for one contact or four lanes.
    #[inline(always)]
    pub fn stiffness_of<R: Real>(given: R, mu_r: R, normal_stiffness: R, r_star: R) -> R {
        let rule = R::splat(2.25) * normal_stiffness * mu_r * mu_r * r_star * r_star;
        R::select(given.gt(R::splat(0.0)), given, rule)
    }

    /// The energy dissipated by a plastic update from the spring `before`
    /// through the uncapped `trial` to the `capped` spring, as
    /// [`super::tangential::ShearSpring::slip_work`]: the mean moment times the
    /// plastic rotation `(trial - capped) / k_r`.
    #[inline(always)]
    pub fn plastic_work(stiffness: f64, before: f64, trial: f64, capped: f64) -> f64 {
        0.5 * (before + capped) * (trial - capped) / stiffness
    }

    /// The sub-model's update, for one contact or four lanes: `k_r`, the spring
    /// `spring - k_r w increment_time` capped at `mu_r R* F_n`, its energy and,
    /// with `DASHPOT` (compiled out without), the dashpot below the cap. The
    /// contact's `mu_r` is not 0 (the scalar law returns before; the lanes
    /// mask such pairs out).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn advance<R: Real, const DASHPOT: bool>(
        mu_r: R,
        given_stiffness: R,
        damping_ratio: R,
        normal_stiffness: R,
        r_star: R,
        elastic_normal: R,
        rolling_velocity: R,
        rolling_inertia: R,
        increment_time: R,
        dt: R,
        spring: R,
    ) -> RollingUpdate<R> {
        let k_r = Self::stiffness_of(given_stiffness, mu_r, normal_stiffness, r_star);
        let w = rolling_velocity;
        let update = CappedUpdate::of(
            spring,
            k_r * w * increment_time,
            mu_r * r_star * elastic_normal,
        );
        let energy = R::splat(0.5) * update.spring * update.spring / k_r;
        let damped = R::and(R::not(update.at_cap), damping_ratio.gt(R::splat(0.0)));
        let (mut moment, mut power) = (update.spring, R::splat(0.0));
        if DASHPOT {
            let c_r = R::splat(2.0) * damping_ratio * (rolling_inertia * k_r).sqrt();
            let c_r_w = c_r * w;
            moment = R::select(damped, moment - c_r_w, moment);
            power = R::select(damped, c_r_w * w * dt, power);
        }
        RollingUpdate {
            stiffness: k_r,
            spring: update,
            energy,
            moment,
            damped,
            power,
        }
    }

    /// The torques on `i` and `j` with the rolling `moment` on `j` (and its
    /// opposite on `i`) added.
    #[inline(always)]
    pub fn with_moment<R: Real>(torque_i: R, torque_j: R, moment: R) -> (R, R) {
        (torque_i - moment, torque_j + moment)
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
        if model.rolling_friction == 0.0 {
            return;
        }
        let r_star = Self::effective_radius(kinematics);
        // the dashpot's terms compiled in only for a model that has one
        macro_rules! advance {
            ($dashpot:literal) => {
                Self::advance::<f64, $dashpot>(
                    model.rolling_friction,
                    model.rolling_stiffness,
                    model.rolling_damping_ratio,
                    force.normal_stiffness,
                    r_star,
                    force.elastic_normal,
                    kinematics.rolling_velocity,
                    kinematics.rolling_inertia,
                    increment_time,
                    dt,
                    history[0],
                )
            };
        }
        let update = if model.rolling_damping_ratio > 0.0 {
            advance!(true)
        } else {
            advance!(false)
        };
        let spring = update.spring;
        if spring.at_cap {
            force.dissipation.rolling +=
                Self::plastic_work(update.stiffness, history[0], spring.trial, spring.capped);
        } else if update.damped {
            force.dissipation.rolling += update.power;
        }
        history[0] = spring.spring;
        force.rolling_spring = spring.spring;
        force.rolling_energy = update.energy;
        force.rolling_moment = update.moment;
        (force.torque_i, force.torque_j) =
            Self::with_moment(force.torque_i, force.torque_j, update.moment);
    }
}
