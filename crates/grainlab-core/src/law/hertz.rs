//! Hertz-Mindlin: the second contact law, chosen per pair of material groups
//! ([`crate::material::ContactLaw::HertzMindlin`]).
//!
//! The sphere law applied to disks, as LAMMPS's `pair granular hertz/material E
//! damping nu tangential mindlin NULL 0 mu` with `damping coeff_restitution`
//! computes it (docs/contact-law.md, "Hertz-Mindlin"):
//! with `E* = E / (2 (1 - nu^2))`, `G* = E / (4 (2 - nu) (1 + nu))` (two grains
//! of one material, or a grain and a wall of it), `R*` the effective radius
//! and `a = sqrt(R* delta)` the contact radius,
//! - normal: `F_ne = 4/3 E* a delta`, tangent stiffness `S_n = 2 E* a`;
//! - damping: `-eta_n v_n` with `eta_n = d(e) sqrt(m* F_ne / delta)`,
//!   `d(e) = -sqrt(5) ln e / sqrt(pi^2 + ln^2 e)`, not clipped (LAMMPS's default);
//! - tangential: the tangential displacement `xi` is the history (m), the
//!   elastic force `-k_t xi` with `k_t = 8 G* a`, capped at `mu |F_n|` (the
//!   normal force with its dashpot), `xi` rescaled to the cap when the contact
//!   slides; no tangential dashpot; the torques' lever arms `r - delta/2`
//!   between grains, `r` against a wall, as LAMMPS takes them;
//! - rolling: the rolling sub-model as for the linear law, its stiffness rule
//!   from the tangent normal stiffness `S_n`.
use std::f64::consts::PI;

use super::rolling::RollingSpring;
use super::{
    shear_torques, with_rolling, ContactForce, ContactKinematics, ContactRecord, TANGENTIAL_HISTORY,
};
use crate::diagnostics::ContactDissipation;
use crate::material::ContactModel;

/// `(E*, G*)` of the pair (Pa): two grains of the model's material, as LAMMPS
/// mixes them (`mix_stiffnessE`, `mix_stiffnessG`; the same against a wall).
#[inline(always)]
pub fn effective_moduli(model: &ContactModel) -> (f64, f64) {
    let (e, nu) = (model.youngs_modulus, model.poisson_ratio);
    (
        e / (2.0 * (1.0 - nu * nu)),
        e / (4.0 * (2.0 - nu) * (1.0 + nu)),
    )
}

/// What a Hertz-Mindlin model's contacts share: `E*`, `G*` and the damping
/// factor `d(e)`, computed once per model (the material table keeps them for
/// the pair kernel) instead of once per contact and step.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HertzConstants {
    /// `E*` (Pa).
    pub e_star: f64,
    /// `G*` (Pa).
    pub g_star: f64,
    /// `d(e)` ([`damping_factor`]).
    pub damping: f64,
}

impl HertzConstants {
    /// The constants of `model`.
    pub fn of(model: &ContactModel) -> Self {
        let (e_star, g_star) = effective_moduli(model);
        HertzConstants {
            e_star,
            g_star,
            damping: damping_factor(model.restitution),
        }
    }

    /// The tangent stiffnesses `(S_n, k_t) = (2 E* a, 8 G* a)` (N/m) at
    /// `overlap` (m) between bodies of effective radius `r_star` (m), `a = sqrt(R* delta)`.
    #[inline(always)]
    pub fn tangent_stiffness(&self, overlap: f64, r_star: f64) -> (f64, f64) {
        let a = (r_star * overlap.max(0.0)).sqrt();
        (2.0 * self.e_star * a, 8.0 * self.g_star * a)
    }
}

/// The tangent stiffnesses `(S_n, k_t) = (2 E* a, 8 G* a)` (N/m) of `model` at
/// `overlap` (m) between bodies of effective radius `r_star` (m).
#[inline(always)]
pub fn tangent_stiffness(model: &ContactModel, overlap: f64, r_star: f64) -> (f64, f64) {
    HertzConstants::of(model).tangent_stiffness(overlap, r_star)
}

/// The damping factor `d(e) = -sqrt(5) ln e / sqrt(pi^2 + ln^2 e)` of a
/// coefficient of restitution `e` (0 for `e = 1`), LAMMPS's `coeff_restitution`
/// for a Hertzian normal force: `eta_n = d(e) sqrt(m* F_ne / delta)`.
#[inline(always)]
pub fn damping_factor(restitution: f64) -> f64 {
    if restitution >= 1.0 {
        return 0.0;
    }
    let ln_e = restitution.ln();
    -(5.0f64).sqrt() * ln_e / (PI * PI + ln_e * ln_e).sqrt()
}

/// The stored energy of a Hertz-Mindlin contact (J): `2/5 F_ne delta =
/// 0.6 F_ne^2 / S_n` in the normal spring, `F_s^2 / (2 k_t)` in the tangential
/// one (LAMMPS's strain energy of the Mindlin spring), from the contact's
/// elastic forces and tangent stiffnesses.
#[inline(always)]
pub fn stored_energy(force: &ContactForce) -> f64 {
    let mut energy = 0.0;
    if force.normal_stiffness > 0.0 {
        energy += 0.6 * force.elastic_normal * force.elastic_normal / force.normal_stiffness;
    }
    if force.shear_stiffness > 0.0 {
        energy += 0.5 * force.shear_spring * force.shear_spring / force.shear_stiffness;
    }
    energy
}

