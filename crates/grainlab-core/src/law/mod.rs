//! The contact laws, chosen per pair of material groups
//! ([`crate::material::ContactLaw`]): the linear law and Hertz-Mindlin
//! ([`hertz`]). The linear law is split into sub-models as LAMMPS GRANULAR
//! splits it: **normal** ([`normal::LinearSpring`]: `kn * overlap`), **damping**
//! ([`damping::ViscousDashpots`]: the optional normal and shear dashpots),
//! **tangential** ([`tangential::ShearSpring`]: the incremental shear spring
//! with its Coulomb cap, paper Eq. 2-4) and **rolling** ([`rolling::RollingSpring`]:
//! the elastic-plastic rolling spring, off unless a model has `rolling_friction`,
//! Hertz-Mindlin's too). [`contact_law`] runs them in that order for one linear
//! contact (and hands a Hertz-Mindlin one to [`hertz::contact_law`]) and
//! returns its forces, its torques on both bodies and each sub-model's
//! dissipation; the pair kernel, the wall contacts, the springs' catch-up and
//! the contact queries call it. The sub-models' arithmetic is written once,
//! generic over [`real::Real`]: `f64` here, four AVX2 lanes in the four-pair
//! loop (`pipeline/pair_lanes.rs`, `law_by_four`), whose tests hold the two to
//! the same bits, rolling resistance included.
//!
//! Each sub-model declares the history it carries per contact
//! ([`SubModel::HISTORY`] values); one contact's history is one
//! [`ContactRecord`] of [`HISTORY_WIDTH`] values, the sub-models' slots side by
//! side in the order above, kept in a [`history::ContactHistory`] that the
//! neighbour rebuild carries over whatever its width.
//!
//! Sign conventions, for a contact between body `i` and body `j` with unit
//! normal `n` pointing from `i` to `j` and tangent `t = perp(n)`:
//! - `overlap > 0` when the bodies interpenetrate;
//! - `normal_velocity = (v_j - v_i) . n` (positive when separating);
//! - `tangential_velocity = (v_j - v_i) . t - (omega_i r_i + omega_j r_j)`,
//!   the sliding speed of `j`'s surface relative to `i`'s (Eq. 2);
//! - the force on `j` is `fn n + fs t` and on `i` its opposite; the torque on
//!   both is `-r fs` with `r` the body's radius (lever arm to the contact);
//! - `rolling_velocity = omega_j - omega_i` (counter-clockwise positive; a
//!   wall, body `i`, does not turn), and the rolling moment `M_r` acts on `j`
//!   and `-M_r` on `i` (a couple: the torques sum to zero).
//!
//! In 2D the shear spring is one scalar along the current tangent, so carrying
//! it from step to step *is* the PFC rotation of the shear force with the contact.
use std::ops::Range;

use crate::diagnostics::ContactDissipation;
use crate::material::{ContactLaw, ContactModel};
use real::Real;

pub mod damping;
pub mod hertz;
pub mod history;
pub mod normal;
pub mod real;
pub mod rolling;
pub mod tangential;

/// What every contact sub-model declares.
pub trait SubModel {
    /// The sub-model's name, as the docs and the energy ledger give it.
    const NAME: &'static str;
    /// How many values of history it carries per contact (its slot in the
    /// [`ContactRecord`]).
    const HISTORY: usize;
    /// Whether `pipeline/pair_lanes.rs` evaluates it four pairs at a time (its
    /// arithmetic generic over [`real::Real`], called there with four lanes;
    /// the same bits as [`contact_law`], which its test checks on random
    /// inputs); the four-pair loop runs only while every sub-model of the law
    /// says so.
    const LANES: bool;
}

/// The normal sub-model: the elastic normal force, which the Coulomb cap refers to.
pub trait NormalModel: SubModel {
    /// The elastic normal force on `j` along `n` (N) at `overlap` (m), from and
    /// into the sub-model's `history`.
    fn elastic_force(model: &ContactModel, overlap: f64, history: &mut [f64]) -> f64;
}

