//! The pair kernel: the contact law over a run of listed pairs, with where
//! its forces go (straight onto the particles, into a buffer, into records),
//! the reset of the resultants, the buffered cross-stripe forces, and the
//! particle-wall contact.
use crate::bond::{Bond, BondSlot};
use crate::cell::PeriodicCell;
use crate::cement::{CementBond, CementSlot, Rupture};
use crate::contact::ContactGeometry;
use crate::diagnostics::ContactDissipation;
use crate::law::history::{forget, HistoryRun};
use crate::law::{
    contact_law, hertz, ContactForce, ContactKinematics, ContactRecord, HISTORY_WIDTH,
};
use crate::material::{ContactLaw, ContactModel, MaterialTable};
use crate::parallel::DisjointWriter;
use crate::state::{ParticleMotion, PEBBLE};
use crate::vec2::{add, dot, mat_vec, perp, scale, sub, Mat2, Vec2};
use crate::wall::Wall;

/// Per-stripe sums of the contact phase.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ContactTally {
    /// What the sub-models dissipated.
    pub(crate) dissipation: ContactDissipation,
    pub(crate) elastic: f64,
    pub(crate) force_sum: f64,
    pub(crate) contacts: usize,
    pub(crate) overlap_violation: bool,
    /// Cement bonds that broke at this evaluation.
    pub(crate) bond_breaks: usize,
    /// Cement bonds that hold, of `contacts` (measured steps).
    pub(crate) cement_holding: usize,
}

impl ContactTally {
    /// Adds another tally's sums (merged in stripe order, for the same bits).
    pub(crate) fn merge(&mut self, o: &ContactTally) {
        self.dissipation.add(&o.dissipation);
        self.elastic += o.elastic;
        self.force_sum += o.force_sum;
        self.contacts += o.contacts;
        self.overlap_violation |= o.overlap_violation;
        self.bond_breaks += o.bond_breaks;
        self.cement_holding += o.cement_holding;
    }
}

/// Particle `q` against `wall` at the current state: the geometry and the
/// contact law's forces and torque on the particle (body `j`; the wall, body
/// `i`, has no lever arm), updating `record` (the pair's history, or a copy
/// for a query) over `increment_time`; `None`, with the record zeroed, when
/// they do not touch.
#[inline]
pub(crate) fn wall_contact(
    wall: &Wall,
    model: &ContactModel,
    p: &ParticleMotion<'_>,
    q: usize,
    dt: f64,
    increment_time: f64,
    record: &mut ContactRecord,
) -> Option<(ContactGeometry, ContactForce)> {
    let r = p.radius[q];
    let g = wall.disk_contact(p.position[q], r);
    if g.overlap <= 0.0 {
        *record = [0.0; HISTORY_WIDTH];
        return None;
    }
    let n = g.normal;
    let t = perp(n);
    let dv = sub(p.velocity[q], wall.velocity);
    let vn = dot(dv, n);
    let vt = dot(dv, t) - p.angular_velocity[q] * r;
    let kinematics = ContactKinematics {
        overlap: g.overlap,
        normal_velocity: vn,
        tangential_velocity: vt,
        radius_i: 0.0,
        radius_j: r,
        reduced_mass: p.mass[q],
        rolling_velocity: p.angular_velocity[q],
        rolling_inertia: p.inertia[q] + p.mass[q] * r * r,
    };
    let c = contact_law::<true>(model, &kinematics, dt, increment_time, record);
    Some((g, c))
}

/// Where a pair's force goes: straight onto the particles, or into a buffer slot.
pub(crate) trait ForceSink {
    /// Adds force `f` on `j` (its opposite on `i`) and the torques, for local pair `k`.
    ///
    /// # Safety
    /// The caller owns `i` and `j` (direct sink) or slot `k` (buffer).
    unsafe fn add(&mut self, k: usize, i: usize, j: usize, f: Vec2, torque_i: f64, torque_j: f64);
    /// Local pair `k` is not in contact.
    fn skip(&mut self, k: usize);
    /// Local pair `k` is in contact with `overlap`, unit normal `n` and the
    /// law's result `c`; only the contact list keeps it.
    #[inline(always)]
    fn record(&mut self, _k: usize, _overlap: f64, _n: Vec2, _c: &ContactForce) {}
}

