//! The clumps of a simulation: bodies of two or more pebbles, moved rigidly.
//!
//! The pebbles stay particles (`Particles`): the neighbour lists, the contact
//! laws, the walls and the bonds see them as disks, except that two pebbles of
//! one clump are never a pair. What a clump adds is its motion. After the
//! particles' integration, each clump sums its pebbles' resultants (contacts,
//! bonds, walls and external loads) into a force and a torque about its
//! centroid, in member order (the same bits on any number of threads), adds
//! its weight, and takes the particles' leapfrog step with PFC's local damping
//! on each of its three degrees of freedom (`F_d = -alpha |F| sign(v)` on the
//! body's resultant, as PFC2D damps a clump). Its pebbles are then put back in
//! place from the centroid and the angle, `x = X + R(theta) o + image`, so a
//! clump never drifts out of shape, with the rigid velocity at their centres
//! (`V + w x r`, less the imposed flow's `L r` in a deforming cell, whose
//! velocities are relative to that flow).
//!
//! A body of one disk is not a clump: it is integrated as the particles are,
//! bit for bit what it was before bodies existed.
use serde::{Deserialize, Serialize};

use crate::cell::PeriodicCell;
use crate::error::{EngineError, Result};
use crate::integrate::{kick, running_max, IntegrationStep, IntegrationTally};
use crate::parallel::{even_bounds, map_stripes, DisjointWriter, Team};
use crate::state::{Particles, FIX_ROTATION, FIX_X, FIX_Y, NO_CLUMP, PEBBLE};
use crate::vec2::{add, cross, mat_vec, sub, Mat2, Vec2};

use super::{ClumpTemplate, GivenMass};

/// Rigid clumps of pebbles: per clump its motion and mass, and its members
/// (internal particle indices, in the order their resultants are summed).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Clumps {
    /// Centroids (m).
    pub centroid: Vec<Vec2>,
    /// Angles from the body frame to the world, counter-clockwise (rad).
    pub angle: Vec<f64>,
    /// Velocities of the centroids (m/s), leapfrog half-step values as the particles'.
    pub velocity: Vec<Vec2>,
    /// Angular velocities (rad/s).
    pub angular_velocity: Vec<f64>,
    /// Masses per unit thickness (kg per m).
    pub mass: Vec<f64>,
    /// Moments of inertia about the centroid per unit thickness (kg m^2 per m).
    pub inertia: Vec<f64>,
    /// Prescribed degrees of freedom (`FIX_X`, `FIX_Y`, `FIX_ROTATION`).
    pub fixity: Vec<u8>,
    /// Resultant force of the last step, weight included, before damping (N).
    pub force: Vec<Vec2>,
    /// Resultant torque about the centroid of the last step, before damping (N m).
    pub torque: Vec<f64>,
    /// Clump `c`'s members are `pebble[start[c]..start[c + 1]]`.
    pub start: Vec<u32>,
    /// The members' internal particle indices.
    pub pebble: Vec<u32>,
    /// The members' centres in the body frame, from the centroid (m).
    pub offset: Vec<Vec2>,
    /// The periodic image each member is kept in (cell vectors `a`, `b`).
    pub image: Vec<[i32; 2]>,
    /// The members' arms from the centroid in the world, `R(angle) offset`,
    /// as last placed (m).
    pub arm: Vec<Vec2>,
    /// Each clump's id, the order it was made in: the clumps are kept in the
    /// order of their first pebble's place in the particles' spatial order,
    /// so that the clumps' step walks the particles' arrays in order.
    pub id: Vec<u32>,
}

/// A new clump: its members (internal indices) and how its mass is known.
pub struct NewClump<'a> {
    /// Internal particle indices of the pebbles (two or more).
    pub members: &'a [usize],
    /// The body frame's angle in the world (rad): the offsets are stored
    /// rotated back by it.
    pub angle: f64,
    /// Mass properties given by the user, else those of the pebbles' union
    /// at their (common) density.
    pub given: Option<GivenMass>,
}

/// `R(angle) o`, with the angle's sine and cosine.
#[inline(always)]
fn rotate((s, c): (f64, f64), o: Vec2) -> Vec2 {
    [c * o[0] - s * o[1], s * o[0] + c * o[1]]
}

