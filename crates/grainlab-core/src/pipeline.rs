//! The simulation and its step, in this order (ARCHITECTURE.md repeats it):
//!
//! 1. **Neighbours**: rebuild the Verlet lists if a contact could otherwise be
//!    missed (wraps particles into the periodic cell, carries contact history over).
//! 2. **Reset**: resultant = external force + gravity, per block of particles.
//! 3. **Particle contacts**: linear law with shear history and Coulomb cap,
//!    blocks in parallel, then the cross-block pairs. The shear increment is the
//!    displacement since the last force evaluation: none on a step that starts
//!    from full-step velocities (see [`Simulation::catch_up_shear_springs`]).
//! 4. **Bonds**: linear normal and shear springs that carry tension.
//! 5. **Wall contacts**: the same law against walls; walls sum their force.
//! 6. **Servo**: servo-controlled walls set their velocity from this step's force.
//! 7. **Integrate**: leapfrog with local damping, in parallel chunks; the
//!    periodic cell's affine map is applied to positions; displacements since
//!    the last build are tracked.
//! 8. **Move**: walls translate, the cell deforms, time advances.
//! 9. **Checks**: non-finite state or an overlap beyond the allowed fraction of
//!    the smaller radius stops the run with an error naming the particles.
use rayon::ThreadPool;
use serde::{Deserialize, Serialize};

use crate::bond::{Bond, Bonds};
use crate::boundary::PressureChain;
use crate::cell::PeriodicCell;
use crate::contact::{disk_disk, ContactGeometry};
use crate::diagnostics::{EnergyLedger, Measurements};
use crate::error::{require_non_negative, require_positive, EngineError, Result};
use crate::integrate::{
    integrate_chunk, IntegrationInputs, IntegrationStep, IntegrationTally, MotionChunk,
};
use crate::law::{elastic_energy, linear_coulomb, linear_coulomb_with, ContactForce};
use crate::material::{ContactModel, MaterialTable};
use crate::neighbor::NeighborList;
use crate::parallel::{
    even_bounds, map_blocks, split_ranges, DisjointWriter, Pacer, Team, PARALLEL_MIN_PARTICLES,
};
use crate::state::Particles;
use crate::vec2::{add, dot, mat_vec, norm, perp, scale, sub, Mat2, Vec2};
use crate::wall::{Wall, WallControl};
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};

/// The first bytes of [`Simulation::to_bytes`]: the layout of the state that
/// follows (bincode of [`Simulation`]); a new field makes a new tag.
const STATE_TAG: &[u8; 8] = b"GLSTATE2";

/// Tunables of the step, in one place.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepParameters {
    /// Time step (s).
    pub time_step: f64,
    /// Local damping coefficient alpha in [0, 1) (paper: 0.8).
    pub local_damping: f64,
    /// Gravity (m/s^2).
    pub gravity: Vec2,
    /// A contact whose overlap exceeds this fraction of the smaller radius stops the run.
    pub max_overlap_ratio: f64,
}

impl StepParameters {
    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        require_positive("time_step", self.time_step)?;
        if !(0.0..1.0).contains(&self.local_damping) {
            return Err(EngineError::invalid(
                "local_damping",
                format!("must be in [0, 1), got {}", self.local_damping),
            ));
        }
        crate::error::require_finite("gravity", self.gravity[0])?;
        crate::error::require_finite("gravity", self.gravity[1])?;
        require_positive("max_overlap_ratio", self.max_overlap_ratio)?;
        Ok(())
    }
}

/// Per-block sums of the contact phase.
#[derive(Debug, Clone, Copy, Default)]
struct ContactTally {
    friction: f64,
    viscous: f64,
    elastic: f64,
    force_sum: f64,
    contacts: usize,
    overlap_violation: bool,
}

impl ContactTally {
    fn merge(&mut self, o: &ContactTally) {
        self.friction += o.friction;
        self.viscous += o.viscous;
        self.elastic += o.elastic;
        self.force_sum += o.force_sum;
        self.contacts += o.contacts;
        self.overlap_violation |= o.overlap_violation;
    }
}

/// A 2D disk DEM simulation: particles, walls, bonds, an optional periodic cell.
#[derive(Serialize, Deserialize)]
pub struct Simulation {
    /// The disks.
    pub particles: Particles,
    /// Contact models per pair of groups.
    pub materials: MaterialTable,
    /// Rigid walls.
    pub walls: Vec<Wall>,
    /// Permanent bonds.
    pub bonds: Bonds,
    /// Chains of boundary particles under a follower pressure.
    pub chains: Vec<PressureChain>,
    /// Periodic cell, if any.
    pub cell: Option<PeriodicCell>,
    /// Step tunables.
    pub params: StepParameters,
    /// Verlet lists and contact history.
    pub neighbors: NeighborList,
    /// Measurements of the last measured step.
    pub measurements: Measurements,
    /// Steps taken.
    pub step_count: u64,
    /// Simulated time (s).
    pub time: f64,
    /// External (user) index of each internal particle slot: the engine keeps
    /// particles in spatial order, renumbered at every neighbour-list build.
    order: Vec<u32>,
    /// Internal slot of each external index (the inverse of `order`).
    rank: Vec<u32>,
    ledger: EnergyLedger,
    /// Velocities are full-step values (set from outside): the next step kicks by `dt/2`.
    half_kick_pending: bool,
    /// The shear springs hold every tangential displacement made so far: nothing
    /// moved since the last force evaluation (or [`Simulation::catch_up_shear_springs`]),
    /// so the next one adds no increment.
    springs_current: bool,
    threads: usize,
    #[serde(skip)]
    pool: Option<ThreadPool>,
    #[serde(skip)]
    cross_forces: Vec<PairForce>,
    /// Follower loads of this step, per internal particle (recomputed every step).
    #[serde(skip)]
    boundary_load: Vec<Vec2>,
    /// Whether any particle has an external force or torque (scanned once per run call).
    #[serde(skip)]
    external_loads: bool,
    /// Whether the steps run with the team or on one thread (timed, `parallel::Pacer`).
    #[serde(skip)]
    pacer: Pacer,
}

impl Simulation {
    /// A simulation of `particles` where every pair of groups uses `model`,
    /// with time step `time_step` and `threads` worker threads (>= 1).
    pub fn new(
        particles: Particles,
        model: ContactModel,
        time_step: f64,
        threads: usize,
    ) -> Result<Self> {
        let params = StepParameters {
            time_step,
            local_damping: 0.0,
            gravity: [0.0; 2],
            max_overlap_ratio: 0.5,
        };
        params.validate()?;
        if threads == 0 {
            return Err(EngineError::invalid("threads", "must be >= 1"));
        }
        let skin = 0.1 * particles.max_radius().max(f64::MIN_POSITIVE);
        let identity: Vec<u32> = (0..particles.len() as u32).collect();
        let mut sim = Simulation {
            particles,
            materials: MaterialTable::uniform(model)?,
            walls: Vec::new(),
            bonds: Bonds::default(),
            chains: Vec::new(),
            cell: None,
            params,
            neighbors: NeighborList::new(skin),
            measurements: Measurements::default(),
            step_count: 0,
            time: 0.0,
            order: identity.clone(),
            rank: identity,
            ledger: EnergyLedger::default(),
            half_kick_pending: true,
            springs_current: true,
            threads,
            pool: None,
            cross_forces: Vec::new(),
            boundary_load: Vec::new(),
            external_loads: false,
            pacer: Pacer::default(),
        };
        sim.make_pool()?;
        Ok(sim)
    }

