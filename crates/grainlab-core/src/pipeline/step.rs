//! The step pipeline: [`Simulation::run`] and the stages of one step, in the
//! order of the module documentation of [`crate::pipeline`].
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};

use super::cement_pass::evaluate_cement_bonds;
use super::deferred::{add_bond_slots, DeferredForces, WallSlot};
use super::pair_kernel::{
    pair_kernel, wall_contact, BufferSink, ContactTally, CrossForces, DirectSink, PairForce,
    PairKernel, ResetKernel, StripeWork,
};
use super::Simulation;
use crate::body::ClumpFrame;
use crate::bond::{bond_slot, Bond, BondSlot};
use crate::cement::{BondBreak, CementBond, CementSlot, Rupture};
use crate::diagnostics::Measurements;
use crate::error::Result;
use crate::integrate::{
    integrate_stripe, IntegrationInputs, IntegrationStep, IntegrationTally, MotionStripe,
};
use crate::law::history::ContactHistory;
use crate::law::ContactRecord;
use crate::neighbor::WallPairList;
use crate::parallel::{
    even_bounds, map_stripes, split_ranges, DisjointWriter, Team, PARALLEL_MIN_PARTICLES,
};
use crate::state::ParticleMotion;
use crate::vec2::{add, dot, perp, scale, sub, Mat2, Vec2};

/// A stripe's two tallies: its pairs' (interior, then across stripes) and
/// its cement bonds'. Kept apart until the pairs across stripes are in, so
/// that a step with a team and one without sum them in the same order.
type StripeTallies = [ContactTally; 2];

/// The tallies of the stripes, in stripe order (each its pairs', then its
/// cement's), then the bonds'.
fn merge_tallies(stripes: &[StripeTallies], bonds: &ContactTally) -> ContactTally {
    let mut contacts = ContactTally::default();
    for [pairs, cement] in stripes {
        contacts.merge(pairs);
        contacts.merge(cement);
    }
    contacts.merge(bonds);
    contacts
}

impl Simulation {
    /// Runs `n` steps without measuring any of them (faster; dissipation is still tallied).
    pub fn advance(&mut self, n: u64) -> Result<()> {
        self.run_steps(n, false)
    }

    /// Runs `n` steps; the last one is measured (see [`Simulation::measurements`]).
    pub fn run(&mut self, n: u64) -> Result<()> {
        self.run_steps(n, true)
    }

    /// The step loop, on the simulation's pool when it has one and the system is
    /// large enough: one broadcast per call, worker 0 steps, the others serve phases.
    fn run_steps(&mut self, n: u64, measure_last: bool) -> Result<()> {
        self.check_consistent()?;
        // the chains and bonds cannot change during a run call (a rebuild maps
        // them along and indexes them again)
        self.index_stripes();
        // external loads cannot change during a run call: scan them once, not every step
        let p = &self.particles;
        self.external_loads = p.external_force.iter().any(|f| *f != [0.0, 0.0])
            || p.external_torque.iter().any(|&t| t != 0.0);
        let steps = |sim: &mut Simulation, team: Option<&Team>| -> Result<()> {
            sim.pacer.start();
            for k in 0..n {
                // with a team, the pacer may run a step on this thread alone
                let team = team.filter(|_| !sim.pacer.alone());
                let builds = sim.neighbors.build_count;
                if measure_last && k + 1 == n {
                    sim.step::<true>(team)?;
                } else {
                    sim.step::<false>(team)?;
                }
                sim.pacer.step_done(sim.neighbors.build_count != builds);
            }
            Ok(())
        };
        let pool = match self.pool.take() {
            Some(pool) if self.particles.len() >= PARALLEL_MIN_PARTICLES && n > 0 => pool,
            other => {
                self.pool = other;
                return steps(self, None);
            }
        };
        let team = Team::new(self.threads);
        let this = SimPtr(self as *mut Simulation);
        let results = pool.broadcast(|ctx| {
            if ctx.index() == 0 {
                // SAFETY: only worker 0 touches the simulation outside of team
                // phases, and the phases obey the stripe ownership rules.
                let sim = unsafe { &mut *this.get() };
                let out = catch_unwind(AssertUnwindSafe(|| steps(sim, Some(&team))));
                team.dismiss();
                Some(out)
            } else {
                team.serve(ctx.index());
                None
            }
        });
        self.pool = Some(pool);
        match results.into_iter().next().flatten() {
            Some(Ok(result)) => result,
            Some(Err(panic)) => resume_unwind(panic),
            None => unreachable!("worker 0 always reports"),
        }
    }

