//! The bonds' and the walls' forces of a step, added to the particles by each
//! stripe's integration instead of by one thread between the two parallel phases.
//!
//! On one thread the forces reach a particle in this order: its stripe's
//! interior pairs, the bonds in bond order, the cement bonds in their order,
//! the wall contacts in wall-pair order, then the pairs across stripes. With a team the bonds and the wall
//! contacts are evaluated in the contact phase (each stripe its share of the
//! bonds and the wall pairs of its own particles) and wait in slots; the walls'
//! forces and the tally are then summed over the slots in wall-pair order, and
//! each stripe's integration adds, to its own particles,
//! first the bond slots that touch them in bond order, then the cement slots
//! in cement order, then their wall slots in wall-pair order, then the cross pairs, so every particle receives the same
//! additions in the same order on any number of threads, and the bits do not
//! change. The particles' force arrays stay in the cache of the worker that
//! owns their stripe, instead of crossing to the thread that ran the serial pass.
use super::pair_kernel::ContactTally;
use crate::bond::{Bond, BondSlot};
use crate::cement::{CementBond, CementSlot};
use crate::diagnostics::ContactDissipation;
use crate::parallel::StripeLists;
use crate::vec2::{add, sub, Vec2};

/// A wall contact's force on its particle this step, and its terms of the
/// step's tally (evaluated by the stripe that owns the particle, in the contact
/// phase; summed onto the walls and the tally in wall-pair order afterwards).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WallSlot {
    /// Force on the particle (N).
    pub force: Vec2,
    /// Torque on the particle (N m), the contact law's.
    pub torque: f64,
    /// Energy dissipated by the contact's sub-models this step (J).
    pub dissipation: ContactDissipation,
    /// Elastic energy (J) and force magnitude (N), measured steps only.
    pub elastic: f64,
    pub force_norm: f64,
    /// The contact's normal tangent stiffness (N/m), for the wall's stiffness sum.
    pub stiffness: f64,
    /// The overlap exceeds the allowed fraction of the radius.
    pub overlap_violation: bool,
    /// Whether the pair touched (a pair in the list may be apart).
    pub active: bool,
}

/// The bond and wall touches of the current stripes (kept current by `run` and
/// every rebuild, like the chains' stripe index).
#[derive(Debug, Clone, Default)]
pub(crate) struct DeferredIndex {
    /// `(bond << 1) | side` (side 0: the bond's `i`, 1: its `j`).
    bonds: StripeLists<u32>,
    /// The cement bonds' ends, as `bonds`.
    cement: StripeLists<u32>,
    /// Wall-pair indices.
    walls: StripeLists<u32>,
}

impl DeferredIndex {
    /// The index of `bonds` and of the wall pairs' particles `wall_particles`
    /// over `stripe_ranges`; empty, so that it fits no stripes (the forces are then
    /// added on one thread), when a particle lies outside them.
    pub(crate) fn new(
        bonds: &[Bond],
        cement: &[CementBond],
        wall_particles: &[u32],
        stripe_ranges: &[(usize, usize)],
    ) -> Self {
        let ends = |(k, i, j): (usize, u32, u32)| {
            let k = k as u32;
            [(i as usize, k << 1), (j as usize, (k << 1) | 1)]
        };
        let bond_items = bonds
            .iter()
            .enumerate()
            .flat_map(|(k, b)| ends((k, b.i, b.j)));
        let cement_items = cement
            .iter()
            .enumerate()
            .flat_map(|(k, b)| ends((k, b.i, b.j)));
        let wall_items = wall_particles
            .iter()
            .enumerate()
            .map(|(k, &q)| (q as usize, k as u32));
        match (
            StripeLists::new(stripe_ranges, bond_items),
            StripeLists::new(stripe_ranges, cement_items),
            StripeLists::new(stripe_ranges, wall_items),
        ) {
            (Some(bonds), Some(cement), Some(walls)) => DeferredIndex {
                bonds,
                cement,
                walls,
            },
            _ => DeferredIndex::default(),
        }
    }

    /// The wall pairs whose particle lies in stripe `b`, in wall-pair order.
    pub(crate) fn walls_of_stripe(&self, b: usize) -> &[u32] {
        self.walls.of_stripe(b)
    }

    /// Whether the index serves `n_stripes` stripes, `n_bonds` bonds,
    /// `n_cement` cement bonds and `n_wall_pairs` wall pairs.
    pub(crate) fn fits(
        &self,
        n_stripes: usize,
        n_bonds: usize,
        n_cement: usize,
        n_wall_pairs: usize,
    ) -> bool {
        let covers =
            |lists: &StripeLists<u32>, n| lists.n_stripes() == n_stripes && lists.len() == n;
        covers(&self.bonds, 2 * n_bonds)
            && covers(&self.cement, 2 * n_cement)
            && covers(&self.walls, n_wall_pairs)
    }
}