/// The damping sub-model: forces that depend on the relative velocity.
pub trait DampingModel: SubModel {
    /// The normal force from the elastic one; its dissipation over `dt` goes
    /// to `dissipation.viscous`. With `DASHPOTS` false the dashpot terms are
    /// compiled out (for a model without dashpots the same bits).
    fn normal_force<const DASHPOTS: bool>(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        elastic_normal: f64,
        dt: f64,
        dissipation: &mut ContactDissipation,
    ) -> f64;

    /// The shear force from the tangential sub-model's `spring`, which is at
    /// the Coulomb cap when `sliding`; dissipation as [`DampingModel::normal_force`].
    fn shear_force<const DASHPOTS: bool>(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        spring: f64,
        sliding: bool,
        dt: f64,
        dissipation: &mut ContactDissipation,
    ) -> f64;
}

/// What a tangential sub-model's update gives: the elastic shear force and
/// whether it is at the Coulomb cap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearState {
    /// The elastic shear force on `j` along `t` (N), after the update.
    pub spring: f64,
    /// Whether it is at the Coulomb cap, `|Fs| = mu Fn`.
    pub sliding: bool,
}

/// The tangential sub-model: the shear force's history and its cap.
pub trait TangentialModel: SubModel {
    /// Updates the sub-model's `history` by the tangential displacement
    /// `tangential_velocity * increment_time` (none when `increment_time` is 0:
    /// a step that starts from full-step velocities), caps it against
    /// `elastic_normal`, books the slip in `dissipation.friction`.
    fn update(
        model: &ContactModel,
        elastic_normal: f64,
        tangential_velocity: f64,
        increment_time: f64,
        history: &mut [f64],
        dissipation: &mut ContactDissipation,
    ) -> ShearState;
}

/// The rolling sub-model: a resisting torque on both bodies.
pub trait RollingModel: SubModel {
    /// Adds its torques to `force.torque_i` / `force.torque_j` and its
    /// dissipation to `force.dissipation.rolling`, from and into `history`.
    fn apply(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        dt: f64,
        increment_time: f64,
        history: &mut [f64],
        force: &mut ContactForce,
    );
}

/// The normal sub-model of the law.
pub type Normal = normal::LinearSpring;
/// The damping sub-model of the law.
pub type Damping = damping::ViscousDashpots;
/// The tangential sub-model of the law.
pub type Tangential = tangential::ShearSpring;
/// The rolling sub-model of the law.
pub type Rolling = rolling::RollingSpring;

/// Values of history per contact: the sub-models' declared [`SubModel::HISTORY`], summed.
pub const HISTORY_WIDTH: usize =
    Normal::HISTORY + Damping::HISTORY + Tangential::HISTORY + Rolling::HISTORY;

/// The normal sub-model's slot in a [`ContactRecord`].
pub const NORMAL_HISTORY: Range<usize> = 0..Normal::HISTORY;
/// The damping sub-model's slot.
pub const DAMPING_HISTORY: Range<usize> = NORMAL_HISTORY.end..NORMAL_HISTORY.end + Damping::HISTORY;
/// The tangential sub-model's slot (its shear spring).
pub const TANGENTIAL_HISTORY: Range<usize> =
    DAMPING_HISTORY.end..DAMPING_HISTORY.end + Tangential::HISTORY;
/// The rolling sub-model's slot.
pub const ROLLING_HISTORY: Range<usize> =
    TANGENTIAL_HISTORY.end..TANGENTIAL_HISTORY.end + Rolling::HISTORY;

/// Whether the four-pair AVX2 loop evaluates this law (every sub-model has
/// lanes, and the record is the tangential spring then the rolling spring,
/// which the lanes load: the shear spring alone, or with rolling resistance
/// both as one 128-bit pair). The lanes' rolling law is compiled in only for
/// a table with rolling resistance
/// ([`crate::material::MaterialTable::rolling`]).
pub const LANES: bool = Normal::LANES
    && Damping::LANES
    && Tangential::LANES
    && Rolling::LANES
    && TANGENTIAL_HISTORY.start == 0
    && ROLLING_HISTORY.start == 1
    && HISTORY_WIDTH == 2;