    /// One step, as the list of its stages (the module documentation gives
    /// their order and what each does); `MEASURE` adds kinetic and elastic
    /// energy, contact counts and the unbalanced force ratio.
    fn step<const MEASURE: bool>(&mut self, team: Option<&Team>) -> Result<()> {
        self.ensure_neighbors()?;
        // with a team, the stripes evaluate their particles' wall contacts in the
        // contact phase, and each stripe's integration adds the bonds' and walls' forces
        let defer = team.is_some()
            && self.deferred_index.fits(
                self.neighbors.stripe_ranges.len(),
                self.bonds.list.len(),
                self.cement.bonds.len(),
                self.neighbors.wall_pairs.wall.len(),
            );
        let mut stripes = self.particle_contacts::<MEASURE>(team, defer);
        let bonds = self.apply_bond_forces::<MEASURE>(!defer);
        let (walls, wall_work) = self.wall_forces::<MEASURE>(defer);
        if team.is_none() {
            self.cross_pairs_in_order::<MEASURE>(&mut stripes);
        }
        let contacts = merge_tallies(&stripes, &bonds);
        self.servo_walls();
        let (mut motion, integration) = self.integrate::<MEASURE>(team, defer);
        self.move_walls();
        self.deform_cell();
        self.move_clumps::<MEASURE>(team, &integration, &mut motion);
        if contacts.bond_breaks > 0 {
            self.remove_broken_cement();
        }
        self.track_displacements(&motion);
        self.book_energy(&contacts, &walls, wall_work, &motion);
        if MEASURE {
            self.record_measurements(&contacts, &bonds, &walls, &motion);
        }
        self.advance_clock();
        // keep the lists valid between steps, so that queries see every contact;
        // the rebuild happens at the same state as it would at the next step's start
        self.ensure_neighbors()?;
        self.check_step(&motion, &contacts, &walls)
    }

    /// Step 6: servo walls set their velocity from this step's force.
    fn servo_walls(&mut self) {
        let dt = self.params.time_step;
        for wall in self.walls.iter_mut().filter(|w| w.active) {
            wall.update_servo(dt);
        }
    }

    /// Step 8a: active walls translate at their velocity (and remember the
    /// displacement for the work ledger).
    fn move_walls(&mut self) {
        let dt = self.params.time_step;
        for wall in self.walls.iter_mut() {
            let d = scale(wall.velocity, dt);
            wall.last_step_displacement = if wall.active { d } else { [0.0; 2] };
            if wall.active && d != [0.0, 0.0] {
                wall.translate(d);
            }
        }
    }

    /// Step 8b: a deforming periodic cell takes its step of the imposed flow.
    fn deform_cell(&mut self) {
        let dt = self.params.time_step;
        if let Some(cell) = &mut self.cell {
            if cell.is_deforming() {
                let m = cell.step_map(dt);
                cell.deform(&m);
            }
        }
    }

    /// Step 8b': the clumps take their step from their pebbles' resultants,
    /// and put their pebbles in place (`body::clumps`), after the cell's
    /// deformation so that the pebbles' images are of the deformed cell.
    fn move_clumps<const MEASURE: bool>(
        &mut self,
        team: Option<&Team>,
        integration: &IntegrationStep,
        motion: &mut IntegrationTally,
    ) {
        if self.clumps.is_empty() {
            return;
        }
        let gradient = self.deforming_gradient();
        let frame = ClumpFrame {
            step: integration,
            cell: self.cell.as_ref(),
            gradient: gradient.as_ref(),
            reference: self.neighbors.reference().reference,
        };
        // as many shares as stripes: a number that depends on the system only
        let chunks = self.neighbors.stripe_ranges.len();
        let tally = self
            .clumps
            .integrate::<MEASURE>(&mut self.particles, &frame, chunks, team);
        motion.merge(&tally);
    }

    /// Step 8c: the largest displacements since the last build, for the
    /// rebuild criterion.
    fn track_displacements(&mut self, motion: &IntegrationTally) {
        let n = &mut self.neighbors;
        n.max_fluctuation_sq = n.max_fluctuation_sq.max(motion.max_fluctuation_sq);
        n.max_displacement_sq = n.max_displacement_sq.max(motion.max_displacement_sq);
    }

    /// Step 8d: the energy ledger's dissipation and work of this step.
    fn book_energy(
        &mut self,
        contacts: &ContactTally,
        walls: &ContactTally,
        wall_work: f64,
        motion: &IntegrationTally,
    ) {
        let ledger = &mut self.ledger;
        // each contact sub-model's dissipation into its own line
        ledger.book_contacts(&contacts.dissipation.plus(&walls.dissipation));
        ledger.damping_dissipated += motion.damping_dissipated;
        ledger.wall_work += wall_work;
        ledger.external_work += motion.external_work;
        ledger.boundary_work += motion.boundary_work;
    }