/// Throws the forces away (the springs' catch-up).
pub(crate) struct NullSink;

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
    pub(crate) overlap: f64,
    /// Unit normal from `i` to `j`.
    pub(crate) normal: Vec2,
    /// Elastic normal force `kn * overlap` (N).
    pub(crate) elastic_normal: f64,
    /// Shear spring after the update (N).
    pub(crate) shear_spring: f64,
    /// Whether the spring is at the Coulomb cap.
    pub(crate) sliding: bool,
    /// The rolling spring after the update, the moment on `j` (N m; 0 without
    /// rolling resistance).
    pub(crate) rolling_spring: f64,
    /// The normal force's tangent stiffness at this overlap (N/m).
    pub(crate) normal_stiffness: f64,
}

/// Keeps every contact's record, in pair order (`None`: not in contact).
pub(crate) struct RecordSink {
    pub(crate) records: Vec<Option<PairRecord>>,
}

impl ForceSink for RecordSink {
    #[inline(always)]
    unsafe fn add(&mut self, _: usize, _: usize, _: usize, _: Vec2, _: f64, _: f64) {}
    #[inline(always)]
    fn skip(&mut self, _k: usize) {}
    fn record(&mut self, k: usize, overlap: f64, n: Vec2, c: &ContactForce) {
        self.records[k] = Some(PairRecord {
            overlap,
            normal: n,
            elastic_normal: c.elastic_normal,
            shear_spring: c.shear_spring,
            sliding: c.sliding,
            rolling_spring: c.rolling_spring,
            normal_stiffness: c.normal_stiffness,
        });
    }
}

/// Adds each pair's forces straight onto its two particles (a stripe's interior
/// pairs, and on one thread the pairs across stripes).
pub(crate) struct DirectSink<'a> {
    pub(crate) force: &'a DisjointWriter<Vec2>,
    pub(crate) torque: &'a DisjointWriter<f64>,
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

/// Keeps each cross-stripe pair's force in its own slot; the stripes'
/// integration applies them ([`CrossForces::apply`]).
pub(crate) struct BufferSink<'a> {
    pub(crate) slots: &'a mut [PairForce],
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

/// The buffered forces of cross-stripe pairs and, per stripe, which of them touch it.
pub(crate) struct CrossForces<'a> {
    pub(crate) pair_i: &'a [u32],
    pub(crate) pair_j: &'a [u32],
    pub(crate) first: usize,
    pub(crate) forces: &'a [PairForce],
    pub(crate) touch: &'a [u32],
    pub(crate) touch_start: &'a [usize],
}

impl CrossForces<'_> {
    /// Adds stripe `b`'s cross-pair forces to `force`/`torque`, which start at particle `lo`.
    pub(crate) fn apply(&self, b: usize, lo: usize, force: &mut [Vec2], torque: &mut [f64]) {
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

/// A cross-stripe pair's force, computed in parallel and applied afterwards.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PairForce {
    pub(crate) force: Vec2,
    pub(crate) torque_i: f64,
    pub(crate) torque_j: f64,
    pub(crate) active: bool,
}

impl PairForce {
    pub(crate) const NONE: PairForce = PairForce {
        force: [0.0; 2],
        torque_i: 0.0,
        torque_j: 0.0,
        active: false,
    };
}

/// One stripe's share of the contact phase.
pub(crate) struct StripeWork<'a> {
    pub(crate) stripe: usize,
    /// The history of the stripe's interior pairs.
    pub(crate) history: HistoryRun<'a>,
    /// The history of the stripe's share of the cross-stripe pairs.
    pub(crate) cross_history: HistoryRun<'a>,
    pub(crate) cross_forces: &'a mut [PairForce],
    /// The stripe's share of the bonds, and the slots of their forces.
    pub(crate) bonds: &'a mut [Bond],
    pub(crate) bond_slots: &'a mut [BondSlot],
    /// The stripe's share of the cement bonds, their slots, the index of the
    /// first in the whole list, and the share's bonds that break at this
    /// evaluation (whole-list index and record, in bond order).
    pub(crate) cement: CementShare<'a>,
}

/// A stripe's cement bonds, their slots, the list index of the first, and
/// the stripe's list of breaks.
pub(crate) type CementShare<'a> = (
    &'a mut [CementBond],
    &'a mut [CementSlot],
    usize,
    &'a mut Vec<(usize, Rupture)>,
);

