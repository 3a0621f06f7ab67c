//! The simulation: its state, its setters and queries, and saving it.
use rayon::ThreadPool;
use serde::{Deserialize, Serialize};

use super::deferred::{DeferredIndex, WallSlot};
use super::pair_kernel::{
    pair_kernel, wall_contact, NullSink, PairForce, PairKernel, PairRecord, RecordSink,
};
use crate::body::Clumps;
use crate::bond::{bond_force, Bond, BondForce, BondSlot, Bonds};
use crate::boundary::{ChainStripes, PressureChain};
use crate::cell::{minimum_image, PeriodicCell};
use crate::cement::{
    advance_springs, BondBreak, Cement, CementBond, CementSlot, CementSpec, Rupture,
};
use crate::contact::{disk_disk, ContactGeometry};
use crate::diagnostics::{EnergyLedger, Measurements};
use crate::error::{
    require_finite_points, require_finite_values, require_non_negative, require_positive,
    EngineError, Result,
};
use crate::law;
use crate::law::rolling::RollingSpring;
use crate::law::ContactForce;
use crate::material::{ContactModel, MaterialTable};
use crate::neighbor::NeighborList;
use crate::parallel::Pacer;
use crate::state::{ParticleMotion, Particles, NO_CLUMP};
use crate::vec2::{add, norm, sub, Mat2, Vec2};
use crate::wall::{Wall, WallControl};

/// The first bytes of [`Simulation::to_bytes`]: the layout of the state that
/// follows (bincode of [`Simulation`]); a new field makes a new tag.
const STATE_TAG: &[u8; 8] = b"GLSTATE7";

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

/// A 2D disk DEM simulation: particles, walls, bonds, an optional periodic cell.
#[derive(Serialize, Deserialize)]
pub struct Simulation {
    /// The disks (a clump's pebbles among them).
    pub(crate) particles: Particles,
    /// Bodies of two or more pebbles.
    pub(crate) clumps: Clumps,
    /// Contact models per pair of groups.
    pub(crate) materials: MaterialTable,
    /// Rigid walls.
    pub(crate) walls: Vec<Wall>,
    /// Permanent bonds.
    pub(crate) bonds: Bonds,
    /// Breakable cement bonds and the log of their breaks.
    pub(crate) cement: Cement,
    /// Chains of boundary particles under a follower pressure.
    pub(crate) chains: Vec<PressureChain>,
    /// Periodic cell, if any.
    pub(crate) cell: Option<PeriodicCell>,
    /// Step tunables.
    pub(crate) params: StepParameters,
    /// Verlet lists and contact history.
    pub(crate) neighbors: NeighborList,
    /// Measurements of the last measured step.
    pub(crate) measurements: Measurements,
    /// Steps taken.
    pub(crate) step_count: u64,
    /// Simulated time (s).
    pub(crate) time: f64,
    /// External (user) index of each internal particle slot: the engine keeps
    /// particles in spatial order, renumbered at every neighbour-list build.
    pub(crate) order: Vec<u32>,
    /// Internal slot of each external index (the inverse of `order`).
    pub(crate) rank: Vec<u32>,
    pub(crate) ledger: EnergyLedger,
    /// Velocities are full-step values (set from outside): the next step kicks by `dt/2`.
    pub(crate) half_kick_pending: bool,
    /// The shear springs hold every tangential displacement made so far: nothing
    /// moved since the last force evaluation (or [`Simulation::catch_up_shear_springs`]),
    /// so the next one adds no increment.
    pub(crate) springs_current: bool,
    pub(crate) threads: usize,
    #[serde(skip)]
    pub(crate) pool: Option<ThreadPool>,
    #[serde(skip)]
    pub(crate) cross_forces: Vec<PairForce>,
    /// The bonds' forces of this step, in bond order (`step::bond_forces`).
    #[serde(skip)]
    pub(crate) bond_slots: Vec<BondSlot>,
    /// The cement bonds' forces of this step, in cement order.
    #[serde(skip)]
    pub(crate) cement_slots: Vec<CementSlot>,
    /// The cement bonds that broke at this step's evaluation, per stripe, in
    /// bond order (whole-list index and record).
    #[serde(skip)]
    pub(crate) cement_ruptures: Vec<Vec<(usize, Rupture)>>,
    /// Follower loads of this step, per internal particle (recomputed every step).
    #[serde(skip)]
    pub(crate) boundary_load: Vec<Vec2>,
    /// The chains' entries per stripe of particles, for the loads' reset (kept
    /// current by `run` and every rebuild).
    #[serde(skip)]
    pub(crate) chain_stripes: ChainStripes,
    /// The bonds' and wall pairs' entries per stripe of particles, for adding
    /// their forces in the integration (kept current like `chain_stripes`).
    #[serde(skip)]
    pub(crate) deferred_index: DeferredIndex,
    /// The wall contacts' forces of this step, per wall pair, when a team adds
    /// them in the integration.
    #[serde(skip)]
    pub(crate) wall_slots: Vec<WallSlot>,
    /// Whether any particle has an external force or torque (scanned once per run call).
    #[serde(skip)]
    pub(crate) external_loads: bool,
    /// Whether the steps run with the team or on one thread (timed, `parallel::Pacer`).
    #[serde(skip)]
    pub(crate) pacer: Pacer,
    /// Whether the step's vector kernels run ([`Simulation::set_simd`]); on by
    /// default where the processor can.
    #[serde(skip, default = "simd_available")]
    pub(crate) simd: bool,
}