    /// Step 8e, measured steps only: kinetic and elastic energy, contact
    /// counts and the mean unbalanced force ratio.
    fn record_measurements(
        &mut self,
        contacts: &ContactTally,
        bonds: &ContactTally,
        walls: &ContactTally,
        motion: &IntegrationTally,
    ) {
        let ledger = &mut self.ledger;
        ledger.kinetic = motion.kinetic;
        ledger.elastic = contacts.elastic + walls.elastic;
        let force_sum = contacts.force_sum + walls.force_sum;
        let n_forces = contacts.contacts + walls.contacts;
        let mean_contact = if n_forces > 0 {
            force_sum / n_forces as f64
        } else {
            0.0
        };
        let mean_unbalanced = if motion.free_count > 0 {
            motion.unbalanced_force_sum / motion.free_count as f64
        } else {
            0.0
        };
        self.measurements = Measurements {
            step: self.step_count,
            contact_count: contacts.contacts - bonds.contacts - contacts.cement_holding,
            wall_contact_count: walls.contacts,
            mean_unbalanced_force_ratio: if mean_contact > 0.0 {
                mean_unbalanced / mean_contact
            } else if mean_unbalanced > 0.0 {
                f64::INFINITY
            } else {
                0.0
            },
            energy: self.ledger,
        };
    }

    /// Step 8f: time advances; the next force evaluation adds the shear
    /// increment of this step's displacement.
    fn advance_clock(&mut self) {
        self.half_kick_pending = false;
        self.springs_current = false;
        self.step_count += 1;
        self.time += self.params.time_step;
    }

    /// Step 9: a non-finite state or an overlap beyond the limit stops the run.
    fn check_step(
        &self,
        motion: &IntegrationTally,
        contacts: &ContactTally,
        walls: &ContactTally,
    ) -> Result<()> {
        if motion.non_finite {
            return Err(self.non_finite_error());
        }
        if contacts.overlap_violation || walls.overlap_violation {
            return Err(self.overlap_error());
        }
        Ok(())
    }

    /// Steps 2-3: reset resultants, then particle-particle contact forces; returns
    /// each stripe's tallies ([`StripeTallies`]). With a team the pairs across stripes are evaluated in
    /// the same phase into a buffer that each stripe's integration applies (step
    /// 7); without one they wait for [`Simulation::cross_pairs_in_order`].
    fn particle_contacts<const MEASURE: bool>(
        &mut self,
        team: Option<&Team>,
        defer: bool,
    ) -> Vec<StripeTallies> {
        let (increment_time, velocity_gradient) =
            (self.increment_time(), self.deforming_gradient());
        let buffer_cross = team.is_some();
        let n_stripes = self.neighbors.stripe_ranges.len();
        let pairs = &mut self.neighbors.pairs;
        let (ranges, stripes) = stripe_shares(
            &mut pairs.history,
            &pairs.stripe_start,
            pairs.i.len(),
            &mut self.cross_forces,
            (&mut self.bonds.list, &mut self.bond_slots),
            (
                &mut self.cement.bonds,
                &mut self.cement_slots,
                &mut self.cement_ruptures,
            ),
            n_stripes,
        );

        // the chains' follower loads, each stripe its own particles' (step 2a)
        let has_chains = !self.chains.is_empty();
        if has_chains {
            self.boundary_load.resize(self.particles.len(), [0.0; 2]);
        }
        let boundary_load = DisjointWriter::new(&mut self.boundary_load);
        debug_assert!(!has_chains || self.chain_stripes.n_stripes() == n_stripes);
        let (chains, chain_stripes, walls) = (&self.chains, &self.chain_stripes, &self.walls);
        let p = &mut self.particles;
        let force = DisjointWriter::new(&mut p.force);
        let torque = DisjointWriter::new(&mut p.torque);
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let reset = ResetKernel {
            boundary_load: has_chains.then_some(&boundary_load),
            external_force: &p.external_force,
            external_torque: &p.external_torque,
            mass: &p.mass,
            gravity: self.params.gravity,
            pebble_fixity: (!self.clumps.is_empty()).then_some(p.fixity.as_slice()),
            no_loads: self.chains.is_empty()
                && !self.external_loads
                && self.params.gravity == [0.0, 0.0],
        };
        // what the bond and wall laws read (not the resultants the stripes write)
        let motion = ParticleMotion {
            position: &p.position,
            velocity: &p.velocity,
            angular_velocity: &p.angular_velocity,
            radius: &p.radius,
            mass: &p.mass,
            inertia: &p.inertia,
        };
        let (cell, vector) = (self.cell.as_ref(), self.simd);
        let stripe_ranges = &self.neighbors.stripe_ranges;
        // the wall pairs, each evaluated by the stripe of its particle (`defer`)
        let wall_pairs =
            WallPairWork::of(&mut self.neighbors.wall_pairs, &mut self.wall_slots, defer);
        let (materials, deferred_index) = (&self.materials, &self.deferred_index);
        let wall_step = WallStep {
            walls,
            materials,
            motion: &motion,
            dt: self.params.time_step,
            increment_time,
            max_overlap_ratio: self.params.max_overlap_ratio,
        };
        let tallies = map_stripes(team, stripes, |work| {
            let b = work.stripe;
            let mut direct = DirectSink {
                force: &force,
                torque: &torque,
            };
            // SAFETY: stripe b resets and writes only the forces of its own particles
            // (interior pairs have both particles in stripe b); cross pairs only
            // write their own slots of the buffer.
            unsafe {
                let (lo, hi) = stripe_ranges[b];
                if has_chains {
                    chain_stripes.stripe_loads(
                        b,
                        lo,
                        chains,
                        kernel.position,
                        walls,
                        boundary_load.range(lo, hi),
                    );
                }
                reset.apply(lo, hi, &force, &torque);
                let mut tally = kernel.run::<MEASURE, _>(ranges[b].0, work.history, &mut direct);
                if buffer_cross {
                    let mut buffered = BufferSink {
                        slots: work.cross_forces,
                    };
                    let cross = kernel.run::<MEASURE, _>(
                        ranges[n_stripes + b].0,
                        work.cross_history,
                        &mut buffered,
                    );
                    tally.merge(&cross);
                }
                let at = (&motion, cell, velocity_gradient, increment_time);
                evaluate_bonds::<MEASURE>((work.bonds, work.bond_slots), at);
                let cement_tally = evaluate_cement_bonds::<MEASURE>(work.cement, at, vector);
                if defer {
                    // SAFETY: each wall pair is in the list of one stripe only
                    wall_pairs.evaluate::<MEASURE>(deferred_index.walls_of_stripe(b), &wall_step);
                }
                [tally, cement_tally]
            }
        });
        // with a buffer the cross-stripe forces are applied by each stripe's
        // integration (step 7)
        tallies
    }