/// `w x r` in the plane.
#[inline(always)]
fn spin(w: f64, r: Vec2) -> Vec2 {
    [-w * r[1], w * r[0]]
}

/// The rigid velocity `v + w x r` at arm `r` from the centroid, relative to
/// the imposed flow `L x` when there is one (`gradient`).
#[inline(always)]
fn rigid_velocity(v: Vec2, w: f64, r: Vec2, gradient: Option<&Mat2>) -> Vec2 {
    let v = add(v, spin(w, r));
    match gradient {
        Some(l) => sub(v, mat_vec(l, r)),
        None => v,
    }
}

/// `s0 a + s1 b` of the cell (zero without one).
fn image_offset(cell: Option<&PeriodicCell>, s: [i32; 2]) -> Vec2 {
    match cell {
        Some(c) if s != [0, 0] => [
            s[0] as f64 * c.a[0] + s[1] as f64 * c.b[0],
            s[0] as f64 * c.a[1] + s[1] as f64 * c.b[1],
        ],
        _ => [0.0; 2],
    }
}

/// The whole cell vectors between `x` and `y` (`x - y` rounded in the cell's
/// frame; zero without a cell).
fn image_between(cell: Option<&PeriodicCell>, x: Vec2, y: Vec2) -> [i32; 2] {
    match cell {
        Some(c) => {
            let f = c.fractional(add(c.origin, sub(x, y)));
            [f[0].round() as i32, f[1].round() as i32]
        }
        None => [0, 0],
    }
}

impl Clumps {
    /// Number of clumps.
    pub fn len(&self) -> usize {
        self.mass.len()
    }

    /// True when no body has more than one pebble.
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    /// The member range of clump `c` in `pebble`, `offset` and `image`.
    pub fn members(&self, c: usize) -> std::ops::Range<usize> {
        self.start[c] as usize..self.start[c + 1] as usize
    }

