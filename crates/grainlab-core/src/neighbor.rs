//! Verlet pair lists with a skin, built from cell lists, that never miss a contact.
//!
//! A pair `(i, j, shift)` is listed when the centre distance of `i` and the
//! image `x_j + shift . H` of `j` is below `r_i + r_j + skin`. Between builds
//! every particle's displacement *relative to the homogeneous deformation* is
//! tracked (`u = x - origin - M_acc (x_ref - origin)`); a listed-out pair's
//! distance `d` obeys `|d| >= |M_acc d_ref| - |u_i| - |u_j|`, so no contact can
//! appear unseen while `2 max|u| + |M_acc - I| (2 r_max + skin) < skin`. Walls
//! use the total displacement of particles plus the wall's own. The list is
//! rebuilt as soon as either bound could be violated, at the start of a step.
//!
//! Pairs are grouped for parallel force evaluation: the particles are split
//! into stripes of bin columns with balanced counts, as many as
//! [`stripe_count`] gives for the system (never a function of the thread
//! count); pairs with both
//! particles in stripe `b` are stored contiguously (`stripe_start[b]..stripe_start[b+1]`)
//! and may be evaluated concurrently with other stripes; pairs across stripes
//! come last. The contact history (one record per pair, whatever the
//! sub-models' width, [`ContactHistory`]) is carried over from the previous
//! list by pair key.

use serde::{Deserialize, Serialize};

use crate::bond::Bonds;
use crate::cell::PeriodicCell;
use crate::error::{EngineError, Result};
use crate::law::history::ContactHistory;
use crate::material::MaterialTable;
use crate::parallel::stripe_count;
use crate::state::{Particles, NO_CLUMP};
use crate::vec2::{add, distance_from_identity, dot, sub, Mat2, Vec2, IDENTITY};
use crate::wall::Wall;

/// Particle-particle pairs with their contact history.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct PairList {
    /// First particle of each pair.
    pub i: Vec<u32>,
    /// Second particle of each pair.
    pub j: Vec<u32>,
    /// Image of `j` in cell vectors.
    pub shift: Vec<[i8; 2]>,
    /// Contact model index in the [`MaterialTable`].
    pub model: Vec<u16>,
    /// Each pair's contact history (the sub-models' records, all zero when
    /// not in contact, and the sliding flags).
    pub history: ContactHistory,
    /// Pairs interior to stripe `b` are `stripe_start[b]..stripe_start[b + 1]`;
    /// cross-stripe pairs follow from `stripe_start[n_stripes]`.
    pub stripe_start: Vec<usize>,
}

impl PairList {
    /// Number of listed pairs.
    pub fn len(&self) -> usize {
        self.i.len()
    }

    /// True when no pair is listed.
    pub fn is_empty(&self) -> bool {
        self.i.is_empty()
    }

    /// Renumbers particles (`new_of_old[old] = new`), keeping `i < j` by swapping
    /// the pair and reversing its image shift (the history is unchanged by the
    /// swap: the shear spring, a force on `j` along `perp(n)`, keeps its sign
    /// since both `n` and `perp(n)` flip).
    pub fn remap(&mut self, new_of_old: &[u32]) {
        for k in 0..self.len() {
            let (i, j) = (
                new_of_old[self.i[k] as usize],
                new_of_old[self.j[k] as usize],
            );
            if i < j {
                (self.i[k], self.j[k]) = (i, j);
            } else {
                (self.i[k], self.j[k]) = (j, i);
                self.shift[k] = [-self.shift[k][0], -self.shift[k][1]];
            }
        }
    }
}

/// Particle-wall pairs with their contact history.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct WallPairList {
    /// Wall index.
    pub wall: Vec<u32>,
    /// Particle index.
    pub particle: Vec<u32>,
    /// Contact model index.
    pub model: Vec<u16>,
    /// Each wall pair's contact history, as [`PairList::history`].
    pub history: ContactHistory,
}