    /// Step 5b, on one thread: the pairs across stripes, after bonds and walls,
    /// in pair order and in the same shares as a team would evaluate them, adding
    /// their forces straight onto the particles. Each particle then receives the
    /// same additions in the same order as from the buffer (which a stripe's
    /// integration applies after the bonds and walls, in pair order), and each
    /// stripe's tally the same merges: the same bits without the buffer.
    fn cross_pairs_in_order<const MEASURE: bool>(&mut self, tallies: &mut [StripeTallies]) {
        let increment_time = self.increment_time();
        let n_stripes = self.neighbors.stripe_ranges.len();
        let pairs = &mut self.neighbors.pairs;
        let cross_start = pairs.stripe_start[n_stripes];
        let shares = even_bounds(pairs.len() - cross_start, n_stripes);
        let p = &mut self.particles;
        let force = DisjointWriter::new(&mut p.force);
        let torque = DisjointWriter::new(&mut p.torque);
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let mut direct = DirectSink {
            force: &force,
            torque: &torque,
        };
        for ([tally, _], &(lo, hi)) in tallies.iter_mut().zip(&shares) {
            let (lo, hi) = (cross_start + lo, cross_start + hi);
            // SAFETY: one thread; the pairs index particles that exist
            let cross =
                unsafe { kernel.run::<MEASURE, _>(lo, pairs.history.run_of(lo, hi), &mut direct) };
            tally.merge(&cross);
        }
    }

    /// Step 4: the bonds' forces, computed with the contact phase
    /// ([`Simulation::particle_contacts`]), added to the particles in bond order
    /// (`apply`; else each stripe's integration adds them, `pipeline::deferred`),
    /// and their tally.
    fn apply_bond_forces<const MEASURE: bool>(&mut self, apply: bool) -> ContactTally {
        let mut tally = ContactTally::default();
        if !apply && !MEASURE {
            return tally;
        }
        let p = &mut self.particles;
        let bonds = (self.bonds.list.as_slice(), self.bond_slots.as_slice());
        let resultants = (p.force.as_mut_slice(), p.torque.as_mut_slice());
        add_bond_slots::<MEASURE, _, _>(bonds, resultants, apply, &mut tally);
        // then the cement bonds' forces, in their order (a broken one's slot
        // holds zeros; their tally is the stripes', made as they evaluate them)
        if apply {
            let cement = (self.cement.bonds.as_slice(), self.cement_slots.as_slice());
            let resultants = (p.force.as_mut_slice(), p.torque.as_mut_slice());
            add_bond_slots::<false, _, _>(cement, resultants, apply, &mut tally);
        }
        tally
    }

