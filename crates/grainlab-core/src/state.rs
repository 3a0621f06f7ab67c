//! Particle state as a structure of arrays: one contiguous array per property.
//!
//! Disks have unit out-of-plane thickness (docs/conventions.md): `m = rho * pi * r^2`,
//! `I = m r^2 / 2`. Velocities are the leapfrog half-step values `v(n - 1/2)`
//! once the simulation has stepped; velocities set by the user are taken as
//! full-step values at the current time, and the next step starts with a half kick.
use serde::{Deserialize, Serialize};

use crate::error::{require_finite, require_positive, EngineError, Result};
use crate::vec2::Vec2;

/// Bit in [`Particles::fixity`]: the x velocity is prescribed.
pub const FIX_X: u8 = 1;
/// Bit in [`Particles::fixity`]: the y velocity is prescribed.
pub const FIX_Y: u8 = 2;
/// Bit in [`Particles::fixity`]: the angular velocity is prescribed.
pub const FIX_ROTATION: u8 = 4;

/// Bit in [`Particles::fixity`], set by the engine only: the particle is a
/// pebble of a clump, moved rigidly with its body (`body::clumps`), not by the
/// particles' integration.
pub const PEBBLE: u8 = 8;

/// [`Particles::clump`] of a particle that is a body of its own (a plain disk).
pub const NO_CLUMP: u32 = u32::MAX;

/// Number of material groups; contact models are set per pair of groups.
pub const MAX_GROUPS: usize = 16;

/// Disks and their per-particle state.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Particles {
    /// Centre positions (m).
    pub position: Vec<Vec2>,
    /// Translational velocities (m/s).
    pub velocity: Vec<Vec2>,
    /// Rotation angles, counter-clockwise (rad).
    pub rotation: Vec<f64>,
    /// Angular velocities, counter-clockwise (rad/s).
    pub angular_velocity: Vec<f64>,
    /// Radii (m).
    pub radius: Vec<f64>,
    /// Densities (kg/m^3).
    pub density: Vec<f64>,
    /// Masses (kg), `rho * pi * r^2` for unit thickness.
    pub mass: Vec<f64>,
    /// Moments of inertia (kg m^2), `m r^2 / 2`.
    pub inertia: Vec<f64>,
    /// `1 / mass`.
    pub inv_mass: Vec<f64>,
    /// `1 / inertia`.
    pub inv_inertia: Vec<f64>,
    /// Material group in `0..MAX_GROUPS`.
    pub group: Vec<u8>,
    /// Prescribed degrees of freedom, a combination of [`FIX_X`], [`FIX_Y`], [`FIX_ROTATION`].
    pub fixity: Vec<u8>,
    /// Constant external force per particle (N), e.g. a boundary load.
    pub external_force: Vec<Vec2>,
    /// Constant external torque per particle (N m).
    pub external_torque: Vec<f64>,
    /// Resultant force of the last step, before damping (N).
    pub force: Vec<Vec2>,
    /// Resultant torque of the last step, before damping (N m).
    pub torque: Vec<f64>,
    /// The clump each particle is a pebble of, or [`NO_CLUMP`]. A pebble's
    /// `mass` and `inertia` are its body's (the contact laws' damping sees the
    /// body), its velocity the body's rigid motion at its centre.
    pub clump: Vec<u32>,
}

impl Particles {
    /// Disks at rest from centres, radii and densities (one density or one per disk).
    pub fn new(position: Vec<Vec2>, radius: Vec<f64>, density: Vec<f64>) -> Result<Self> {
        let n = position.len();
        if radius.len() != n {
            return Err(EngineError::invalid(
                "radius",
                format!("has {} entries but positions has {n}", radius.len()),
            ));
        }
        let density = match density.len() {
            1 => vec![density[0]; n],
            len if len == n => density,
            len => {
                return Err(EngineError::invalid(
                    "density",
                    format!("has {len} entries; give 1 or one per particle ({n})"),
                ))
            }
        };
        for (k, p) in position.iter().enumerate() {
            require_finite(&format!("position[{k}]"), p[0])?;
            require_finite(&format!("position[{k}]"), p[1])?;
        }
        for (k, &r) in radius.iter().enumerate() {
            require_positive(&format!("radius[{k}]"), r)?;
        }
        for (k, &rho) in density.iter().enumerate() {
            require_positive(&format!("density[{k}]"), rho)?;
        }
        let mut particles = Particles {
            velocity: vec![[0.0; 2]; n],
            rotation: vec![0.0; n],
            angular_velocity: vec![0.0; n],
            mass: vec![0.0; n],
            inertia: vec![0.0; n],
            inv_mass: vec![0.0; n],
            inv_inertia: vec![0.0; n],
            group: vec![0; n],
            fixity: vec![0; n],
            external_force: vec![[0.0; 2]; n],
            external_torque: vec![0.0; n],
            force: vec![[0.0; 2]; n],
            torque: vec![0.0; n],
            clump: vec![NO_CLUMP; n],
            position,
            radius,
            density,
        };
        particles.update_mass_properties();
        Ok(particles)
    }