/// The slots of one step, ready to be added stripe by stripe.
pub(crate) struct DeferredForces<'a> {
    pub(crate) index: &'a DeferredIndex,
    pub(crate) bonds: &'a [Bond],
    pub(crate) bond_slots: &'a [BondSlot],
    pub(crate) cement: &'a [CementBond],
    pub(crate) cement_slots: &'a [CementSlot],
    pub(crate) wall_particles: &'a [u32],
    pub(crate) wall_slots: &'a [WallSlot],
}

/// A bond as the force passes read it (permanent or cement): its particles.
pub(crate) trait BondEnds {
    /// Its two particles (internal indices).
    fn ends(&self) -> (u32, u32);
}

impl BondEnds for Bond {
    #[inline(always)]
    fn ends(&self) -> (u32, u32) {
        (self.i, self.j)
    }
}

impl BondEnds for CementBond {
    #[inline(always)]
    fn ends(&self) -> (u32, u32) {
        (self.i, self.j)
    }
}

/// A bond's slot as the force passes read it: the force on `j`, the torques
/// taken from `i` and `j`, and its terms of a measured step's tally.
pub(crate) trait BondForce {
    /// `(force on j, torque taken from i, torque taken from j)`.
    fn parts(&self) -> (Vec2, f64, f64);
    /// `(elastic energy, force magnitude)` for the serial pass's tally, or
    /// `None` when the evaluation tallied it.
    fn measured(&self) -> Option<(f64, f64)>;
}

impl BondForce for BondSlot {
    #[inline(always)]
    fn parts(&self) -> (Vec2, f64, f64) {
        (self.force, self.torque_i, self.torque_j)
    }
    #[inline(always)]
    fn measured(&self) -> Option<(f64, f64)> {
        Some((self.elastic, self.force_norm))
    }
}

impl BondForce for CementSlot {
    #[inline(always)]
    fn parts(&self) -> (Vec2, f64, f64) {
        (self.force, self.torque_i, self.torque_j)
    }
    /// Never measured here: the stripe that evaluates a cement bond tallies it.
    #[inline(always)]
    fn measured(&self) -> Option<(f64, f64)> {
        None
    }
}

/// Adds the slots of `entries` (`(bond << 1) | side`) to `force` / `torque`,
/// which start at particle `lo`: a stripe's share of one list of bonds.
#[inline]
fn apply_ends<B: BondEnds, S: BondForce>(
    entries: &[u32],
    (bonds, slots): (&[B], &[S]),
    lo: usize,
    force: &mut [Vec2],
    torque: &mut [f64],
) {
    for &entry in entries {
        let k = (entry >> 1) as usize;
        let (i, j) = bonds[k].ends();
        let (f, torque_i, torque_j) = slots[k].parts();
        if entry & 1 == 1 {
            let q = j as usize - lo;
            force[q] = add(force[q], f);
            torque[q] -= torque_j;
        } else {
            let q = i as usize - lo;
            force[q] = sub(force[q], f);
            torque[q] -= torque_i;
        }
    }
}

/// The serial pass of one list of bonds: each slot's force added to the
/// particles in bond order (`apply`), and its terms to `tally` (`MEASURE`).
#[inline]
pub(crate) fn add_bond_slots<const MEASURE: bool, B: BondEnds, S: BondForce>(
    (bonds, slots): (&[B], &[S]),
    (force, torque): (&mut [Vec2], &mut [f64]),
    apply: bool,
    tally: &mut ContactTally,
) {
    for (bond, slot) in bonds.iter().zip(slots) {
        if apply {
            let (i, j) = bond.ends();
            let (i, j) = (i as usize, j as usize);
            let (f, torque_i, torque_j) = slot.parts();
            force[j] = add(force[j], f);
            force[i] = sub(force[i], f);
            torque[i] -= torque_i;
            torque[j] -= torque_j;
        }
        if MEASURE {
            if let Some((elastic, force_norm)) = slot.measured() {
                tally.elastic += elastic;
                tally.force_sum += force_norm;
                tally.contacts += 1;
            }
        }
    }
}