    /// Makes clumps of existing particles: mass properties from the union of
    /// each clump's pebbles (their density must then be one) or as given,
    /// velocity and angular velocity those that keep the pebbles' momentum and
    /// angular momentum, pebbles put in rigid motion. The caller has checked
    /// that the members exist, are plain disks and are in one clump each.
    pub(crate) fn add(
        &mut self,
        particles: &mut Particles,
        cell: Option<&PeriodicCell>,
        clumps: &[NewClump<'_>],
    ) -> Result<()> {
        if self.start.is_empty() {
            self.start.push(0);
        }
        for (k, new) in clumps.iter().enumerate() {
            self.add_one(particles, cell, k, new)?;
        }
        self.assign_pebble_masses(particles);
        self.place_pebbles(particles, cell, None);
        Ok(())
    }

    fn add_one(
        &mut self,
        particles: &mut Particles,
        cell: Option<&PeriodicCell>,
        k: usize,
        new: &NewClump<'_>,
    ) -> Result<()> {
        let p = &*particles;
        let first = p.position[new.members[0]];
        // the pebbles as one piece: each at its image nearest the first
        let centres: Vec<Vec2> = new
            .members
            .iter()
            .map(|&q| {
                let x = p.position[q];
                sub(x, image_offset(cell, image_between(cell, x, first)))
            })
            .collect();
        let radii: Vec<f64> = new.members.iter().map(|&q| p.radius[q]).collect();
        let (template, placement) = match new.given {
            Some(given) => ClumpTemplate::with_mass(&centres, &radii, given),
            None => {
                let density = p.density[new.members[0]];
                if let Some(&q) = new.members.iter().find(|&&q| p.density[q] != density) {
                    return Err(EngineError::invalid(
                        format!("bodies[{k}]"),
                        format!(
                            "pebbles {} and {q} have different densities: give the body's mass",
                            new.members[0]
                        ),
                    ));
                }
                ClumpTemplate::from_pebbles(&centres, &radii, density)
            }
        }
        .map_err(|e| match e {
            EngineError::InvalidInput { field, message } => {
                EngineError::invalid(format!("bodies[{k}].{field}"), message)
            }
            other => other,
        })?;
        let (mass, inertia) = (template.mass(), template.moment_of_inertia());
        // the rigid motion with the pebbles' momentum and angular momentum
        // about the centroid, the pebbles taken as disks of their own
        let (mut momentum, mut disk_mass) = ([0.0; 2], 0.0);
        for &q in new.members {
            let (m, v) = (p.mass[q], p.velocity[q]);
            momentum = add(momentum, [m * v[0], m * v[1]]);
            disk_mass += m;
        }
        let mean = [momentum[0] / disk_mass, momentum[1] / disk_mass];
        let (mut spin_momentum, mut spin_inertia) = (0.0, 0.0);
        for (&q, &x) in new.members.iter().zip(&centres) {
            let r = sub(x, placement.centroid);
            let m = p.mass[q];
            spin_momentum +=
                m * cross(r, sub(p.velocity[q], mean)) + p.inertia[q] * p.angular_velocity[q];
            spin_inertia += m * (r[0] * r[0] + r[1] * r[1]) + p.inertia[q];
        }
        let velocity = mean;
        let angular_velocity = spin_momentum / spin_inertia;
        let c = self.len() as u32;
        let back = (-new.angle).sin_cos();
        for ((&q, &o), &x) in new.members.iter().zip(template.offsets()).zip(&centres) {
            self.pebble.push(q as u32);
            self.offset.push(rotate(back, o));
            self.image.push(image_between(cell, p.position[q], x));
            self.arm.push([0.0; 2]);
        }
        let fixity = p.fixity[new.members[0]] & !PEBBLE;
        for &q in new.members {
            particles.clump[q] = c;
        }
        // the body's fixity is its pebbles' (the caller checked they agree)
        self.fixity.push(fixity);
        self.centroid.push(placement.centroid);
        self.angle.push(new.angle);
        self.velocity.push(velocity);
        self.angular_velocity.push(angular_velocity);
        self.mass.push(mass);
        self.inertia.push(inertia);
        self.force.push([0.0; 2]);
        self.torque.push(0.0);
        self.start.push(self.pebble.len() as u32);
        self.id.push(c);
        Ok(())
    }

    /// Grows clump `c` (in the clumps' order) by `factor` about its centroid:
    /// pebble radii and offsets times `factor`, mass times `factor^2` and
    /// moment of inertia times `factor^4` (a similar body of the same
    /// density); the caller puts the pebbles in place.
    pub(crate) fn scale(&mut self, c: usize, factor: f64, particles: &mut Particles) {
        for m in self.members(c) {
            let q = self.pebble[m] as usize;
            particles.radius[q] *= factor;
            self.offset[m] = [self.offset[m][0] * factor, self.offset[m][1] * factor];
        }
        let area_factor = factor * factor;
        self.mass[c] *= area_factor;
        self.inertia[c] *= area_factor * area_factor;
    }

    /// Gives clump `c` the density `density` (its pebbles', which agree): its
    /// mass and moment of inertia times the ratio to the pebbles' old density
    /// (`particles.density`, not yet changed), exact for a body of uniform
    /// density, given or computed; the pebbles' masses follow
    /// ([`Clumps::assign_pebble_masses`]).
    pub(crate) fn rescale_density(&mut self, c: usize, density: f64, particles: &Particles) {
        let old = particles.density[self.pebble[self.start[c] as usize] as usize];
        if density != old {
            let ratio = density / old;
            self.mass[c] *= ratio;
            self.inertia[c] *= ratio;
        }
    }

    /// Gives every pebble its clump's mass and inertia and the `PEBBLE` bit.
    pub(crate) fn assign_pebble_masses(&self, particles: &mut Particles) {
        for c in 0..self.len() {
            let (m, i) = (self.mass[c], self.inertia[c]);
            for &q in &self.pebble[self.members(c)] {
                let q = q as usize;
                particles.mass[q] = m;
                particles.inertia[q] = i;
                particles.inv_mass[q] = 1.0 / m;
                particles.inv_inertia[q] = 1.0 / i;
                particles.fixity[q] = self.fixity[c] | PEBBLE;
            }
        }
    }

    /// Follows a renumbering of the particles (`new_of_old[old] = new`),
    /// and puts the clumps in the order of their first pebbles.
    pub(crate) fn remap(&mut self, new_of_old: &[u32], particles: &mut Particles) {
        for q in self.pebble.iter_mut() {
            *q = new_of_old[*q as usize];
        }
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by_key(|&c| self.pebble[self.start[c] as usize]);
        fn gather<T: Copy>(v: &mut Vec<T>, order: &[usize]) {
            *v = order.iter().map(|&o| v[o]).collect();
        }
        fn gather_members<T: Copy>(v: &mut Vec<T>, order: &[usize], start: &[u32]) {
            *v = order
                .iter()
                .flat_map(|&o| v[start[o] as usize..start[o + 1] as usize].to_vec())
                .collect();
        }
        let start = self.start.clone();
        gather_members(&mut self.pebble, &order, &start);
        gather_members(&mut self.offset, &order, &start);
        gather_members(&mut self.image, &order, &start);
        gather_members(&mut self.arm, &order, &start);
        for v in [&mut self.centroid, &mut self.velocity, &mut self.force] {
            gather(v, &order);
        }
        for v in [
            &mut self.angle,
            &mut self.angular_velocity,
            &mut self.mass,
            &mut self.inertia,
            &mut self.torque,
        ] {
            gather(v, &order);
        }
        gather(&mut self.fixity, &order);
        gather(&mut self.id, &order);
        let mut next = 0u32;
        self.start = std::iter::once(0)
            .chain(order.iter().map(|&o| {
                next += start[o + 1] - start[o];
                next
            }))
            .collect();
        for (c, q) in self.member_clumps().collect::<Vec<_>>() {
            particles.clump[q as usize] = c as u32;
        }
    }

    /// The clumps' values in id order, from values in the clumps' order.
    pub fn in_id_order<T: Copy + Default>(&self, values: &[T]) -> Vec<T> {
        let mut out = vec![T::default(); values.len()];
        for (c, &id) in self.id.iter().enumerate() {
            out[id as usize] = values[c];
        }
        out
    }

    /// After the neighbour-list build wrapped the particles: the centroids
    /// wrapped too, and each pebble's image read again from where it is.
    pub(crate) fn rewrap(&mut self, particles: &Particles, cell: Option<&PeriodicCell>) {
        let Some(cell) = cell else { return };
        for c in 0..self.len() {
            cell.wrap(&mut self.centroid[c]);
            for m in self.members(c) {
                let rigid = add(self.centroid[c], self.arm[m]);
                let x = particles.position[self.pebble[m] as usize];
                self.image[m] = image_between(Some(cell), x, rigid);
            }
        }
    }

    /// The clumps with a member whose entry of `new` (a per-particle array)
    /// differs from `current`'s.
    pub(crate) fn changed<T: PartialEq>(&self, current: &[T], new: &[T]) -> Vec<usize> {
        (0..self.len())
            .filter(|&c| {
                self.pebble[self.members(c)]
                    .iter()
                    .any(|&q| current[q as usize] != new[q as usize])
            })
            .collect()
    }

    /// Clump `c` placed where its pebbles' `positions` put it: the rotation and
    /// translation of its body frame closest to them in least squares (exact
    /// for a rigidly moved clump), each pebble taken at its image nearest the
    /// first; the images read again.
    pub(crate) fn fit_placement(
        &mut self,
        c: usize,
        positions: &[Vec2],
        cell: Option<&PeriodicCell>,
    ) {
        let members = self.members(c);
        let first = positions[self.pebble[members.start] as usize];
        let world: Vec<Vec2> = self.pebble[members.clone()]
            .iter()
            .map(|&q| {
                let x = positions[q as usize];
                sub(x, image_offset(cell, image_between(cell, x, first)))
            })
            .collect();
        let n = world.len() as f64;
        let mean = |points: &mut dyn Iterator<Item = Vec2>| {
            let s = points.fold([0.0; 2], add);
            [s[0] / n, s[1] / n]
        };
        let offsets = &self.offset[members.clone()];
        let (body_mean, world_mean) = (
            mean(&mut offsets.iter().copied()),
            mean(&mut world.iter().copied()),
        );
        let (mut along, mut across) = (0.0, 0.0);
        for (&o, &p) in offsets.iter().zip(&world) {
            let (o, p) = (sub(o, body_mean), sub(p, world_mean));
            along += o[0] * p[0] + o[1] * p[1];
            across += cross(o, p);
        }
        let angle = across.atan2(along);
        self.angle[c] = angle;
        self.centroid[c] = sub(world_mean, rotate(angle.sin_cos(), body_mean));
        for (m, &x) in members.zip(&world) {
            let q = self.pebble[m] as usize;
            self.image[m] = image_between(cell, positions[q], x);
        }
    }

    /// Clump `c`'s velocity and angular velocity fitted to its pebbles'
    /// `velocity` (relative to the imposed flow when `gradient`): the rigid
    /// motion `V + w x r` closest to them in least squares (exact for a rigid
    /// one), at the pebbles' current arms.
    pub(crate) fn fit_velocity(&mut self, c: usize, velocity: &[Vec2], gradient: Option<&Mat2>) {
        let members = self.members(c);
        let n = members.len() as f64;
        let absolute = |m: usize| {
            let v = velocity[self.pebble[m] as usize];
            match gradient {
                Some(l) => add(v, mat_vec(l, self.arm[m])),
                None => v,
            }
        };
        let (mut r_sum, mut v_sum) = ([0.0; 2], [0.0; 2]);
        for m in members.clone() {
            r_sum = add(r_sum, self.arm[m]);
            v_sum = add(v_sum, absolute(m));
        }
        let (r_mean, v_mean) = ([r_sum[0] / n, r_sum[1] / n], [v_sum[0] / n, v_sum[1] / n]);
        let (mut turn, mut spread) = (0.0, 0.0);
        for m in members {
            let (r, v) = (sub(self.arm[m], r_mean), sub(absolute(m), v_mean));
            turn += cross(r, v);
            spread += r[0] * r[0] + r[1] * r[1];
        }
        let w = if spread > 0.0 { turn / spread } else { 0.0 };
        self.angular_velocity[c] = w;
        self.velocity[c] = sub(v_mean, spin(w, r_mean));
    }

    /// Clump `c`'s angular velocity: the mean of its pebbles' `angular_velocity`.
    pub(crate) fn fit_angular_velocity(&mut self, c: usize, angular_velocity: &[f64]) {
        let members = self.members(c);
        let n = members.len() as f64;
        let sum: f64 = self.pebble[members]
            .iter()
            .map(|&q| angular_velocity[q as usize])
            .sum();
        self.angular_velocity[c] = sum / n;
    }

    /// Puts every pebble at its rigid place and velocity, with the clump's
    /// angle, angular velocity and fixity; `gradient` is the deforming cell's
    /// velocity gradient, if any.
    pub(crate) fn place_pebbles(
        &mut self,
        particles: &mut Particles,
        cell: Option<&PeriodicCell>,
        gradient: Option<&Mat2>,
    ) {
        for c in 0..self.len() {
            self.place_clump(c, particles, cell, gradient);
        }
    }

    /// [`Clumps::place_pebbles`] for clump `c` alone.
    pub(crate) fn place_clump(
        &mut self,
        c: usize,
        particles: &mut Particles,
        cell: Option<&PeriodicCell>,
        gradient: Option<&Mat2>,
    ) {
        {
            let turn = self.angle[c].sin_cos();
            for m in self.members(c) {
                let q = self.pebble[m] as usize;
                let r = rotate(turn, self.offset[m]);
                self.arm[m] = r;
                particles.position[q] =
                    add(add(self.centroid[c], r), image_offset(cell, self.image[m]));
                let (v, w) = (self.velocity[c], self.angular_velocity[c]);
                particles.velocity[q] = rigid_velocity(v, w, r, gradient);
                particles.angular_velocity[q] = self.angular_velocity[c];
                particles.rotation[q] = self.angle[c];
            }
        }
    }

    /// One leapfrog step of every clump, after the particles' (their pebbles'
    /// resultants complete): see the module documentation. The clumps go in
    /// `chunks` contiguous shares (a number that depends on the system only,
    /// so that the sums come out the same on any team), on the team if any.
    pub(crate) fn integrate<const MEASURE: bool>(
        &mut self,
        particles: &mut Particles,
        frame: &ClumpFrame<'_>,
        chunks: usize,
        team: Option<&Team>,
    ) -> IntegrationTally {
        let shares = even_bounds(self.len(), chunks);
        let pass = ClumpPass::new(self, particles, frame);
        let tallies = map_stripes(team, shares, |(lo, hi)| {
            let mut sums = ClumpSums::default();
            for c in lo..hi {
                // SAFETY: each clump is in one share, and its pebbles are its own
                unsafe { pass.step_one::<MEASURE>(c, &mut sums) };
            }
            sums
        });
        let mut total = IntegrationTally::default();
        for sums in &tallies {
            let mut tally = sums.tally;
            tally.damping_dissipated = -sums.damping_work * frame.step.kick;
            total.merge(&tally);
        }
        total
    }

    /// The members of every clump in order, with the index of their clump.
    pub fn member_clumps(&self) -> impl Iterator<Item = (usize, u32)> + '_ {
        (0..self.len()).flat_map(move |c| self.members(c).map(move |m| (c, self.pebble[m])))
    }