    fn make_pool(&mut self) -> Result<()> {
        self.pool = if self.threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(self.threads)
                    .build()
                    .map_err(|e| EngineError::invalid("threads", e.to_string()))?,
            )
        } else {
            None
        };
        Ok(())
    }

    /// Worker threads used by the step. Results are bitwise the same for every
    /// count: the work partition depends on the system only (`parallel::stripe_count`).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Changes the thread count, at any time: the results do not change.
    pub fn set_threads(&mut self, threads: usize) -> Result<()> {
        if threads == 0 {
            return Err(EngineError::invalid("threads", "must be >= 1"));
        }
        self.threads = threads;
        self.make_pool()
    }

    /// Sets the step tunables.
    pub fn set_params(&mut self, params: StepParameters) -> Result<()> {
        params.validate()?;
        // the last step's displacement was made with the old time step
        self.catch_up_shear_springs();
        self.params = params;
        Ok(())
    }

    /// Sets the Verlet skin (m, > 0).
    pub fn set_skin(&mut self, skin: f64) -> Result<()> {
        require_positive("skin", skin)?;
        self.neighbors.skin = skin;
        self.neighbors.invalidate();
        Ok(())
    }

    /// Sets the contact model between groups `a` and `b`.
    pub fn set_contact_model(&mut self, a: usize, b: usize, model: ContactModel) -> Result<()> {
        model.validate("contact_model")?;
        self.catch_up_shear_springs();
        self.materials.set(a, b, model)?;
        self.neighbors.invalidate();
        Ok(())
    }

    /// Sets (or removes) the periodic cell.
    pub fn set_cell(&mut self, cell: Option<PeriodicCell>) -> Result<()> {
        if let Some(c) = &cell {
            c.validate()?;
        }
        // the last step's displacement was made in the old cell's flow
        self.catch_up_shear_springs();
        self.cell = cell;
        self.neighbors.invalidate();
        Ok(())
    }

    /// Adds a wall and returns its id.
    pub fn add_wall(&mut self, wall: Wall) -> usize {
        self.walls.push(wall);
        self.neighbors.invalidate();
        self.walls.len() - 1
    }

    /// The wall with id `id`, or an error naming the valid range. A change of its
    /// velocity or position by hand must follow [`Simulation::catch_up_shear_springs`]
    /// ([`Simulation::set_wall_velocity`] and [`Simulation::translate_wall`] do it).
    pub fn wall_mut(&mut self, id: usize) -> Result<&mut Wall> {
        let n = self.walls.len();
        self.walls.get_mut(id).ok_or_else(|| {
            EngineError::invalid(
                "wall_id",
                format!("unknown wall {id}; valid ids are 0..{n}"),
            )
        })
    }

    /// Sets a wall's control mode (validated).
    pub fn set_wall_control(&mut self, id: usize, control: WallControl) -> Result<()> {
        if let WallControl::Servo(s) = control {
            s.validate()?;
        }
        self.wall_mut(id)?.control = control;
        Ok(())
    }

    /// Puts wall `id` under velocity control at `velocity` (m/s, finite). The
    /// springs first take the displacement the wall made at its old velocity.
    pub fn set_wall_velocity(&mut self, id: usize, velocity: Vec2) -> Result<()> {
        crate::error::require_finite("velocity", velocity[0])?;
        crate::error::require_finite("velocity", velocity[1])?;
        self.wall_mut(id)?;
        self.catch_up_shear_springs();
        let wall = self.wall_mut(id)?;
        wall.control = WallControl::Velocity;
        wall.velocity = velocity;
        Ok(())
    }

    /// Moves wall `id` at once by `d` (m), between steps: a jump, not a shear
    /// displacement of its contacts (their springs are caught up first).
    pub fn translate_wall(&mut self, id: usize, d: Vec2) -> Result<()> {
        crate::error::require_finite("displacement", d[0])?;
        crate::error::require_finite("displacement", d[1])?;
        self.wall_mut(id)?;
        self.catch_up_shear_springs();
        self.wall_mut(id)?.translate(d);
        Ok(())
    }

    /// Bonds particles `i` and `j` with a spring of rest length `rest_length`
    /// (their current distance if `None`).
    pub fn add_bond(
        &mut self,
        i: usize,
        j: usize,
        normal_stiffness: f64,
        shear_stiffness: f64,
        rest_length: Option<f64>,
    ) -> Result<()> {
        self.particles.check_index("bond.i", i)?;
        self.particles.check_index("bond.j", j)?;
        let (i, j) = (self.internal_index(i), self.internal_index(j));
        if i == j {
            return Err(EngineError::invalid(
                "bond",
                format!("cannot bond particle {i} to itself"),
            ));
        }
        if self.bonds.contains(i as u32, j as u32) {
            return Err(EngineError::invalid(
                "bond",
                format!(
                    "particles {} and {} are already bonded",
                    self.external_index(i),
                    self.external_index(j)
                ),
            ));
        }
        require_positive("bond.normal_stiffness", normal_stiffness)?;
        require_positive("bond.shear_stiffness", shear_stiffness)?;
        let rest = match rest_length {
            Some(r) => {
                require_non_negative("bond.rest_length", r)?;
                r
            }
            None => norm(self.branch(i, j)),
        };
        // a new bond starts from zero shear: no displacement before it existed counts
        self.catch_up_shear_springs();
        self.bonds.push(Bond {
            i: i as u32,
            j: j as u32,
            normal_stiffness,
            shear_stiffness,
            rest_length: rest,
            shear: 0.0,
        });
        self.neighbors.invalidate();
        Ok(())
    }

    /// Branch vector from internal slot `i` to the nearest image of internal slot `j`.
    pub(crate) fn branch(&self, i: usize, j: usize) -> Vec2 {
        let d = sub(self.particles.position[j], self.particles.position[i]);
        minimum_image(self.cell.as_ref(), d)
    }

    /// Appends disks at rest (one density or one per disk); they get the next
    /// external indices. Contact history of the existing particles is kept.
    pub fn add_particles(
        &mut self,
        position: Vec<Vec2>,
        radius: Vec<f64>,
        density: Vec<f64>,
    ) -> Result<()> {
        let added = Particles::new(position, radius, density)?;
        self.catch_up_shear_springs();
        let first = self.particles.len() as u32;
        let count = added.len() as u32;
        self.particles.extend(added);
        self.order.extend(first..first + count);
        self.rank.extend(first..first + count);
        self.neighbors.invalidate();
        Ok(())
    }

    /// Adds a chain of boundary particles (external indices, in order with the
    /// sample on their right) under a follower `pressure` (Pa); the ends are
    /// anchored on the lines of `start_wall` and `end_wall` if given. Returns its id.
    pub fn add_pressure_chain(
        &mut self,
        particles: &[usize],
        pressure: f64,
        start_wall: Option<usize>,
        end_wall: Option<usize>,
    ) -> Result<usize> {
        let chain = self.make_chain(particles, pressure, start_wall, end_wall)?;
        self.chains.push(chain);
        Ok(self.chains.len() - 1)
    }

    /// Replaces chain `id` (its particles, pressure and anchors).
    pub fn set_pressure_chain(
        &mut self,
        id: usize,
        particles: &[usize],
        pressure: f64,
        start_wall: Option<usize>,
        end_wall: Option<usize>,
    ) -> Result<()> {
        let n = self.chains.len();
        if id >= n {
            return Err(EngineError::invalid(
                "chain_id",
                format!("unknown chain {id}; valid ids are 0..{n}"),
            ));
        }
        self.chains[id] = self.make_chain(particles, pressure, start_wall, end_wall)?;
        Ok(())
    }

    /// Chain `id`, with its particles as external indices.
    pub fn pressure_chain(&self, id: usize) -> Result<PressureChain> {
        let c = self.chains.get(id).ok_or_else(|| {
            EngineError::invalid(
                "chain_id",
                format!("unknown chain {id}; valid ids are 0..{}", self.chains.len()),
            )
        })?;
        let mut chain = c.clone();
        for q in chain.particles.iter_mut() {
            *q = self.external_index(*q as usize) as u32;
        }
        Ok(chain)
    }

    fn make_chain(
        &self,
        particles: &[usize],
        pressure: f64,
        start_wall: Option<usize>,
        end_wall: Option<usize>,
    ) -> Result<PressureChain> {
        require_non_negative("pressure", pressure)?;
        if particles.is_empty() {
            return Err(EngineError::invalid(
                "particles",
                "a pressure chain needs at least one particle",
            ));
        }
        for (k, &q) in particles.iter().enumerate() {
            self.particles.check_index(&format!("particles[{k}]"), q)?;
        }
        for (name, w) in [("start_wall", start_wall), ("end_wall", end_wall)] {
            if let Some(w) = w {
                if w >= self.walls.len() {
                    return Err(EngineError::invalid(
                        name,
                        format!("unknown wall {w}; valid ids are 0..{}", self.walls.len()),
                    ));
                }
            }
        }
        Ok(PressureChain {
            particles: particles
                .iter()
                .map(|&q| self.internal_index(q) as u32)
                .collect(),
            pressure,
            start_wall: start_wall.map(|w| w as u32),
            end_wall: end_wall.map(|w| w as u32),
        })
    }

    /// Step 2a: the follower loads of the pressure chains at the current positions.
    fn boundary_loads(&mut self) {
        if self.chains.is_empty() {
            return;
        }
        self.boundary_load.clear();
        self.boundary_load.resize(self.particles.len(), [0.0; 2]);
        for chain in &self.chains {
            chain.apply(
                &self.particles.position,
                &self.walls,
                &mut self.boundary_load,
            );
        }
    }

    /// Switches a wall on or off; an inactive wall has no contacts and stays put.
    pub fn set_wall_active(&mut self, id: usize, active: bool) -> Result<()> {
        self.wall_mut(id)?;
        self.catch_up_shear_springs();
        let wall = self.wall_mut(id)?;
        wall.active = active;
        if !active {
            wall.velocity = [0.0; 2];
            wall.control = WallControl::Velocity;
            wall.force = [0.0; 2];
            wall.contact_count = 0;
            wall.stiffness_sum = 0.0;
        }
        self.neighbors.invalidate();
        Ok(())
    }

    /// Marks the neighbour lists stale (after positions or radii changed).
    pub fn invalidate_neighbors(&mut self) {
        self.neighbors.invalidate();
    }

    /// Changes the velocities and angular velocities (internal order, see
    /// [`Simulation::to_internal`]) through `change`. The values it leaves are
    /// full-step values: the next step starts with a half kick and adds no shear
    /// increment, and the displacement of the last step, made at the old
    /// half-step velocities, is first added to the springs, so it is counted once.
    pub fn change_velocities(&mut self, change: impl FnOnce(&mut [Vec2], &mut [f64])) {
        self.catch_up_shear_springs();
        let p = &mut self.particles;
        change(&mut p.velocity, &mut p.angular_velocity);
        self.half_kick_pending = true;
    }

    /// Changes the positions (internal order) through `change`: a jump, not a
    /// displacement, so the springs are caught up first and the jump adds nothing
    /// to them; the neighbour lists are rebuilt at the next step or query.
    pub fn change_positions(&mut self, change: impl FnOnce(&mut [Vec2])) {
        self.catch_up_shear_springs();
        change(&mut self.particles.position);
        self.neighbors.invalidate();
    }

    /// Whether the next force evaluation adds a shear increment: false after a
    /// state was built or its velocities set, or after
    /// [`Simulation::catch_up_shear_springs`]; true after a step.
    pub fn shear_increment_pending(&self) -> bool {
        !self.springs_current
    }

    /// The time over which the current velocities displaced the contacts since
    /// their springs were last updated: the time step after a step, else 0.
    fn increment_time(&self) -> f64 {
        if self.springs_current {
            0.0
        } else {
            self.params.time_step
        }
    }

    /// Adds to every shear spring (contacts, wall contacts, bonds) the increment
    /// of the displacement made by the last step, `-ks v_t dt` at the current
    /// positions and half-step velocities, capped as the next force evaluation
    /// would; that evaluation then adds none. A no-op when the springs are
    /// current. Every method that changes what the increment would be (velocities,
    /// positions, the time step, contact models, the cell, walls, bonds,
    /// particles) calls it first; call it yourself before changing the public
    /// fields by hand. Slip in it is booked as friction dissipation.
    pub fn catch_up_shear_springs(&mut self) {
        if self.springs_current {
            return;
        }
        let dt = self.params.time_step;
        let pairs = &mut self.neighbors.pairs;
        let p = &self.particles;
        let kernel = pair_kernel!(self, p, pairs, dt);
        // SAFETY: one caller, and the sink writes nothing
        let tally = unsafe {
            kernel.run::<false, _>(0, &mut pairs.shear, &mut pairs.sliding, &mut NullSink)
        };
        let mut friction = tally.friction;
        let l = self.deforming_gradient();
        for bond in self.bonds.list.iter_mut() {
            let copy = *bond;
            bond_force(
                &copy,
                &self.particles,
                self.cell.as_ref(),
                l,
                dt,
                &mut bond.shear,
            );
        }
        let wp = &mut self.neighbors.wall_pairs;
        for k in 0..wp.wall.len() {
            let wall = &self.walls[wp.wall[k] as usize];
            let model = self.materials.by_index(wp.model[k]);
            let q = wp.particle[k] as usize;
            match wall_contact(wall, model, &self.particles, q, dt, dt, &mut wp.shear[k]) {
                Some((_, c)) => {
                    wp.sliding[k] = c.sliding;
                    friction += c.friction_dissipation;
                }
                None => wp.sliding[k] = false,
            }
        }
        self.ledger.friction_dissipated += friction;
        self.springs_current = true;
    }

    /// Every listed pair as the next force evaluation will see it, without
    /// changing the state (the springs are updated in copies).
    pub(crate) fn preview_pairs(&self) -> Vec<Option<PairRecord>> {
        let increment_time = self.increment_time();
        let pairs = &self.neighbors.pairs;
        let (mut shear, mut sliding) = (pairs.shear.clone(), pairs.sliding.clone());
        let p = &self.particles;
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let mut sink = RecordSink {
            records: vec![None; pairs.len()],
        };
        // SAFETY: one caller, and the sink writes only its own records
        unsafe { kernel.run::<false, _>(0, &mut shear, &mut sliding, &mut sink) };
        sink.records
    }

    /// Every wall pair as the next force evaluation will see it: the geometry,
    /// the law's forces and the updated spring (in a copy), or `None`.
    pub(crate) fn preview_wall_pairs(&self) -> Vec<Option<(ContactGeometry, ContactForce, f64)>> {
        let (dt, increment_time) = (self.params.time_step, self.increment_time());
        let wp = &self.neighbors.wall_pairs;
        (0..wp.wall.len())
            .map(|k| {
                let mut spring = wp.shear[k];
                let wall = &self.walls[wp.wall[k] as usize];
                let model = self.materials.by_index(wp.model[k]);
                let q = wp.particle[k] as usize;
                wall_contact(
                    wall,
                    model,
                    &self.particles,
                    q,
                    dt,
                    increment_time,
                    &mut spring,
                )
                .map(|(g, c)| (g, c, spring))
            })
            .collect()
    }

    /// Every bond as the next force evaluation will see it (springs in copies).
    pub(crate) fn preview_bonds(&self) -> Vec<BondForce> {
        let (increment_time, l) = (self.increment_time(), self.deforming_gradient());
        self.bonds
            .list
            .iter()
            .map(|b| {
                let mut shear = b.shear;
                bond_force(
                    b,
                    &self.particles,
                    self.cell.as_ref(),
                    l,
                    increment_time,
                    &mut shear,
                )
            })
            .collect()
    }

    /// The velocity gradient of a deforming periodic cell, if any.
    fn deforming_gradient(&self) -> Option<Mat2> {
        self.cell
            .as_ref()
            .filter(|c| c.is_deforming())
            .map(|c| c.velocity_gradient)
    }

    /// The energy ledger (kinetic and elastic as of the last measured step).
    pub fn energy(&self) -> EnergyLedger {
        self.ledger
    }

    /// A time step estimate: `safety * min_i min(sqrt(m_i / k_n,i), sqrt(I_i / (k_s,i r_i^2)))`
    /// where `k_n,i` and `k_s,i` sum the stiffnesses of particle `i`'s current
    /// contacts and bonds (one contact of its stiffest model when it has none).
    pub fn critical_time_step(&mut self, safety: f64) -> Result<f64> {
        require_positive("safety", safety)?;
        self.ensure_neighbors()?;
        let n = self.particles.len();
        let mut kn = vec![0.0; n];
        let mut ks = vec![0.0; n];
        let p = &self.particles;
        let pairs = &self.neighbors.pairs;
        for k in 0..pairs.len() {
            let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
            let d = sub(
                add(p.position[j], self.image_offset(pairs.shift[k])),
                p.position[i],
            );
            if disk_disk(d, p.radius[i], p.radius[j]).overlap > 0.0 {
                let m = self.materials.by_index(pairs.model[k]);
                for q in [i, j] {
                    kn[q] += m.normal_stiffness;
                    ks[q] += m.shear_stiffness;
                }
            }
        }
        let wp = &self.neighbors.wall_pairs;
        for k in 0..wp.wall.len() {
            let q = wp.particle[k] as usize;
            if self.walls[wp.wall[k] as usize]
                .disk_contact(p.position[q], p.radius[q])
                .overlap
                > 0.0
            {
                let m = self.materials.by_index(wp.model[k]);
                kn[q] += m.normal_stiffness;
                ks[q] += m.shear_stiffness;
            }
        }
        for b in &self.bonds.list {
            for q in [b.i as usize, b.j as usize] {
                kn[q] += b.normal_stiffness;
                ks[q] += b.shear_stiffness;
            }
        }
        let mut dt = f64::INFINITY;
        for q in 0..n {
            let fallback = self.materials.max_stiffness_for_group(p.group[q]);
            let kn_q = if kn[q] > 0.0 { kn[q] } else { fallback };
            let ks_q = if ks[q] > 0.0 { ks[q] } else { fallback };
            let r = p.radius[q];
            dt = dt
                .min((p.mass[q] / kn_q).sqrt())
                .min((p.inertia[q] / (ks_q * r * r)).sqrt());
        }
        Ok(safety * dt)
    }

    #[inline(always)]
    fn image_offset(&self, shift: [i8; 2]) -> Vec2 {
        match &self.cell {
            Some(c) if shift != [0, 0] => c.image_offset(shift),
            _ => [0.0; 2],
        }
    }

    /// Rebuilds the neighbour lists if a contact could otherwise be missed. Safe to
    /// call at any time: it rebuilds exactly when the next step would.
    pub fn ensure_neighbors(&mut self) -> Result<()> {
        if self.neighbors.needs_rebuild(&self.walls) {
            self.rebuild()?;
        }
        Ok(())
    }

    fn rebuild(&mut self) -> Result<()> {
        let new_of_old = self.neighbors.build(
            &mut self.particles,
            &mut self.order,
            self.cell.as_ref(),
            &self.walls,
            &mut self.bonds,
            &self.materials,
        )?;
        for chain in self.chains.iter_mut() {
            chain.remap(&new_of_old);
        }
        for (k, &e) in self.order.iter().enumerate() {
            self.rank[e as usize] = k as u32;
        }
        Ok(())
    }

    /// External (user) index of internal particle slot `k`. The engine keeps
    /// [`Simulation::particles`] in spatial order; every index that leaves the
    /// engine through the public methods below is external.
    pub fn external_index(&self, k: usize) -> usize {
        self.order[k] as usize
    }

    /// Internal slot of external particle `e`.
    pub fn internal_index(&self, e: usize) -> usize {
        self.rank[e] as usize
    }

    /// A per-particle array in external order, from the internal one.
    pub fn to_external<T: Copy>(&self, internal: &[T]) -> Vec<T> {
        self.rank.iter().map(|&k| internal[k as usize]).collect()
    }

    /// A per-particle array in internal order, from an external one.
    pub fn to_internal<T: Copy>(&self, external: &[T]) -> Vec<T> {
        self.order.iter().map(|&e| external[e as usize]).collect()
    }

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
                // phases, and the phases obey the block ownership rules.
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

    /// One step; `MEASURE` adds kinetic and elastic energy, contact counts and
    /// the unbalanced force ratio.
    fn step<const MEASURE: bool>(&mut self, team: Option<&Team>) -> Result<()> {
        self.ensure_neighbors()?;
        let dt = self.params.time_step;
        self.boundary_loads();
        let mut stripes = self.particle_contacts::<MEASURE>(team);
        let bond_tally = self.bond_forces::<MEASURE>();
        let (wall_tally, wall_work) = self.wall_forces::<MEASURE>();
        if team.is_none() {
            self.cross_pairs_in_order::<MEASURE>(&mut stripes);
        }
        let mut contacts = ContactTally::default();
        for t in &stripes {
            contacts.merge(t);
        }
        contacts.merge(&bond_tally);
        for wall in self.walls.iter_mut().filter(|w| w.active) {
            wall.update_servo(dt);
        }
        let motion = self.integrate::<MEASURE>(team);
        for wall in self.walls.iter_mut() {
            let d = scale(wall.velocity, dt);
            wall.last_step_displacement = if wall.active { d } else { [0.0; 2] };
            if wall.active && d != [0.0, 0.0] {
                wall.translate(d);
            }
        }
        if let Some(cell) = &mut self.cell {
            if cell.is_deforming() {
                let m = cell.step_map(dt);
                cell.deform(&m);
            }
        }
        self.neighbors.max_fluctuation_sq = self
            .neighbors
            .max_fluctuation_sq
            .max(motion.max_fluctuation_sq);
        self.neighbors.max_displacement_sq = self
            .neighbors
            .max_displacement_sq
            .max(motion.max_displacement_sq);

        let ledger = &mut self.ledger;
        ledger.friction_dissipated += contacts.friction + wall_tally.friction;
        ledger.viscous_dissipated += contacts.viscous + wall_tally.viscous;
        ledger.damping_dissipated += motion.damping_dissipated;
        ledger.wall_work += wall_work;
        ledger.external_work += motion.external_work;
        ledger.boundary_work += motion.boundary_work;
        if MEASURE {
            ledger.kinetic = motion.kinetic;
            ledger.elastic = contacts.elastic + wall_tally.elastic;
            let force_sum = contacts.force_sum + wall_tally.force_sum;
            let n_forces = contacts.contacts + wall_tally.contacts;
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
                contact_count: contacts.contacts - bond_tally.contacts,
                wall_contact_count: wall_tally.contacts,
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
        self.half_kick_pending = false;
        self.springs_current = false;
        self.step_count += 1;
        self.time += dt;
        // keep the lists valid between steps, so that queries see every contact;
        // the rebuild happens at the same state as it would at the next step's start
        self.ensure_neighbors()?;

        if motion.non_finite {
            return Err(self.non_finite_error());
        }
        if contacts.overlap_violation || wall_tally.overlap_violation {
            return Err(self.overlap_error());
        }
        Ok(())
    }

    /// Steps 2-3: reset resultants, then particle-particle contact forces; returns
    /// each stripe's tally. With a team the pairs across stripes are evaluated in
    /// the same phase into a buffer that each stripe's integration applies (step
    /// 7); without one they wait for [`Simulation::cross_pairs_in_order`].
    fn particle_contacts<const MEASURE: bool>(&mut self, team: Option<&Team>) -> Vec<ContactTally> {
        let increment_time = self.increment_time();
        let buffer_cross = team.is_some();
        let n_blocks = self.neighbors.block_ranges.len();
        let pairs = &mut self.neighbors.pairs;
        let starts = &pairs.block_start;
        // interior pairs of each block, then the cross-block pairs shared out evenly
        let cross_start = starts[n_blocks];
        let n_pairs = pairs.len();
        let cross_ranges: Vec<(usize, usize)> = even_bounds(n_pairs - cross_start, n_blocks)
            .into_iter()
            .map(|(lo, hi)| (cross_start + lo, cross_start + hi))
            .collect();
        let mut ranges: Vec<(usize, usize)> =
            (0..n_blocks).map(|b| (starts[b], starts[b + 1])).collect();
        ranges.extend(&cross_ranges);
        let mut shear_parts = split_ranges(&mut pairs.shear, &ranges);
        let mut sliding_parts = split_ranges(&mut pairs.sliding, &ranges);
        let cross_shear = shear_parts.split_off(n_blocks);
        let cross_sliding = sliding_parts.split_off(n_blocks);
        // every slot is rewritten by the kernel (a force or `skip`), so no clearing
        self.cross_forces
            .resize(n_pairs - cross_start, PairForce::NONE);
        let local: Vec<(usize, usize)> = cross_ranges
            .iter()
            .map(|&(lo, hi)| (lo - cross_start, hi - cross_start))
            .collect();
        let cross_buffers = split_ranges(&mut self.cross_forces, &local);

        let p = &mut self.particles;
        let force = DisjointWriter::new(&mut p.force);
        let torque = DisjointWriter::new(&mut p.torque);
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let reset = ResetKernel {
            boundary_load: (!self.chains.is_empty()).then_some(self.boundary_load.as_slice()),
            external_force: &p.external_force,
            external_torque: &p.external_torque,
            mass: &p.mass,
            gravity: self.params.gravity,
            no_loads: self.chains.is_empty()
                && !self.external_loads
                && self.params.gravity == [0.0, 0.0],
        };
        let blocks: Vec<BlockWork<'_>> = shear_parts
            .into_iter()
            .zip(sliding_parts)
            .zip(cross_shear.into_iter().zip(cross_sliding))
            .zip(cross_buffers)
            .enumerate()
            .map(
                |(b, (((shear, sliding), (cross_shear, cross_sliding)), cross_forces))| BlockWork {
                    block: b,
                    shear,
                    sliding,
                    cross_shear,
                    cross_sliding,
                    cross_forces,
                },
            )
            .collect();
        let block_ranges = &self.neighbors.block_ranges;
        let tallies = map_blocks(team, blocks, |work| {
            let b = work.block;
            let mut direct = DirectSink {
                force: &force,
                torque: &torque,
            };
            // SAFETY: block b resets and writes only the forces of its own particles
            // (interior pairs have both particles in block b); cross pairs only
            // write their own slots of the buffer.
            unsafe {
                let (lo, hi) = block_ranges[b];
                reset.apply(lo, hi, &force, &torque);
                let mut tally =
                    kernel.run::<MEASURE, _>(ranges[b].0, work.shear, work.sliding, &mut direct);
                if buffer_cross {
                    let mut buffered = BufferSink {
                        slots: work.cross_forces,
                    };
                    let cross = kernel.run::<MEASURE, _>(
                        ranges[n_blocks + b].0,
                        work.cross_shear,
                        work.cross_sliding,
                        &mut buffered,
                    );
                    tally.merge(&cross);
                }
                tally
            }
        });
        // with a buffer the cross-block forces are applied by each block's
        // integration (step 7)
        tallies
    }

    /// Step 5b, on one thread: the pairs across stripes, after bonds and walls,
    /// in pair order and in the same chunks as a team would evaluate them, adding
    /// their forces straight onto the particles. Each particle then receives the
    /// same additions in the same order as from the buffer (which a stripe's
    /// integration applies after the bonds and walls, in pair order), and each
    /// stripe's tally the same merges: the same bits without the buffer.
    fn cross_pairs_in_order<const MEASURE: bool>(&mut self, tallies: &mut [ContactTally]) {
        let increment_time = self.increment_time();
        let n_blocks = self.neighbors.block_ranges.len();
        let pairs = &mut self.neighbors.pairs;
        let cross_start = pairs.block_start[n_blocks];
        let chunks = even_bounds(pairs.len() - cross_start, n_blocks);
        let p = &mut self.particles;
        let force = DisjointWriter::new(&mut p.force);
        let torque = DisjointWriter::new(&mut p.torque);
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let mut direct = DirectSink {
            force: &force,
            torque: &torque,
        };
        for (tally, &(lo, hi)) in tallies.iter_mut().zip(&chunks) {
            let (lo, hi) = (cross_start + lo, cross_start + hi);
            // SAFETY: one thread; the pairs index particles that exist
            let cross = unsafe {
                kernel.run::<MEASURE, _>(
                    lo,
                    &mut pairs.shear[lo..hi],
                    &mut pairs.sliding[lo..hi],
                    &mut direct,
                )
            };
            tally.merge(&cross);
        }
    }

    /// Step 4: bonds (sequential; chains of membrane disks are short).
    fn bond_forces<const MEASURE: bool>(&mut self) -> ContactTally {
        let mut tally = ContactTally::default();
        let increment_time = self.increment_time();
        let l = self.deforming_gradient();
        for bond in self.bonds.list.iter_mut() {
            let copy = *bond;
            let b = bond_force(
                &copy,
                &self.particles,
                self.cell.as_ref(),
                l,
                increment_time,
                &mut bond.shear,
            );
            let (i, j) = (copy.i as usize, copy.j as usize);
            let p = &mut self.particles;
            let f = add(
                scale(b.normal, b.normal_force),
                scale(perp(b.normal), b.shear_force),
            );
            p.force[j] = add(p.force[j], f);
            p.force[i] = sub(p.force[i], f);
            p.torque[i] -= p.radius[i] * b.shear_force;
            p.torque[j] -= p.radius[j] * b.shear_force;
            if MEASURE {
                let (fn_, fs) = (b.normal_force, b.shear_force);
                tally.elastic +=
                    0.5 * fn_ * fn_ / copy.normal_stiffness + 0.5 * fs * fs / copy.shear_stiffness;
                tally.force_sum += (fn_ * fn_ + fs * fs).sqrt();
                tally.contacts += 1;
            }
        }
        tally
    }

    /// Step 5: particle-wall contacts; returns the tally and the walls' work over
    /// their last step's displacement.
    fn wall_forces<const MEASURE: bool>(&mut self) -> (ContactTally, f64) {
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
            let q = wp.particle[k] as usize;
            let model = self.materials.by_index(wp.model[k]);
            let Some((g, c)) = wall_contact(
                wall,
                model,
                &self.particles,
                q,
                dt,
                increment_time,
                &mut wp.shear[k],
            ) else {
                wp.sliding[k] = false;
                continue;
            };
            wp.sliding[k] = c.sliding;
            let p = &mut self.particles;
            let r = p.radius[q];
            let n = g.normal;
            let f = add(scale(n, c.normal), scale(perp(n), c.shear));
            p.force[q] = add(p.force[q], f);
            p.torque[q] -= r * c.shear;
            wall.force = sub(wall.force, f);
            wall.contact_count += 1;
            wall.stiffness_sum += model.normal_stiffness;
            tally.friction += c.friction_dissipation;
            tally.viscous += c.viscous_dissipation;
            if g.overlap > self.params.max_overlap_ratio * r {
                tally.overlap_violation = true;
            }
            if MEASURE {
                tally.elastic += elastic_energy(model, c.elastic_normal, wp.shear[k]);
                tally.force_sum += (c.normal * c.normal + c.shear * c.shear).sqrt();
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

    /// Step 7: leapfrog with local damping in parallel chunks.
    fn integrate<const MEASURE: bool>(&mut self, team: Option<&Team>) -> IntegrationTally {
        // with a team the cross-block forces wait in the buffer (else they are applied)
        let buffered = team.is_some();
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
        let p = &mut self.particles;
        let has_external = self.params.gravity != [0.0, 0.0] || self.external_loads;
        let step = IntegrationStep {
            dt,
            kick: if self.half_kick_pending { 0.5 * dt } else { dt },
            half_kick: self.half_kick_pending,
            alpha: self.params.local_damping,
            gravity: self.params.gravity,
            has_external,
            step_map,
            accumulated_map,
        };
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
        let bounds = self.neighbors.block_ranges.clone();
        let cross = CrossForces {
            pair_i: &self.neighbors.pairs.i,
            pair_j: &self.neighbors.pairs.j,
            first: self
                .neighbors
                .pairs
                .block_start
                .last()
                .copied()
                .unwrap_or(0),
            forces: &self.cross_forces,
            touch: &self.neighbors.cross_touch,
            touch_start: &self.neighbors.cross_touch_start,
        };
        type Work<'w> = (
            usize,
            usize,
            &'w mut [Vec2],
            &'w mut [Vec2],
            &'w mut [f64],
            &'w mut [f64],
            &'w mut [Vec2],
            &'w mut [f64],
        );
        let chunks: Vec<Work<'_>> = split_ranges(&mut p.position, &bounds)
            .into_iter()
            .zip(split_ranges(&mut p.velocity, &bounds))
            .zip(split_ranges(&mut p.rotation, &bounds))
            .zip(split_ranges(&mut p.angular_velocity, &bounds))
            .zip(split_ranges(&mut p.force, &bounds))
            .zip(split_ranges(&mut p.torque, &bounds))
            .zip(&bounds)
            .enumerate()
            .map(
                |(
                    b,
                    (
                        (((((position, velocity), rotation), angular_velocity), force), torque),
                        &(lo, _),
                    ),
                )| {
                    (
                        b,
                        lo,
                        position,
                        velocity,
                        rotation,
                        angular_velocity,
                        force,
                        torque,
                    )
                },
            )
            .collect();
        let tallies = map_blocks(
            team,
            chunks,
            |(b, lo, position, velocity, rotation, angular_velocity, force, torque)| {
                if buffered {
                    // the cross-block pairs touching this block, in pair order, as a
                    // sequential pass over all of them adds them
                    cross.apply(b, lo, force, torque);
                }
                let chunk = MotionChunk {
                    lo,
                    position,
                    velocity,
                    rotation,
                    angular_velocity,
                    force,
                    torque,
                };
                integrate_chunk::<MEASURE>(chunk, &inputs, &step)
            },
        );
        let mut total = IntegrationTally::default();
        for t in &tallies {
            total.merge(t);
        }
        total
    }

    fn non_finite_error(&self) -> EngineError {
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

    fn overlap_error(&self) -> EngineError {
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

    /// Serialises the complete state (contact history, pending shear increment
    /// and neighbour lists included), after a tag naming its layout.
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut bytes = STATE_TAG.to_vec();
        bincode::serialize_into(&mut bytes, self)
            .map_err(|e| EngineError::invalid("state", e.to_string()))?;
        Ok(bytes)
    }

    /// Restores a state written by [`Simulation::to_bytes`]; it continues bitwise
    /// identically.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let Some(body) = bytes.strip_prefix(STATE_TAG.as_slice()) else {
            return Err(EngineError::invalid(
                "state",
                "not a grainlab engine state of this engine's layout (a state written \
                 by an older grainlab engine cannot be resumed by this one: start the run again)",
            ));
        };
        let mut sim: Simulation = bincode::deserialize(body).map_err(|e| {
            EngineError::invalid("state", format!("not a grainlab engine state: {e}"))
        })?;
        sim.check_consistent()?;
        sim.make_pool()?;
        Ok(sim)
    }

    /// Checks that the state indexes only what it holds: the force kernels read
    /// particle arrays without bounds checks, so a stale or edited state (a
    /// loaded file, or public fields changed by hand) must be refused before any
    /// step rather than read out of bounds. Linear in particles and pairs: run
    /// at every load and at the start of every `run` call.
    fn check_consistent(&self) -> Result<()> {
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
        self.neighbors
            .check_consistent(n, self.walls.len(), self.materials.len())
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

/// Nearest-image branch vector for bonds.
pub fn minimum_image(cell: Option<&PeriodicCell>, d: Vec2) -> Vec2 {
    match cell {
        Some(c) if c.periodic[0] || c.periodic[1] => {
            let zero = c.origin;
            let f = c.fractional(add(zero, d));
            let mut shift = [0i8; 2];
            for k in 0..2 {
                if c.periodic[k] {
                    shift[k] = -(f[k].round() as i8);
                }
            }
            add(d, c.image_offset(shift))
        }
        _ => d,
    }
}

/// A bond's geometry and forces at the current state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BondForce {
    /// Unit normal from `i` to `j`.
    pub normal: Vec2,
    /// Centre distance (m).
    pub distance: f64,
    /// Normal force on `j` (N), positive in compression.
    pub normal_force: f64,
    /// Shear force on `j` along `perp(normal)` (N): the updated spring.
    pub shear_force: f64,
}

/// Evaluates `bond` at the current state, adding `-ks v_t increment_time` to `shear`
/// (its spring: the bond's own, or a copy for a query).
#[inline]
pub(crate) fn bond_force(
    bond: &Bond,
    p: &Particles,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
    shear: &mut f64,
) -> BondForce {
    let (i, j) = (bond.i as usize, bond.j as usize);
    let d = minimum_image(cell, sub(p.position[j], p.position[i]));
    let dist = norm(d);
    let n = scale(d, 1.0 / dist);
    let t = perp(n);
    let mut dv = sub(p.velocity[j], p.velocity[i]);
    if let Some(l) = &velocity_gradient {
        dv = add(dv, mat_vec(l, d));
    }
    let (ri, rj) = (p.radius[i], p.radius[j]);
    let vt = dot(dv, t) - (p.angular_velocity[i] * ri + p.angular_velocity[j] * rj);
    *shear -= bond.shear_stiffness * vt * increment_time;
    BondForce {
        normal: n,
        distance: dist,
        normal_force: bond.normal_stiffness * (bond.rest_length - dist),
        shear_force: *shear,
    }
}

/// Particle `q` against `wall` at the current state: the geometry and the
/// contact law's forces on the particle, updating `spring` (the pair's shear
/// spring, or a copy for a query) over `increment_time`; `None`, with the
/// spring zeroed, when they do not touch.
#[inline]
pub(crate) fn wall_contact(
    wall: &Wall,
    model: &ContactModel,
    p: &Particles,
    q: usize,
    dt: f64,
    increment_time: f64,
    spring: &mut f64,
) -> Option<(ContactGeometry, ContactForce)> {
    let r = p.radius[q];
    let g = wall.disk_contact(p.position[q], r);
    if g.overlap <= 0.0 {
        *spring = 0.0;
        return None;
    }
    let n = g.normal;
    let t = perp(n);
    let dv = sub(p.velocity[q], wall.velocity);
    let vn = dot(dv, n);
    let vt = dot(dv, t) - p.angular_velocity[q] * r;
    let c = linear_coulomb(
        model,
        g.overlap,
        vn,
        vt,
        dt,
        increment_time,
        p.mass[q],
        spring,
    );
    Some((g, c))
}

/// Where a pair's force goes: straight onto the particles, or into a buffer slot.
trait ForceSink {
    /// Adds force `f` on `j` (its opposite on `i`) and the torques, for local pair `k`.
    ///
    /// # Safety
    /// The caller owns `i` and `j` (direct sink) or slot `k` (buffer).
    unsafe fn add(&mut self, k: usize, i: usize, j: usize, f: Vec2, torque_i: f64, torque_j: f64);
    /// Local pair `k` is not in contact.
    fn skip(&mut self, k: usize);
    /// Local pair `k` is in contact with `overlap`, unit normal `n`, forces `c` and
    /// (updated) shear spring `spring`; only the contact list keeps it.
    #[inline(always)]
    fn record(&mut self, _k: usize, _overlap: f64, _n: Vec2, _c: &ContactForce, _spring: f64) {}
}

/// Throws the forces away (the springs' catch-up).
struct NullSink;

impl ForceSink for NullSink {
    #[inline(always)]
    unsafe fn add(&mut self, _: usize, _: usize, _: usize, _: Vec2, _: f64, _: f64) {}
    #[inline(always)]
    fn skip(&mut self, _k: usize) {}
}

/// A particle pair's contact as the force evaluation saw it, for the contact list.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairRecord {
    /// Overlap (m).
    pub overlap: f64,
    /// Unit normal from `i` to `j`.
    pub normal: Vec2,
    /// Elastic normal force `kn * overlap` (N).
    pub elastic_normal: f64,
    /// Shear spring after the update (N).
    pub shear_spring: f64,
    /// Whether the spring is at the Coulomb cap.
    pub sliding: bool,
}