/// The reset of step 2: each particle's resultant starts from its external
/// force, gravity and follower load, its torque from its external torque.
pub(crate) struct ResetKernel<'a> {
    pub(crate) boundary_load: Option<&'a DisjointWriter<Vec2>>,
    pub(crate) external_force: &'a [Vec2],
    pub(crate) external_torque: &'a [f64],
    pub(crate) mass: &'a [f64],
    pub(crate) gravity: Vec2,
    /// The particles' fixity when there are clumps: a pebble gets no weight
    /// here (its clump gets its own, `body::clumps`).
    pub(crate) pebble_fixity: Option<&'a [u8]>,
    /// No pressure chain, gravity or external force or torque: every external
    /// force is +-0, so `f_e + m g` is +0 whatever its sign, and the torques
    /// (+-0) are copied as they are.
    pub(crate) no_loads: bool,
}

impl ResetKernel<'_> {
    /// Resets the resultants of particles `lo..hi` to their external loads.
    ///
    /// # Safety
    /// `lo..hi` in bounds and owned by the calling task.
    #[inline(always)]
    pub(crate) unsafe fn apply(
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
        // the stripe's slices, so that the loop keeps its pointers in registers
        let forces = force.range(lo, hi);
        let loads = self.boundary_load.map(|load| &*load.range(lo, hi));
        let (external, mass) = (&self.external_force[lo..hi], &self.mass[lo..hi]);
        let g = self.gravity;
        let pebbles = self.pebble_fixity.map(|fixity| &fixity[lo..hi]);
        for (q, f) in forces.iter_mut().enumerate() {
            let (fe, mut m) = (external[q], mass[q]);
            if pebbles.is_some_and(|fixity| fixity[q] & PEBBLE != 0) {
                m = 0.0;
            }
            *f = [fe[0] + m * g[0], fe[1] + m * g[1]];
            if let Some(loads) = loads {
                *f = add(*f, loads[q]);
            }
        }
        torque
            .range(lo, hi)
            .copy_from_slice(&self.external_torque[lo..hi]);
    }
}

/// A [`PairKernel`] over the particles `$p` and pair list `$pairs` of simulation
/// `$sim` (a macro, so that the shear springs can be borrowed mutably apart).
macro_rules! pair_kernel {
    ($sim:expr, $p:expr, $pairs:expr, $increment_time:expr) => {{
        let rolling = $sim.materials.rolling();
        PairKernel {
            position: &$p.position,
            velocity: &$p.velocity,
            angular_velocity: &$p.angular_velocity,
            radius: &$p.radius,
            mass: &$p.mass,
            inertia: &$p.inertia,
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
            undamped: $sim.materials.undamped(),
            all_hertz: $sim.materials.all_hertz(),
            rolling,
            // (the table scanned again only when it has rolling resistance)
            rolling_damped: rolling && $sim.materials.rolling_damped(),
            vector: $sim.simd,
        }
    }};
}
pub(crate) use pair_kernel;

/// The contact law over a run of listed pairs: what it reads of the particles,
/// the pair list, the materials and the step.
pub(crate) struct PairKernel<'a> {
    pub(crate) position: &'a [Vec2],
    pub(crate) velocity: &'a [Vec2],
    pub(crate) angular_velocity: &'a [f64],
    pub(crate) radius: &'a [f64],
    pub(crate) mass: &'a [f64],
    pub(crate) inertia: &'a [f64],
    pub(crate) pair_i: &'a [u32],
    pub(crate) pair_j: &'a [u32],
    pub(crate) shift: &'a [[i8; 2]],
    pub(crate) model: &'a [u16],
    pub(crate) materials: &'a MaterialTable,
    pub(crate) cell: Option<&'a PeriodicCell>,
    pub(crate) velocity_gradient: Option<Mat2>,
    pub(crate) dt: f64,
    pub(crate) increment_time: f64,
    pub(crate) max_overlap_ratio: f64,
    /// The one model of every pair when there is one and it has no dashpot.
    pub(crate) single_model: Option<ContactModel>,
    /// No model has a dashpot.
    pub(crate) undamped: bool,
    /// Every model is Hertz-Mindlin.
    pub(crate) all_hertz: bool,
    /// Some model has rolling resistance (the four-pair loop then evaluates it).
    pub(crate) rolling: bool,
    /// Some model with rolling resistance has a rolling dashpot.
    pub(crate) rolling_damped: bool,
    /// Whether undamped pairs run four at a time ([`crate::Simulation::set_simd`]).
    pub(crate) vector: bool,
}