    /// Step 8b'': the cement bonds that broke at this step's evaluation leave
    /// the list (the others keep their order), in cement order: each break is
    /// logged and its bond's strain energy booked as released. On any number
    /// of threads the same bonds break, so the same bits follow.
    fn remove_broken_cement(&mut self) {
        let ruptures: Vec<(usize, Rupture)> = self
            .cement_ruptures
            .iter_mut()
            .flat_map(|stripe| stripe.drain(..))
            .collect();
        for &(k, r) in &ruptures {
            let bond = &self.cement.bonds[k];
            self.ledger.bond_released += r.booked;
            self.cement.breaks.push(BondBreak {
                step: self.step_count,
                time: self.time,
                i: self.order[bond.i as usize],
                j: self.order[bond.j as usize],
                position: r.position,
                normal: r.normal,
                mode: r.mode,
                energy: r.energy,
                normal_force: r.normal_force,
                shear_force: r.shear_force,
                moment: r.moment,
            });
        }
        let mut broken = ruptures.iter().map(|&(k, _)| k).peekable();
        let mut k = 0;
        self.cement.bonds.retain(|_| {
            let gone = broken.next_if_eq(&k).is_some();
            k += 1;
            !gone
        });
        self.cement_slots.clear();
        self.index_stripes();
    }

    /// Step 5: particle-wall contacts, their forces added to the particles (or,
    /// `defer`, evaluated by the stripes in the contact phase and kept in slots for
    /// each stripe's integration to add: here only summed onto the walls and the
    /// tally, in wall-pair order); returns the tally and the walls' work over
    /// their last step's displacement.
    fn wall_forces<const MEASURE: bool>(&mut self, defer: bool) -> (ContactTally, f64) {
        let mut tally = ContactTally::default();
        let previous_force: Vec<Vec2> = self.walls.iter().map(|w| w.force).collect();
        for wall in &mut self.walls {
            wall.force = [0.0; 2];
            wall.contact_count = 0;
            wall.stiffness_sum = 0.0;
        }
        let dt = self.params.time_step;
        let increment_time = self.increment_time();
        let wp = &mut self.neighbors.wall_pairs;
        for k in 0..wp.wall.len() {
            let wall = &mut self.walls[wp.wall[k] as usize];
            let model = self.materials.by_index(wp.model[k]);
            let slot = if defer {
                match self.wall_slots[k] {
                    slot if slot.active => slot,
                    _ => continue,
                }
            } else {
                let q = wp.particle[k] as usize;
                let contact = wall_contact(
                    wall,
                    model,
                    &ParticleMotion::of(&self.particles),
                    q,
                    dt,
                    increment_time,
                    &mut wp.history.records[k],
                );
                let Some((g, c)) = contact else {
                    wp.history.sliding[k] = false;
                    continue;
                };
                wp.history.sliding[k] = c.sliding;
                let p = &mut self.particles;
                let r = p.radius[q];
                let n = g.normal;
                let f = add(scale(n, c.normal), scale(perp(n), c.shear));
                p.force[q] = add(p.force[q], f);
                p.torque[q] += c.torque_j;
                WallSlot {
                    force: f,
                    dissipation: c.dissipation,
                    stiffness: c.normal_stiffness,
                    overlap_violation: g.overlap > self.params.max_overlap_ratio * r,
                    elastic: if MEASURE { c.stored_energy(model) } else { 0.0 },
                    force_norm: if MEASURE {
                        (c.normal * c.normal + c.shear * c.shear).sqrt()
                    } else {
                        0.0
                    },
                    ..WallSlot::default()
                }
            };
            wall.force = sub(wall.force, slot.force);
            wall.contact_count += 1;
            wall.stiffness_sum += slot.stiffness;
            tally.dissipation.add(&slot.dissipation);
            tally.overlap_violation |= slot.overlap_violation;
            if MEASURE {
                tally.elastic += slot.elastic;
                tally.force_sum += slot.force_norm;
                tally.contacts += 1;
            }
        }
        // the work of a wall on the particles over its last step's displacement d,
        // with the trapezoid of the forces before and after it: the counterpart of
        // leapfrog's kinetic energy and the springs' elastic energy (docs/contact-law.md)
        let work = self
            .walls
            .iter()
            .zip(&previous_force)
            .map(|(w, f0)| -0.5 * dot(add(*f0, w.force), w.last_step_displacement))
            .sum();
        (tally, work)
    }

