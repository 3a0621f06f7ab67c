//! The simulation's bodies: making clumps of its particles, their motion from
//! outside, and what the rest of the simulation asks of them (`body::clumps`).
use super::Simulation;
use crate::body::{Clumps, GivenMass, NewClump};
use crate::error::{
    require_finite_points, require_finite_values, require_positive, EngineError, Result,
};
use crate::state::{NO_CLUMP, PEBBLE};
use crate::vec2::{norm, Vec2};

/// A body to make of existing particles (external indices).
#[derive(Debug, Clone, PartialEq)]
pub struct BodySpec {
    /// The pebbles: one (a plain disk, left as it is) or more (a clump).
    pub pebbles: Vec<usize>,
    /// The body frame's angle in the world (rad): 0 makes the world's axes
    /// the body's, a template's placement angle keeps the template's frame.
    pub angle: f64,
    /// Mass properties given by the user, else the union's at the pebbles' density.
    pub given: Option<GivenMass>,
}

impl Simulation {
    /// The clumps (bodies of two or more pebbles), with internal particle indices.
    pub fn clumps(&self) -> &Clumps {
        &self.clumps
    }

    /// Makes bodies of particles that are not in one yet. Refused, before any
    /// change: a body with no pebble, a pebble named twice or already in a
    /// clump, a pebble in a pressure chain, a bond between two pebbles of one
    /// body, pebbles of one body with different fixity (or densities, unless
    /// the mass is given), a zero or negative given mass.
    pub fn add_bodies(&mut self, bodies: &[BodySpec]) -> Result<()> {
        self.check_bodies(bodies)?;
        let internal: Vec<Vec<usize>> = bodies
            .iter()
            .map(|b| b.pebbles.iter().map(|&e| self.internal_index(e)).collect())
            .collect();
        let new: Vec<NewClump<'_>> = bodies
            .iter()
            .zip(&internal)
            .filter(|(b, _)| b.pebbles.len() > 1)
            .map(|(b, members)| NewClump {
                members,
                angle: b.angle,
                given: b.given,
            })
            .collect();
        if new.is_empty() {
            return Ok(());
        }
        // the clumps are made on a copy, so that a refusal changes nothing
        let mut particles = self.particles.clone();
        let mut clumps = self.clumps.clone();
        clumps.add(&mut particles, self.cell.as_ref(), &new)?;
        self.modify_motion(|s| {
            s.particles = particles;
            s.clumps = clumps;
            s.half_kick_pending = true;
            s.neighbors.invalidate();
        });
        Ok(())
    }