/// The Verlet lists and the bookkeeping that says when to rebuild them.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NeighborList {
    /// Verlet skin (m).
    pub skin: f64,
    /// Particle pairs.
    pub pairs: PairList,
    /// Particle-wall pairs.
    pub wall_pairs: WallPairList,
    /// Internal index range of the particles owned by each stripe.
    pub stripe_ranges: Vec<(usize, usize)>,
    /// For each stripe, the cross-stripe pairs that touch its particles, as
    /// `(local cross index << 1) | side` (side 0: the pair's `i`, 1: its `j`),
    /// in pair order: CSR offsets in `cross_touch_start`.
    pub cross_touch: Vec<u32>,
    /// Offsets of each stripe's entries in `cross_touch` (`n_stripes + 1`).
    pub cross_touch_start: Vec<usize>,
    /// Number of builds so far.
    pub build_count: u64,
    valid: bool,
    reference: Vec<Vec2>,
    accumulated_map: Mat2,
    wall_reference: Vec<Vec2>,
    max_radius: f64,
    /// Largest squared displacement relative to the homogeneous deformation since the build.
    pub max_fluctuation_sq: f64,
    /// Largest squared total displacement since the build.
    pub max_displacement_sq: f64,
}

/// A view of the build reference that the integrator uses to track displacements.
pub struct DisplacementReference<'a> {
    /// Positions at the last build.
    pub reference: &'a [Vec2],
    /// Accumulated affine map since the build, including the current step.
    pub accumulated_map: Mat2,
}

impl NeighborList {
    /// An empty, invalid list with the given skin.
    pub fn new(skin: f64) -> Self {
        NeighborList {
            skin,
            pairs: PairList::default(),
            wall_pairs: WallPairList::default(),
            stripe_ranges: Vec::new(),
            cross_touch: Vec::new(),
            cross_touch_start: Vec::new(),
            build_count: 0,
            valid: false,
            reference: Vec::new(),
            accumulated_map: IDENTITY,
            wall_reference: Vec::new(),
            max_radius: 0.0,
            max_fluctuation_sq: 0.0,
            max_displacement_sq: 0.0,
        }
    }

    /// Renames the listed pairs' image shifts after the cell's `b` became
    /// `b - k a` (`PeriodicCell::reduce_tilt`): `s0 a + s1 b = (s0 + k s1) a + s1 (b - k a)`.
    pub fn rename_shifts_for_tilt(&mut self, k: i8) {
        for s in self.pairs.shift.iter_mut() {
            s[0] += k * s[1];
        }
    }

    /// Forces a rebuild at the next step (after radii, positions or walls changed).
    pub fn invalidate(&mut self) {
        self.valid = false;
    }

