//! The linear contact law with incremental shear spring and Coulomb cap (paper Eq. 2-4).
//!
//! Sign conventions, for a contact between body `i` and body `j` with unit
//! normal `n` pointing from `i` to `j` and tangent `t = perp(n)`:
//! - `overlap > 0` when the bodies interpenetrate;
//! - `normal_velocity = (v_j - v_i) . n` (positive when separating);
//! - `tangential_velocity = (v_j - v_i) . t - (omega_i r_i + omega_j r_j)`,
//!   the sliding speed of `j`'s surface relative to `i`'s (Eq. 2);
//! - the force on `j` is `fn n + fs t` and on `i` its opposite; the torque on
//!   both is `-r fs` with `r` the body's radius (lever arm to the contact).
//!
//! In 2D the shear spring is one scalar along the current tangent, so carrying
//! it from step to step *is* the PFC rotation of the shear force with the contact.
use crate::material::ContactModel;

/// What the contact law returns for one contact in one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactForce {
    /// Normal force on `j` along `n` (N), >= 0 for unbonded contacts, dashpot included.
    pub normal: f64,
    /// Elastic normal force `kn * overlap` (N), which the Coulomb cap refers to.
    pub elastic_normal: f64,
    /// Shear force on `j` along `t` (N), elastic plus viscous.
    pub shear: f64,
    /// Whether the shear spring is at the Coulomb cap, `|Fs| = mu kn overlap`.
    pub sliding: bool,
    /// Energy dissipated by frictional slip this step (J).
    pub friction_dissipation: f64,
    /// Energy dissipated by the viscous dashpots this step (J).
    pub viscous_dissipation: f64,
}

/// What one update of a shear spring did; see [`shear_spring_update`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearUpdate {
    /// Whether the spring ended at the Coulomb cap.
    pub sliding: bool,
    /// Energy dissipated by the slip (J), 0 while the contact sticks.
    pub friction_dissipation: f64,
}

/// Adds the increment `-ks * v_t * increment_time` to the shear spring, then caps
/// it at `mu * elastic_normal`.
///
/// `increment_time` is the time over which `v_t` displaced the contact since the
/// spring was last updated: the time step, or 0 when no displacement happened
/// since (the first force evaluation from full-step velocities, see
/// `docs/contact-law.md`). The contact slides exactly when the updated spring is
/// at the cap, `|Fs| = mu Fn`.
#[inline(always)]
pub fn shear_spring_update(
    model: &ContactModel,
    elastic_normal: f64,
    tangential_velocity: f64,
    increment_time: f64,
    shear_spring: &mut f64,
) -> ShearUpdate {
    let trial = *shear_spring - model.shear_stiffness * tangential_velocity * increment_time;
    let cap = model.friction * elastic_normal;
    let sliding = trial.abs() >= cap;
    let mut friction_dissipation = 0.0;
    if sliding {
        let capped = cap.copysign(trial);
        // work of the mean shear force over the slip, minus the spring's energy change:
        // the exact counterpart of leapfrog's trapezoidal work
        friction_dissipation =
            0.5 * (*shear_spring + capped) * (trial - capped) / model.shear_stiffness;
        *shear_spring = capped;
    } else {
        *shear_spring = trial;
    }
    ShearUpdate {
        sliding,
        friction_dissipation,
    }
}

/// Linear spring-dashpot contact with Coulomb friction.
///
/// `shear_spring` is the contact's shear history (elastic shear force, N),
/// updated in place by [`shear_spring_update`] over `increment_time` (the time
/// step, or 0 on a step that starts from full-step velocities) and capped at
/// `mu * kn * overlap`. The dashpots act on top of the springs: the normal one
/// (clipped so that the normal force never pulls) and, while the contact
/// sticks, the shear one; `reduced_mass` (`m_i m_j / (m_i + m_j)`, or the
/// particle mass against a wall) sets them and `dt` books their dissipation.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn linear_coulomb(
    model: &ContactModel,
    overlap: f64,
    normal_velocity: f64,
    tangential_velocity: f64,
    dt: f64,
    increment_time: f64,
    reduced_mass: f64,
    shear_spring: &mut f64,
) -> ContactForce {
    linear_coulomb_with::<true>(
        model,
        overlap,
        normal_velocity,
        tangential_velocity,
        dt,
        increment_time,
        reduced_mass,
        shear_spring,
    )
}

