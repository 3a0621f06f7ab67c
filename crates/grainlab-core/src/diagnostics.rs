//! What a step measures: the energy ledger, the unbalanced force ratio, contact
//! counts, and the paper's Eq. 16 density scaling factor.
use serde::{Deserialize, Serialize};

/// Energies (J per unit thickness). `kinetic` and `elastic` are the state at the
/// last measured step (full-step velocities); the rest accumulate from step 0.
///
/// Balance: `kinetic + elastic + friction + viscous + rolling + damping +
/// bond_released - wall_work - external_work - boundary_work` stays constant, up to the work
/// of prescribed velocities and of the periodic cell's imposed deformation,
/// which are not counted. The contact law's sub-models book their dissipation
/// in one entry each ([`ContactDissipation`], `docs/contact-law.md`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyLedger {
    /// Translational plus rotational kinetic energy.
    pub kinetic: f64,
    /// Elastic energy in contact and bond springs (cement bonds' bending included).
    pub elastic: f64,
    /// Energy dissipated by Coulomb slip.
    pub friction_dissipated: f64,
    /// Energy dissipated by the viscous contact dashpots.
    pub viscous_dissipated: f64,
    /// Energy dissipated by the rolling-resistance sub-model (0 with the
    /// linear law's sub-models, which resist no rolling).
    pub rolling_dissipated: f64,
    /// Energy dissipated by local damping.
    pub damping_dissipated: f64,
    /// Work done on the particles by moving walls: for each step's displacement of
    /// a wall, the trapezoid of its forces before and after it.
    pub wall_work: f64,
    /// Work done by external forces and torques and by gravity.
    pub external_work: f64,
    /// Work done by the follower loads of pressure chains (the confining pressure).
    pub boundary_work: f64,
    /// Strain energy released by broken cement bonds: each break books the
    /// energy its bond held at the evaluation that broke it ([`crate::cement`]).
    pub bond_released: f64,
}

impl EnergyLedger {
    /// `kinetic + elastic + dissipated - work in`: constant in an exact integration.
    pub fn balance(&self) -> f64 {
        self.kinetic
            + self.elastic
            + self.friction_dissipated
            + self.viscous_dissipated
            + self.rolling_dissipated
            + self.damping_dissipated
            + self.bond_released
            - self.wall_work
            - self.external_work
            - self.boundary_work
    }
}

/// Energy taken out of the system by the contact law's sub-models (J), one
/// entry per sub-model that dissipates: what one contact's evaluation returns
/// ([`crate::law::ContactForce::dissipation`]), what a step's tallies sum, and
/// what [`EnergyLedger::book_contacts`] adds to the ledger.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactDissipation {
    /// Coulomb slip of the tangential sub-model (its shear spring at the cap).
    pub friction: f64,
    /// The damping sub-model's viscous dashpots.
    pub viscous: f64,
    /// The rolling sub-model's resistance.
    pub rolling: f64,
}

impl ContactDissipation {
    /// Adds `other`'s entries, entry by entry.
    #[inline(always)]
    pub fn add(&mut self, other: &ContactDissipation) {
        self.friction += other.friction;
        self.viscous += other.viscous;
        self.rolling += other.rolling;
    }

    /// The entry-by-entry sum `self + other`.
    #[inline(always)]
    pub fn plus(&self, other: &ContactDissipation) -> ContactDissipation {
        ContactDissipation {
            friction: self.friction + other.friction,
            viscous: self.viscous + other.viscous,
            rolling: self.rolling + other.rolling,
        }
    }
}

impl EnergyLedger {
    /// Books the contact sub-models' dissipation: each entry into its own line.
    pub fn book_contacts(&mut self, d: &ContactDissipation) {
        self.friction_dissipated += d.friction;
        self.viscous_dissipated += d.viscous;
        self.rolling_dissipated += d.rolling;
    }
}

/// Measurements of the last measured step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Measurements {
    /// Step count of the measurement.
    pub step: u64,
    /// Particle-particle contacts (overlap > 0, bonds excluded).
    pub contact_count: usize,
    /// Particle-wall contacts.
    pub wall_contact_count: usize,
    /// Mean |resultant force| over free particles / mean |contact force| over
    /// contacts (PFC's mean unbalanced force ratio); 0 when both vanish.
    pub mean_unbalanced_force_ratio: f64,
    /// Energy ledger.
    pub energy: EnergyLedger,
}

/// The paper's Eq. 16 density scaling factor (an inertial number):
/// `I = strain_rate * sqrt(density * r_min^2 / pressure)`; the paper keeps it below 1e-3.
pub fn density_scaling_factor(
    strain_rate: f64,
    density: f64,
    min_radius: f64,
    pressure: f64,
) -> f64 {
    strain_rate.abs() * (density * min_radius * min_radius / pressure).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_factor_of_the_paper_setup() {
        // 2 %/min, rho = 2e8, r_min = 0.25 mm, p = 100 kPa
        let rate = 0.02 / 60.0;
        let i = density_scaling_factor(rate, 2e8, 0.25e-3, 1e5);
        let expected = rate * (2e8f64 * 0.25e-3 * 0.25e-3 / 1e5).sqrt();
        assert!((i - expected).abs() < 1e-18);
        assert!(i < 1e-3);
    }
}