    /// Checks the lists against the system they index (a loaded state is
    /// trusted by the force kernels, which read without bounds checks).
    pub fn check_consistent(
        &self,
        n_particles: usize,
        n_walls: usize,
        n_models: usize,
    ) -> Result<()> {
        let bad = |what: &str| {
            Err(EngineError::invalid(
                "state",
                format!("inconsistent neighbour lists: {what}"),
            ))
        };
        if self.reference.len() != n_particles && self.valid {
            return bad("reference positions");
        }
        let p = &self.pairs;
        let m = p.i.len();
        if [
            p.j.len(),
            p.shift.len(),
            p.model.len(),
            p.history.records.len(),
            p.history.sliding.len(),
        ]
        .iter()
        .any(|&l| l != m)
        {
            return bad("pair arrays of different lengths");
        }
        if p.i.iter().chain(&p.j).any(|&q| q as usize >= n_particles) {
            return bad("a pair names a particle that does not exist");
        }
        if p.model.iter().any(|&k| k as usize >= n_models) {
            return bad("a pair names a contact model that does not exist");
        }
        let n_stripes = self.stripe_ranges.len();
        if self.valid {
            if p.stripe_start.len() != n_stripes + 1
                || p.stripe_start.windows(2).any(|w| w[0] > w[1])
                || p.stripe_start.last().is_some_and(|&last| last > m)
            {
                return bad("stripe starts");
            }
            let mut next = 0usize;
            for &(lo, hi) in &self.stripe_ranges {
                if lo != next || hi < lo {
                    return bad("stripe ranges");
                }
                next = hi;
            }
            if next != n_particles {
                return bad("stripe ranges do not cover the particles");
            }
            let cross = m - p.stripe_start[n_stripes];
            if self.cross_touch_start.len() != n_stripes + 1
                || self.cross_touch_start.windows(2).any(|w| w[0] > w[1])
                || self.cross_touch_start.last() != Some(&self.cross_touch.len())
                || self.cross_touch.iter().any(|&e| (e >> 1) as usize >= cross)
            {
                return bad("cross-stripe pairs");
            }
        }
        let w = &self.wall_pairs;
        let k = w.wall.len();
        if [
            w.particle.len(),
            w.model.len(),
            w.history.records.len(),
            w.history.sliding.len(),
        ]
        .iter()
        .any(|&l| l != k)
            || w.particle.iter().any(|&q| q as usize >= n_particles)
            || w.wall.iter().any(|&q| q as usize >= n_walls)
            || w.model.iter().any(|&q| q as usize >= n_models)
        {
            return bad("wall pairs");
        }
        Ok(())
    }

