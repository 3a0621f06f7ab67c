//! A stripe's pass over its cement bonds: each bond's law at the current
//! state (four at a time where the processor can, `cement_lanes.rs`, with
//! the same bits), its slot, its break and its measured terms, in bond order.
use super::pair_kernel::{CementShare, ContactTally};
use super::step::BondStep;
use crate::cement::{bond_law, conclude, BondInput, CementBond, CementEvaluation, CementSlot};

/// Evaluates a stripe's share of the cement bonds (the first of which is
/// bond `first` of the list) into their slots, recording the ones that break
/// in `ruptures`, in bond order, four at a time with `vector`; returns the
/// tally of the holding ones' terms (`MEASURE`) and the breaks.
#[inline]
pub(super) fn evaluate_cement_bonds<const MEASURE: bool>(
    (cement, slots, first, ruptures): CementShare<'_>,
    (motion, cell, gradient, increment_time): BondStep<'_>,
    vector: bool,
) -> ContactTally {
    let mut tally = ContactTally::default();
    let tally = &mut tally;
    let mut one_by_one =
        |k: usize, bonds: &mut [CementBond], slots: &mut [CementSlot], tally: &mut ContactTally| {
            for (l, (bond, slot)) in bonds.iter_mut().zip(slots.iter_mut()).enumerate() {
                let input = BondInput::of(bond, motion);
                let law = bond_law::<f64, MEASURE>(input, cell, gradient, increment_time);
                match conclude(bond, motion, &law, increment_time) {
                    CementEvaluation::Holds {
                        slot: held,
                        elastic,
                        force_norm,
                    } => {
                        *slot = held;
                        if MEASURE {
                            tally.elastic += elastic;
                            tally.force_sum += force_norm;
                            tally.contacts += 1;
                            tally.cement_holding += 1;
                        }
                    }
                    CementEvaluation::Breaks(rupture) => {
                        *slot = CementSlot::default();
                        ruptures.push((first + k + l, rupture));
                        tally.bond_breaks += 1;
                    }
                }
            }
        };
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if vector {
        let at = (cell, gradient, increment_time);
        while done + 4 <= cement.len() {
            let range = done..done + 4;
            let (quad, quad_slots) = (&mut cement[range.clone()], &mut slots[range]);
            // SAFETY: `vector` only where the processor has AVX2
            // (`Simulation::set_simd`); the bonds' disks exist
            let held = unsafe {
                super::cement_lanes::evaluate_four::<MEASURE>(quad, quad_slots, motion, at, tally)
            };
            if !held {
                one_by_one(done, quad, quad_slots, tally);
            }
            done += 4;
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = vector;
    one_by_one(done, &mut cement[done..], &mut slots[done..], tally);
    *tally
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::PeriodicCell;
    use crate::cement::{CementKind, CementSpec};
    use crate::state::ParticleMotion;
    use crate::vec2::{Mat2, Vec2};

    /// A small deterministic generator (SplitMix64).
    struct Rng(u64);

    impl Rng {
        fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
        }
    }

    /// Disks in pairs near their rest length (pair k: disks 2k and 2k + 1,
    /// the second put back into the cell along `a`, so that some bonds
    /// cross the boundary), with random motion.
    struct Disks {
        position: Vec<Vec2>,
        velocity: Vec<Vec2>,
        angular_velocity: Vec<f64>,
        radius: Vec<f64>,
        zeros: Vec<f64>,
        rest: Vec<f64>,
    }

    const LENGTH: f64 = 0.02;

    fn disks(rng: &mut Rng, pairs: usize) -> Disks {
        let n = 2 * pairs;
        let radius: Vec<f64> = (0..n).map(|_| rng.uniform(0.5e-3, 1.5e-3)).collect();
        let (mut position, mut rest) = (Vec::new(), Vec::new());
        for k in 0..pairs {
            let first = [rng.uniform(0.0, LENGTH), rng.uniform(0.0, LENGTH)];
            let l0 = radius[2 * k] + radius[2 * k + 1];
            let d = l0 * rng.uniform(0.998, 1.002);
            let angle = rng.uniform(0.0, std::f64::consts::TAU);
            let x = (first[0] + d * angle.cos()).rem_euclid(LENGTH);
            position.extend([first, [x, first[1] + d * angle.sin()]]);
            rest.push(l0);
        }
        Disks {
            position,
            velocity: (0..n)
                .map(|_| [rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)])
                .collect(),
            angular_velocity: (0..n).map(|_| rng.uniform(-50.0, 50.0)).collect(),
            radius,
            zeros: vec![0.0; n],
            rest,
        }
    }

    /// One bond per pair of `d`, parallel or contact, with random
    /// stiffnesses, strengths and springs (some beyond their strength).
    fn bonds(rng: &mut Rng, d: &Disks) -> Vec<CementBond> {
        (0..d.rest.len())
            .map(|k| {
                let (i, j) = (2 * k, 2 * k + 1);
                let kind = if k % 5 == 0 {
                    CementKind::Contact
                } else {
                    CementKind::Parallel
                };
                let spec = CementSpec {
                    kind,
                    radius_multiplier: rng.uniform(0.3, 1.0),
                    normal_stiffness: rng.uniform(1.0e10, 1.0e11),
                    shear_stiffness: rng.uniform(1.0e10, 1.0e11),
                    tensile_strength: rng.uniform(0.1e6, 2.0e6),
                    cohesion: rng.uniform(0.1e6, 2.0e6),
                    friction_angle: rng.uniform(0.0, 40.0),
                };
                let (ri, rj) = (d.radius[i], d.radius[j]);
                let mut b = CementBond::new(i as u32, j as u32, ri, rj, d.rest[k], &spec);
                b.shear = rng.uniform(-300.0, 300.0);
                b.moment = rng.uniform(-0.03, 0.03);
                b
            })
            .collect()
    }

    /// Everything a pass writes, as bits.
    fn pass_bits<const MEASURE: bool>(
        bonds: &[CementBond],
        d: &Disks,
        cell: Option<&PeriodicCell>,
        vector: bool,
    ) -> (Vec<u64>, Vec<usize>) {
        let mut bonds = bonds.to_vec();
        let mut slots = vec![CementSlot::default(); bonds.len()];
        let mut ruptures = Vec::new();
        let p = ParticleMotion {
            position: &d.position,
            velocity: &d.velocity,
            angular_velocity: &d.angular_velocity,
            radius: &d.radius,
            mass: &d.zeros,
            inertia: &d.zeros,
        };
        let gradient: Option<Mat2> = cell.map(|c| c.velocity_gradient);
        let at = (&p, cell, gradient, 1.0e-5);
        let work = (bonds.as_mut_slice(), slots.as_mut_slice(), 7, &mut ruptures);
        let tally = evaluate_cement_bonds::<MEASURE>(work, at, vector);
        let mut bits = Vec::new();
        for (b, s) in bonds.iter().zip(&slots) {
            bits.extend(
                [
                    b.shear, b.moment, s.force[0], s.force[1], s.torque_i, s.torque_j,
                ]
                .map(f64::to_bits),
            );
        }
        for (k, r) in &ruptures {
            bits.extend([*k as u64, r.mode as u64]);
            let values = [
                r.position[0],
                r.position[1],
                r.normal[0],
                r.normal[1],
                r.energy,
                r.booked,
            ];
            bits.extend(values.map(f64::to_bits));
            bits.extend([r.normal_force, r.shear_force, r.moment].map(f64::to_bits));
        }
        bits.extend([tally.elastic, tally.force_sum].map(f64::to_bits));
        bits.extend([tally.contacts, tally.cement_holding, tally.bond_breaks].map(|c| c as u64));
        (bits, ruptures.iter().map(|(k, _)| k - 7).collect())
    }

    /// Random bonds (parallel and contact, stretched, squeezed, bent and
    /// sheared, some across the cell's boundary, some past their strength)
    /// in a fixed, a periodic, a half-periodic and a sheared deforming cell:
    /// four at a time, the pass must write the bits of one at a time, its
    /// slots, springs, breaks and measured terms.
    #[test]
    fn four_bonds_at_a_time_write_the_bits_of_one_at_a_time() {
        if !crate::simd::available() {
            return;
        }
        let mut rng = Rng(11);
        // 63 bonds: fifteen quads and a tail of three
        let d = disks(&mut rng, 63);
        let cell = |b: Vec2, periodic: [bool; 2], gradient: Mat2| PeriodicCell {
            origin: [0.0, 0.0],
            a: [LENGTH, 0.0],
            b,
            periodic,
            velocity_gradient: gradient,
        };
        let still = [[0.0; 2]; 2];
        let cells = [
            None,
            Some(cell([0.0, LENGTH], [true, true], still)),
            Some(cell([0.0, LENGTH], [true, false], still)),
            Some(cell(
                [0.3 * LENGTH, LENGTH],
                [true, true],
                [[0.0, 2.0], [0.0, 0.0]],
            )),
        ];
        let (mut broken, mut quads_held) = (0, 0);
        for cell in cells.iter() {
            let bonds = bonds(&mut rng, &d);
            let (one, breaks) = pass_bits::<true>(&bonds, &d, cell.as_ref(), false);
            assert_eq!(pass_bits::<true>(&bonds, &d, cell.as_ref(), true).0, one);
            let unmeasured = pass_bits::<false>(&bonds, &d, cell.as_ref(), false).0;
            assert_eq!(
                pass_bits::<false>(&bonds, &d, cell.as_ref(), true).0,
                unmeasured
            );
            broken += breaks.len();
            quads_held += (0..15)
                .filter(|q| !breaks.iter().any(|k| k / 4 == *q))
                .count();
        }
        // some bonds break (the one-bond path books their quads), most hold,
        // and most quads hold whole (the lanes write them)
        assert!(broken > 5 && broken < 100, "{broken} of 252 broke");
        assert!(
            quads_held > 30,
            "{quads_held} of 60 quads held, {broken} bonds broke"
        );
    }
}