/// One contact's history: every sub-model's values, in its slot; all zero for
/// a contact that has not touched (or has separated).
pub type ContactRecord = [f64; HISTORY_WIDTH];

/// One contact's state as the sub-models read it (conventions above).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactKinematics {
    /// Overlap (m), > 0 in contact.
    pub overlap: f64,
    /// `(v_j - v_i) . n` (m/s).
    pub normal_velocity: f64,
    /// `(v_j - v_i) . t - (omega_i r_i + omega_j r_j)` (m/s).
    pub tangential_velocity: f64,
    /// Body `i`'s lever arm to the contact (m; 0 for a wall).
    pub radius_i: f64,
    /// Body `j`'s lever arm to the contact (m).
    pub radius_j: f64,
    /// `m_i m_j / (m_i + m_j)`, or the particle's mass against a wall (kg);
    /// read only by the dashpots (0 when no model has one).
    pub reduced_mass: f64,
    /// `omega_j - omega_i` (rad/s), the relative rolling velocity.
    pub rolling_velocity: f64,
    /// The equivalent rotational inertia about the contact (kg m^2),
    /// `[1/(I_i + m_i r_i^2) + 1/(I_j + m_j r_j^2)]^-1`, `I + m r^2` against a
    /// wall; read only by the rolling dashpot (0 when the model has none).
    pub rolling_inertia: f64,
}

/// What the contact law returns for one contact in one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactForce {
    /// Normal force on `j` along `n` (N), >= 0 for unbonded contacts, dashpot included.
    pub normal: f64,
    /// Elastic normal force `kn * overlap` (N), which the Coulomb cap refers to.
    pub elastic_normal: f64,
    /// Shear force on `j` along `t` (N), elastic plus viscous.
    pub shear: f64,
    /// The tangential sub-model's elastic shear force (N): its spring after the update.
    pub shear_spring: f64,
    /// Whether the shear spring is at the Coulomb cap, `|Fs| = mu kn overlap`.
    pub sliding: bool,
    /// Torque on body `i` (N m): `-r_i Fs - M_r`.
    pub torque_i: f64,
    /// Torque on body `j` (N m): `-r_j Fs + M_r`.
    pub torque_j: f64,
    /// The rolling sub-model's spring `M_r^k` after the update (N m; 0 when off).
    pub rolling_spring: f64,
    /// The rolling moment on `j` (N m), spring plus dashpot (0 when off).
    pub rolling_moment: f64,
    /// The rolling spring's elastic energy `M_r^2 / (2 k_r)` (J; 0 when off).
    pub rolling_energy: f64,
    /// The normal force's tangent stiffness `dF_n / d(overlap)` at this overlap
    /// (N/m): `kn` for the linear law, `2 E* a` for Hertz-Mindlin; the servo's
    /// stiffness sum and the rolling stiffness rule read it.
    pub normal_stiffness: f64,
    /// The tangential spring's stiffness (N/m): `ks`, or Mindlin's `8 G* a`.
    pub shear_stiffness: f64,
    /// Energy each dissipating sub-model took out of the system this step (J).
    pub dissipation: ContactDissipation,
}