    fn check_bodies(&self, bodies: &[BodySpec]) -> Result<()> {
        let n = self.particles.len();
        let mut body_of = vec![usize::MAX; n];
        for (b, body) in bodies.iter().enumerate() {
            let field = format!("bodies[{b}]");
            if body.pebbles.is_empty() {
                return Err(EngineError::invalid(
                    field,
                    "a body needs at least one pebble",
                ));
            }
            require_finite_values(&format!("{field}.angle"), &[body.angle])?;
            for &e in &body.pebbles {
                self.particles.check_index(&format!("{field}.pebbles"), e)?;
                let q = self.internal_index(e);
                if body_of[q] != usize::MAX {
                    return Err(EngineError::invalid(
                        field,
                        format!("particle {e} is also a pebble of body {}", body_of[q]),
                    ));
                }
                if self.particles.clump[q] != NO_CLUMP {
                    return Err(EngineError::invalid(
                        field,
                        format!("particle {e} is already a pebble of a clump"),
                    ));
                }
                body_of[q] = b;
                let first = self.internal_index(body.pebbles[0]);
                if self.particles.fixity[q] != self.particles.fixity[first] {
                    return Err(EngineError::invalid(
                        field,
                        format!(
                            "particles {} and {e} have different fixity; a body's degrees \
                             of freedom are fixed as one",
                            body.pebbles[0]
                        ),
                    ));
                }
            }
        }
        let clumped = |q: usize| body_of[q] != usize::MAX && bodies[body_of[q]].pebbles.len() > 1;
        if let Some(q) = self
            .chains
            .iter()
            .flat_map(|c| c.particles.iter())
            .map(|&q| q as usize)
            .find(|&q| clumped(q))
        {
            return Err(EngineError::invalid(
                format!("bodies[{}]", body_of[q]),
                format!(
                    "particle {} is in a pressure chain, whose particles are bodies of their own",
                    self.external_index(q)
                ),
            ));
        }
        let bonded = self.bonds.list.iter().map(|b| (b.i, b.j));
        let cemented = self.cement.bonds.iter().map(|b| (b.i, b.j));
        if let Some((i, j)) = bonded.chain(cemented).find(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            clumped(i) && body_of[i] == body_of[j]
        }) {
            return Err(EngineError::invalid(
                format!("bodies[{}]", body_of[i as usize]),
                format!(
                    "particles {} and {} are bonded; two pebbles of one body cannot be",
                    self.external_index(i as usize),
                    self.external_index(j as usize)
                ),
            ));
        }
        Ok(())
    }

    /// The body of every particle, in external order: the clumps are bodies
    /// `0..clumps().len()` in the order they were made, then each plain disk
    /// is a body of its own, numbered on in external order.
    pub fn body_of_particles(&self) -> Vec<u32> {
        let mut next = self.clumps.len() as u32;
        (0..self.particles.len())
            .map(|e| match self.particles.clump[self.internal_index(e)] {
                NO_CLUMP => {
                    next += 1;
                    next - 1
                }
                c => self.clumps.id[c as usize],
            })
            .collect()
    }

    /// Sets every clump's velocity (m/s) and angular velocity (rad/s), in id
    /// order (the order they were made in), as
    /// full-step values (the next step starts with a half kick, as after
    /// [`Simulation::set_velocities`]); the pebbles follow.
    pub fn set_clump_velocities(
        &mut self,
        velocities: &[Vec2],
        angular_velocities: &[f64],
    ) -> Result<()> {
        let n = self.clumps.len();
        for (name, len) in [
            ("clump_velocities", velocities.len()),
            ("clump_angular_velocities", angular_velocities.len()),
        ] {
            if len != n {
                return Err(EngineError::invalid(
                    name,
                    format!("expected {n} values, one per clump, got {len}"),
                ));
            }
        }
        require_finite_points("clump_velocities", velocities)?;
        require_finite_values("clump_angular_velocities", angular_velocities)?;
        self.modify_motion(|s| {
            let ids = &s.clumps.id;
            s.clumps.velocity = ids.iter().map(|&i| velocities[i as usize]).collect();
            s.clumps.angular_velocity = ids
                .iter()
                .map(|&i| angular_velocities[i as usize])
                .collect();
            let gradient = s.deforming_gradient();
            s.clumps
                .place_pebbles(&mut s.particles, s.cell.as_ref(), gradient.as_ref());
            s.half_kick_pending = true;
        });
        Ok(())
    }

    /// Grows every clump by `factors` (in id order, finite and > 0) about its
    /// centroid: its pebbles' radii and offsets scale by the factor, its mass
    /// by its square and its moment of inertia by its fourth power (a similar
    /// body of the same density); velocities are kept. For samples made by
    /// radius expansion ([`Simulation::set_radii`] grows the disks).
    pub fn scale_clumps(&mut self, factors: &[f64]) -> Result<()> {
        let n = self.clumps.len();
        if factors.len() != n {
            return Err(EngineError::invalid(
                "factors",
                format!("expected {n} values, one per clump, got {}", factors.len()),
            ));
        }
        for (k, &f) in factors.iter().enumerate() {
            require_positive(&format!("factors[{k}]"), f)?;
        }
        self.modify_motion(|s| {
            for c in 0..n {
                let factor = factors[s.clumps.id[c] as usize];
                s.clumps.scale(c, factor, &mut s.particles);
            }
            s.clumps.assign_pebble_masses(&mut s.particles);
            let gradient = s.deforming_gradient();
            s.clumps
                .place_pebbles(&mut s.particles, s.cell.as_ref(), gradient.as_ref());
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Refuses a per-particle array (internal order) that changes a pebble's
    /// entry: a pebble moves with its body.
    pub(crate) fn check_pebbles_kept<T: PartialEq + Copy>(
        &self,
        field: &str,
        current: &[T],
        new: &[T],
    ) -> Result<()> {
        if self.clumps.is_empty() {
            return Ok(());
        }
        match (0..new.len()).find(|&q| self.particles.clump[q] != NO_CLUMP && new[q] != current[q])
        {
            Some(q) => Err(EngineError::invalid(
                format!("{field}[{}]", self.external_index(q)),
                format!(
                    "particle {} is a pebble of clump {}: it turns and is sized with its \
                     body (scale_clumps)",
                    self.external_index(q),
                    self.clumps.id[self.particles.clump[q] as usize]
                ),
            )),
            None => Ok(()),
        }
    }

    /// Refuses a per-particle array (internal order) in which two pebbles of
    /// one clump differ, the value being the body's (`why` says so).
    pub(crate) fn check_clumps_agree<T: PartialEq + Copy + std::fmt::Debug>(
        &self,
        field: &str,
        values: &[T],
        why: &str,
    ) -> Result<()> {
        for c in 0..self.clumps.len() {
            let members = &self.clumps.pebble[self.clumps.members(c)];
            let first = values[members[0] as usize];
            if let Some(&q) = members.iter().find(|&&q| values[q as usize] != first) {
                return Err(EngineError::invalid(
                    format!("{field}[{}]", self.external_index(q as usize)),
                    format!(
                        "particles {} and {} are pebbles of clump {} with different {field} \
                         ({first:?} and {:?}); {why}",
                        self.external_index(members[0] as usize),
                        self.external_index(q as usize),
                        self.clumps.id[c],
                        values[q as usize]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A user's fixity (internal order) with each clump's pebbles agreeing,
    /// the clumps' fixity taken from it and the pebble bit kept.
    pub(crate) fn fixity_with_clumps(&mut self, mut fixity: Vec<u8>) -> Result<Vec<u8>> {
        self.check_clumps_agree(
            "fixity",
            &fixity,
            "a body's degrees of freedom are fixed as one",
        )?;
        for c in 0..self.clumps.len() {
            let first = self.clumps.pebble[self.clumps.start[c] as usize] as usize;
            self.clumps.fixity[c] = fixity[first];
            for &q in &self.clumps.pebble[self.clumps.members(c)] {
                fixity[q as usize] |= PEBBLE;
            }
        }
        Ok(fixity)
    }

    /// The critical time step of the clumps, from per-particle stiffness sums
    /// (normal, shear, rolling; 0 where a particle has no contact, then
    /// `fallback`): `min(sqrt(M / sum k_n), sqrt(I / sum (k_n |r|^2 + k_s
    /// (|r| + R)^2 + k_r)))` over the pebbles of each clump, `r` a pebble's arm
    /// from the centroid and `R` its radius (the normal force of a contact acts
    /// through the pebble's centre, the shear force at most `|r| + R` away).
    pub(crate) fn clump_time_step(
        &self,
        [kn, ks, kr]: [&[f64]; 3],
        fallback: impl Fn(usize) -> f64,
    ) -> f64 {
        let c = &self.clumps;
        let mut dt = f64::INFINITY;
        for k in 0..c.len() {
            let (mut translation, mut rotation) = (0.0, 0.0);
            for m in c.members(k) {
                let q = c.pebble[m] as usize;
                let kn_q = if kn[q] > 0.0 { kn[q] } else { fallback(q) };
                let ks_q = if ks[q] > 0.0 { ks[q] } else { fallback(q) };
                let arm = norm(c.offset[m]);
                let reach = arm + self.particles.radius[q];
                translation += kn_q;
                rotation += kn_q * arm * arm + ks_q * reach * reach + kr[q];
            }
            dt = dt
                .min((c.mass[k] / translation).sqrt())
                .min((c.inertia[k] / rotation).sqrt());
        }
        dt
    }
}