    /// Whether the list is currently valid.
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// Records one more step of homogeneous deformation and returns the reference
    /// the integrator measures displacements against.
    pub fn advance_map(&mut self, step_map: &Mat2) -> DisplacementReference<'_> {
        self.accumulated_map = PeriodicCell::accumulate(&self.accumulated_map, step_map);
        DisplacementReference {
            reference: &self.reference,
            accumulated_map: self.accumulated_map,
        }
    }

    /// The reference without a deformation step.
    pub fn reference(&self) -> DisplacementReference<'_> {
        DisplacementReference {
            reference: &self.reference,
            accumulated_map: self.accumulated_map,
        }
    }

    /// Whether a contact could have been missed if the list were kept.
    pub fn needs_rebuild(&self, walls: &[Wall]) -> bool {
        if !self.valid {
            return true;
        }
        let strain = distance_from_identity(&self.accumulated_map);
        let fluctuation = self.max_fluctuation_sq.sqrt();
        if 2.0 * fluctuation + strain * (2.0 * self.max_radius + self.skin) >= self.skin {
            return true;
        }
        if !walls.is_empty() {
            let wall_move = walls
                .iter()
                .zip(&self.wall_reference)
                .map(|(w, r)| {
                    let d = sub(w.displacement, *r);
                    dot(d, d).sqrt()
                })
                .fold(0.0, f64::max);
            if self.max_displacement_sq.sqrt() + wall_move >= self.skin {
                return true;
            }
        }
        false
    }

    /// Rebuilds the lists: wraps particles into the periodic cell, bins them,
    /// lists pairs and wall pairs, and carries over the contact history.
    ///
    /// The particles are also put in *spatial order* (by bin, bins column by
    /// column): each stripe is then a contiguous index range, which keeps the
    /// threads' writes apart in memory and a pair's two particles close in cache.
    /// `order` maps internal to external (user) indices and is permuted along,
    /// as are the bonds and the old lists' indices. Returns the renumbering
    /// `new_of_old[old] = new` for the caller's other per-particle references.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        &mut self,
        particles: &mut Particles,
        order: &mut Vec<u32>,
        cell: Option<&PeriodicCell>,
        walls: &[Wall],
        bonds: &mut Bonds,
        materials: &MaterialTable,
    ) -> Result<Vec<u32>> {
        let n = particles.len();
        let r_max = particles.max_radius();
        let cutoff = 2.0 * r_max + self.skin;

        // 1. wrap, remembering each particle's wrap so old image shifts can be corrected
        let mut wraps = vec![[0i8; 2]; n];
        if let Some(cell) = cell {
            for (x, w) in particles.position.iter_mut().zip(wraps.iter_mut()) {
                *w = cell.wrap(x);
            }
        }

        // 2. bins in fractional coordinates
        let grid = BinGrid::new(&particles.position, cell, cutoff)?;
        let n_stripes = stripe_count(n, grid.n[0]);
        let bins = grid.assign(&particles.position, cell);
        let (bin_start, perm) = counting_sort(&bins, grid.count());

        // 2b. spatial order: new index k is old index perm[k]
        let mut new_of_old = vec![0u32; n];
        for (k, &o) in perm.iter().enumerate() {
            new_of_old[o as usize] = k as u32;
        }
        particles.permute(&perm);
        *order = perm.iter().map(|&o| order[o as usize]).collect();
        let wraps: Vec<[i8; 2]> = perm.iter().map(|&o| wraps[o as usize]).collect();
        let bins: Vec<u32> = perm.iter().map(|&o| bins[o as usize]).collect();
        bonds.remap(&new_of_old);
        self.pairs.remap(&new_of_old);
        for q in self.wall_pairs.particle.iter_mut() {
            *q = new_of_old[*q as usize];
        }

        // 3. stripes: contiguous ranges of bin columns with balanced particle counts
        let (stripe_of, stripe_ranges) = stripes(&grid, &bins, n_stripes);

        // 4. pairs, in bin order for locality, sorted into stripes
        let per_stripe = candidate_pairs(
            &grid,
            &bin_start,
            particles,
            &PairRules {
                cell,
                bonds,
                materials,
                skin: self.skin,
            },
            &stripe_of,
            n_stripes,
        );

        // 5. carry the history of touching pairs over, correcting shifts for the wraps
        let history = PairHistory::new(&self.pairs, &wraps, n);
        let mut pairs = PairList::default();
        for list in &per_stripe {
            pairs.stripe_start.push(pairs.len());
            for &(i, j, shift) in list {
                let model =
                    MaterialTable::index(particles.group[i as usize], particles.group[j as usize]);
                pairs.i.push(i);
                pairs.j.push(j);
                pairs.shift.push(shift);
                pairs.model.push(model);
                match history.get(i, j, shift) {
                    Some(old) => pairs.history.push_from(&self.pairs.history, old),
                    None => pairs.history.push_untouched(),
                }
            }
        }

        // 6. wall pairs
        let wall_pairs = wall_pairs(&self.wall_pairs, walls, particles, materials, self.skin);

        self.pairs = pairs;
        self.wall_pairs = wall_pairs;
        // which stripe applies each cross pair's force to each of its particles
        let cross_first = self.pairs.stripe_start[n_stripes];
        let mut touches: Vec<Vec<u32>> = vec![Vec::new(); n_stripes];
        for c in 0..self.pairs.len() - cross_first {
            let k = cross_first + c;
            touches[stripe_of[self.pairs.i[k] as usize] as usize].push((c as u32) << 1);
            touches[stripe_of[self.pairs.j[k] as usize] as usize].push(((c as u32) << 1) | 1);
        }
        self.cross_touch_start = std::iter::once(0)
            .chain(touches.iter().scan(0usize, |acc, t| {
                *acc += t.len();
                Some(*acc)
            }))
            .collect();
        self.cross_touch = touches.concat();
        self.stripe_ranges = stripe_ranges;
        self.reference = particles.position.clone();
        self.accumulated_map = IDENTITY;
        self.wall_reference = walls.iter().map(|w| w.displacement).collect();
        self.max_radius = r_max;
        self.max_fluctuation_sq = 0.0;
        self.max_displacement_sq = 0.0;
        self.valid = true;
        self.build_count += 1;
        Ok(new_of_old)
    }
}