/// Keeps every contact's record, in pair order (`None`: not in contact).
struct RecordSink {
    records: Vec<Option<PairRecord>>,
}

impl ForceSink for RecordSink {
    #[inline(always)]
    unsafe fn add(&mut self, _: usize, _: usize, _: usize, _: Vec2, _: f64, _: f64) {}
    #[inline(always)]
    fn skip(&mut self, _k: usize) {}
    fn record(&mut self, k: usize, overlap: f64, n: Vec2, c: &ContactForce, spring: f64) {
        self.records[k] = Some(PairRecord {
            overlap,
            normal: n,
            elastic_normal: c.elastic_normal,
            shear_spring: spring,
            sliding: c.sliding,
        });
    }
}

struct DirectSink<'a> {
    force: &'a DisjointWriter<Vec2>,
    torque: &'a DisjointWriter<f64>,
}

impl ForceSink for DirectSink<'_> {
    #[inline(always)]
    unsafe fn add(&mut self, _k: usize, i: usize, j: usize, f: Vec2, torque_i: f64, torque_j: f64) {
        let fj = self.force.get(j);
        fj[0] += f[0];
        fj[1] += f[1];
        let fi = self.force.get(i);
        fi[0] -= f[0];
        fi[1] -= f[1];
        *self.torque.get(i) += torque_i;
        *self.torque.get(j) += torque_j;
    }

    #[inline(always)]
    fn skip(&mut self, _k: usize) {}
}