    /// Checks the clumps against the particles (after loading a state).
    pub(crate) fn check_consistent(&self, particles: &Particles) -> Result<()> {
        let n_clumps = self.len();
        let per_clump = [
            self.angle.len(),
            self.angular_velocity.len(),
            self.inertia.len(),
            self.fixity.len(),
            self.torque.len(),
            self.velocity.len(),
            self.centroid.len(),
            self.force.len(),
        ];
        let members = self.pebble.len();
        let bad = per_clump.iter().any(|&l| l != n_clumps)
            || (n_clumps > 0 && self.start.len() != n_clumps + 1)
            || self.offset.len() != members
            || self.image.len() != members
            || self.arm.len() != members
            || self.id.len() != n_clumps
            || {
                let mut seen = vec![false; n_clumps];
                self.id.iter().any(|&i| {
                    let repeated = (i as usize) >= n_clumps || seen[i as usize];
                    if !repeated {
                        seen[i as usize] = true;
                    }
                    repeated
                })
            }
            || self.start.windows(2).any(|w| w[1] < w[0] + 2)
            || self.start.last().is_some_and(|&s| s as usize != members)
            || self.pebble.iter().any(|&q| q as usize >= particles.len())
            || self
                .member_clumps()
                .any(|(c, q)| particles.clump[q as usize] != c as u32)
            || particles.clump.iter().filter(|&&c| c != NO_CLUMP).count() != members;
        if bad {
            return Err(EngineError::invalid(
                "state",
                "inconsistent state: the clumps and their pebbles disagree",
            ));
        }
        Ok(())
    }
}