/// The stripe of every particle (in spatial order, `bins` its bin) and each
/// stripe's contiguous range: whole bin columns, with balanced particle counts.
fn stripes(grid: &BinGrid, bins: &[u32], n_stripes: usize) -> (Vec<u8>, Vec<(usize, usize)>) {
    let n = bins.len();
    let mut column_counts = vec![0usize; grid.n[0]];
    for &b in bins {
        column_counts[b as usize / grid.n[1]] += 1;
    }
    let mut stripe_of_column = vec![0u8; grid.n[0]];
    let mut seen = 0usize;
    for (c, count) in column_counts.iter().enumerate() {
        let stripe = ((seen * n_stripes) / n.max(1)).min(n_stripes - 1);
        stripe_of_column[c] = stripe as u8;
        seen += count;
    }
    let stripe_of: Vec<u8> = bins
        .iter()
        .map(|&b| stripe_of_column[b as usize / grid.n[1]])
        .collect();
    // stripes are contiguous in the spatial order
    let mut stripe_ranges = vec![(0usize, 0usize); n_stripes];
    let mut start = 0usize;
    for (b, range) in stripe_ranges.iter_mut().enumerate() {
        let mut end = start;
        while end < n && stripe_of[end] as usize == b {
            end += 1;
        }
        *range = (start, end);
        start = end;
    }
    debug_assert_eq!(start, n);
    (stripe_of, stripe_ranges)
}

/// What makes two particles a candidate pair besides their bins.
struct PairRules<'a> {
    cell: Option<&'a PeriodicCell>,
    bonds: &'a Bonds,
    materials: &'a MaterialTable,
    skin: f64,
}

/// The pairs closer than the sum of their radii and the skin, neither bonded
/// nor two pebbles of one clump, between groups that interact, in bin order;
/// per stripe of both particles, the pairs across stripes last.
fn candidate_pairs(
    grid: &BinGrid,
    bin_start: &[usize],
    particles: &Particles,
    rules: &PairRules<'_>,
    stripe_of: &[u8],
    n_stripes: usize,
) -> Vec<Vec<(u32, u32, [i8; 2])>> {
    let mut per_stripe: Vec<Vec<(u32, u32, [i8; 2])>> = vec![Vec::new(); n_stripes + 1];
    let (positions, radii) = (&particles.position, &particles.radius);
    let (groups, clump) = (&particles.group, &particles.clump);
    for bx in 0..grid.n[0] {
        for by in 0..grid.n[1] {
            let home = bx * grid.n[1] + by;
            for pi in bin_start[home] as u32..bin_start[home + 1] as u32 {
                let i = pi as usize;
                let (xi, ri) = (positions[i], radii[i]);
                for dx in -1i64..=1 {
                    let Some((nx, sx)) = grid.neighbor(0, bx as i64 + dx) else {
                        continue;
                    };
                    for dy in -1i64..=1 {
                        let Some((ny, sy)) = grid.neighbor(1, by as i64 + dy) else {
                            continue;
                        };
                        let shift = [sx, sy];
                        let offset = rules.cell.map_or([0.0; 2], |c| c.image_offset(shift));
                        let other = nx * grid.n[1] + ny;
                        for pj in bin_start[other] as u32..bin_start[other + 1] as u32 {
                            if pj <= pi {
                                continue;
                            }
                            let j = pj as usize;
                            let d = sub(add(positions[j], offset), xi);
                            let reach = ri + radii[j] + rules.skin;
                            if dot(d, d) < reach * reach
                                && (clump[i] == NO_CLUMP || clump[i] != clump[j])
                                && !rules.bonds.contains(pi, pj)
                                && rules.materials.interacts(groups[i], groups[j])
                            {
                                let (bi, bj) = (stripe_of[i], stripe_of[j]);
                                let slot = if bi == bj { bi as usize } else { n_stripes };
                                per_stripe[slot].push((pi, pj, shift));
                            }
                        }
                    }
                }
            }
        }
    }
    per_stripe
}