struct BufferSink<'a> {
    slots: &'a mut [PairForce],
}

impl ForceSink for BufferSink<'_> {
    #[inline(always)]
    unsafe fn add(
        &mut self,
        k: usize,
        _i: usize,
        _j: usize,
        f: Vec2,
        torque_i: f64,
        torque_j: f64,
    ) {
        self.slots[k] = PairForce {
            force: f,
            torque_i,
            torque_j,
            active: true,
        };
    }

    #[inline(always)]
    fn skip(&mut self, k: usize) {
        self.slots[k].active = false;
    }
}

/// The buffered forces of cross-block pairs and, per block, which of them touch it.
struct CrossForces<'a> {
    pair_i: &'a [u32],
    pair_j: &'a [u32],
    first: usize,
    forces: &'a [PairForce],
    touch: &'a [u32],
    touch_start: &'a [usize],
}

impl CrossForces<'_> {
    /// Adds block `b`'s cross-pair forces to `force`/`torque`, which start at particle `lo`.
    fn apply(&self, b: usize, lo: usize, force: &mut [Vec2], torque: &mut [f64]) {
        if self.touch_start.len() <= b + 1 {
            return;
        }
        for &entry in &self.touch[self.touch_start[b]..self.touch_start[b + 1]] {
            let c = (entry >> 1) as usize;
            let pf = &self.forces[c];
            if !pf.active {
                continue;
            }
            let k = self.first + c;
            if entry & 1 == 1 {
                let q = self.pair_j[k] as usize - lo;
                force[q][0] += pf.force[0];
                force[q][1] += pf.force[1];
                torque[q] += pf.torque_j;
            } else {
                let q = self.pair_i[k] as usize - lo;
                force[q][0] -= pf.force[0];
                force[q][1] -= pf.force[1];
                torque[q] += pf.torque_i;
            }
        }
    }
}