/// The law for one touching contact (conventions and arguments as
/// [`super::contact_law`]); the record's tangential slot holds the tangential
/// displacement `xi` (m). Not inlined: its code kept out of the linear law's
/// loops, which test for it on every pair (the four-pair loop's tail among them).
#[inline(never)]
pub fn contact_law(
    model: &ContactModel,
    kinematics: &ContactKinematics,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
) -> ContactForce {
    let constants = HertzConstants::of(model);
    contact_law_with(&constants, model, kinematics, dt, increment_time, record)
}

/// [`contact_law`] with the model's `constants` computed beforehand (the pair
/// kernel's: the same values, so the same bits); not inlined, as [`contact_law`].
#[inline(never)]
pub fn contact_law_with(
    constants: &HertzConstants,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
) -> ContactForce {
    law(constants, model, kinematics, dt, increment_time, record)
}

/// The law itself, inlined where it is called: into [`contact_law_with`],
/// and into the pair loop of a table whose every model is Hertz-Mindlin.
#[inline(always)]
pub(crate) fn law(
    constants: &HertzConstants,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
) -> ContactForce {
    let mut dissipation = ContactDissipation::default();
    let overlap = kinematics.overlap;
    let r_star = RollingSpring::effective_radius(kinematics);
    let (normal_stiffness, shear_stiffness) = constants.tangent_stiffness(overlap, r_star);
    let elastic_normal = (2.0 / 3.0) * normal_stiffness * overlap;
    let normal = damped_normal(
        constants.damping,
        kinematics,
        elastic_normal,
        normal_stiffness,
        dt,
        &mut dissipation,
    );
    let (spring, sliding) = mindlin(
        model,
        normal,
        shear_stiffness,
        kinematics.tangential_velocity * increment_time,
        &mut record[TANGENTIAL_HISTORY.start],
        &mut dissipation,
    );
    // LAMMPS's lever arms: to the middle of the overlap between two grains
    // (`r - delta/2`, `pair granular`), the grain's radius against a wall
    // (`fix wall/gran`; a wall, body i, has none)
    let (arm_i, arm_j) = if kinematics.radius_i > 0.0 {
        (
            kinematics.radius_i - 0.5 * overlap,
            kinematics.radius_j - 0.5 * overlap,
        )
    } else {
        (0.0, kinematics.radius_j)
    };
    let (torque_i, torque_j) = shear_torques(arm_i, arm_j, spring);
    let force = ContactForce {
        normal,
        elastic_normal,
        shear: spring,
        shear_spring: spring,
        sliding,
        torque_i,
        torque_j,
        rolling_spring: 0.0,
        rolling_moment: 0.0,
        rolling_energy: 0.0,
        normal_stiffness,
        shear_stiffness,
        dissipation,
    };
    with_rolling(model, kinematics, dt, increment_time, record, force)
}

/// The normal force with the restitution's dashpot, as LAMMPS computes it by
/// default (without `limit_damping`): not clipped, so that the rebound's
/// coefficient of restitution is `e` exactly; the dashpot pulls a little as a
/// contact opens. Its work over `dt` goes to `dissipation.viscous`.
#[inline(always)]
fn damped_normal(
    factor: f64,
    kinematics: &ContactKinematics,
    elastic_normal: f64,
    normal_stiffness: f64,
    dt: f64,
    dissipation: &mut ContactDissipation,
) -> f64 {
    if factor == 0.0 {
        return elastic_normal;
    }
    // m* F_ne / delta = m* (2/3) S_n
    let eta = factor * (kinematics.reduced_mass * (2.0 / 3.0) * normal_stiffness).sqrt();
    let vn = kinematics.normal_velocity;
    let damped = elastic_normal - eta * vn;
    dissipation.viscous += (elastic_normal - damped) * vn * dt;
    damped
}