/// The contact law: the sub-models in order (normal, damping of the normal
/// force, tangential, damping of the shear force, rolling) for one touching
/// contact, updating its `record` in place.
///
/// `dt` books the dashpots' dissipation; `increment_time` is the time over
/// which `tangential_velocity` displaced the contact since the record was last
/// updated (the time step, or 0 on a step that starts from full-step
/// velocities, `docs/contact-law.md`). With `DASHPOTS` false the dashpot terms
/// are compiled out: for a model whose damping ratios are both 0 the two give
/// the same bits (the terms are skipped for a zero ratio too), so a kernel that
/// knows no model has a dashpot calls it without the tests.
#[inline(always)]
pub fn contact_law<const DASHPOTS: bool>(
    model: &ContactModel,
    kinematics: &ContactKinematics,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
) -> ContactForce {
    if model.law == ContactLaw::HertzMindlin {
        return hertz::contact_law(model, kinematics, dt, increment_time, record);
    }
    let mut dissipation = ContactDissipation::default();
    let elastic_normal =
        Normal::elastic_force(model, kinematics.overlap, &mut record[NORMAL_HISTORY]);
    let normal =
        Damping::normal_force::<DASHPOTS>(model, kinematics, elastic_normal, dt, &mut dissipation);
    let state = Tangential::update(
        model,
        elastic_normal,
        kinematics.tangential_velocity,
        increment_time,
        &mut record[TANGENTIAL_HISTORY],
        &mut dissipation,
    );
    let shear = Damping::shear_force::<DASHPOTS>(
        model,
        kinematics,
        state.spring,
        state.sliding,
        dt,
        &mut dissipation,
    );
    let (torque_i, torque_j) = shear_torques(kinematics.radius_i, kinematics.radius_j, shear);
    let force = ContactForce {
        normal,
        elastic_normal,
        shear,
        shear_spring: state.spring,
        sliding: state.sliding,
        torque_i,
        torque_j,
        rolling_spring: 0.0,
        rolling_moment: 0.0,
        rolling_energy: 0.0,
        normal_stiffness: model.normal_stiffness,
        shear_stiffness: model.shear_stiffness,
        dissipation,
    };
    with_rolling(model, kinematics, dt, increment_time, record, force)
}

/// The torques `(-r_i F_s, -r_j F_s)` of the shear force `shear` on both
/// bodies, of one contact or four lanes.
#[inline(always)]
pub fn shear_torques<R: Real>(radius_i: R, radius_j: R, shear: R) -> (R, R) {
    (-radius_i * shear, -radius_j * shear)
}

/// `force` with the rolling sub-model's torques and dissipation added, from and
/// into its slot of `record` (the last sub-model of either law).
#[inline(always)]
pub(crate) fn with_rolling(
    model: &ContactModel,
    kinematics: &ContactKinematics,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
    mut force: ContactForce,
) -> ContactForce {
    Rolling::apply(
        model,
        kinematics,
        dt,
        increment_time,
        &mut record[ROLLING_HISTORY],
        &mut force,
    );
    force
}

/// The tangent stiffnesses `(k_n, k_s)` (N/m) of `model`'s law at `overlap`
/// (m) between bodies of effective radius `r_star` (m): `(kn, ks)` for the
/// linear law, `(2 E* a, 8 G* a)` for Hertz-Mindlin. The time step asks it.
#[inline]
pub fn tangent_stiffness(model: &ContactModel, overlap: f64, r_star: f64) -> (f64, f64) {
    match model.law {
        ContactLaw::Linear => (model.normal_stiffness, model.shear_stiffness),
        ContactLaw::HertzMindlin => hertz::tangent_stiffness(model, overlap, r_star),
    }
}

/// Elastic energy stored in a linear contact with normal force `normal` and
/// shear spring `shear` (J).
#[inline(always)]
pub fn elastic_energy(model: &ContactModel, normal: f64, shear: f64) -> f64 {
    0.5 * normal * normal / model.normal_stiffness + 0.5 * shear * shear / model.shear_stiffness
}

impl ContactForce {
    /// Elastic energy of the law's normal and tangential springs (J), without
    /// the rolling spring's: [`elastic_energy`] for the linear law,
    /// [`hertz::stored_energy`] for Hertz-Mindlin.
    #[inline(always)]
    pub fn spring_energy(&self, model: &ContactModel) -> f64 {
        match model.law {
            ContactLaw::Linear => elastic_energy(model, self.elastic_normal, self.shear_spring),
            ContactLaw::HertzMindlin => hertz::stored_energy(self),
        }
    }