/// A cross-block pair's force, computed in parallel and applied afterwards.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PairForce {
    force: Vec2,
    torque_i: f64,
    torque_j: f64,
    active: bool,
}

impl PairForce {
    const NONE: PairForce = PairForce {
        force: [0.0; 2],
        torque_i: 0.0,
        torque_j: 0.0,
        active: false,
    };
}

/// One block's share of the contact phase.
struct BlockWork<'a> {
    block: usize,
    shear: &'a mut [f64],
    sliding: &'a mut [bool],
    cross_shear: &'a mut [f64],
    cross_sliding: &'a mut [bool],
    cross_forces: &'a mut [PairForce],
}

struct ResetKernel<'a> {
    boundary_load: Option<&'a [Vec2]>,
    external_force: &'a [Vec2],
    external_torque: &'a [f64],
    mass: &'a [f64],
    gravity: Vec2,
    /// No pressure chain, gravity or external force or torque: every external
    /// force is +-0, so `f_e + m g` is +0 whatever its sign, and the torques
    /// (+-0) are copied as they are.
    no_loads: bool,
}

impl ResetKernel<'_> {
    /// Resets the resultants of particles `lo..hi` to their external loads.
    ///
    /// # Safety
    /// `lo..hi` in bounds and owned by the calling task.
    #[inline(always)]
    unsafe fn apply(
        &self,
        lo: usize,
        hi: usize,
        force: &DisjointWriter<Vec2>,
        torque: &DisjointWriter<f64>,
    ) {
        if self.no_loads {
            force.range(lo, hi).fill([0.0; 2]);
            torque
                .range(lo, hi)
                .copy_from_slice(&self.external_torque[lo..hi]);
            return;
        }
        for q in lo..hi {
            let fe = self.external_force[q];
            let m = self.mass[q];
            let mut f = [fe[0] + m * self.gravity[0], fe[1] + m * self.gravity[1]];
            if let Some(load) = self.boundary_load {
                f = add(f, load[q]);
            }
            *force.get(q) = f;
            *torque.get(q) = self.external_torque[q];
        }
    }
}

