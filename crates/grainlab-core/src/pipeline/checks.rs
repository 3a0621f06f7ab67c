//! The consistency checks: a state that indexes only what it holds (the
//! force kernels read without bounds checks), and the errors that stop an
//! unstable run, naming the particles.
use super::Simulation;
use crate::contact::disk_disk;
use crate::error::{EngineError, Result};
use crate::vec2::{add, sub};

impl Simulation {
    /// The error of a non-finite position or velocity, naming the particles
    /// (external indices).
    pub(crate) fn non_finite_error(&self) -> EngineError {
        let p = &self.particles;
        let bad: Vec<usize> = (0..p.len())
            .filter(|&q| {
                !(p.position[q][0].is_finite()
                    && p.position[q][1].is_finite()
                    && p.velocity[q][0].is_finite()
                    && p.velocity[q][1].is_finite()
                    && p.angular_velocity[q].is_finite())
            })
            .map(|q| self.external_index(q))
            .collect();
        let shown: Vec<String> = bad.iter().take(10).map(|q| q.to_string()).collect();
        EngineError::Unstable {
            step: self.step_count,
            message: format!(
                "non-finite position or velocity of {} particle(s): {}{}; reduce the time step",
                bad.len(),
                shown.join(", "),
                if bad.len() > 10 { ", ..." } else { "" }
            ),
            particles: bad,
        }
    }

    /// The error of an overlap beyond the limit, naming the pair (or the
    /// particle and the wall) of the largest overlap ratio.
    pub(crate) fn overlap_error(&self) -> EngineError {
        let p = &self.particles;
        let ratio = self.params.max_overlap_ratio;
        let pairs = &self.neighbors.pairs;
        let mut worst: Option<(f64, usize, Option<usize>)> = None;
        for k in 0..pairs.len() {
            let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
            let d = sub(
                add(p.position[j], self.image_offset(pairs.shift[k])),
                p.position[i],
            );
            let g = disk_disk(d, p.radius[i], p.radius[j]);
            let r = g.overlap / p.radius[i].min(p.radius[j]);
            if worst.is_none_or(|(w, _, _)| r > w) {
                worst = Some((r, i, Some(j)));
            }
        }
        let wp = &self.neighbors.wall_pairs;
        for k in 0..wp.wall.len() {
            let q = wp.particle[k] as usize;
            let g = self.walls[wp.wall[k] as usize].disk_contact(p.position[q], p.radius[q]);
            let r = g.overlap / p.radius[q];
            if worst.is_none_or(|(w, _, _)| r > w) {
                worst = Some((r, q, None));
            }
        }
        let (r, i, j) = worst.unwrap_or((0.0, 0, None));
        let i = self.external_index(i);
        let j = j.map(|j| self.external_index(j));
        let (what, particles) = match j {
            Some(j) => (format!("particles {i} and {j}"), vec![i, j]),
            None => (format!("particle {i} and a wall"), vec![i]),
        };
        EngineError::Unstable {
            step: self.step_count,
            message: format!(
                "overlap of {what} reached {:.3} of the smaller radius (limit {ratio}); reduce the time step or the loading rate",
                r
            ),
            particles,
        }
    }

    /// Checks that the state indexes only what it holds: the force kernels read
    /// particle arrays without bounds checks, so a stale or edited state (a
    /// loaded file) must be refused before any step rather than read out of
    /// bounds. Linear in particles and pairs: run
    /// at every load and at the start of every `run` call.
    pub(crate) fn check_consistent(&self) -> Result<()> {
        let bad = |what: &str| {
            Err(EngineError::invalid(
                "state",
                format!("inconsistent state: {what}"),
            ))
        };
        let p = &self.particles;
        let n = p.len();
        let vec2s = [&p.velocity, &p.external_force, &p.force];
        let scalars = [
            &p.rotation,
            &p.angular_velocity,
            &p.radius,
            &p.mass,
            &p.inertia,
            &p.inv_mass,
            &p.inv_inertia,
            &p.external_torque,
            &p.torque,
        ];
        if vec2s.iter().any(|a| a.len() != n)
            || scalars.iter().any(|a| a.len() != n)
            || p.group.len() != n
            || p.fixity.len() != n
            || p.clump.len() != n
            || (p.density.len() != n && p.density.len() != 1)
        {
            return bad("particle arrays of different lengths");
        }
        if self.order.len() != n
            || self.rank.len() != n
            || self
                .order
                .iter()
                .chain(&self.rank)
                .any(|&q| q as usize >= n)
        {
            return bad("particle order");
        }
        if self
            .bonds
            .list
            .iter()
            .any(|b| b.i as usize >= n || b.j as usize >= n)
            || self
                .cement
                .bonds
                .iter()
                .any(|b| b.i as usize >= n || b.j as usize >= n)
            || self.chains.iter().any(|c| {
                c.particles.iter().any(|&q| q as usize >= n)
                    || [c.start_wall, c.end_wall]
                        .iter()
                        .flatten()
                        .any(|&w| w as usize >= self.walls.len())
            })
        {
            return bad("a bond or pressure chain names a particle that does not exist");
        }
        self.clumps.check_consistent(p)?;
        self.neighbors
            .check_consistent(n, self.walls.len(), self.materials.len())
    }
}