impl PairKernel<'_> {
    /// Evaluates pairs `first..first + history.len()`, updating their
    /// `history` and adding their forces to both particles through `sink`.
    ///
    /// # Safety
    /// Concurrent callers must touch disjoint particles.
    #[inline(always)]
    pub(crate) unsafe fn run<const MEASURE: bool, S: ForceSink>(
        &self,
        first: usize,
        history: HistoryRun<'_>,
        sink: &mut S,
    ) -> ContactTally {
        let (records, sliding) = (history.records, history.sliding);
        if self.all_hertz {
            return if self.velocity_gradient.is_some() {
                self.hertz_pairs::<MEASURE, true, S>(first, records, sliding, sink)
            } else {
                self.hertz_pairs::<MEASURE, false, S>(first, records, sliding, sink)
            };
        }
        // the loop specialised on what is fixed for the whole call: the same
        // arithmetic in every variant, minus the tests whose outcome is known
        match (
            self.velocity_gradient.is_some(),
            self.single_model.is_some(),
            self.undamped,
        ) {
            (false, false, false) => {
                self.pairs::<MEASURE, false, false, true, S>(first, records, sliding, sink)
            }
            (false, false, true) => {
                self.pairs::<MEASURE, false, false, false, S>(first, records, sliding, sink)
            }
            (false, true, _) => {
                self.pairs::<MEASURE, false, true, false, S>(first, records, sliding, sink)
            }
            (true, false, false) => {
                self.pairs::<MEASURE, true, false, true, S>(first, records, sliding, sink)
            }
            (true, false, true) => {
                self.pairs::<MEASURE, true, false, false, S>(first, records, sliding, sink)
            }
            (true, true, _) => {
                self.pairs::<MEASURE, true, true, false, S>(first, records, sliding, sink)
            }
        }
    }

    /// The loop of [`PairKernel::run`]: `DEFORMING` when the cell has a velocity
    /// gradient, `SINGLE` when [`PairKernel::single_model`] is set, `DASHPOTS`
    /// unless no model has a normal or shear dashpot (whose terms are then
    /// skipped, as the law skips them for a zero damping ratio). Without those
    /// dashpots, and when [`PairKernel::vector`] is set, four pairs at a time
    /// ([`PairKernel::pairs_by_four`], the same bits), with the rolling law
    /// (and its dashpot) when some model has rolling resistance.
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(always)]
    unsafe fn pairs<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        const DASHPOTS: bool,
        S: ForceSink,
    >(
        &self,
        first: usize,
        records: &mut [ContactRecord],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        // (`vector` is never set where the four-pair loop does not exist)
        if !DASHPOTS && self.vector && crate::law::LANES {
            // the rolling law (and its dashpot) compiled in only for a table
            // that has it, so that the loop without it is the same code as before
            #[cfg(target_arch = "x86_64")]
            return match (self.rolling, self.rolling_damped) {
                (false, _) => self.pairs_by_four::<MEASURE, DEFORMING, SINGLE, false, false, S>(
                    first, records, sliding, sink,
                ),
                (true, false) => self.pairs_by_four::<MEASURE, DEFORMING, SINGLE, true, false, S>(
                    first, records, sliding, sink,
                ),
                (true, true) => self.pairs_by_four::<MEASURE, DEFORMING, SINGLE, true, true, S>(
                    first, records, sliding, sink,
                ),
            };
        }
        self.whole_run::<MEASURE, DEFORMING, SINGLE, DASHPOTS, false, S>(
            first, records, sliding, sink,
        )
    }

    /// The loop of a table whose every model is Hertz-Mindlin, with the law
    /// inlined (the same bits as through [`hertz::contact_law_with`]).
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(never)]
    unsafe fn hertz_pairs<const MEASURE: bool, const DEFORMING: bool, S: ForceSink>(
        &self,
        first: usize,
        records: &mut [ContactRecord],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        self.whole_run::<MEASURE, DEFORMING, false, true, true, S>(first, records, sliding, sink)
    }

    /// Every pair of the run from `first`, one at a time, and their tally.
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(always)]
    unsafe fn whole_run<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        const DASHPOTS: bool,
        const HERTZ: bool,
        S: ForceSink,
    >(
        &self,
        first: usize,
        records: &mut [ContactRecord],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        let mut tally = ContactTally::default();
        let fixed = self.loop_constants();
        let columns = self.columns(first, records.len().min(sliding.len()));
        let all = 0..columns.len();
        self.pairs_one_at_a_time::<MEASURE, DEFORMING, SINGLE, DASHPOTS, HERTZ, S>(
            &fixed, &columns, all, records, sliding, sink, &mut tally,
        );
        tally
    }

    /// Local pairs `range` of `columns`, one at a time ([`PairKernel::one_pair`]).
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn pairs_one_at_a_time<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        const DASHPOTS: bool,
        const HERTZ: bool,
        S: ForceSink,
    >(
        &self,
        fixed: &LoopConstants,
        columns: &PairColumns<'_>,
        range: std::ops::Range<usize>,
        records: &mut [ContactRecord],
        sliding: &mut [bool],
        sink: &mut S,
        tally: &mut ContactTally,
    ) {
        for k in range {
            self.one_pair::<MEASURE, DEFORMING, SINGLE, DASHPOTS, HERTZ, S>(
                fixed,
                columns,
                k,
                &mut records[k],
                &mut sliding[k],
                sink,
                tally,
            );
        }
    }

    /// What the pair loop reads of the kernel once per call.
    #[inline(always)]
    pub(super) fn loop_constants(&self) -> LoopConstants {
        LoopConstants {
            gradient: self.velocity_gradient.unwrap_or([[0.0; 2]; 2]),
            single: self
                .single_model
                .unwrap_or(ContactModel::linear(1.0, 1.0, 0.0)),
        }
    }

    /// The pairs' columns `first..first + n`, so that one index walks them all.
    #[inline(always)]
    pub(super) fn columns(&self, first: usize, n: usize) -> PairColumns<'_> {
        PairColumns {
            i: &self.pair_i[first..first + n],
            j: &self.pair_j[first..first + n],
            shift: &self.shift[first..first + n],
            model: &self.model[first..first + n],
        }
    }

    /// The contact model of local pair `k`.
    #[inline(always)]
    pub(super) fn model_of<'m, const SINGLE: bool>(
        &'m self,
        fixed: &'m LoopConstants,
        columns: &PairColumns<'_>,
        k: usize,
    ) -> &'m ContactModel {
        if SINGLE {
            &fixed.single
        } else {
            self.materials.by_index(columns.model[k])
        }
    }

    /// Local pair `k` of `columns`: the law, its forces into `sink`, its sums into `tally`.
    ///
    /// # Safety
    /// As [`PairKernel::run`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn one_pair<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        const DASHPOTS: bool,
        const HERTZ: bool,
        S: ForceSink,
    >(
        &self,
        fixed: &LoopConstants,
        columns: &PairColumns<'_>,
        k: usize,
        record: &mut ContactRecord,
        slide: &mut bool,
        sink: &mut S,
        tally: &mut ContactTally,
    ) {
        // SAFETY: the neighbour list holds pairs of particles that exist
        // (`NeighborList::build`), so every particle index below is in
        // bounds; the checks would cost a tenth of the loop
        let i = columns.i[k] as usize;
        let j = columns.j[k] as usize;
        debug_assert!(i < self.position.len() && j < self.position.len());
        let xi = *self.position.get_unchecked(i);
        let mut xj = *self.position.get_unchecked(j);
        let s = columns.shift[k];
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
            no_contact(sink, k, record, slide);
            return;
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
            dv = add(dv, mat_vec(&fixed.gradient, d));
        }
        let vn = dot(dv, n);
        let (wi, wj) = (
            *self.angular_velocity.get_unchecked(i),
            *self.angular_velocity.get_unchecked(j),
        );
        let vt = dot(dv, t) - (wi * ri + wj * rj);
        let model = self.model_of::<SINGLE>(fixed, columns, k);
        let reduced_mass = if DASHPOTS
            && (model.normal_damping_ratio > 0.0
                || model.shear_damping_ratio > 0.0
                || model.law == ContactLaw::HertzMindlin)
        {
            let (mi, mj) = (self.mass[i], self.mass[j]);
            mi * mj / (mi + mj)
        } else {
            0.0
        };
        let kinematics = ContactKinematics {
            overlap,
            normal_velocity: vn,
            tangential_velocity: vt,
            radius_i: ri,
            radius_j: rj,
            reduced_mass,
            rolling_velocity: wj - wi,
            rolling_inertia: if model.rolling_damping_ratio > 0.0 {
                let ii = self.inertia[i] + self.mass[i] * ri * ri;
                let ij = self.inertia[j] + self.mass[j] * rj * rj;
                ii * ij / (ii + ij)
            } else {
                0.0
            },
        };
        let (dt, increment_time) = (self.dt, self.increment_time);
        let c = if HERTZ {
            // (a table of Hertz-Mindlin alone: `hertz_pairs`)
            let constants = self.materials.hertz_constants(columns.model[k]);
            hertz::law(constants, model, &kinematics, dt, increment_time, record)
        } else if !DASHPOTS {
            contact_law::<false>(model, &kinematics, dt, increment_time, record)
        } else if model.law == ContactLaw::HertzMindlin {
            // (a table with Hertz-Mindlin is never `SINGLE`: the pair's own model index)
            let constants = self.materials.hertz_constants(columns.model[k]);
            hertz::contact_law_with(constants, model, &kinematics, dt, increment_time, record)
        } else {
            contact_law::<true>(model, &kinematics, dt, increment_time, record)
        };
        let f = [
            c.normal * n[0] + c.shear * t[0],
            c.normal * n[1] + c.shear * t[1],
        ];
        let contact = PairContact {
            k,
            i,
            j,
            ri,
            rj,
            overlap,
            normal: n,
            force: f,
        };
        self.finish_contact::<MEASURE, S>(&contact, &c, model, slide, sink, tally);
    }

    /// A touching pair's bookkeeping after the law: its sliding flag, the record,
    /// the forces and torques into `sink`, the sums into `tally`.
    ///
    /// # Safety
    /// As [`ForceSink::add`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn finish_contact<const MEASURE: bool, S: ForceSink>(
        &self,
        p: &PairContact,
        c: &ContactForce,
        model: &ContactModel,
        slide: &mut bool,
        sink: &mut S,
        tally: &mut ContactTally,
    ) {
        *slide = c.sliding;
        sink.record(p.k, p.overlap, p.normal, c);
        sink.add(p.k, p.i, p.j, p.force, c.torque_i, c.torque_j);
        tally.dissipation.add(&c.dissipation);
        tally.overlap_violation |= p.overlap > self.max_overlap_ratio * p.ri.min(p.rj);
        if MEASURE {
            // the rolling spring's energy added apart, in this order (the lanes' bits)
            tally.elastic += c.spring_energy(model);
            if c.rolling_energy != 0.0 {
                tally.elastic += c.rolling_energy;
            }
            tally.force_sum += (c.normal * c.normal + c.shear * c.shear).sqrt();
            tally.contacts += 1;
        }
    }
}