/// Where the clumps' step happens: the step's constants, the cell after this
/// step's deformation, its velocity gradient when it deforms, and the
/// positions at the last neighbour-list build.
pub(crate) struct ClumpFrame<'a> {
    pub(crate) step: &'a IntegrationStep,
    pub(crate) cell: Option<&'a PeriodicCell>,
    pub(crate) gradient: Option<&'a Mat2>,
    pub(crate) reference: &'a [Vec2],
}

impl ClumpFrame<'_> {
    /// `origin - M_acc origin`: the accumulated map's image of a reference
    /// point `r` is `shift + M_acc r` (zero without a deforming cell).
    fn accumulated_shift(&self) -> Vec2 {
        match &self.step.step_map {
            Some((origin, _)) => sub(*origin, mat_vec(&self.step.accumulated_map, *origin)),
            None => [0.0; 2],
        }
    }
}

/// The running sums of one share of the clumps' step.
#[derive(Default)]
struct ClumpSums {
    tally: IntegrationTally,
    damping_work: f64,
}

/// The clumps' and the particles' arrays as one share of the clumps' step
/// reads and writes them: each clump writes only its own entries and its
/// own pebbles'.
struct ClumpPass<'a> {
    frame: &'a ClumpFrame<'a>,
    accumulated_shift: Vec2,
    clumps: ClumpColumns,
    members: MemberColumns<'a>,
    mass: (&'a [f64], &'a [f64], &'a [u8]),
    arm: DisjointWriter<Vec2>,
    load: (&'a [Vec2], &'a [f64], &'a [Vec2], &'a [f64]),
    position: DisjointWriter<Vec2>,
    velocity: DisjointWriter<Vec2>,
    angular_velocity: DisjointWriter<f64>,
    rotation: DisjointWriter<f64>,
}