    /// Elastic energy stored in the contact (J): the law's springs
    /// ([`elastic_energy`] for the linear law, [`hertz::stored_energy`]) plus
    /// the rolling spring's, added only when there is one (so that a contact
    /// without rolling resistance keeps its bits).
    #[inline(always)]
    pub fn stored_energy(&self, model: &ContactModel) -> f64 {
        let e = self.spring_energy(model);
        if self.rolling_energy != 0.0 {
            e + self.rolling_energy
        } else {
            e
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(mu: f64) -> ContactModel {
        ContactModel::linear(1.0e6, 5.0e5, mu)
    }

    /// The law on a contact of two unit disks.
    #[allow(clippy::too_many_arguments)]
    fn law(
        m: &ContactModel,
        overlap: f64,
        vn: f64,
        vt: f64,
        dt: f64,
        increment_time: f64,
        mass: f64,
        s: &mut f64,
    ) -> ContactForce {
        let kinematics = ContactKinematics {
            overlap,
            normal_velocity: vn,
            tangential_velocity: vt,
            radius_i: 1.0,
            radius_j: 1.0,
            reduced_mass: mass,
            rolling_velocity: 0.0,
            rolling_inertia: 0.0,
        };
        let mut record = [0.0; HISTORY_WIDTH];
        record[TANGENTIAL_HISTORY.start] = *s;
        let f = contact_law::<true>(m, &kinematics, dt, increment_time, &mut record);
        *s = record[TANGENTIAL_HISTORY.start];
        f
    }

    #[test]
    fn the_record_holds_each_sub_models_declared_history() {
        assert_eq!(HISTORY_WIDTH, 2);
        assert_eq!(TANGENTIAL_HISTORY, 0..1);
        assert!(NORMAL_HISTORY.is_empty() && DAMPING_HISTORY.is_empty());
        assert_eq!(ROLLING_HISTORY, 1..2);
        assert!(LANES);
    }

    #[test]
    fn normal_force_is_stiffness_times_overlap() {
        let mut s = 0.0;
        let f = law(&model(0.5), 2.0e-6, 0.0, 0.0, 1e-5, 1e-5, 1.0, &mut s);
        assert_eq!(f.normal, 2.0);
        assert_eq!(f.shear, 0.0);
        assert!(!f.sliding);
    }

    #[test]
    fn the_torques_are_minus_each_lever_arm_times_the_shear_force() {
        let m = model(0.5);
        let kinematics = ContactKinematics {
            overlap: 2.0e-6,
            normal_velocity: 0.0,
            tangential_velocity: 1.0,
            radius_i: 0.25,
            radius_j: 3.0,
            reduced_mass: 1.0,
            rolling_velocity: 0.0,
            rolling_inertia: 0.0,
        };
        let mut record = [0.0; HISTORY_WIDTH];
        let f = contact_law::<true>(&m, &kinematics, 1e-6, 1e-6, &mut record);
        assert_eq!(f.shear, -0.5);
        assert_eq!((f.torque_i, f.torque_j), (0.125, 1.5));
        assert_eq!(f.dissipation.rolling, 0.0);
    }

    #[test]
    fn shear_spring_increments_then_caps_at_coulomb() {
        let m = model(0.5);
        let mut s = 0.0;
        // one step of tangential motion: Fs = -ks * v_t * dt = -5e5 * 1 * 1e-6 = -0.5 N
        let f = law(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 0.5).abs() < 1e-12 && !f.sliding);
        // a little more motion stays below the cap mu * Fn = 0.5 * 2 = 1.0 N: elastic
        let f = law(&m, 2.0e-6, 0.0, 0.9, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 0.95).abs() < 1e-12 && !f.sliding);
        // the trial -1.45 N exceeds the cap: the spring stays at the cap, the contact slides
        let f = law(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!((f.shear + 1.0).abs() < 1e-12 && f.sliding, "{f:?}");
        let f = law(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!(f.sliding);
        assert_eq!(f.shear, -1.0);
        assert_eq!(s, -1.0);
        // dissipation = mean force (-1 N) times slip (-0.5 N / ks) in steady sliding
        assert!((f.dissipation.friction - 1.0 * 0.5 / 5.0e5).abs() < 1e-18);
        // at the onset the mean force is (-1.0 + -1.0)/2 ... from a spring at -0.75 N
        s = -0.75;
        let f = law(&m, 2.0e-6, 0.0, 1.0, 1e-6, 1e-6, 1.0, &mut s);
        let slip = (-1.25f64 + 1.0) / 5.0e5;
        assert!((f.dissipation.friction - 0.5 * (-0.75 - 1.0) * slip).abs() < 1e-18);
    }

    #[test]
    fn normal_dashpot_never_pulls() {
        let mut m = model(0.0);
        m.normal_damping_ratio = 1.0;
        let mut s = 0.0;
        // separating fast: the dashpot would make the force attractive; it is clipped to 0
        let f = law(&m, 1.0e-9, 10.0, 0.0, 1e-6, 1e-6, 1.0, &mut s);
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
        let f = law(&m, 1.0e-3, vn, 0.0, dt, dt, mass, &mut s);
        assert!((f.normal - (1000.0 - c_n * vn)).abs() < 1e-9);
        assert!((f.dissipation.viscous - c_n * vn * vn * dt).abs() < 1e-15);
        // separating: the dashpot holds back and still dissipates c_n vn^2 dt
        let f = law(&m, 1.0e-3, -vn, 0.0, dt, dt, mass, &mut s);
        assert!(f.normal < 1000.0 && f.normal > 0.0);
        assert!((f.dissipation.viscous - c_n * vn * vn * dt).abs() < 1e-15);
        // clipped at zero (no pull): it takes out the work of the spring force it removed
        let f = law(&m, 1.0e-6, -vn, 0.0, dt, dt, mass, &mut s);
        assert_eq!(f.normal, 0.0);
        assert!((f.dissipation.viscous - 1.0 * -vn * dt).abs() < 1e-18);
    }

    #[test]
    fn no_increment_time_leaves_the_spring_and_a_spring_at_the_cap_slides() {
        let m = model(0.5);
        // a spring strictly inside the cap is left as it is, whatever the velocity
        let mut s = 0.3;
        let f = law(&m, 2.0e-6, 0.0, 7.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!(
            (s, f.shear, f.sliding, f.dissipation.friction),
            (0.3, 0.3, false, 0.0)
        );
        // exactly at the cap: sliding (|Fs| = mu Fn), no slip and no dissipation
        let mut s = -1.0;
        let f = law(&m, 2.0e-6, 0.0, 7.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!((s, f.sliding, f.dissipation.friction), (-1.0, true, 0.0));
        // a smaller overlap than the spring was made for caps it again and dissipates
        let f = law(&m, 1.0e-6, 0.0, 0.0, 1e-6, 0.0, 1.0, &mut s);
        assert_eq!((s, f.sliding), (-0.5, true));
        assert!((f.dissipation.friction - 0.5 * (-1.5) * (-0.5) / 5.0e5).abs() < 1e-18);
    }

    #[test]
    fn the_cap_is_mu_times_the_elastic_normal_force_with_a_normal_dashpot() {
        let mut m = model(0.5);
        m.normal_damping_ratio = 0.5;
        let mut s = 0.0;
        // approaching fast: the dashpot adds to the normal force, the cap stays mu kn overlap
        let f = law(&m, 2.0e-6, -1.0, 10.0, 1e-6, 1e-6, 1.0, &mut s);
        assert!(f.normal > f.elastic_normal);
        assert_eq!(f.elastic_normal, 2.0);
        assert!(f.sliding && s == -1.0, "{f:?}");
    }

    #[test]
    fn a_shear_dashpot_acts_only_while_the_contact_sticks() {
        let mut m = model(0.5);
        m.shear_damping_ratio = 0.4;
        let (mass, dt, vt) = (2.0, 1e-6, 0.2);
        let c_s = 2.0 * 0.4 * (mass * m.shear_stiffness).sqrt();
        // sticking: the dashpot's force -c_s vt on top of the spring, c_s vt^2 dt dissipated
        let mut s = 0.0;
        let f = law(&m, 2.0e-6, 0.0, vt, dt, dt, mass, &mut s);
        assert!(!f.sliding);
        assert_eq!(f.shear, f.shear_spring - c_s * vt);
        assert_eq!(f.dissipation.viscous, c_s * vt * vt * dt);
        // sliding: the spring alone, and no viscous dissipation
        let mut s = -1.0;
        let f = law(&m, 2.0e-6, 0.0, vt, dt, dt, mass, &mut s);
        assert!(f.sliding);
        assert_eq!((f.shear, f.dissipation.viscous), (-1.0, 0.0));
    }

    /// Two disks of radii 1 and 3 (R* = 0.75) in contact at 2e-6 overlap with
    /// kn = 1e6 (F_n = 2 N), rolling resistance mu_r and stiffness k_r.
    fn rolling_contact(
        mu_r: f64,
        k_r: f64,
        rolling_velocity: f64,
    ) -> (ContactModel, ContactKinematics) {
        let mut m = model(0.5);
        m.rolling_friction = mu_r;
        m.rolling_stiffness = k_r;
        let kinematics = ContactKinematics {
            overlap: 2.0e-6,
            normal_velocity: 0.0,
            tangential_velocity: 0.0,
            radius_i: 1.0,
            radius_j: 3.0,
            reduced_mass: 1.0,
            rolling_velocity,
            rolling_inertia: 2.0,
        };
        (m, kinematics)
    }

    /// Oracle (two disks, a prescribed relative rotation): after rotating `j`
    /// against `i` by `dtheta = (omega_j - omega_i) dt` in one increment the
    /// rolling spring is exactly `-k_r dtheta` while below the cap
    /// `mu_r R* F_n`, and the moment acts on `j` and its opposite on `i` (a
    /// couple: the two torques, with no shear force, sum to zero). Rotated on,
    /// the spring stops at the cap and the plastic rotation's work is booked
    /// in `rolling`, as a slip's is in `friction`.
    #[test]
    fn the_rolling_spring_is_minus_k_r_times_the_rotation_then_its_cap() {
        // cap = mu_r R* F_n = 0.1 * 0.75 * 2 = 0.15 N m; k_r = 100 N m/rad
        let (m, k) = rolling_contact(0.1, 100.0, 1.0);
        let dt = 1.0e-3; // dtheta = 1e-3 rad: M_r = -0.1 N m, elastic
        let mut record = [0.0; HISTORY_WIDTH];
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!(f.rolling_spring, -100.0 * 1.0e-3);
        assert_eq!(record[ROLLING_HISTORY.start], f.rolling_spring);
        assert_eq!((f.torque_i, f.torque_j), (0.1, -0.1));
        assert_eq!(f.torque_i + f.torque_j, 0.0);
        assert_eq!(f.dissipation.rolling, 0.0);
        assert!((f.rolling_energy - 0.5 * 0.01 / 100.0).abs() < 1e-18);
        // another 1e-3 rad: the trial -0.2 N m passes the cap, the spring stays at -0.15
        let cap = 0.1 * 0.75 * f.elastic_normal;
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!(f.rolling_spring, -cap);
        assert!((cap - 0.15).abs() < 1e-15);
        assert_eq!((f.torque_i, f.torque_j), (cap, -cap));
        // dissipated: the mean moment (-0.1 - 0.15)/2 times the plastic rotation (-0.05/k_r)
        let work = 0.5 * (-0.1 - 0.15) * (-0.2 + 0.15) / 100.0;
        assert!((f.dissipation.rolling - work).abs() < 1e-16);
        // at the cap, turning on: the moment stays, each increment k_r dtheta dissipated at the cap
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!(f.rolling_spring, -cap);
        assert!((f.dissipation.rolling - 0.15 * 1.0e-3).abs() < 1e-15);
        // turning back unloads elastically: -0.15 + 100 * 1e-3 = -0.05
        let (_, back) = rolling_contact(0.1, 100.0, -1.0);
        let f = contact_law::<true>(&m, &back, dt, dt, &mut record);
        assert!((f.rolling_spring + 0.05).abs() < 1e-15);
        assert_eq!(f.dissipation.rolling, 0.0);
        // no increment time (a step from full-step velocities): the spring is left as it is
        let f = contact_law::<true>(&m, &back, dt, 0.0, &mut record);
        assert!((f.rolling_spring + 0.05).abs() < 1e-15);
    }

    #[test]
    fn the_rolling_stiffness_rule_is_2_25_kn_mu_r_squared_r_star_squared() {
        let (m, k) = rolling_contact(0.2, 0.0, 1.0);
        let r_star = rolling::RollingSpring::effective_radius(&k);
        assert_eq!(r_star, 0.75);
        let k_r = 2.25 * 1.0e6 * 0.2 * 0.2 * 0.75 * 0.75;
        assert_eq!(
            rolling::RollingSpring::stiffness(&m, m.normal_stiffness, r_star),
            k_r
        );
        let mut record = [0.0; HISTORY_WIDTH];
        let dt = 1.0e-7; // k_r dtheta = 5.06e-3 N m, below the cap 0.3 N m
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!(f.rolling_spring, -(k_r * 1.0 * dt));
        // against a wall (r_i = 0), R* is the particle's radius
        let wall = ContactKinematics { radius_i: 0.0, ..k };
        assert_eq!(rolling::RollingSpring::effective_radius(&wall), 3.0);
    }

    /// The rolling dashpot `-eta_r 2 sqrt(I_r k_r) (omega_j - omega_i)` acts on
    /// top of the spring while it is below the cap, is not stored, and takes
    /// `c_r w^2 dt` out; at the cap it is off.
    #[test]
    fn the_rolling_dashpot_acts_only_below_the_cap() {
        let (mut m, k) = rolling_contact(0.1, 100.0, 0.5);
        m.rolling_damping_ratio = 0.3;
        let c_r = 2.0 * 0.3 * (2.0f64 * 100.0).sqrt();
        let dt = 1.0e-3;
        let mut record = [0.0; HISTORY_WIDTH];
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!(f.rolling_spring, -0.05);
        assert_eq!(record[ROLLING_HISTORY.start], -0.05);
        assert_eq!(f.rolling_moment, -0.05 - c_r * 0.5);
        assert_eq!(
            (f.torque_i, f.torque_j),
            (-f.rolling_moment, f.rolling_moment)
        );
        assert_eq!(f.dissipation.rolling, c_r * 0.5 * 0.5 * dt);
        let cap = 0.1 * 0.75 * f.elastic_normal;
        record[ROLLING_HISTORY.start] = -cap;
        let f = contact_law::<true>(&m, &k, dt, dt, &mut record);
        assert_eq!((f.rolling_spring, f.rolling_moment), (-cap, -cap));
        assert!((f.dissipation.rolling - 0.15 * 0.5e-3).abs() < 1e-15);
    }

    /// With `rolling_friction` 0 (the default) the rolling sub-model does
    /// nothing: the law's bits, torques and record are today's.
    #[test]
    fn without_rolling_friction_the_rolling_slot_is_left_and_no_moment_acts() {
        let (mut m, k) = rolling_contact(0.0, 100.0, 3.0);
        m.rolling_damping_ratio = 0.5;
        let k = ContactKinematics {
            tangential_velocity: 1.0,
            ..k
        };
        let mut record = [0.0; HISTORY_WIDTH];
        let f = contact_law::<true>(&m, &k, 1e-6, 1e-6, &mut record);
        assert_eq!(record[ROLLING_HISTORY.start].to_bits(), 0.0f64.to_bits());
        assert_eq!(
            (f.rolling_spring, f.rolling_moment, f.rolling_energy),
            (0.0, 0.0, 0.0)
        );
        assert_eq!((f.torque_i, f.torque_j), (-f.shear, -3.0 * f.shear));
        assert_eq!(f.dissipation.rolling, 0.0);
    }
}