/// Mindlin's tangential spring: the displacement `xi` moved by `displacement`,
/// the force `-k_t xi` capped at `mu |F_n|`, the normal force with its dashpot,
/// as LAMMPS caps it (the contact slides when it ends at the cap, and `xi` is
/// rescaled to it); the slip's work (the mean force over
/// the slip at the current `k_t`) goes to `dissipation.friction`. Returns the
/// elastic shear force and whether the contact slides.
#[inline(always)]
fn mindlin(
    model: &ContactModel,
    normal: f64,
    shear_stiffness: f64,
    displacement: f64,
    xi: &mut f64,
    dissipation: &mut ContactDissipation,
) -> (f64, bool) {
    let before = -shear_stiffness * *xi;
    *xi += displacement;
    let trial = -shear_stiffness * *xi;
    let cap = model.friction * normal.abs();
    if trial.abs() <= cap {
        return (trial, false);
    }
    let capped = cap.copysign(trial);
    if shear_stiffness > 0.0 {
        dissipation.friction += 0.5 * (before + capped) * (trial - capped) / shear_stiffness;
        *xi = -capped / shear_stiffness;
    } else {
        *xi = 0.0;
    }
    (capped, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::HISTORY_WIDTH;

    fn steel() -> ContactModel {
        ContactModel::hertz_mindlin(200.0e9, 0.3, 1.0, 0.5)
    }

    fn kinematics(overlap: f64, vn: f64, vt: f64) -> ContactKinematics {
        ContactKinematics {
            overlap,
            normal_velocity: vn,
            tangential_velocity: vt,
            radius_i: 0.01,
            radius_j: 0.01,
            reduced_mass: 0.5,
            rolling_velocity: 0.0,
            rolling_inertia: 0.0,
        }
    }

    #[test]
    fn the_normal_force_is_hertzs_four_thirds_e_star_sqrt_r_star_overlap_to_three_halves() {
        let m = steel();
        let e_star = 200.0e9 / (2.0 * (1.0 - 0.09));
        let (delta, r_star): (f64, f64) = (1.0e-6, 0.005);
        let mut record = [0.0; HISTORY_WIDTH];
        let f = contact_law(&m, &kinematics(delta, 0.0, 0.0), 1e-7, 1e-7, &mut record);
        let hertz = 4.0 / 3.0 * e_star * r_star.sqrt() * delta.powf(1.5);
        assert!(
            (f.normal - hertz).abs() < 1e-12 * hertz,
            "{} {hertz}",
            f.normal
        );
        assert_eq!(f.elastic_normal, f.normal);
        // the tangent stiffness dF/d(delta) = 2 E* a, checked by a finite difference
        let g = contact_law(
            &m,
            &kinematics(delta * (1.0 + 1e-6), 0.0, 0.0),
            1e-7,
            1e-7,
            &mut record,
        );
        let slope = (g.normal - f.normal) / (delta * 1e-6);
        assert!((slope / f.normal_stiffness - 1.0).abs() < 1e-5);
        // the stored energy is the integral of the force: 2/5 F delta
        assert!((f.stored_energy(&m) / (0.4 * hertz * delta) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn mindlin_stiffness_is_eight_g_star_a_and_the_cap_rescales_the_displacement() {
        let m = steel();
        let g_star = 200.0e9 / (4.0 * 1.7 * 1.3);
        let (delta, r_star): (f64, f64) = (1.0e-6, 0.005);
        let a = (r_star * delta).sqrt();
        let mut record = [0.0; HISTORY_WIDTH];
        // one increment of 1e-9 m: F_s = -8 G* a 1e-9, below the cap
        let f = contact_law(&m, &kinematics(delta, 0.0, 1.0e-2), 1e-7, 1e-7, &mut record);
        let k_t = 8.0 * g_star * a;
        assert!((f.shear / (-k_t * 1.0e-9) - 1.0).abs() < 1e-9);
        assert!((record[TANGENTIAL_HISTORY.start] - 1.0e-9).abs() < 1e-24);
        assert!(!f.sliding);
        // a large increment slides: the force at mu F_n, the displacement at the cap's
        let f = contact_law(&m, &kinematics(delta, 0.0, 10.0), 1e-7, 1e-7, &mut record);
        assert!(f.sliding);
        assert_eq!(f.shear, -0.5 * f.elastic_normal);
        let xi = record[TANGENTIAL_HISTORY.start];
        assert!((-k_t * xi / f.shear - 1.0).abs() < 1e-12);
        assert!(f.dissipation.friction > 0.0);
    }

    #[test]
    fn the_restitutions_dashpot_opposes_the_normal_velocity() {
        let mut m = steel();
        m.restitution = 0.5;
        let mut record = [0.0; HISTORY_WIDTH];
        let approach = contact_law(&m, &kinematics(1.0e-6, -1.0, 0.0), 1e-7, 1e-7, &mut record);
        assert!(approach.normal > approach.elastic_normal);
        assert!(approach.dissipation.viscous > 0.0);
        // opening fast at a small overlap, the dashpot pulls (LAMMPS's default)
        let apart = contact_law(&m, &kinematics(1.0e-9, 100.0, 0.0), 1e-7, 1e-7, &mut record);
        assert!(apart.normal < 0.0 && apart.dissipation.viscous > 0.0);
        assert_eq!(damping_factor(1.0), 0.0);
        // LAMMPS's factor at e = 0.5: sqrt(5) ln 2 / sqrt(pi^2 + ln^2 2)
        let ln2 = 2.0f64.ln();
        assert!(
            (damping_factor(0.5) - 5.0f64.sqrt() * ln2 / (PI * PI + ln2 * ln2).sqrt()).abs()
                < 1e-15
        );
    }

    #[test]
    fn the_moduli_mix_as_lammps_for_one_material() {
        let (e_star, g_star) = effective_moduli(&steel());
        assert!((e_star - 1.098901098901099e11).abs() < 1.0);
        assert!((g_star - 2.262443438914027e10).abs() < 1.0);
    }
}