/// The clumps' members: `start` (CSR), pebble, body-frame offset, image.
struct MemberColumns<'a> {
    start: &'a [u32],
    pebble: &'a [u32],
    offset: &'a [Vec2],
    image: &'a [[i32; 2]],
}

/// The clumps' per-clump motion, written clump by clump.
struct ClumpColumns {
    centroid: DisjointWriter<Vec2>,
    angle: DisjointWriter<f64>,
    velocity: DisjointWriter<Vec2>,
    angular_velocity: DisjointWriter<f64>,
    force: DisjointWriter<Vec2>,
    torque: DisjointWriter<f64>,
}

// SAFETY: the writers are used for disjoint elements only (`ClumpPass`).
unsafe impl Sync for ClumpPass<'_> {}

impl<'a> ClumpPass<'a> {
    fn new(
        clumps: &'a mut Clumps,
        particles: &'a mut Particles,
        frame: &'a ClumpFrame<'a>,
    ) -> Self {
        let columns = ClumpColumns {
            centroid: DisjointWriter::new(&mut clumps.centroid),
            angle: DisjointWriter::new(&mut clumps.angle),
            velocity: DisjointWriter::new(&mut clumps.velocity),
            angular_velocity: DisjointWriter::new(&mut clumps.angular_velocity),
            force: DisjointWriter::new(&mut clumps.force),
            torque: DisjointWriter::new(&mut clumps.torque),
        };
        let arm = DisjointWriter::new(&mut clumps.arm);
        let p = particles;
        ClumpPass {
            frame,
            accumulated_shift: frame.accumulated_shift(),
            clumps: columns,
            members: MemberColumns {
                start: &clumps.start,
                pebble: &clumps.pebble,
                offset: &clumps.offset,
                image: &clumps.image,
            },
            mass: (&clumps.mass, &clumps.inertia, &clumps.fixity),
            arm,
            position: DisjointWriter::new(&mut p.position),
            velocity: DisjointWriter::new(&mut p.velocity),
            angular_velocity: DisjointWriter::new(&mut p.angular_velocity),
            rotation: DisjointWriter::new(&mut p.rotation),
            load: (&p.force, &p.torque, &p.external_force, &p.external_torque),
        }
    }