/// The particle-wall pairs within the skin of the active walls, with the
/// history of the `old` ones that touched.
fn wall_pairs(
    old: &WallPairList,
    walls: &[Wall],
    particles: &Particles,
    materials: &MaterialTable,
    skin: f64,
) -> WallPairList {
    let mut wall_history: PairMap<(u32, u32), usize> = PairMap::default();
    for k in 0..old.wall.len() {
        if old.history.touched(k) {
            wall_history.insert((old.wall[k], old.particle[k]), k);
        }
    }
    let mut pairs = WallPairList::default();
    for (w, wall) in walls.iter().enumerate().filter(|(_, w)| w.active) {
        for p in 0..particles.len() {
            let g = wall.disk_contact(particles.position[p], particles.radius[p]);
            if g.overlap > -skin && materials.interacts(wall.group, particles.group[p]) {
                match wall_history.get(&(w as u32, p as u32)) {
                    Some(&k) => pairs.history.push_from(&old.history, k),
                    None => pairs.history.push_untouched(),
                }
                pairs.wall.push(w as u32);
                pairs.particle.push(p as u32);
                pairs
                    .model
                    .push(MaterialTable::index(wall.group, particles.group[p]));
            }
        }
    }
    pairs
}

/// Uniform bins over fractional coordinates, at least `cutoff` wide.
struct BinGrid {
    n: [usize; 2],
    lo: [f64; 2],
    span: [f64; 2],
    periodic: [bool; 2],
}

impl BinGrid {
    fn new(positions: &[Vec2], cell: Option<&PeriodicCell>, cutoff: f64) -> Result<Self> {
        let (periodic, widths) = match cell {
            Some(c) => (c.periodic, c.widths()),
            None => ([false; 2], [1.0, 1.0]),
        };
        let mut lo = [0.0; 2];
        let mut span = [1.0; 2];
        let mut n = [1usize; 2];
        for k in 0..2 {
            if !periodic[k] {
                let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
                for x in positions {
                    let f = cell.map_or(*x, |c| c.fractional(*x))[k];
                    min = min.min(f);
                    max = max.max(f);
                }
                if positions.is_empty() {
                    (min, max) = (0.0, 0.0);
                }
                if !(min.is_finite() && max.is_finite()) {
                    return Err(EngineError::invalid("position", "positions must be finite"));
                }
                let pad = 1e-9 * (max - min).abs().max(1e-300);
                lo[k] = min - pad;
                span[k] = (max - min) + 2.0 * pad;
            }
            n[k] = ((span[k] * widths[k] / cutoff).floor() as usize).max(1);
            if periodic[k] && n[k] < 3 {
                return Err(EngineError::invalid(
                    "cell",
                    format!(
                        "periodic cell width {:.6e} m along {} must be at least 3 x (largest diameter + skin) = {:.6e} m",
                        widths[k],
                        if k == 0 { "a" } else { "b" },
                        3.0 * cutoff
                    ),
                ));
            }
        }
        // keep the grid size proportional to the particle count when particles spread out
        let limit = (4 * positions.len() + 16) as f64;
        let total = (n[0] * n[1]) as f64;
        if total > limit {
            let free: Vec<usize> = (0..2).filter(|&k| !periodic[k]).collect();
            let factor = (total / limit).powf(1.0 / free.len().max(1) as f64);
            for k in free {
                n[k] = ((n[k] as f64 / factor).floor() as usize).max(1);
            }
        }
        Ok(BinGrid {
            n,
            lo,
            span,
            periodic,
        })
    }

    fn count(&self) -> usize {
        self.n[0] * self.n[1]
    }

    fn assign(&self, positions: &[Vec2], cell: Option<&PeriodicCell>) -> Vec<u32> {
        positions
            .iter()
            .map(|x| {
                let f = cell.map_or(*x, |c| c.fractional(*x));
                let mut b = [0usize; 2];
                for k in 0..2 {
                    let t = ((f[k] - self.lo[k]) / self.span[k] * self.n[k] as f64).floor();
                    b[k] = (t.max(0.0) as usize).min(self.n[k] - 1);
                }
                (b[0] * self.n[1] + b[1]) as u32
            })
            .collect()
    }