    /// The constants of this step's integration; in a deforming cell the
    /// accumulated map since the last build takes this step's.
    fn integration_step(&mut self) -> IntegrationStep {
        let dt = self.params.time_step;
        let step_map = self
            .cell
            .as_ref()
            .filter(|c| c.is_deforming())
            .map(|c| (c.origin, c.step_map(dt)));
        let accumulated_map: Mat2 = match &step_map {
            Some((_, m)) => self.neighbors.advance_map(m).accumulated_map,
            None => self.neighbors.reference().accumulated_map,
        };
        IntegrationStep {
            dt,
            kick: if self.half_kick_pending { 0.5 * dt } else { dt },
            half_kick: self.half_kick_pending,
            alpha: self.params.local_damping,
            gravity: self.params.gravity,
            has_external: self.params.gravity != [0.0, 0.0] || self.external_loads,
            step_map,
            accumulated_map,
            vector: self.simd,
        }
    }

    /// Step 7: leapfrog with local damping stripe by stripe in parallel; with a team each
    /// stripe first adds its particles' deferred bond and wall forces (`defer`),
    /// then their cross-stripe pairs.
    fn integrate<const MEASURE: bool>(
        &mut self,
        team: Option<&Team>,
        defer: bool,
    ) -> (IntegrationTally, IntegrationStep) {
        // with a team the cross-stripe forces wait in the buffer (else they are applied)
        let buffered = team.is_some();
        let step = self.integration_step();
        let p = &mut self.particles;
        let inputs = IntegrationInputs {
            inv_mass: &p.inv_mass,
            inv_inertia: &p.inv_inertia,
            mass: &p.mass,
            inertia: &p.inertia,
            fixity: &p.fixity,
            external_force: &p.external_force,
            external_torque: &p.external_torque,
            boundary_load: (!self.chains.is_empty()).then_some(self.boundary_load.as_slice()),
            reference: self.neighbors.reference().reference,
        };
        // the stripes of the contact phase: a worker integrates (first) the
        // stripes whose contacts it just computed
        let bounds = self.neighbors.stripe_ranges.clone();
        let cross = CrossForces {
            pair_i: &self.neighbors.pairs.i,
            pair_j: &self.neighbors.pairs.j,
            first: self
                .neighbors
                .pairs
                .stripe_start
                .last()
                .copied()
                .unwrap_or(0),
            forces: &self.cross_forces,
            touch: &self.neighbors.cross_touch,
            touch_start: &self.neighbors.cross_touch_start,
        };
        let deferred = DeferredForces {
            index: &self.deferred_index,
            bonds: &self.bonds.list,
            bond_slots: &self.bond_slots,
            cement: &self.cement.bonds,
            cement_slots: &self.cement_slots,
            wall_particles: &self.neighbors.wall_pairs.particle,
            wall_slots: &self.wall_slots,
        };
        let whole = OpenStripe {
            lo: 0,
            position: &mut p.position,
            velocity: &mut p.velocity,
            rotation: &mut p.rotation,
            angular_velocity: &mut p.angular_velocity,
            force: &mut p.force,
            torque: &mut p.torque,
        };
        let stripes = MotionWork::split(whole, &bounds);
        let tallies = map_stripes(team, stripes, |work| {
            let MotionWork { stripe: b, motion } = work;
            if defer {
                // the bonds, the cement bonds, then the wall contacts, as their
                // serial passes add them
                deferred.apply(b, motion.lo, motion.force, motion.torque);
            }
            if buffered {
                // the cross-stripe pairs touching this stripe, in pair order, as a
                // sequential pass over all of them adds them
                cross.apply(b, motion.lo, motion.force, motion.torque);
            }
            integrate_stripe::<MEASURE>(motion.into_stripe(), &inputs, &step)
        });
        let mut total = IntegrationTally::default();
        for t in &tallies {
            total.merge(t);
        }
        (total, step)
    }
}

/// One stripe's share of the particles' motion in the integration: its
/// forces still open to the deferred and cross-stripe additions.
struct MotionWork<'w> {
    stripe: usize,
    motion: OpenStripe<'w>,
}

/// A stripe's motion arrays with its resultants writable.
struct OpenStripe<'w> {
    lo: usize,
    position: &'w mut [Vec2],
    velocity: &'w mut [Vec2],
    rotation: &'w mut [f64],
    angular_velocity: &'w mut [f64],
    force: &'w mut [Vec2],
    torque: &'w mut [f64],
}