/// A [`PairKernel`] over the particles `$p` and pair list `$pairs` of simulation
/// `$sim` (a macro, so that the shear springs can be borrowed mutably apart).
macro_rules! pair_kernel {
    ($sim:expr, $p:expr, $pairs:expr, $increment_time:expr) => {
        PairKernel {
            position: &$p.position,
            velocity: &$p.velocity,
            angular_velocity: &$p.angular_velocity,
            radius: &$p.radius,
            mass: &$p.mass,
            pair_i: &$pairs.i,
            pair_j: &$pairs.j,
            shift: &$pairs.shift,
            model: &$pairs.model,
            materials: &$sim.materials,
            cell: $sim.cell.as_ref(),
            velocity_gradient: $sim
                .cell
                .as_ref()
                .filter(|c| c.is_deforming())
                .map(|c| c.velocity_gradient),
            dt: $sim.params.time_step,
            increment_time: $increment_time,
            max_overlap_ratio: $sim.params.max_overlap_ratio,
            single_model: $sim.materials.single_undamped_model(),
        }
    };
}
pub(crate) use pair_kernel;

pub(crate) struct PairKernel<'a> {
    position: &'a [Vec2],
    velocity: &'a [Vec2],
    angular_velocity: &'a [f64],
    radius: &'a [f64],
    mass: &'a [f64],
    pair_i: &'a [u32],
    pair_j: &'a [u32],
    shift: &'a [[i8; 2]],
    model: &'a [u16],
    materials: &'a MaterialTable,
    cell: Option<&'a PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    dt: f64,
    increment_time: f64,
    max_overlap_ratio: f64,
    /// The one model of every pair when there is one and it has no dashpot.
    single_model: Option<ContactModel>,
}