    /// Neighbouring bin index along `k`, with the image shift when it wraps.
    #[inline]
    fn neighbor(&self, k: usize, idx: i64) -> Option<(usize, i8)> {
        let n = self.n[k] as i64;
        if (0..n).contains(&idx) {
            Some((idx as usize, 0))
        } else if self.periodic[k] {
            if idx < 0 {
                Some(((idx + n) as usize, -1))
            } else {
                Some(((idx - n) as usize, 1))
            }
        } else {
            None
        }
    }
}

/// Groups item indices by bin: returns CSR offsets and members.
fn counting_sort(bins: &[u32], n_bins: usize) -> (Vec<usize>, Vec<u32>) {
    let mut start = vec![0usize; n_bins + 1];
    for &b in bins {
        start[b as usize + 1] += 1;
    }
    for k in 0..n_bins {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; bins.len()];
    for (p, &b) in bins.iter().enumerate() {
        members[fill[b as usize]] = p as u32;
        fill[b as usize] += 1;
    }
    (start, members)
}

/// The old list's touching pairs (any history), renumbered, with
/// their image shifts corrected for this rebuild's wraps, grouped by their first
/// particle `i` (a counting sort: CSR over `i`), for the carry-over. A new pair
/// finds its history among the few entries of its `i`; the new pairs come in
/// increasing `i` within each stripe's list, so the lookups walk the entries
/// nearly in order, where a hash map of millions of pairs missed the cache on
/// every insert and lookup.
struct PairHistory {
    /// Offsets of each particle's entries (`n + 1`).
    start: Vec<u32>,
    /// `(j, shift, index in the old list)` per touching pair, grouped by `i`.
    entries: Vec<(u32, [i8; 2], u32)>,
}

impl PairHistory {
    /// The touching pairs of `old` (renumbered, `i < j`) among `n` particles;
    /// `wraps` are the new indices' wraps of this rebuild.
    fn new(old: &PairList, wraps: &[[i8; 2]], n: usize) -> Self {
        let touching = |k: usize| old.history.touched(k);
        let mut start = vec![0u32; n + 1];
        for k in (0..old.len()).filter(|&k| touching(k)) {
            start[old.i[k] as usize + 1] += 1;
        }
        for q in 0..n {
            start[q + 1] += start[q];
        }
        let mut fill: Vec<u32> = start[..n].to_vec();
        let mut entries = vec![(0u32, [0i8; 2], 0u32); start[n] as usize];
        for k in (0..old.len()).filter(|&k| touching(k)) {
            let (i, j) = (old.i[k] as usize, old.j[k] as usize);
            let s = old.shift[k];
            let shift = [
                s[0] - wraps[j][0] + wraps[i][0],
                s[1] - wraps[j][1] + wraps[i][1],
            ];
            let slot = &mut fill[i];
            entries[*slot as usize] = (old.j[k], shift, k as u32);
            *slot += 1;
        }
        PairHistory { start, entries }
    }

    /// The old list's index of pair `(i, j, shift)`, if it touched.
    fn get(&self, i: u32, j: u32, shift: [i8; 2]) -> Option<usize> {
        let (lo, hi) = (self.start[i as usize], self.start[i as usize + 1]);
        self.entries[lo as usize..hi as usize]
            .iter()
            .find(|e| e.0 == j && e.1 == shift)
            .map(|e| e.2 as usize)
    }
}

/// A map keyed by particle indices, for the history carry-over of a rebuild:
/// only inserted into and looked up (never iterated), so its hash function
/// cannot change a result, and rustc-hash's multiplicative one is much cheaper
/// than the default (which resists adversarial keys, which indices are not).
type PairMap<K, V> = rustc_hash::FxHashMap<K, V>;