/// [`linear_coulomb`], with the dashpots compiled out when `DASHPOTS` is false:
/// for a model whose damping ratios are both 0 the two give the same bits (the
/// dashpot terms are then skipped by [`linear_coulomb`] too), so a kernel that
/// knows no model has a dashpot calls this one without the tests.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn linear_coulomb_with<const DASHPOTS: bool>(
    model: &ContactModel,
    overlap: f64,
    normal_velocity: f64,
    tangential_velocity: f64,
    dt: f64,
    increment_time: f64,
    reduced_mass: f64,
    shear_spring: &mut f64,
) -> ContactForce {
    let elastic_normal = model.normal_stiffness * overlap;
    let mut normal = elastic_normal;
    let mut viscous_dissipation = 0.0;
    if DASHPOTS && model.normal_damping_ratio > 0.0 {
        let c_n = 2.0 * model.normal_damping_ratio * (reduced_mass * model.normal_stiffness).sqrt();
        let damped = (normal - c_n * normal_velocity).max(0.0);
        // the dashpot's force (damped - normal) opposes the normal velocity; the
        // energy it takes out of the system is its negative power
        viscous_dissipation += (normal - damped) * normal_velocity * dt;
        normal = damped;
    }
    let update = shear_spring_update(
        model,
        elastic_normal,
        tangential_velocity,
        increment_time,
        shear_spring,
    );
    let mut shear = *shear_spring;
    if DASHPOTS && !update.sliding && model.shear_damping_ratio > 0.0 {
        let c_s = 2.0 * model.shear_damping_ratio * (reduced_mass * model.shear_stiffness).sqrt();
        shear -= c_s * tangential_velocity;
        viscous_dissipation += c_s * tangential_velocity * tangential_velocity * dt;
    }
    ContactForce {
        normal,
        elastic_normal,
        shear,
        sliding: update.sliding,
        friction_dissipation: update.friction_dissipation,
        viscous_dissipation,
    }
}