impl PairKernel<'_> {
    /// Evaluates pairs `first..first + shear.len()`, adding forces to both particles.
    ///
    /// # Safety
    /// Concurrent callers must touch disjoint particles.
    #[inline(always)]
    unsafe fn run<const MEASURE: bool, S: ForceSink>(
        &self,
        first: usize,
        shear: &mut [f64],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        // the loop specialised on what is fixed for the whole call: the same
        // arithmetic in every variant, minus the tests whose outcome is known
        match (
            self.velocity_gradient.is_some(),
            self.single_model.is_some(),
        ) {
            (false, false) => self.pairs::<MEASURE, false, false, S>(first, shear, sliding, sink),
            (false, true) => self.pairs::<MEASURE, false, true, S>(first, shear, sliding, sink),
            (true, false) => self.pairs::<MEASURE, true, false, S>(first, shear, sliding, sink),
            (true, true) => self.pairs::<MEASURE, true, true, S>(first, shear, sliding, sink),
        }
    }

    /// The loop of [`PairKernel::run`]: `DEFORMING` when the cell has a velocity
    /// gradient, `SINGLE` when [`PairKernel::single_model`] is set.
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(always)]
    unsafe fn pairs<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        S: ForceSink,
    >(
        &self,
        first: usize,
        shear: &mut [f64],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        let mut tally = ContactTally::default();
        let gradient = self.velocity_gradient.unwrap_or([[0.0; 2]; 2]);
        let single = self
            .single_model
            .unwrap_or(ContactModel::linear(1.0, 1.0, 0.0));
        let max_overlap_ratio = self.max_overlap_ratio;
        let mut overlap_violation = false;
        debug_assert!(first + shear.len() <= self.pair_i.len());
        for (k, (spring, slide)) in shear.iter_mut().zip(sliding.iter_mut()).enumerate() {
            let pair = first + k;
            // SAFETY: the neighbour list holds pairs `first..first + shear.len()` of
            // particles that exist (`NeighborList::build`), so every index below is
            // in bounds; the checks would cost a tenth of the loop
            let i = *self.pair_i.get_unchecked(pair) as usize;
            let j = *self.pair_j.get_unchecked(pair) as usize;
            debug_assert!(i < self.position.len() && j < self.position.len());
            let xi = *self.position.get_unchecked(i);
            let mut xj = *self.position.get_unchecked(j);
            let s = *self.shift.get_unchecked(pair);
            if s != [0, 0] {
                if let Some(c) = self.cell {
                    xj = add(xj, c.image_offset(s));
                }
            }
            let d = sub(xj, xi);
            let (ri, rj) = (*self.radius.get_unchecked(i), *self.radius.get_unchecked(j));
            let reach = ri + rj;
            let dist_sq = dot(d, d);
            if dist_sq >= reach * reach {
                if *spring != 0.0 || *slide {
                    *spring = 0.0;
                    *slide = false;
                }
                sink.skip(k);
                continue;
            }
            let dist = dist_sq.sqrt();
            let n = scale(d, 1.0 / dist);
            let overlap = reach - dist;
            let t = perp(n);
            let mut dv = sub(
                *self.velocity.get_unchecked(j),
                *self.velocity.get_unchecked(i),
            );
            if DEFORMING {
                dv = add(dv, mat_vec(&gradient, d));
            }
            let vn = dot(dv, n);
            let vt = dot(dv, t)
                - (*self.angular_velocity.get_unchecked(i) * ri
                    + *self.angular_velocity.get_unchecked(j) * rj);
            let model = if SINGLE {
                &single
            } else {
                self.materials.by_index(*self.model.get_unchecked(pair))
            };
            let reduced_mass = if !SINGLE
                && (model.normal_damping_ratio > 0.0 || model.shear_damping_ratio > 0.0)
            {
                let (mi, mj) = (self.mass[i], self.mass[j]);
                mi * mj / (mi + mj)
            } else {
                0.0
            };
            let (dt, increment_time) = (self.dt, self.increment_time);
            let c = if SINGLE {
                linear_coulomb_with::<false>(
                    model,
                    overlap,
                    vn,
                    vt,
                    dt,
                    increment_time,
                    reduced_mass,
                    spring,
                )
            } else {
                linear_coulomb(
                    model,
                    overlap,
                    vn,
                    vt,
                    dt,
                    increment_time,
                    reduced_mass,
                    spring,
                )
            };
            *slide = c.sliding;
            sink.record(k, overlap, n, &c, *spring);
            let f = [
                c.normal * n[0] + c.shear * t[0],
                c.normal * n[1] + c.shear * t[1],
            ];
            sink.add(k, i, j, f, -ri * c.shear, -rj * c.shear);
            tally.friction += c.friction_dissipation;
            tally.viscous += c.viscous_dissipation;
            overlap_violation |= overlap > max_overlap_ratio * ri.min(rj);
            if MEASURE {
                tally.elastic += elastic_energy(model, model.normal_stiffness * overlap, *spring);
                tally.force_sum += (c.normal * c.normal + c.shear * c.shear).sqrt();
                tally.contacts += 1;
            }
        }
        tally.overlap_violation = overlap_violation;
        tally
    }
}
