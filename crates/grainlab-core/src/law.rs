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
    /// Normal force on `j` along `n` (N), >= 0 for unbonded contacts.
    pub normal: f64,
    /// Shear force on `j` along `t` (N), elastic plus viscous.
    pub shear: f64,
    /// Whether the Coulomb cap was reached this step.
    pub sliding: bool,
    /// Energy dissipated by frictional slip this step (J).
    pub friction_dissipation: f64,
    /// Energy dissipated by the viscous dashpots this step (J).
    pub viscous_dissipation: f64,
}

/// Linear spring-dashpot contact with Coulomb friction.
///
/// `shear_spring` is the contact's shear history (elastic shear force, N) and
/// is updated in place: `Fs <- Fs - ks * v_t * dt`, then capped at `mu * Fn`.
/// `reduced_mass` (`m_i m_j / (m_i + m_j)`, or the particle mass against a wall)
/// is used only by the viscous dashpots.
#[inline(always)]
pub fn linear_coulomb(
    model: &ContactModel,
    overlap: f64,
    normal_velocity: f64,
    tangential_velocity: f64,
    dt: f64,
    reduced_mass: f64,
    shear_spring: &mut f64,
) -> ContactForce {
    let mut normal = model.normal_stiffness * overlap;
    let mut viscous_dissipation = 0.0;
    if model.normal_damping_ratio > 0.0 {
        let c_n = 2.0 * model.normal_damping_ratio * (reduced_mass * model.normal_stiffness).sqrt();
        let damped = (normal - c_n * normal_velocity).max(0.0);
        // the dashpot's force (damped - normal) opposes the normal velocity; the
        // energy it takes out of the system is its negative power
        viscous_dissipation += (normal - damped) * normal_velocity * dt;
        normal = damped;
    }
    let trial = *shear_spring - model.shear_stiffness * tangential_velocity * dt;
    let cap = model.friction * normal;
    let mut friction_dissipation = 0.0;
    let sliding = trial.abs() > cap;
    let elastic = if sliding {
        let capped = cap.copysign(trial);
        // work of the mean shear force over the slip, minus the spring's energy change:
        // the exact counterpart of leapfrog's trapezoidal work
        friction_dissipation =
            0.5 * (*shear_spring + capped) * (trial - capped) / model.shear_stiffness;
        capped
    } else {
        trial
    };
    *shear_spring = elastic;
    let mut shear = elastic;
    if !sliding && model.shear_damping_ratio > 0.0 {
        let c_s = 2.0 * model.shear_damping_ratio * (reduced_mass * model.shear_stiffness).sqrt();
        shear -= c_s * tangential_velocity;
        viscous_dissipation += c_s * tangential_velocity * tangential_velocity * dt;
    }
    ContactForce {
        normal,
        shear,
        sliding,
        friction_dissipation,
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
        let f = linear_coulomb(&model(0.5), 2.0e-6, 0.0, 0.0, 1e-5, 1.0, &mut s);
        assert_eq!(f.normal, 2.0);
        assert_eq!(f.shear, 0.0);
        assert!(!f.sliding);
    }

    #[test]
    fn shear_spring_increments_then_caps_at_coulomb() {
        let m = model(0.5);
        let mut s = 0.0;
        // one step of tangential motion: Fs = -ks * v_t * dt = -5e5 * 1 * 1e-6 = -0.5 N
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1.0, &mut s);
        assert!((f.shear + 0.5).abs() < 1e-12 && !f.sliding);
        // further motion would reach -1.0 N, above mu * Fn = 1.0? cap is 0.5*2 = 1.0: still elastic
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1.0, &mut s);
        assert!((f.shear + 1.0).abs() < 1e-12 && !f.sliding);
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1.0, &mut s);
        assert!(f.sliding);
        assert_eq!(f.shear, -1.0);
        assert_eq!(s, -1.0);
        // dissipation = mean force (-1 N) times slip (-0.5 N / ks) in steady sliding
        assert!((f.friction_dissipation - 1.0 * 0.5 / 5.0e5).abs() < 1e-18);
        // at the onset the mean force is (-1.0 + -1.0)/2 ... from a spring at -0.75 N
        s = -0.75;
        let f = linear_coulomb(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1.0, &mut s);
        let slip = (-1.25f64 + 1.0) / 5.0e5;
        assert!((f.friction_dissipation - 0.5 * (-0.75 - 1.0) * slip).abs() < 1e-18);
    }

    #[test]
    fn normal_dashpot_never_pulls() {
        let mut m = model(0.0);
        m.normal_damping_ratio = 1.0;
        let mut s = 0.0;
        // separating fast: the dashpot would make the force attractive; it is clipped to 0
        let f = linear_coulomb(&m, 1.0e-9, 10.0, 0.0, 1e-6, 1.0, &mut s);
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
        let f = linear_coulomb(&m, 1.0e-3, vn, 0.0, dt, mass, &mut s);
        assert!((f.normal - (1000.0 - c_n * vn)).abs() < 1e-9);
        assert!((f.viscous_dissipation - c_n * vn * vn * dt).abs() < 1e-15);
        // separating: the dashpot holds back and still dissipates c_n vn^2 dt
        let f = linear_coulomb(&m, 1.0e-3, -vn, 0.0, dt, mass, &mut s);
        assert!(f.normal < 1000.0 && f.normal > 0.0);
        assert!((f.viscous_dissipation - c_n * vn * vn * dt).abs() < 1e-15);
        // clipped at zero (no pull): it takes out the work of the spring force it removed
        let f = linear_coulomb(&m, 1.0e-6, -vn, 0.0, dt, mass, &mut s);
        assert_eq!(f.normal, 0.0);
        assert!((f.viscous_dissipation - 1.0 * -vn * dt).abs() < 1e-18);
    }
}