impl<'w> OpenStripe<'w> {
    /// The stripe as the integration reads it, its resultants complete.
    fn into_stripe(self) -> MotionStripe<'w> {
        MotionStripe {
            lo: self.lo,
            position: self.position,
            velocity: self.velocity,
            rotation: self.rotation,
            angular_velocity: self.angular_velocity,
            force: self.force,
            torque: self.torque,
        }
    }
}

impl<'w> MotionWork<'w> {
    /// The particles' whole arrays (`p`, from index 0) cut into the stripes `bounds`.
    fn split(p: OpenStripe<'w>, bounds: &[(usize, usize)]) -> Vec<MotionWork<'w>> {
        let mut position = split_ranges(p.position, bounds).into_iter();
        let mut velocity = split_ranges(p.velocity, bounds).into_iter();
        let mut rotation = split_ranges(p.rotation, bounds).into_iter();
        let mut angular_velocity = split_ranges(p.angular_velocity, bounds).into_iter();
        let mut force = split_ranges(p.force, bounds).into_iter();
        let mut torque = split_ranges(p.torque, bounds).into_iter();
        let mut next = move |stripe: usize, lo: usize| -> Option<MotionWork<'w>> {
            Some(MotionWork {
                stripe,
                motion: OpenStripe {
                    lo,
                    position: position.next()?,
                    velocity: velocity.next()?,
                    rotation: rotation.next()?,
                    angular_velocity: angular_velocity.next()?,
                    force: force.next()?,
                    torque: torque.next()?,
                },
            })
        };
        bounds
            .iter()
            .enumerate()
            .map_while(|(b, &(lo, _))| next(b, lo))
            .collect()
    }
}

/// The simulation handed to worker 0 of a broadcast.
struct SimPtr(*mut Simulation);

// SAFETY: the pointer is dereferenced by worker 0 only, while `run_steps` holds
// the exclusive borrow it came from.
unsafe impl Send for SimPtr {}
unsafe impl Sync for SimPtr {}

impl SimPtr {
    fn get(&self) -> *mut Simulation {
        self.0
    }
}

/// The wall pairs as the contact phase's stripes evaluate them: each stripe its
/// own particles' pairs (`DeferredIndex::walls_of_stripe`), writing only their
/// springs, flags and slots.
struct WallPairWork<'a> {
    wall: &'a [u32],
    particle: &'a [u32],
    model: &'a [u16],
    records: DisjointWriter<ContactRecord>,
    sliding: DisjointWriter<bool>,
    slots: DisjointWriter<WallSlot>,
}

impl<'a> WallPairWork<'a> {
    /// The work of the wall pairs `wp`, their results going to `slots` (sized to
    /// the pairs when the stripes evaluate them, `defer`).
    fn of(wp: &'a mut WallPairList, slots: &'a mut Vec<WallSlot>, defer: bool) -> Self {
        if defer {
            slots.resize(wp.wall.len(), WallSlot::default());
        }
        WallPairWork {
            wall: &wp.wall,
            particle: &wp.particle,
            model: &wp.model,
            records: DisjointWriter::new(&mut wp.history.records),
            sliding: DisjointWriter::new(&mut wp.history.sliding),
            slots: DisjointWriter::new(slots),
        }
    }
}

/// What a wall pair's evaluation reads besides the pair: the walls, the
/// models, the particles' motion and the step's constants.
struct WallStep<'a> {
    walls: &'a [crate::wall::Wall],
    materials: &'a crate::material::MaterialTable,
    motion: &'a ParticleMotion<'a>,
    dt: f64,
    increment_time: f64,
    max_overlap_ratio: f64,
}

impl WallPairWork<'_> {
    /// The wall pairs `pairs` (of one stripe's particles): each pair's law,
    /// its spring and sliding flag updated, its force in its slot.
    ///
    /// # Safety
    /// No other task evaluates any of `pairs` at the same time.
    unsafe fn evaluate<const MEASURE: bool>(&self, pairs: &[u32], at: &WallStep<'_>) {
        for &k in pairs {
            let k = k as usize;
            let wall = &at.walls[self.wall[k] as usize];
            let model = at.materials.by_index(self.model[k]);
            let q = self.particle[k] as usize;
            let record = self.records.get(k);
            let contact = wall_contact(wall, model, at.motion, q, at.dt, at.increment_time, record);
            let slot = self.slots.get(k);
            let Some((g, c)) = contact else {
                *self.sliding.get(k) = false;
                slot.active = false;
                continue;
            };
            *self.sliding.get(k) = c.sliding;
            let r = at.motion.radius[q];
            let n = g.normal;
            *slot = WallSlot {
                force: add(scale(n, c.normal), scale(perp(n), c.shear)),
                torque: c.torque_j,
                dissipation: c.dissipation,
                stiffness: c.normal_stiffness,
                overlap_violation: g.overlap > at.max_overlap_ratio * r,
                active: true,
                ..WallSlot::default()
            };
            if MEASURE {
                slot.elastic = c.stored_energy(model);
                slot.force_norm = (c.normal * c.normal + c.shear * c.shear).sqrt();
            }
        }
    }
}