#[cfg(test)]
mod tests {
    use crate::{ContactModel, Particles, PeriodicCell, Simulation};

    /// 400 overlapping disks on a jittered grid in a periodic square cell.
    fn small_packing() -> Simulation {
        let (s, n_side) = (1.0e-3, 20);
        let mut pos = Vec::new();
        let mut rad = Vec::new();
        for a in 0..n_side {
            for b in 0..n_side {
                let jitter = 0.03 * (((a * 7 + b * 13) % 11) as f64 / 11.0 - 0.5);
                pos.push([(a as f64 + 0.5 + jitter) * s, (b as f64 + 0.5 - jitter) * s]);
                rad.push((0.5 + 0.04 * (((a + 3 * b) % 5) as f64 / 5.0)) * s);
            }
        }
        let particles = Particles::new(pos, rad, vec![2.0e8]).unwrap();
        let model = ContactModel::linear(8.45e7, 8.45e7, 0.5);
        let mut sim = Simulation::new(particles, model, 1.0e-5, 1).unwrap();
        let l = n_side as f64 * s;
        let cell = PeriodicCell::rectangle([0.0, 0.0], l, l, [true, true]).unwrap();
        sim.set_cell(Some(cell)).unwrap();
        sim
    }

    #[test]
    fn a_state_indexing_what_it_does_not_hold_is_refused() {
        // The force kernels read particle arrays without bounds checks, trusting the
        // neighbour lists; a stale or edited state must be refused when loaded.
        let mut sim = small_packing();
        sim.run(5).unwrap();
        let good = sim.to_bytes().unwrap();
        assert!(Simulation::from_bytes(&good).is_ok());
        let n = sim.particles.len() as u32;
        type Edit = Box<dyn Fn(&mut Simulation)>;
        let cases: Vec<(&str, Edit)> = vec![
            (
                "a pair names a particle",
                Box::new(move |s| s.neighbors.pairs.j[0] = n + 7),
            ),
            (
                "pair arrays",
                Box::new(|s| {
                    s.neighbors.pairs.history.records.pop();
                }),
            ),
            (
                "contact model",
                Box::new(|s| s.neighbors.pairs.model[0] = u16::MAX),
            ),
            (
                "stripe ranges",
                Box::new(|s| s.neighbors.stripe_ranges[0].1 += 1),
            ),
            (
                "particle arrays",
                Box::new(|s| {
                    s.particles.velocity.pop();
                }),
            ),
        ];
        for (what, edit) in cases {
            let mut broken = Simulation::from_bytes(&good).unwrap();
            edit(&mut broken);
            let err = Simulation::from_bytes(&broken.to_bytes().unwrap())
                .err()
                .unwrap_or_else(|| panic!("{what}: must be refused"));
            assert!(err.to_string().contains("inconsistent"), "{what}: {err}");
            // the same edit made in memory is refused by the next run, before any step
            let mut edited = Simulation::from_bytes(&good).unwrap();
            edit(&mut edited);
            let err = edited
                .run(1)
                .err()
                .unwrap_or_else(|| panic!("{what}: run must refuse"));
            assert!(err.to_string().contains("inconsistent"), "{what}: {err}");
        }
    }
}