    /// Clump `c`'s step: its resultant about the centroid from its pebbles'
    /// (their arms from the last placement), the kick with local damping per
    /// degree of freedom, the drift, and its pebbles put in place.
    ///
    /// # Safety
    /// No other task steps clump `c` at the same time.
    #[inline(always)]
    unsafe fn step_one<const MEASURE: bool>(&self, c: usize, sums: &mut ClumpSums) {
        let step = self.frame.step;
        let (start, pebble) = (self.members.start, self.members.pebble);
        let members = start[c] as usize..start[c + 1] as usize;
        let (force, torque, external_force, external_torque) = self.load;
        let (mut f, mut t) = ([0.0; 2], 0.0);
        let (mut fe, mut te) = ([0.0; 2], 0.0);
        for m in members.clone() {
            let q = pebble[m] as usize;
            let r = *self.arm.get(m);
            let fq = force[q];
            f = add(f, fq);
            t += torque[q] + cross(r, fq);
            if step.has_external {
                let e = external_force[q];
                fe = add(fe, e);
                te += external_torque[q] + cross(r, e);
            }
        }
        let (masses, inertias, fixities) = self.mass;
        let mass = masses[c];
        let weight = [mass * step.gravity[0], mass * step.gravity[1]];
        f = add(f, weight);
        fe = add(fe, weight);
        let cc = &self.clumps;
        *cc.force.get(c) = f;
        *cc.torque.get(c) = t;
        let fix = fixities[c];
        let (v_old, w_old) = (*cc.velocity.get(c), *cc.angular_velocity.get(c));
        let (mut v, mut w, mut fd) = (v_old, w_old, [0.0; 3]);
        let (alpha, inv_m) = (step.alpha, 1.0 / mass);
        if fix & FIX_X == 0 {
            (v[0], fd[0]) = kick::<true>(v_old[0], f[0], inv_m, alpha, step.kick);
        }
        if fix & FIX_Y == 0 {
            (v[1], fd[1]) = kick::<true>(v_old[1], f[1], inv_m, alpha, step.kick);
        }
        if fix & FIX_ROTATION == 0 {
            (w, fd[2]) = kick::<true>(w_old, t, 1.0 / inertias[c], alpha, step.kick);
        }
        // the same energy identities as the particles' (`StripeKernel::book`)
        let v_full = [0.5 * (v_old[0] + v[0]), 0.5 * (v_old[1] + v[1])];
        let w_full = 0.5 * (w_old + w);
        sums.damping_work += fd[0] * v_full[0] + fd[1] * v_full[1] + fd[2] * w_full;
        if step.has_external {
            let free = |bit: u8, x: f64| if fix & bit == 0 { x } else { 0.0 };
            sums.tally.external_work += (free(FIX_X, fe[0]) * v_full[0]
                + free(FIX_Y, fe[1]) * v_full[1]
                + free(FIX_ROTATION, te) * w_full)
                * step.kick;
        }
        if MEASURE {
            let (vk, wk) = if step.half_kick {
                (v_old, w_old)
            } else {
                (v, w)
            };
            sums.tally.kinetic +=
                0.5 * mass * (v_old[0] * vk[0] + v_old[1] * vk[1]) + 0.5 * inertias[c] * w_old * wk;
            if fix == 0 {
                sums.tally.unbalanced_force_sum += (f[0] * f[0] + f[1] * f[1]).sqrt();
                sums.tally.free_count += 1;
            }
        }
        let mut x = *cc.centroid.get(c);
        x[0] += step.dt * v[0];
        x[1] += step.dt * v[1];
        if let Some((origin, map)) = &step.step_map {
            x = add(*origin, mat_vec(map, sub(x, *origin)));
        }
        sums.tally.non_finite |= !(x[0].is_finite() & x[1].is_finite() & w.is_finite());
        let angle = *cc.angle.get(c) + step.dt * w;
        *cc.centroid.get(c) = x;
        *cc.velocity.get(c) = v;
        *cc.angular_velocity.get(c) = w;
        *cc.angle.get(c) = angle;
        self.place::<true>(members, [x, v], [angle, w], sums);
    }