/// Elastic energy stored in a contact with normal force `normal` and shear spring `shear` (J).
#[inline(always)]
pub fn elastic_energy(model: &ContactModel, normal: f64, shear: f64) -> f64 {
    0.5 * normal * normal / model.normal_stiffness + 0.5 * shear * shear / model.shear_stiffness
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(mu: f64) -> ContactModel {
        ContactModel::linear(1.0e6, 5.0e5, mu)
    }

    #[test]
    fn normal_force_is_stiffness_times_overlap() {
        let mut s = 0.0;
        let f = linear_coulomb(&model(0.5), 2.0e-6, 0.0, 0.0, 1e-5, 1e-5, 1.0, &mut s);
        assert_eq!(f.normal, 2.0);
        assert_eq!(f.shear, 0.0);
        assert!(!f.sliding);
    }

    #[test]
    fn shear_spring_increments_then_caps_at_coulomb() {
        let m = model(0.5);
        let mut s = 0.0;
        // one step of tangential motion: Fs = -ks * v_t * dt = -5e5 * 1 * 1e-6 = -0.5 N
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 0.5).abs() < 1e-12 && !f.sliding);
        // a little more motion stays below the cap mu * Fn = 0.5 * 2 = 1.0 N: elastic
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 0.9, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 0.95).abs() < 1e-12 && !f.sliding);
        // the trial -1.45 N exceeds the cap: the spring stays at the cap, the contact slides
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 1.0).abs() < 1e-12 && f.sliding, "{f:?}");
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!(f.sliding);
        assert_eq!(f.shear, -1.0);
        assert_eq!(s, -1.0);
        // dissipation = mean force (-1 N) times slip (-0.5 N / ks) in steady sliding
        assert!((f.friction_dissipation - 1.0 * 0.5 / 5.0e5).abs() < 1e-18);
        // at the onset the mean force is (-1.0 + -1.0)/2 ... from a spring at -0.75 N
        s = -0.75;
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        let slip = (-1.25f64 + 1.0) / 5.0e5;
        assert!((f.friction_dissipation - 0.5 * (-0.75 - 1.0) * slip).abs() < 1e-18);
    }

    #[test]
    fn normal_dashpot_never_pulls() {
        let mut m = model(0.0);
        m.normal_damping_ratio = 1.0;
        let mut s = 0.0;
        // separating fast: the dashpot would make the force attractive; it is clipped to 0
        let f = linear_coulomb(&m, 1.0e-9, 10.0, 0.0, 1e-6, 1e-6, 1.0, &mut s);
        assert_eq!(f.normal, 0.0);
    }

    #[test]
    fn normal_dashpot_dissipates_its_power() {
        let mut m = model(0.0);
        m.normal_damping_ratio = 0.3;
        let (mass, vn, dt) = (2.0, -0.4, 1e-6);
        let c_n = 2.0 * 0.3 * (mass * m.normal_stiffness).sqrt();
        let mut s = 0.0;
        // approaching: the dashpot pushes harder and takes c_n vn^2 dt out of the system
        let f = linear_coulomb(&m, 1.0e-3, vn, 0.0, dt, dt, mass, &mut s);
        assert!((f.normal - (1000.0 - c_n * vn)).abs() < 1e-9);
        assert!((f.viscous_dissipation - c_n * vn * vn * dt).abs() < 1e-15);
        // separating: the dashpot holds back and still dissipates c_n vn^2 dt
        let f = linear_coulomb(&m, 1.0e-3, -vn, 0.0, dt, dt, mass, &mut s);
        assert!(f.normal < 1000.0 && f.normal > 0.0);
        assert!((f.viscous_dissipation - c_n * vn * vn * dt).abs() < 1e-15);
        // clipped at zero (no pull): it takes out the work of the spring force it removed
        let f = linear_coulomb(&m, 1.0e-6, -vn, 0.0, dt, dt, mass, &mut s);
        assert_eq!(f.normal, 0.0);
        assert!((f.viscous_dissipation - 1.0 * -vn * dt).abs() < 1e-18);
    }

    #[test]
    fn no_increment_time_leaves_the_spring_and_a_spring_at_the_cap_slides() {
        let m = model(0.5);
        // a spring strictly inside the cap is left as it is, whatever the velocity
        let mut s = 0.3;
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 7.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!(
            (s, f.shear, f.sliding, f.friction_dissipation),
            (0.3, 0.3, false, 0.0)
        );
        // exactly at the cap: sliding (|Fs| = mu Fn), no slip and no dissipation
        let mut s = -1.0;
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 7.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!((s, f.sliding, f.friction_dissipation), (-1.0, true, 0.0));
        // a smaller overlap than the spring was made for caps it again and dissipates
        let f = linear_coulomb(&m, 1.0e-6, 0.0, 0.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!((s, f.sliding), (-0.5, true));
        assert!((f.friction_dissipation - 0.5 * (-1.5) * (-0.5) / 5.0e5).abs() < 1e-18);
    }

    #[test]
    fn the_cap_is_mu_times_the_elastic_normal_force_with_a_normal_dashpot() {
        let mut m = model(0.5);
        m.normal_damping_ratio = 0.5;
        let mut s = 0.0;
        // approaching fast: the dashpot adds to the normal force, the cap stays mu kn overlap
        let f = linear_coulomb(&m, 2.0e-6, -1.0, 10.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!(f.normal > f.elastic_normal);
        assert_eq!(f.elastic_normal, 2.0);
        assert!(f.sliding && s == -1.0, "{f:?}");
    }
}
