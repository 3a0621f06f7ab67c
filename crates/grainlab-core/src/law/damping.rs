//! Damping sub-models: forces of the relative velocity, on top of the springs.
use super::{ContactKinematics, DampingModel, SubModel};
use crate::diagnostics::ContactDissipation;
use crate::material::ContactModel;

/// The viscous dashpots of the contact model's damping ratios (fractions of
/// critical damping, 0 for none): `c_n = 2 beta_n sqrt(m* kn)` on the normal
/// force, clipped so that it never pulls, and `c_s = 2 beta_s sqrt(m* ks)` on
/// the shear force while the contact sticks (not stored in the spring, not in
/// the Coulomb cap). No history; their work is the ledger's `viscous` entry.
/// The four-pair lanes evaluate only models without dashpots (so the
/// dashpots' one form is this scalar one).
#[derive(Debug, Clone, Copy)]
pub struct ViscousDashpots;

impl SubModel for ViscousDashpots {
    const NAME: &'static str = "viscous dashpots";
    const HISTORY: usize = 0;
    const LANES: bool = true;
}

impl DampingModel for ViscousDashpots {
    #[inline(always)]
    fn normal_force<const DASHPOTS: bool>(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        elastic_normal: f64,
        dt: f64,
        dissipation: &mut ContactDissipation,
    ) -> f64 {
        let mut normal = elastic_normal;
        if DASHPOTS && model.normal_damping_ratio > 0.0 {
            let vn = kinematics.normal_velocity;
            let c_n = 2.0
                * model.normal_damping_ratio
                * (kinematics.reduced_mass * model.normal_stiffness).sqrt();
            let damped = (normal - c_n * vn).max(0.0);
            // the dashpot's force (damped - normal) opposes the normal velocity; the
            // energy it takes out of the system is its negative power
            dissipation.viscous += (normal - damped) * vn * dt;
            normal = damped;
        }
        normal
    }

    #[inline(always)]
    fn shear_force<const DASHPOTS: bool>(
        model: &ContactModel,
        kinematics: &ContactKinematics,
        spring: f64,
        sliding: bool,
        dt: f64,
        dissipation: &mut ContactDissipation,
    ) -> f64 {
        let mut shear = spring;
        if DASHPOTS && !sliding && model.shear_damping_ratio > 0.0 {
            let vt = kinematics.tangential_velocity;
            let c_s = 2.0
                * model.shear_damping_ratio
                * (kinematics.reduced_mass * model.shear_stiffness).sqrt();
            shear -= c_s * vt;
            dissipation.viscous += c_s * vt * vt * dt;
        }
        shear
    }
}