/// Whether this processor runs the step's vector kernels (AVX2).
fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        crate::simd::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
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
            clumps: Clumps::default(),
            materials: MaterialTable::uniform(model)?,
            walls: Vec::new(),
            bonds: Bonds::default(),
            cement: Cement::default(),
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
            bond_slots: Vec::new(),
            cement_slots: Vec::new(),
            cement_ruptures: Vec::new(),
            boundary_load: Vec::new(),
            chain_stripes: ChainStripes::default(),
            deferred_index: DeferredIndex::default(),
            wall_slots: Vec::new(),
            external_loads: false,
            pacer: Pacer::default(),
            simd: simd_available(),
        };
        sim.make_pool()?;
        Ok(sim)
    }

    /// The worker pool of `threads` (none for one thread).
    pub(crate) fn make_pool(&mut self) -> Result<()> {
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

    /// The disks, in the engine's internal (spatial) order: map an index with
    /// [`Simulation::external_index`], or a whole array with
    /// [`Simulation::to_external`], before reading it as a user's index.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Contact models per pair of groups.
    pub fn materials(&self) -> &MaterialTable {
        &self.materials
    }

    /// The walls, by id.
    pub fn walls(&self) -> &[Wall] {
        &self.walls
    }

    /// The permanent bonds (internal particle indices).
    pub fn bonds(&self) -> &Bonds {
        &self.bonds
    }

    /// The intact cement bonds (internal particle indices) and the breaks not
    /// yet taken ([`Simulation::take_bond_breaks`]).
    pub fn cement(&self) -> &Cement {
        &self.cement
    }

    /// The breaks of cement bonds since the last call, in the order they
    /// happened (particles as external indices); the log is emptied.
    pub fn take_bond_breaks(&mut self) -> Vec<BondBreak> {
        std::mem::take(&mut self.cement.breaks)
    }

    /// Each intact cement bond's normal force at the current state (N,
    /// compression positive: `k_n (L_0 - d)`), in cement order.
    pub fn cement_normal_forces(&self) -> Vec<f64> {
        self.cement
            .bonds
            .iter()
            .map(|b| {
                let d = norm(self.branch(b.i as usize, b.j as usize));
                b.normal_stiffness * (b.rest_length - d)
            })
            .collect()
    }

    /// Number of pressure chains.
    pub fn pressure_chain_count(&self) -> usize {
        self.chains.len()
    }

    /// The periodic cell, if any.
    pub fn cell(&self) -> Option<&PeriodicCell> {
        self.cell.as_ref()
    }

    /// The step tunables.
    pub fn params(&self) -> StepParameters {
        self.params
    }

    /// The Verlet lists and contact history (internal particle indices).
    pub fn neighbors(&self) -> &NeighborList {
        &self.neighbors
    }

    /// Measurements of the last measured step.
    pub fn measurements(&self) -> Measurements {
        self.measurements
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// A per-particle array given in external order, checked for its length
    /// and put in internal order.
    fn internal_array<T: Copy>(&self, field: &str, external: &[T]) -> Result<Vec<T>> {
        let n = self.particles.len();
        if external.len() != n {
            return Err(EngineError::invalid(
                field,
                format!(
                    "expected {n} values, one per particle, got {}",
                    external.len()
                ),
            ));
        }
        Ok(self.to_internal(external))
    }

    /// Sets the external forces (N, finite, external order).
    pub fn set_external_forces(&mut self, forces: &[Vec2]) -> Result<()> {
        require_finite_points("external_forces", forces)?;
        self.particles.external_force = self.internal_array("external_forces", forces)?;
        Ok(())
    }

    /// Sets the external torques (N m, finite, external order).
    pub fn set_external_torques(&mut self, torques: &[f64]) -> Result<()> {
        require_finite_values("external_torques", torques)?;
        self.particles.external_torque = self.internal_array("external_torques", torques)?;
        Ok(())
    }

    /// Sets the rotations (rad, finite, external order).
    pub fn set_rotations(&mut self, rotations: &[f64]) -> Result<()> {
        require_finite_values("rotations", rotations)?;
        let rotation = self.internal_array("rotations", rotations)?;
        self.check_pebbles_kept("rotations", &self.particles.rotation, &rotation)?;
        self.particles.rotation = rotation;
        Ok(())
    }

    /// Sets the radii (m, > 0, external order): new overlaps, so the last
    /// step's displacement is first added to the springs; the masses and
    /// moments of inertia follow and the neighbour lists are rebuilt.
    pub fn set_radii(&mut self, radii: &[f64]) -> Result<()> {
        for (k, &r) in radii.iter().enumerate() {
            require_positive(&format!("radii[{k}]"), r)?;
        }
        let radius = self.internal_array("radii", radii)?;
        self.check_pebbles_kept("radii", &self.particles.radius, &radius)?;
        self.modify_motion(|s| {
            s.particles.radius = radius;
            s.particles.update_mass_properties();
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Sets the densities (kg/m^3, > 0, external order); the masses and
    /// moments of inertia follow.
    pub fn set_densities(&mut self, densities: &[f64]) -> Result<()> {
        for (k, &d) in densities.iter().enumerate() {
            require_positive(&format!("densities[{k}]"), d)?;
        }
        let density = self.internal_array("densities", densities)?;
        self.check_clumps_agree("densities", &density, "a clump has one density")?;
        for c in 0..self.clumps.len() {
            let first = self.clumps.pebble[self.clumps.start[c] as usize] as usize;
            self.clumps
                .rescale_density(c, density[first], &self.particles);
        }
        self.particles.density = density;
        self.particles.update_mass_properties();
        self.clumps.assign_pebble_masses(&mut self.particles);
        Ok(())
    }

    /// Sets the material groups (0..16, external order): the contact models
    /// change, so the springs are caught up first and the lists rebuilt.
    pub fn set_groups(&mut self, groups: &[u8]) -> Result<()> {
        if let Some((k, g)) = groups
            .iter()
            .enumerate()
            .find(|(_, &g)| g as usize >= crate::state::MAX_GROUPS)
        {
            return Err(EngineError::invalid(
                format!("groups[{k}]"),
                format!("group {g} out of range 0..{}", crate::state::MAX_GROUPS),
            ));
        }
        let group = self.internal_array("groups", groups)?;
        self.modify_motion(|s| {
            s.particles.group = group;
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Sets the prescribed degrees of freedom (`FIX_X | FIX_Y | FIX_ROTATION`,
    /// external order).
    pub fn set_fixity(&mut self, fixity: &[u8]) -> Result<()> {
        let all = crate::state::FIX_X | crate::state::FIX_Y | crate::state::FIX_ROTATION;
        if let Some((k, f)) = fixity.iter().enumerate().find(|(_, &f)| f & !all != 0) {
            return Err(EngineError::invalid(
                format!("fixity[{k}]"),
                format!("{f} is not a combination of 1 (x), 2 (y), 4 (rotation)"),
            ));
        }
        let fixity = self.internal_array("fixity", fixity)?;
        self.particles.fixity = self.fixity_with_clumps(fixity)?;
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
        self.modify_motion(|s| s.params = params);
        Ok(())
    }

    /// Runs the step's vector kernels (`true`, the default where the processor
    /// has AVX2: undamped particle pairs four at a time, free particles
    /// integrated two at a time) or the scalar ones; the results are the same
    /// bits either way, only the speed differs. Returns whether the vector
    /// kernels are now in use (never on a processor without AVX2).
    pub fn set_simd(&mut self, enabled: bool) -> bool {
        self.simd = enabled && simd_available();
        self.simd
    }

    /// Whether the step's vector kernels run ([`Simulation::set_simd`]).
    pub fn simd(&self) -> bool {
        self.simd
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
        MaterialTable::check_groups(a, b)?;
        self.modify_motion(|s| {
            s.materials.set(a, b, model)?;
            s.neighbors.invalidate();
            Ok(())
        })
    }

    /// Sets (or removes) the periodic cell.
    pub fn set_cell(&mut self, cell: Option<PeriodicCell>) -> Result<()> {
        if let Some(c) = &cell {
            c.validate()?;
        }
        // the last step's displacement was made in the old cell's flow
        self.modify_motion(|s| {
            s.cell = cell;
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Sets the periodic cell's imposed velocity gradient alone (1/s), keeping the
    /// neighbour lists: their rebuild criterion follows the cell's accumulated map,
    /// whatever the gradient was, so a test that steers the cell every few steps
    /// (a stress-controlled cell) does not pay a rebuild each time.
    pub fn set_velocity_gradient(&mut self, gradient: Mat2) -> Result<()> {
        if self.cell.is_none() {
            return Err(EngineError::invalid(
                "velocity_gradient",
                "set a periodic cell first",
            ));
        }
        for row in &gradient {
            for &v in row {
                crate::error::require_finite("cell.velocity_gradient", v)?;
            }
        }
        // the last step's displacement was made in the old flow
        self.modify_motion(|s| {
            if let Some(cell) = &mut s.cell {
                cell.velocity_gradient = gradient;
            }
        });
        Ok(())
    }

    /// Adds a wall and returns its id.
    pub fn add_wall(&mut self, wall: Wall) -> usize {
        self.walls.push(wall);
        self.neighbors.invalidate();
        self.walls.len() - 1
    }

    /// The wall with id `id`, or an error naming the valid range.
    pub fn wall(&self, id: usize) -> Result<&Wall> {
        let n = self.walls.len();
        self.walls.get(id).ok_or_else(|| {
            EngineError::invalid(
                "wall_id",
                format!("unknown wall {id}; valid ids are 0..{n}"),
            )
        })
    }

    /// The wall with id `id`, to change (inside [`Simulation::modify_motion`]
    /// when its motion changes).
    pub(crate) fn wall_mut(&mut self, id: usize) -> Result<&mut Wall> {
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
        self.wall(id)?;
        self.modify_motion(|s| {
            let wall = s.wall_mut(id)?;
            wall.control = WallControl::Velocity;
            wall.velocity = velocity;
            Ok(())
        })
    }

    /// Moves wall `id` at once by `d` (m), between steps: a jump, not a shear
    /// displacement of its contacts (their springs are caught up first).
    pub fn translate_wall(&mut self, id: usize, d: Vec2) -> Result<()> {
        crate::error::require_finite("displacement", d[0])?;
        crate::error::require_finite("displacement", d[1])?;
        self.wall(id)?;
        self.modify_motion(|s| {
            s.wall_mut(id)?.translate(d);
            Ok(())
        })
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
        let clump = self.particles.clump[i];
        if clump != NO_CLUMP && clump == self.particles.clump[j] {
            return Err(EngineError::invalid(
                "bond",
                format!(
                    "particles {} and {} are pebbles of one clump and cannot be bonded",
                    self.external_index(i),
                    self.external_index(j)
                ),
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
        self.modify_motion(|s| {
            s.bonds.push(Bond {
                i: i as u32,
                j: j as u32,
                normal_stiffness,
                shear_stiffness,
                rest_length: rest,
                shear: 0.0,
            });
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Cements the pairs `pairs` (external indices), bond `k` made from
    /// `specs[k]` (or `specs[0]` for all when it has one entry), each
    /// stress-free at the pair's current distance ([`crate::cement`]). Every
    /// pair and value is checked before any bond is made: an index out of
    /// range, a particle cemented to itself or to a pebble of its own clump,
    /// a pair named twice or already bonded (cemented or by a permanent bond),
    /// a bad value (naming its field and index).
    pub fn add_cement_bonds(
        &mut self,
        pairs: &[(usize, usize)],
        specs: &[CementSpec],
    ) -> Result<()> {
        if specs.len() != pairs.len() && specs.len() != 1 {
            return Err(EngineError::invalid(
                "cement",
                format!(
                    "{} pairs but {} sets of parameters (give one, or one per pair)",
                    pairs.len(),
                    specs.len()
                ),
            ));
        }
        for (k, spec) in specs.iter().enumerate() {
            spec.validate(&format!("[{k}]"))?;
        }
        let internal = self.cement_pairs(pairs)?;
        let p = &self.particles;
        let bonds: Vec<CementBond> = internal
            .iter()
            .enumerate()
            .map(|(k, &(i, j))| {
                let spec = &specs[if specs.len() == 1 { 0 } else { k }];
                let rest = norm(self.branch(i, j));
                CementBond::new(i as u32, j as u32, p.radius[i], p.radius[j], rest, spec)
            })
            .collect();
        // new springs start from zero: no displacement before they existed counts
        self.modify_motion(|s| {
            s.cement.bonds.extend(bonds);
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// The internal pairs of `pairs` (external indices), each checked for a
    /// cement bond: in range, two particles, not of one clump, new.
    fn cement_pairs(&self, pairs: &[(usize, usize)]) -> Result<Vec<(usize, usize)>> {
        let mut seen: std::collections::HashSet<(u32, u32)> = self
            .cement
            .bonds
            .iter()
            .map(|b| (b.i.min(b.j), b.i.max(b.j)))
            .collect();
        let mut out = Vec::with_capacity(pairs.len());
        for (k, &(ei, ej)) in pairs.iter().enumerate() {
            self.particles.check_index(&format!("cement.i[{k}]"), ei)?;
            self.particles.check_index(&format!("cement.j[{k}]"), ej)?;
            let (i, j) = (self.internal_index(ei), self.internal_index(ej));
            let refuse = |why: String| Err(EngineError::invalid(format!("cement[{k}]"), why));
            if i == j {
                return refuse(format!("cannot cement particle {ei} to itself"));
            }
            let clump = self.particles.clump[i];
            if clump != NO_CLUMP && clump == self.particles.clump[j] {
                return refuse(format!(
                    "particles {ei} and {ej} are pebbles of one clump and cannot be cemented"
                ));
            }
            let key = ((i as u32).min(j as u32), (i as u32).max(j as u32));
            if self.bonds.contains(i as u32, j as u32) {
                return refuse(format!("particles {ei} and {ej} have a permanent bond"));
            }
            if !seen.insert(key) {
                return refuse(format!("particles {ei} and {ej} are already cemented"));
            }
            out.push((i, j));
        }
        Ok(out)
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
        self.modify_motion(|s| {
            let first = s.particles.len() as u32;
            let count = added.len() as u32;
            s.particles.extend(added);
            s.order.extend(first..first + count);
            s.rank.extend(first..first + count);
            s.neighbors.invalidate();
        });
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

    /// A pressure chain from external indices, checked (particles, walls,
    /// pressure), with internal indices.
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
            if self.particles.clump[self.internal_index(q)] != NO_CLUMP {
                return Err(EngineError::invalid(
                    format!("particles[{k}]"),
                    format!("particle {q} is a pebble of a clump; a chain's particles are bodies of their own"),
                ));
            }
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

    /// Switches a wall on or off; an inactive wall has no contacts and stays put.
    pub fn set_wall_active(&mut self, id: usize, active: bool) -> Result<()> {
        self.wall(id)?;
        self.modify_motion(|s| {
            let wall = s.wall_mut(id)?;
            wall.active = active;
            if !active {
                wall.velocity = [0.0; 2];
                wall.control = WallControl::Velocity;
                wall.force = [0.0; 2];
                wall.contact_count = 0;
                wall.stiffness_sum = 0.0;
            }
            s.neighbors.invalidate();
            Ok(())
        })
    }

    /// Marks the neighbour lists stale (after positions or radii changed).
    pub fn invalidate_neighbors(&mut self) {
        self.neighbors.invalidate();
    }

    /// Sets the positions (m, finite, external order): a jump, not a
    /// displacement, so the springs are caught up first and the jump adds
    /// nothing to them; the neighbour lists are rebuilt at the next step or query.
    /// A clump whose pebbles moved goes where they put it (the rigid placement
    /// closest to them in least squares), its pebbles back in its shape.
    pub fn set_positions(&mut self, positions: &[Vec2]) -> Result<()> {
        require_finite_points("positions", positions)?;
        let position = self.internal_array("positions", positions)?;
        let moved = self.clumps.changed(&self.particles.position, &position);
        self.modify_motion(|s| {
            s.particles.position = position;
            let gradient = s.deforming_gradient();
            for c in moved {
                let cell = s.cell.as_ref();
                s.clumps.fit_placement(c, &s.particles.position, cell);
                s.clumps
                    .place_clump(c, &mut s.particles, cell, gradient.as_ref());
            }
            s.neighbors.invalidate();
        });
        Ok(())
    }

    /// Sets the velocities (m/s, finite, external order). They are full-step
    /// values: the next step starts with a half kick and adds no shear
    /// increment, and the displacement of the last step, made at the old
    /// half-step velocities, is first added to the springs, so it is counted once.
    /// A clump whose pebbles' velocities changed takes the rigid motion closest
    /// to them in least squares (zero for zeros), its pebbles its rigid velocity.
    pub fn set_velocities(&mut self, velocities: &[Vec2]) -> Result<()> {
        require_finite_points("velocities", velocities)?;
        let velocity = self.internal_array("velocities", velocities)?;
        let changed = self.clumps.changed(&self.particles.velocity, &velocity);
        self.modify_motion(|s| {
            s.particles.velocity = velocity;
            let gradient = s.deforming_gradient();
            for c in changed {
                s.clumps
                    .fit_velocity(c, &s.particles.velocity, gradient.as_ref());
                s.clumps
                    .place_clump(c, &mut s.particles, s.cell.as_ref(), gradient.as_ref());
            }
            s.half_kick_pending = true;
        });
        Ok(())
    }

    /// Sets the angular velocities (rad/s, finite, external order), full-step
    /// values as in [`Simulation::set_velocities`]; a clump whose pebbles'
    /// changed takes their mean.
    pub fn set_angular_velocities(&mut self, angular_velocities: &[f64]) -> Result<()> {
        require_finite_values("angular_velocities", angular_velocities)?;
        let omega = self.internal_array("angular_velocities", angular_velocities)?;
        let changed = self
            .clumps
            .changed(&self.particles.angular_velocity, &omega);
        self.modify_motion(|s| {
            s.particles.angular_velocity = omega;
            let gradient = s.deforming_gradient();
            for c in changed {
                s.clumps
                    .fit_angular_velocity(c, &s.particles.angular_velocity);
                s.clumps
                    .place_clump(c, &mut s.particles, s.cell.as_ref(), gradient.as_ref());
            }
            s.half_kick_pending = true;
        });
        Ok(())
    }

    /// Whether the next force evaluation adds a shear increment: false after a
    /// state was built or its velocities set, or after
    /// [`Simulation::catch_up_shear_springs`]; true after a step.
    pub fn shear_increment_pending(&self) -> bool {
        !self.springs_current
    }

    /// The time over which the current velocities displaced the contacts since
    /// their springs were last updated: the time step after a step, else 0.
    pub(crate) fn increment_time(&self) -> f64 {
        if self.springs_current {
            0.0
        } else {
            self.params.time_step
        }
    }

    /// The one way a setter changes what the pending shear increment depends
    /// on (velocities and spins, positions, radii, groups, the step parameters,
    /// contact models, the cell, a wall's velocity, translation or activity,
    /// bonds, particles): the springs first take the last step's increment
    /// ([`Simulation::catch_up_shear_springs`]), then `change` runs. A setter
    /// checks its input before, so that a refused change leaves the springs as
    /// they were; the test below refuses a setter that writes those fields
    /// outside of it.
    pub(crate) fn modify_motion<R>(&mut self, change: impl FnOnce(&mut Self) -> R) -> R {
        self.catch_up_shear_springs();
        change(self)
    }

    /// Adds to every shear spring (contacts, wall contacts, bonds) the increment
    /// of the displacement made by the last step, `-ks v_t dt` at the current
    /// positions and half-step velocities, capped as the next force evaluation
    /// would; that evaluation then adds none. A no-op when the springs are
    /// current. Every method that changes what the increment would be (velocities,
    /// positions, the time step, contact models, the cell, walls, bonds,
    /// particles) makes its change through [`Simulation::modify_motion`], which
    /// calls it first. Slip in it is booked in the ledger's lines of the
    /// sub-models that carry history (friction, rolling).
    pub fn catch_up_shear_springs(&mut self) {
        if self.springs_current {
            return;
        }
        let dt = self.params.time_step;
        let pairs = &mut self.neighbors.pairs;
        let p = &self.particles;
        let kernel = pair_kernel!(self, p, pairs, dt);
        // SAFETY: one caller, and the sink writes nothing
        let tally = unsafe { kernel.run::<false, _>(0, pairs.history.run(), &mut NullSink) };
        let mut dissipation = tally.dissipation;
        let l = self.deforming_gradient();
        for bond in self.bonds.list.iter_mut() {
            let copy = *bond;
            bond_force(
                &copy,
                &ParticleMotion::of(&self.particles),
                self.cell.as_ref(),
                l,
                dt,
                &mut bond.shear,
            );
        }
        for bond in self.cement.bonds.iter_mut() {
            let motion = ParticleMotion::of(&self.particles);
            advance_springs(bond, &motion, self.cell.as_ref(), l, dt);
        }
        let wp = &mut self.neighbors.wall_pairs;
        let motion = ParticleMotion::of(&self.particles);
        for k in 0..wp.wall.len() {
            let wall = &self.walls[wp.wall[k] as usize];
            let model = self.materials.by_index(wp.model[k]);
            let q = wp.particle[k] as usize;
            match wall_contact(wall, model, &motion, q, dt, dt, &mut wp.history.records[k]) {
                Some((_, c)) => {
                    wp.history.sliding[k] = c.sliding;
                    dissipation.friction += c.dissipation.friction;
                    dissipation.rolling += c.dissipation.rolling;
                }
                None => wp.history.sliding[k] = false,
            }
        }
        // the slip of the increments (the springs' history), not the dashpots'
        // power, which the step books over its own time step
        self.ledger.friction_dissipated += dissipation.friction;
        self.ledger.rolling_dissipated += dissipation.rolling;
        self.springs_current = true;
    }

    /// Every listed pair as the next force evaluation will see it, without
    /// changing the state (the springs are updated in copies).
    pub(crate) fn preview_pairs(&self) -> Vec<Option<PairRecord>> {
        let increment_time = self.increment_time();
        let pairs = &self.neighbors.pairs;
        let mut history = pairs.history.clone();
        let p = &self.particles;
        let kernel = pair_kernel!(self, p, pairs, increment_time);
        let mut sink = RecordSink {
            records: vec![None; pairs.len()],
        };
        // SAFETY: one caller, and the sink writes only its own records
        unsafe { kernel.run::<false, _>(0, history.run(), &mut sink) };
        sink.records
    }

    /// Every wall pair as the next force evaluation will see it: the geometry
    /// and the law's forces (the history updated in a copy), or `None`.
    pub(crate) fn preview_wall_pairs(&self) -> Vec<Option<(ContactGeometry, ContactForce)>> {
        let (dt, increment_time) = (self.params.time_step, self.increment_time());
        let wp = &self.neighbors.wall_pairs;
        (0..wp.wall.len())
            .map(|k| {
                let mut record = wp.history.records[k];
                let wall = &self.walls[wp.wall[k] as usize];
                let model = self.materials.by_index(wp.model[k]);
                let q = wp.particle[k] as usize;
                wall_contact(
                    wall,
                    model,
                    &ParticleMotion::of(&self.particles),
                    q,
                    dt,
                    increment_time,
                    &mut record,
                )
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
                    &ParticleMotion::of(&self.particles),
                    self.cell.as_ref(),
                    l,
                    increment_time,
                    &mut shear,
                )
            })
            .collect()
    }

    /// The velocity gradient of a deforming periodic cell, if any.
    pub(crate) fn deforming_gradient(&self) -> Option<Mat2> {
        self.cell
            .as_ref()
            .filter(|c| c.is_deforming())
            .map(|c| c.velocity_gradient)
    }

    /// The energy ledger (kinetic and elastic as of the last measured step).
    pub fn energy(&self) -> EnergyLedger {
        self.ledger
    }

    /// A time step estimate: `safety * min_i min(sqrt(m_i / k_n,i), sqrt(I_i / (k_s,i r_i^2 + k_r,i)))`
    /// where `k_n,i`, `k_s,i` and `k_r,i` sum the normal, shear and rolling
    /// stiffnesses of particle `i`'s current contacts and bonds (one contact of
    /// its stiffest model when it has none; rolling only where a model has
    /// rolling resistance). A contact's stiffnesses are its law's tangent ones
    /// at its overlap ([`law::tangent_stiffness`]: `kn`, `ks` for the linear
    /// law, `2 E* a`, `8 G* a` for Hertz-Mindlin, whose "stiffest contact" is
    /// the one at the largest overlap a run allows, `max_overlap_ratio` of the
    /// radius).
    pub fn critical_time_step(&mut self, safety: f64) -> Result<f64> {
        require_positive("safety", safety)?;
        self.ensure_neighbors()?;
        let n = self.particles.len();
        let mut kn = vec![0.0; n];
        let mut ks = vec![0.0; n];
        let mut kr = vec![0.0; n];
        let p = &self.particles;
        let pairs = &self.neighbors.pairs;
        for k in 0..pairs.len() {
            let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
            let d = sub(
                add(p.position[j], self.image_offset(pairs.shift[k])),
                p.position[i],
            );
            let overlap = disk_disk(d, p.radius[i], p.radius[j]).overlap;
            if overlap > 0.0 {
                let m = self.materials.by_index(pairs.model[k]);
                let (ri, rj) = (p.radius[i], p.radius[j]);
                let r_star = ri * rj / (ri + rj);
                let (k_n, k_s) = law::tangent_stiffness(m, overlap, r_star);
                for q in [i, j] {
                    kn[q] += k_n;
                    ks[q] += k_s;
                }
                if m.rolling_friction > 0.0 {
                    let k_r = RollingSpring::stiffness(m, k_n, r_star);
                    kr[i] += k_r;
                    kr[j] += k_r;
                }
            }
        }
        let wp = &self.neighbors.wall_pairs;
        for k in 0..wp.wall.len() {
            let q = wp.particle[k] as usize;
            let overlap = self.walls[wp.wall[k] as usize]
                .disk_contact(p.position[q], p.radius[q])
                .overlap;
            if overlap > 0.0 {
                let m = self.materials.by_index(wp.model[k]);
                let (k_n, k_s) = law::tangent_stiffness(m, overlap, p.radius[q]);
                kn[q] += k_n;
                ks[q] += k_s;
                if m.rolling_friction > 0.0 {
                    kr[q] += RollingSpring::stiffness(m, k_n, p.radius[q]);
                }
            }
        }
        for b in &self.bonds.list {
            for q in [b.i as usize, b.j as usize] {
                kn[q] += b.normal_stiffness;
                ks[q] += b.shear_stiffness;
            }
        }
        for b in &self.cement.bonds {
            for q in [b.i as usize, b.j as usize] {
                kn[q] += b.normal_stiffness;
                ks[q] += b.shear_stiffness;
                kr[q] += b.bending_stiffness;
            }
        }
        let fallback = |q: usize| {
            self.materials.max_stiffness_for_group(
                p.group[q],
                p.radius[q],
                self.params.max_overlap_ratio,
            )
        };
        let mut dt = self.clump_time_step([&kn, &ks, &kr], fallback);
        for q in (0..n).filter(|&q| p.clump[q] == NO_CLUMP) {
            let fallback = fallback(q);
            let kn_q = if kn[q] > 0.0 { kn[q] } else { fallback };
            let ks_q = if ks[q] > 0.0 { ks[q] } else { fallback };
            let r = p.radius[q];
            let rotation = if kr[q] > 0.0 {
                ks_q * r * r + kr[q]
            } else {
                ks_q * r * r
            };
            dt = dt
                .min((p.mass[q] / kn_q).sqrt())
                .min((p.inertia[q] / rotation).sqrt());
        }
        Ok(safety * dt)
    }

    /// The offset of periodic image `shift` (zero without a cell).
    #[inline(always)]
    pub(crate) fn image_offset(&self, shift: [i8; 2]) -> Vec2 {
        match &self.cell {
            Some(c) if shift != [0, 0] => c.image_offset(shift),
            _ => [0.0; 2],
        }
    }

    /// Rebuilds the neighbour lists if a contact could otherwise be missed. Safe to
    /// call at any time: it rebuilds exactly when the next step would.
    pub fn ensure_neighbors(&mut self) -> Result<()> {
        let tilt_due = self.cell.as_ref().is_some_and(|c| c.tilt_reduction() != 0);
        if tilt_due || self.neighbors.needs_rebuild(&self.walls) {
            self.rebuild()?;
        }
        Ok(())
    }

    /// Rebuilds the neighbour lists: wraps and renumbers the particles in
    /// spatial order, and maps the chains and the user's order along.
    pub(crate) fn rebuild(&mut self) -> Result<()> {
        if let Some(cell) = &mut self.cell {
            let k = cell.tilt_reduction();
            if k != 0 {
                cell.reduce_tilt(k);
                self.neighbors.rename_shifts_for_tilt(k);
            }
        }
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
        self.cement.remap(&new_of_old);
        self.clumps.remap(&new_of_old, &mut self.particles);
        self.clumps.rewrap(&self.particles, self.cell.as_ref());
        self.index_stripes();
        for (k, &e) in self.order.iter().enumerate() {
            self.rank[e as usize] = k as u32;
        }
        Ok(())
    }

    /// The per-stripe indexes of the chains, bonds and wall pairs, for the
    /// current stripes (at the start of a run call and after every rebuild).
    pub(crate) fn index_stripes(&mut self) {
        let stripes = &self.neighbors.stripe_ranges;
        self.chain_stripes = ChainStripes::new(&self.chains, stripes);
        self.deferred_index = DeferredIndex::new(
            &self.bonds.list,
            &self.cement.bonds,
            &self.neighbors.wall_pairs.particle,
            stripes,
        );
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
}

#[cfg(test)]
mod tests {
    /// Writes to what the pending shear increment depends on, as this file
    /// spells them (`self.` in a setter, `s.` in its `modify_motion` closure).
    const MOTION_WRITES: &[&str] = &[
        "particles.position =",
        "particles.velocity =",
        "particles.angular_velocity =",
        "particles.radius =",
        "particles.group =",
        "particles.extend(",
        "params =",
        "cell =",
        "materials.set(",
        "bonds.push(",
        "cement.bonds.extend(",
        ".translate(",
        "wall.velocity =",
        "wall.active =",
    ];

    /// The methods of this file, each as `(name, text up to the next method)`.
    fn methods(source: &str) -> Vec<(String, String)> {
        let starts: Vec<usize> = source
            .match_indices("\n    ")
            .map(|(k, _)| k + 5)
            .filter(|&k| {
                let line = &source[k..];
                ["pub fn ", "pub(crate) fn ", "fn "]
                    .iter()
                    .any(|p| line.starts_with(p))
            })
            .collect();
        starts
            .iter()
            .enumerate()
            .map(|(n, &k)| {
                let end = starts.get(n + 1).copied().unwrap_or(source.len());
                let text = &source[k..end];
                let name = text
                    .split("fn ")
                    .nth(1)
                    .and_then(|t| t.split(['(', '<']).next())
                    .unwrap_or("")
                    .to_string();
                (name, text.to_string())
            })
            .collect()
    }

    /// The part of a method's text that is code (comments and strings dropped).
    fn code(text: &str) -> String {
        text.lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The offsets of the motion writes in `code`, with the write.
    fn motion_writes(code: &str) -> Vec<(usize, &'static str)> {
        let mut found = Vec::new();
        for &w in MOTION_WRITES {
            for (k, _) in code.match_indices(w) {
                // `==` is a comparison, not a write
                if !code[k + w.len()..].starts_with('=') {
                    found.push((k, w));
                }
            }
        }
        found
    }

    #[test]
    fn every_setter_of_motion_goes_through_modify_motion() {
        let source = include_str!("simulation.rs");
        let source = &source[..source.find("#[cfg(test)]\nmod tests").unwrap()];
        let mut setters = 0;
        for (name, text) in methods(source) {
            let code = code(&text);
            let writes = motion_writes(&code);
            if name == "new" || name == "from_bytes" || name == "modify_motion" {
                continue;
            }
            if name != "modify_motion" && name != "catch_up_shear_springs" {
                assert!(
                    !code.contains("catch_up_shear_springs()"),
                    "{name}: catches the springs up itself; change them through modify_motion"
                );
            }
            if writes.is_empty() {
                continue;
            }
            setters += 1;
            let entry = code.find(".modify_motion(").unwrap_or_else(|| {
                panic!("{name}: writes {:?} outside of modify_motion", writes[0].1)
            });
            for (k, w) in writes {
                assert!(
                    k > entry,
                    "{name}: writes {w:?} before entering modify_motion"
                );
            }
        }
        // the setters of velocities, spins, positions, radii, groups, the step
        // parameters, contact models, the cell, walls (velocity, translation,
        // activity), bonds, cement bonds and particles
        assert_eq!(setters, 14, "the setters of motion found in this file");
    }

    #[test]
    fn a_setter_that_skips_modify_motion_is_found() {
        let skipping = "\n    pub fn set_spins(&mut self, w: Vec<f64>) {\n        \
                        self.particles.angular_velocity = w;\n    }\n";
        let (name, text) = &methods(skipping)[0];
        assert_eq!(name, "set_spins");
        let code = code(text);
        assert!(!motion_writes(&code).is_empty() && !code.contains(".modify_motion("));
        let late = "\n    pub fn set_spins(&mut self, w: Vec<f64>) {\n        \
                    self.particles.velocity = w;\n        self.modify_motion(|_| ());\n    }\n";
        let code = super::tests::code(&methods(late)[0].1);
        let entry = code.find(".modify_motion(").unwrap();
        assert!(motion_writes(&code).iter().any(|&(k, _)| k < entry));
    }
}