/// The shares of one force evaluation, one per stripe (step 5): the ranges of
/// the pair list (each stripe's interior pairs, then the cross-stripe pairs
/// shared out evenly, one range each) and each stripe's work: its interior
/// pairs' history, its share of the cross pairs' history and of their force
/// buffer (every slot rewritten by the kernel, so not cleared), its share of
/// the bonds and of their force slots.
fn stripe_shares<'a>(
    history: &'a mut ContactHistory,
    starts: &[usize],
    n_pairs: usize,
    cross_forces: &'a mut Vec<PairForce>,
    (bonds, bond_slots): (&'a mut [Bond], &'a mut Vec<BondSlot>),
    (cement, cement_slots, cement_ruptures): CementShares<'a>,
    n_stripes: usize,
) -> (Vec<(usize, usize)>, Vec<StripeWork<'a>>) {
    let cross_start = starts[n_stripes];
    let cross_ranges: Vec<(usize, usize)> = even_bounds(n_pairs - cross_start, n_stripes)
        .into_iter()
        .map(|(lo, hi)| (cross_start + lo, cross_start + hi))
        .collect();
    let mut ranges: Vec<(usize, usize)> =
        (0..n_stripes).map(|b| (starts[b], starts[b + 1])).collect();
    ranges.extend(&cross_ranges);
    let mut history_parts = history.split(&ranges);
    let cross_history = history_parts.split_off(n_stripes);
    cross_forces.resize(n_pairs - cross_start, PairForce::NONE);
    let local: Vec<(usize, usize)> = cross_ranges
        .iter()
        .map(|&(lo, hi)| (lo - cross_start, hi - cross_start))
        .collect();
    let cross_buffers = split_ranges(cross_forces, &local);
    let bond_ranges = even_bounds(bonds.len(), n_stripes);
    bond_slots.resize(bonds.len(), BondSlot::default());
    let bond_parts = split_ranges(bonds, &bond_ranges);
    let bond_slot_parts = split_ranges(bond_slots, &bond_ranges);
    let cement_ranges = even_bounds(cement.len(), n_stripes);
    cement_slots.resize(cement.len(), CementSlot::default());
    let cement_parts = split_ranges(cement, &cement_ranges);
    let cement_slot_parts = split_ranges(cement_slots, &cement_ranges);
    cement_ruptures.resize_with(n_stripes, Vec::new);
    let stripes = history_parts
        .into_iter()
        .zip(cross_history)
        .zip(cross_buffers)
        .zip(bond_parts.into_iter().zip(bond_slot_parts))
        .zip(cement_parts.into_iter().zip(cement_slot_parts))
        .zip(cement_ruptures.iter_mut())
        .enumerate()
        .map(
            |(b, (((((history, cross_history), cross_forces), bonds), cement), ruptures))| {
                StripeWork {
                    stripe: b,
                    history,
                    cross_history,
                    cross_forces,
                    bonds: bonds.0,
                    bond_slots: bonds.1,
                    cement: (cement.0, cement.1, cement_ranges[b].0, ruptures),
                }
            },
        )
        .collect();
    (ranges, stripes)
}

/// The cement bonds, their slots and the per-stripe lists of their ruptures.
type CementShares<'a> = (
    &'a mut [CementBond],
    &'a mut Vec<CementSlot>,
    &'a mut Vec<Vec<(usize, Rupture)>>,
);

/// What a bond's evaluation reads besides the bond: the particles' motion,
/// the cell, its velocity gradient and the increment's time.
pub(super) type BondStep<'a> = (
    &'a ParticleMotion<'a>,
    Option<&'a crate::cell::PeriodicCell>,
    Option<Mat2>,
    f64,
);

/// Evaluates a stripe's share of the bonds into their slots.
#[inline]
fn evaluate_bonds<const MEASURE: bool>(
    (bonds, bond_slots): (&mut [Bond], &mut [BondSlot]),
    (motion, cell, gradient, increment_time): BondStep<'_>,
) {
    for (bond, slot) in bonds.iter_mut().zip(bond_slots.iter_mut()) {
        *slot = bond_slot::<MEASURE>(bond, motion, cell, gradient, increment_time);
    }
}