/// A pair that is not in contact: its history is cleared
/// ([`forget`]) and its sink slot skipped.
#[inline(always)]
pub(super) fn no_contact<S: ForceSink>(
    sink: &mut S,
    k: usize,
    record: &mut ContactRecord,
    slide: &mut bool,
) {
    forget(record, slide);
    sink.skip(k);
}

/// What the pair loop reads once per call: the cell's velocity gradient (zero
/// when it does not deform) and the single model (a placeholder without one).
pub(super) struct LoopConstants {
    pub(super) gradient: Mat2,
    pub(super) single: ContactModel,
}

/// The pair list's columns over one run of pairs.
pub(super) struct PairColumns<'a> {
    pub(super) i: &'a [u32],
    pub(super) j: &'a [u32],
    pub(super) shift: &'a [[i8; 2]],
    pub(super) model: &'a [u16],
}

impl PairColumns<'_> {
    /// Number of pairs.
    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.i.len()
    }
}

/// A touching pair as the law saw it: local index `k`, particles `i` and `j`,
/// radii, overlap (m), unit normal from `i` to `j`, force on `j` (N).
pub(super) struct PairContact {
    pub(super) k: usize,
    pub(super) i: usize,
    pub(super) j: usize,
    pub(super) ri: f64,
    pub(super) rj: f64,
    pub(super) overlap: f64,
    pub(super) normal: Vec2,
    pub(super) force: Vec2,
}