    /// Appends disks at rest (validated like [`Particles::new`]).
    pub fn extend(&mut self, other: Particles) {
        let Particles {
            position,
            velocity,
            rotation,
            angular_velocity,
            radius,
            density,
            mass,
            inertia,
            inv_mass,
            inv_inertia,
            group,
            fixity,
            external_force,
            external_torque,
            force,
            torque,
            clump,
        } = other;
        self.position.extend(position);
        self.velocity.extend(velocity);
        self.rotation.extend(rotation);
        self.angular_velocity.extend(angular_velocity);
        self.radius.extend(radius);
        self.density.extend(density);
        self.mass.extend(mass);
        self.inertia.extend(inertia);
        self.inv_mass.extend(inv_mass);
        self.inv_inertia.extend(inv_inertia);
        self.group.extend(group);
        self.fixity.extend(fixity);
        self.external_force.extend(external_force);
        self.external_torque.extend(external_torque);
        self.force.extend(force);
        self.torque.extend(torque);
        self.clump.extend(clump);
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// True when there are no disks.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Recomputes mass and inertia from radius and density (after either
    /// changed), for the particles that are bodies of their own (a pebble's
    /// are its clump's).
    pub fn update_mass_properties(&mut self) {
        for k in 0..self.len() {
            if self.clump[k] != NO_CLUMP {
                continue;
            }
            let r = self.radius[k];
            let m = self.density[k] * std::f64::consts::PI * r * r;
            let inertia = 0.5 * m * r * r;
            self.mass[k] = m;
            self.inertia[k] = inertia;
            self.inv_mass[k] = 1.0 / m;
            self.inv_inertia[k] = 1.0 / inertia;
        }
    }

    /// Reorders every array: new index `k` takes old index `perm[k]`.
    pub fn permute(&mut self, perm: &[u32]) {
        fn gather<T: Copy>(v: &mut Vec<T>, perm: &[u32]) {
            *v = perm.iter().map(|&o| v[o as usize]).collect();
        }
        gather(&mut self.position, perm);
        gather(&mut self.velocity, perm);
        gather(&mut self.rotation, perm);
        gather(&mut self.angular_velocity, perm);
        gather(&mut self.radius, perm);
        gather(&mut self.density, perm);
        gather(&mut self.mass, perm);
        gather(&mut self.inertia, perm);
        gather(&mut self.inv_mass, perm);
        gather(&mut self.inv_inertia, perm);
        gather(&mut self.group, perm);
        gather(&mut self.fixity, perm);
        gather(&mut self.external_force, perm);
        gather(&mut self.external_torque, perm);
        gather(&mut self.force, perm);
        gather(&mut self.torque, perm);
        gather(&mut self.clump, perm);
    }

    /// Checks that `index` names a particle.
    pub fn check_index(&self, field: &str, index: usize) -> Result<()> {
        if index < self.len() {
            Ok(())
        } else {
            Err(EngineError::invalid(
                field,
                format!("particle index {index} out of range 0..{}", self.len()),
            ))
        }
    }

    /// Largest radius (0 when empty).
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().fold(0.0, |a, &b| a.max(b))
    }
}

/// What the contact and bond laws read of the particles: slices, so that the
/// laws can run while the resultants are being written elsewhere.
#[derive(Clone, Copy)]
pub(crate) struct ParticleMotion<'a> {
    pub position: &'a [Vec2],
    pub velocity: &'a [Vec2],
    pub angular_velocity: &'a [f64],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub inertia: &'a [f64],
}

impl<'a> ParticleMotion<'a> {
    /// The particles' positions, velocities, radii and masses.
    pub(crate) fn of(p: &'a Particles) -> Self {
        ParticleMotion {
            position: &p.position,
            velocity: &p.velocity,
            angular_velocity: &p.angular_velocity,
            radius: &p.radius,
            mass: &p.mass,
            inertia: &p.inertia,
        }
    }
}