    /// Puts the pebbles `members` of a clump at centroid `x`, velocity `v`,
    /// angle and angular velocity `[angle, w]`, and (`TRACK`) measures their
    /// displacements since the last build for the rebuild criterion, as the
    /// particles' integration does.
    ///
    /// # Safety
    /// As [`ClumpPass::step_one`], for the clump of `members`.
    #[inline(always)]
    unsafe fn place<const TRACK: bool>(
        &self,
        members: std::ops::Range<usize>,
        [x, v]: [Vec2; 2],
        [angle, w]: [f64; 2],
        sums: &mut ClumpSums,
    ) {
        let frame = self.frame;
        let MemberColumns {
            pebble,
            offset,
            image,
            ..
        } = self.members;
        let turn = angle.sin_cos();
        for m in members {
            let q = pebble[m] as usize;
            let r = rotate(turn, offset[m]);
            *self.arm.get(m) = r;
            let xq = add(add(x, r), image_offset(frame.cell, image[m]));
            *self.position.get(q) = xq;
            *self.velocity.get(q) = rigid_velocity(v, w, r, frame.gradient);
            *self.angular_velocity.get(q) = w;
            *self.rotation.get(q) = angle;
            if TRACK {
                sums.track(xq, frame.reference[q], frame.step, self.accumulated_shift);
            }
        }
    }
}

impl ClumpSums {
    /// A pebble's displacement from its place `r` at the last build, and its
    /// fluctuation about the accumulated affine map in a deforming cell
    /// (`shift`: [`ClumpFrame::accumulated_shift`]).
    #[inline(always)]
    fn track(&mut self, x: Vec2, r: Vec2, step: &IntegrationStep, shift: Vec2) {
        let d = sub(x, r);
        let d2 = d[0] * d[0] + d[1] * d[1];
        let t = &mut self.tally;
        t.max_displacement_sq = running_max(t.max_displacement_sq, d2);
        t.max_fluctuation_sq = match &step.step_map {
            Some(_) => {
                let u = sub(x, add(shift, mat_vec(&step.accumulated_map, r)));
                running_max(t.max_fluctuation_sq, u[0] * u[0] + u[1] * u[1])
            }
            None => t.max_displacement_sq,
        };
    }
}