impl DeferredForces<'_> {
    /// Adds the bond and wall forces on stripe `b`'s particles to `force` /
    /// `torque` (which start at particle `lo`), as the serial passes add them.
    pub(crate) fn apply(&self, b: usize, lo: usize, force: &mut [Vec2], torque: &mut [f64]) {
        let bonds = (self.bonds, self.bond_slots);
        apply_ends(self.index.bonds.of_stripe(b), bonds, lo, force, torque);
        // a broken bond's slot holds zeros: adding them keeps the serial pass's bits
        let cement = (self.cement, self.cement_slots);
        apply_ends(self.index.cement.of_stripe(b), cement, lo, force, torque);
        for &k in self.index.walls.of_stripe(b) {
            let slot = &self.wall_slots[k as usize];
            if slot.active {
                let q = self.wall_particles[k as usize] as usize - lo;
                force[q] = add(force[q], slot.force);
                torque[q] += slot.torque;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bond(i: u32, j: u32) -> Bond {
        Bond {
            i,
            j,
            normal_stiffness: 1.0,
            shear_stiffness: 1.0,
            rest_length: 1.0,
            shear: 0.0,
        }
    }

    #[test]
    fn every_bond_end_and_wall_pair_lands_in_its_stripe_in_list_order() {
        let stripes = [(0, 3), (3, 5), (5, 8)];
        let bonds = [bond(0, 4), bond(6, 1), bond(3, 4)];
        let index = DeferredIndex::new(&bonds, &[], &[7, 2, 5], &stripes);
        assert!(index.fits(3, 3, 0, 3));
        assert!(!index.fits(3, 4, 0, 3));
        assert_eq!(index.bonds.of_stripe(0), &[0 << 1, (1 << 1) | 1]);
        assert_eq!(index.bonds.of_stripe(1), &[1, 2 << 1, (2 << 1) | 1]);
        assert_eq!(index.bonds.of_stripe(2), &[1 << 1]);
        assert_eq!(index.walls.of_stripe(0), &[1]);
        assert!(index.walls.of_stripe(1).is_empty());
        assert_eq!(index.walls.of_stripe(2), &[0, 2]);
    }

    #[test]
    fn a_particle_outside_the_stripes_leaves_the_index_invalid() {
        let index = DeferredIndex::new(&[bond(0, 9)], &[], &[], &[(0, 3), (3, 5)]);
        assert!(!index.fits(2, 1, 0, 0));
    }

    #[test]
    fn stripe_by_stripe_adds_what_the_serial_passes_add_bit_for_bit() {
        // awkward magnitudes, so that any change of the addition order shows
        let stripes = [(0, 2), (2, 4)];
        let bonds = [bond(0, 3), bond(2, 0), bond(1, 2)];
        let bond_slots: Vec<BondSlot> = (0..3)
            .map(|k| BondSlot {
                force: [1e16 / (k as f64 + 3.0), -0.1 * (k as f64 + 1.0)],
                torque_i: 1e-3 * (k as f64 + 0.7),
                torque_j: 3.3e8 * (k as f64 - 1.1),
                ..BondSlot::default()
            })
            .collect();
        let wall_particles = [0, 3, 0, 1];
        let wall_slots: Vec<WallSlot> = (0..4)
            .map(|k| WallSlot {
                force: [0.3 * k as f64 - 1e15, 1e-7 / (k as f64 + 1.0)],
                torque: 7e7 * k as f64 + 0.1,
                active: k != 1,
                ..WallSlot::default()
            })
            .collect();
        let start_force: Vec<Vec2> = (0..4).map(|q| [0.1 * q as f64 + 1.0, 1e17]).collect();
        let start_torque: Vec<f64> = (0..4).map(|q| 1e-9 * (q as f64 + 1.0)).collect();
        // the serial passes: bonds in bond order, then the wall contacts in order
        let (mut force, mut torque) = (start_force.clone(), start_torque.clone());
        for (b, s) in bonds.iter().zip(&bond_slots) {
            let (i, j) = (b.i as usize, b.j as usize);
            force[j] = add(force[j], s.force);
            force[i] = sub(force[i], s.force);
            torque[i] -= s.torque_i;
            torque[j] -= s.torque_j;
        }
        for (&q, s) in wall_particles.iter().zip(&wall_slots) {
            if s.active {
                force[q as usize] = add(force[q as usize], s.force);
                torque[q as usize] += s.torque;
            }
        }
        let index = DeferredIndex::new(&bonds, &[], &wall_particles, &stripes);
        let deferred = DeferredForces {
            index: &index,
            bonds: &bonds,
            bond_slots: &bond_slots,
            cement: &[],
            cement_slots: &[],
            wall_particles: &wall_particles,
            wall_slots: &wall_slots,
        };
        let (mut by_stripe_force, mut by_stripe_torque) = (start_force, start_torque);
        for (b, &(lo, hi)) in stripes.iter().enumerate() {
            deferred.apply(
                b,
                lo,
                &mut by_stripe_force[lo..hi],
                &mut by_stripe_torque[lo..hi],
            );
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&by_stripe_force.concat()),
            bits(&force.concat()),
            "forces"
        );
        assert_eq!(bits(&by_stripe_torque), bits(&torque), "torques");
        assert_ne!(force[0], [1.0, 1e17], "the case adds something");
    }
}
