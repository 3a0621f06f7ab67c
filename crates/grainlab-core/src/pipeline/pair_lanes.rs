//! The undamped pair loop four pairs at a time, in the 256-bit registers of
//! AVX2, with the same bits as the scalar loop of `pair_kernel.rs`.
//!
//! The law of four pairs is [`law_by_four`]: the sub-models of
//! [`crate::law::contact_law`] without the normal and shear dashpots (normal
//! spring, shear spring with its cap and, compiled in only for a table with
//! rolling resistance, the rolling spring with its cap and its dashpot),
//! their own code called with four lanes (the laws are written once over
//! [`crate::law::real::Real`]); its test gives both the same random contacts
//! and requires the same bits. The loop runs only while every sub-model of
//! the law has lanes ([`crate::law::LANES`]).
//!
//! Why the bits are the same: every pair's law is computed lane by lane with
//! the operations of the scalar code in its order (IEEE additions,
//! multiplications, divisions and square roots, all correctly
//! rounded in both forms, and no fused multiply-add, which Rust never forms on
//! its own), and branches become selects of the value the branch would have
//! kept. What is summed over pairs, the forces and torques on the particles and
//! the step's tallies, is summed afterwards one pair at a time in pair order,
//! by the scalar code's own bookkeeping ([`PairKernel::finish_contact`],
//! [`no_contact`]). The pairs of a run are independent (the loop reads
//! positions and velocities, and writes each pair's own spring), so computing
//! four before booking them changes nothing.
//!
//! The four pairs are held in the registers' lanes in the order 0, 2, 1, 3:
//! the order the interleaved `[x, y]` of two pairs' vectors unpack into
//! ([`SWAP_MIDDLE`] and [`pair_order`] turn it back).
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use super::pair_kernel::{no_contact, ContactTally, ForceSink, PairKernel};
use crate::diagnostics::ContactDissipation;
use crate::law::normal::LinearSpring;
use crate::law::rolling::RollingSpring;
use crate::law::tangential::ShearSpring;
use crate::law::{
    elastic_energy, shear_torques, ContactForce, ContactRecord, ROLLING_HISTORY, TANGENTIAL_HISTORY,
};
use crate::simd::{spill, F64x4};

/// `_mm256_permute4x64_pd`'s selector that swaps lanes 1 and 2: pairs in
/// memory order into register order and back.
const SWAP_MIDDLE: i32 = 0b11_01_10_00;

/// Four values, one per pair, into register order.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn lanes(v: [f64; 4]) -> __m256d {
    _mm256_set_pd(v[3], v[1], v[2], v[0])
}

/// Four `[x, y]` vectors (as 128-bit registers) into their x and y lanes.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn unpack(a: [__m128d; 4]) -> (__m256d, __m256d) {
    let low = _mm256_insertf128_pd(_mm256_castpd128_pd256(a[0]), a[1], 1);
    let high = _mm256_insertf128_pd(_mm256_castpd128_pd256(a[2]), a[3], 1);
    (_mm256_unpacklo_pd(low, high), _mm256_unpackhi_pd(low, high))
}

/// A register's lanes in pair order.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn in_order(v: __m256d) -> [f64; 4] {
    spill(_mm256_permute4x64_pd::<SWAP_MIDDLE>(v))
}

/// A `movemask` of lanes in register order as bits in pair order.
#[inline]
fn pair_order(mask: i32) -> u32 {
    let m = mask as u32;
    (m & 0b1001) | ((m & 0b0010) << 1) | ((m & 0b0100) >> 1)
}

/// The sliding flags of four pairs (bytes 0 or 1 from `flags`) as lane masks in register order.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn slid_lanes(flags: *const bool) -> __m256d {
    let bytes = (flags as *const u32).read_unaligned();
    let wide = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(bytes as i32));
    let set = _mm256_cmpgt_epi64(wide, _mm256_setzero_si256());
    _mm256_castsi256_pd(_mm256_permute4x64_epi64::<SWAP_MIDDLE>(set))
}

impl PairKernel<'_> {
    // hot kernel: every undamped pair of every step, four at a time; split, its registers would spill across calls
    /// [`PairKernel::pairs`] without normal and shear dashpots, four pairs at
    /// a time and the rest one at a time; `ROLLING` when some model has
    /// rolling resistance ([`PairKernel::rolling`]: without it the rolling law
    /// is not compiled in, and the rolling slot of each record is left as it
    /// is), `ROLLING_DASHPOT` when one of those has a rolling dashpot
    /// ([`PairKernel::rolling_damped`]).
    ///
    /// # Safety
    /// As [`PairKernel::run`]; the processor has AVX2 ([`crate::simd::available`]).
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn pairs_by_four<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
        const ROLLING: bool,
        const ROLLING_DASHPOT: bool,
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
        let n = columns.len();
        let g = fixed.gradient;
        let (g00, g01, g10, g11) = (
            _mm256_set1_pd(g[0][0]),
            _mm256_set1_pd(g[0][1]),
            _mm256_set1_pd(g[1][0]),
            _mm256_set1_pd(g[1][1]),
        );
        let increment_time = _mm256_set1_pd(self.increment_time);
        let dt = _mm256_set1_pd(self.dt);
        let sign_bit = _mm256_set1_pd(-0.0);
        let one = _mm256_set1_pd(1.0);
        let max_overlap_ratio = _mm256_set1_pd(self.max_overlap_ratio);
        let position = self.position.as_ptr() as *const f64;
        let velocity = self.velocity.as_ptr() as *const f64;
        let mut k0 = 0;
        while k0 + 4 <= n {
            // gather the geometry: each pair's indices, radii and the positions
            // of both particles (j at its image); the motion only if one touches
            let mut ij = [[0usize; 2]; 4];
            let (mut ri, mut rj) = ([0.0; 4], [0.0; 4]);
            let mut xi = [_mm_setzero_pd(); 4];
            let mut xj = [_mm_setzero_pd(); 4];
            for l in 0..4 {
                let k = k0 + l;
                // SAFETY: k < n, the length of every column (`PairKernel::columns`)
                let (i, j) = (
                    *columns.i.get_unchecked(k) as usize,
                    *columns.j.get_unchecked(k) as usize,
                );
                debug_assert!(i < self.position.len() && j < self.position.len());
                ij[l] = [i, j];
                ri[l] = *self.radius.get_unchecked(i);
                rj[l] = *self.radius.get_unchecked(j);
                xi[l] = _mm_loadu_pd(position.add(2 * i));
                xj[l] = _mm_loadu_pd(position.add(2 * j));
                let s = *columns.shift.get_unchecked(k);
                if s != [0, 0] {
                    if let Some(c) = self.cell {
                        let offset = c.image_offset(s);
                        xj[l] = _mm_add_pd(xj[l], _mm_loadu_pd(offset.as_ptr()));
                    }
                }
            }
            let (xi_x, xi_y) = unpack(xi);
            let (xj_x, xj_y) = unpack(xj);
            let (r_i, r_j) = (lanes(ri), lanes(rj));
            let dx = _mm256_sub_pd(xj_x, xi_x);
            let dy = _mm256_sub_pd(xj_y, xi_y);
            let reach = _mm256_add_pd(r_i, r_j);
            let dist_sq = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
            // touching unless dist_sq >= reach^2 (so a NaN distance touches, as in the scalar test)
            let touching = _mm256_cmp_pd::<_CMP_NGE_UQ>(dist_sq, _mm256_mul_pd(reach, reach));
            let touching_bits = _mm256_movemask_pd(touching) as usize;
            if touching_bits == 0 {
                for l in 0..4 {
                    let k = k0 + l;
                    no_contact(
                        sink,
                        k,
                        records.get_unchecked_mut(k),
                        sliding.get_unchecked_mut(k),
                    );
                }
                k0 += 4;
                continue;
            }
            let dist = _mm256_sqrt_pd(dist_sq);
            let inverse = _mm256_div_pd(one, dist);
            let nx = _mm256_mul_pd(dx, inverse);
            let ny = _mm256_mul_pd(dy, inverse);
            let overlap = _mm256_sub_pd(reach, dist);
            // t = perp(n) = (-n_y, n_x)
            let tx = _mm256_xor_pd(ny, sign_bit);
            let ty = nx;
            let (mut wi, mut wj) = ([0.0; 4], [0.0; 4]);
            let mut vi = [_mm_setzero_pd(); 4];
            let mut vj = [_mm_setzero_pd(); 4];
            for l in 0..4 {
                let [i, j] = ij[l];
                wi[l] = *self.angular_velocity.get_unchecked(i);
                wj[l] = *self.angular_velocity.get_unchecked(j);
                vi[l] = _mm_loadu_pd(velocity.add(2 * i));
                vj[l] = _mm_loadu_pd(velocity.add(2 * j));
            }
            let (vi_x, vi_y) = unpack(vi);
            let (vj_x, vj_y) = unpack(vj);
            let mut dvx = _mm256_sub_pd(vj_x, vi_x);
            let mut dvy = _mm256_sub_pd(vj_y, vi_y);
            if DEFORMING {
                let ux = _mm256_add_pd(_mm256_mul_pd(g00, dx), _mm256_mul_pd(g01, dy));
                let uy = _mm256_add_pd(_mm256_mul_pd(g10, dx), _mm256_mul_pd(g11, dy));
                dvx = _mm256_add_pd(dvx, ux);
                dvy = _mm256_add_pd(dvy, uy);
            }
            // (the undamped law does not use the normal velocity)
            let spin = _mm256_add_pd(_mm256_mul_pd(lanes(wi), r_i), _mm256_mul_pd(lanes(wj), r_j));
            let vt = _mm256_sub_pd(
                _mm256_add_pd(_mm256_mul_pd(dvx, tx), _mm256_mul_pd(dvy, ty)),
                spin,
            );
            let (kn, ks, mu) = if SINGLE {
                let m = &fixed.single;
                (
                    _mm256_set1_pd(m.normal_stiffness),
                    _mm256_set1_pd(m.shear_stiffness),
                    _mm256_set1_pd(m.friction),
                )
            } else {
                let (mut kn, mut ks, mut mu) = ([0.0; 4], [0.0; 4], [0.0; 4]);
                for l in 0..4 {
                    let m = self.model_of::<SINGLE>(&fixed, &columns, k0 + l);
                    (kn[l], ks[l], mu[l]) = (m.normal_stiffness, m.shear_stiffness, m.friction);
                }
                (lanes(kn), lanes(ks), lanes(mu))
            };
            // the law, lane by lane ([`law_by_four`]); each record is [shear
            // spring, rolling spring] (`law::LANES`): with `ROLLING` the four
            // records unpack into both springs' lanes (stored back one by
            // one, which measured fewer instructions than 128-bit stores),
            // without it the rolling slot, off in every model of the table,
            // is left as it is
            // (with `ROLLING`, `spring_before` is not read: a slip's work
            // takes its spring out of the lanes)
            let spring_before: [f64; 4] =
                std::array::from_fn(|l| records.get_unchecked(k0 + l)[TANGENTIAL_HISTORY.start]);
            let mut spring = lanes(spring_before);
            let mut rolling_before = _mm256_setzero_pd();
            if ROLLING {
                let record = |l: usize| _mm_loadu_pd(records.as_ptr().add(k0 + l) as *const f64);
                (spring, rolling_before) = unpack([record(0), record(1), record(2), record(3)]);
            }
            let slid_before = slid_lanes(sliding.as_ptr().add(k0));
            let rolling = if ROLLING {
                let (mu_r, k_r, eta_r) = if SINGLE {
                    let m = &fixed.single;
                    (
                        _mm256_set1_pd(m.rolling_friction),
                        _mm256_set1_pd(m.rolling_stiffness),
                        _mm256_set1_pd(m.rolling_damping_ratio),
                    )
                } else {
                    let (mut mu_r, mut k_r, mut eta_r) = ([0.0; 4], [0.0; 4], [0.0; 4]);
                    for l in 0..4 {
                        let m = self.model_of::<SINGLE>(&fixed, &columns, k0 + l);
                        (mu_r[l], k_r[l], eta_r[l]) = (
                            m.rolling_friction,
                            m.rolling_stiffness,
                            m.rolling_damping_ratio,
                        );
                    }
                    (lanes(mu_r), lanes(k_r), lanes(eta_r))
                };
                // I + m r^2 of both bodies, combined as `PairKernel::one_pair` does
                let rolling_inertia = if ROLLING_DASHPOT {
                    let mut inertia = [[0.0; 4]; 2];
                    let mut mass = [[0.0; 4]; 2];
                    for l in 0..4 {
                        for (side, &q) in ij[l].iter().enumerate() {
                            inertia[side][l] = *self.inertia.get_unchecked(q);
                            mass[side][l] = *self.mass.get_unchecked(q);
                        }
                    }
                    let about_i = _mm256_add_pd(
                        lanes(inertia[0]),
                        _mm256_mul_pd(_mm256_mul_pd(lanes(mass[0]), r_i), r_i),
                    );
                    let about_j = _mm256_add_pd(
                        lanes(inertia[1]),
                        _mm256_mul_pd(_mm256_mul_pd(lanes(mass[1]), r_j), r_j),
                    );
                    _mm256_div_pd(
                        _mm256_mul_pd(about_i, about_j),
                        _mm256_add_pd(about_i, about_j),
                    )
                } else {
                    _mm256_setzero_pd()
                };
                FourRolling {
                    mu_r,
                    k_r,
                    eta_r,
                    rolling_velocity: _mm256_sub_pd(lanes(wj), lanes(wi)),
                    rolling_inertia,
                    spring: rolling_before,
                }
            } else {
                FourRolling::off()
            };
            let law = law_by_four::<ROLLING, ROLLING_DASHPOT>(
                FourContacts {
                    kn,
                    ks,
                    mu,
                    overlap,
                    tangential_velocity: vt,
                    radius_i: r_i,
                    radius_j: r_j,
                    spring,
                    touching,
                    slid_before,
                },
                rolling,
                increment_time,
                dt,
            );
            let new_spring = law.spring;
            let slides = law.slides;
            let fx = _mm256_add_pd(
                _mm256_mul_pd(law.elastic_normal, nx),
                _mm256_mul_pd(new_spring, tx),
            );
            let fy = _mm256_add_pd(
                _mm256_mul_pd(law.elastic_normal, ny),
                _mm256_mul_pd(new_spring, ty),
            );
            let (torque_i, torque_j) = (law.torque_i, law.torque_j);
            let too_deep = _mm256_and_pd(
                touching,
                _mm256_cmp_pd::<_CMP_GT_OQ>(
                    overlap,
                    _mm256_mul_pd(max_overlap_ratio, _mm256_min_pd(r_i, r_j)),
                ),
            );
            tally.overlap_violation |= _mm256_movemask_pd(too_deep) != 0;
            // the springs and sliding flags back in pair order; a pair out of
            // contact forgets its whole record, as the scalar loop does
            let sliding_bits = pair_order(_mm256_movemask_pd(slides));
            let touching_bits = pair_order(touching_bits as i32);
            // with `ROLLING`, the records [shear, rolling] of pairs 0 and 1,
            // then 2 and 3, from the lanes (the inverse of `unpack`)
            let (overlap, new_spring) = (in_order(overlap), in_order(new_spring));
            let elastic_normal = in_order(law.elastic_normal);
            let rolling_record = if ROLLING {
                in_order(law.rolling_record)
            } else {
                [0.0; 4]
            };
            for (l, &after) in new_spring.iter().enumerate() {
                let k = k0 + l;
                if touching_bits & (1 << l) != 0 {
                    let record = records.get_unchecked_mut(k);
                    record[TANGENTIAL_HISTORY.start] = after;
                    if ROLLING {
                        record[ROLLING_HISTORY.start] = rolling_record[l];
                    }
                    *sliding.get_unchecked_mut(k) = sliding_bits & (1 << l) != 0;
                } else {
                    no_contact(
                        sink,
                        k,
                        records.get_unchecked_mut(k),
                        sliding.get_unchecked_mut(k),
                    );
                }
            }
            let (fx, fy) = (in_order(fx), in_order(fy));
            let (torque_i, torque_j) = (in_order(torque_i), in_order(torque_j));
            let (trial, capped) = (in_order(law.trial), in_order(law.capped));
            let (nx, ny) = (in_order(nx), in_order(ny));
            let [rolling_spring, rolling_moment] = if ROLLING {
                [law.rolling_spring, law.rolling_moment].map(|v| in_order(v))
            } else {
                [[0.0; 4]; 2]
            };
            let rolling_power = if ROLLING_DASHPOT {
                in_order(law.rolling_power)
            } else {
                [0.0; 4]
            };
            let plastic_bits = if ROLLING {
                pair_order(_mm256_movemask_pd(law.rolling_plastic))
            } else {
                0
            };
            // (its division only on a measured step)
            let rolling_energy = if ROLLING && MEASURE {
                in_order(law.rolling_energy)
            } else {
                [0.0; 4]
            };
            // the bookkeeping, one touching pair at a time in pair order
            let mut touched = touching_bits;
            while touched != 0 {
                let l = touched.trailing_zeros() as usize;
                touched &= touched - 1;
                let k = k0 + l;
                let [i, j] = ij[l];
                let model = self.model_of::<SINGLE>(&fixed, &columns, k);
                let slid = sliding_bits & (1 << l) != 0;
                let c = ContactForce {
                    normal: elastic_normal[l],
                    elastic_normal: elastic_normal[l],
                    shear: new_spring[l],
                    shear_spring: new_spring[l],
                    sliding: slid,
                    torque_i: torque_i[l],
                    torque_j: torque_j[l],
                    rolling_spring: rolling_spring[l],
                    rolling_moment: rolling_moment[l],
                    rolling_energy: rolling_energy[l],
                    normal_stiffness: model.normal_stiffness,
                    shear_stiffness: model.shear_stiffness,
                    dissipation: ContactDissipation::default(), // (not read by the record)
                };
                sink.record(k, overlap[l], [nx[l], ny[l]], &c);
                sink.add(k, i, j, [fx[l], fy[l]], torque_i[l], torque_j[l]);
                if slid {
                    // the slip's work (the tangential sub-model's); a sticking
                    // contact adds +0, which leaves the sum (never -0) as it is
                    let before = if ROLLING {
                        in_order(spring)[l]
                    } else {
                        spring_before[l]
                    };
                    tally.dissipation.friction +=
                        ShearSpring::slip_work(model, before, trial[l], capped[l]);
                }
                if MEASURE {
                    let (en, fs) = (elastic_normal[l], new_spring[l]);
                    tally.elastic += elastic_energy(model, en, fs);
                    if ROLLING && rolling_energy[l] != 0.0 {
                        tally.elastic += rolling_energy[l];
                    }
                    tally.force_sum += (en * en + fs * fs).sqrt();
                    tally.contacts += 1;
                }
            }
            // the contacts' rolling dissipation in pair order, as the scalar
            // loop adds it (0 + the plastic work or the dashpot's power; its
            // own sum, so apart from the loop above): the contacts at the cap
            // (a few in a thousand in a dense packing) and, with the dashpot,
            // every touching one; the others add +0, which leaves the sum
            // (never -0) as it is
            let mut booked = if ROLLING_DASHPOT {
                touching_bits
            } else {
                plastic_bits
            };
            while booked != 0 {
                let l = booked.trailing_zeros() as usize;
                booked &= booked - 1;
                if plastic_bits & (1 << l) != 0 {
                    let [k_r, before, trial, capped] = [
                        law.rolling_stiffness,
                        rolling.spring,
                        law.rolling_trial,
                        law.rolling_capped,
                    ]
                    .map(|v| in_order(v)[l]);
                    tally.dissipation.rolling +=
                        0.0 + RollingSpring::plastic_work(k_r, before, trial, capped);
                } else {
                    tally.dissipation.rolling += 0.0 + rolling_power[l];
                }
            }
            k0 += 4;
        }
        self.pairs_one_at_a_time::<MEASURE, DEFORMING, SINGLE, false, false, S>(
            &fixed,
            &columns,
            k0..n,
            records,
            sliding,
            sink,
            &mut tally,
        );
        tally
    }
}

/// Four pairs of a run, in register order, as [`law_by_four`] reads them.
#[derive(Clone, Copy)]
pub(super) struct FourContacts {
    /// Normal and shear stiffness, friction coefficient.
    pub(super) kn: __m256d,
    pub(super) ks: __m256d,
    pub(super) mu: __m256d,
    /// Overlap (m).
    pub(super) overlap: __m256d,
    /// `(v_j - v_i) . t - (omega_i r_i + omega_j r_j)` (m/s).
    pub(super) tangential_velocity: __m256d,
    /// The lever arms.
    pub(super) radius_i: __m256d,
    pub(super) radius_j: __m256d,
    /// The shear springs before the update.
    pub(super) spring: __m256d,
    /// All-ones lanes: the pair touches; the pair slid in its last evaluation.
    pub(super) touching: __m256d,
    pub(super) slid_before: __m256d,
}

/// The rolling part of four pairs, in register order, as [`law_by_four`]
/// reads it when it has the rolling law.
#[derive(Clone, Copy)]
pub(super) struct FourRolling {
    /// Rolling friction `mu_r`, the given rolling stiffness (0: the rule) and
    /// the rolling dashpot's damping ratio.
    pub(super) mu_r: __m256d,
    pub(super) k_r: __m256d,
    pub(super) eta_r: __m256d,
    /// `omega_j - omega_i` (rad/s).
    pub(super) rolling_velocity: __m256d,
    /// The equivalent rotational inertia about the contact (kg m^2; read only
    /// with the rolling dashpot).
    pub(super) rolling_inertia: __m256d,
    /// The rolling springs before the update (N m).
    pub(super) spring: __m256d,
}

impl FourRolling {
    /// No rolling part (for the law without it, which does not read it).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn off() -> FourRolling {
        let zero = _mm256_setzero_pd();
        FourRolling {
            mu_r: zero,
            k_r: zero,
            eta_r: zero,
            rolling_velocity: zero,
            rolling_inertia: zero,
            spring: zero,
        }
    }
}

/// What [`law_by_four`] gives, in register order.
#[derive(Clone, Copy)]
pub(super) struct FourLaws {
    /// `kn * overlap` (N).
    pub(super) elastic_normal: __m256d,
    /// The springs plus the increment, before the cap.
    pub(super) trial: __m256d,
    /// The cap with the trial's sign.
    pub(super) capped: __m256d,
    /// All-ones lanes: the touching pairs whose spring ends at the cap.
    pub(super) slides: __m256d,
    /// The springs after the update (a pair that does not touch: its record
    /// as [`crate::law::history::forget`] leaves it).
    pub(super) spring: __m256d,
    /// Torques on `i` and `j`, `-r Fs`, and with the rolling law `-M_r` and `+M_r`.
    pub(super) torque_i: __m256d,
    pub(super) torque_j: __m256d,
    /// With the rolling law: the rolling slot of the record after the update
    /// (left as it is where `mu_r` is 0; a pair that does not touch: as
    /// [`crate::law::history::forget`] leaves it).
    pub(super) rolling_record: __m256d,
    /// With the rolling law, [`ContactForce`]'s `rolling_spring`,
    /// `rolling_moment` and `rolling_energy` (each 0 where `mu_r` is 0).
    pub(super) rolling_spring: __m256d,
    pub(super) rolling_moment: __m256d,
    pub(super) rolling_energy: __m256d,
    /// With the rolling law: `k_r`, the rolling springs plus the increment
    /// before the cap, the cap with the trial's sign, and all-ones lanes where
    /// the rolling spring ends at the cap (its plastic work is
    /// [`RollingSpring::plastic_work`] of those, the contact's whole rolling
    /// dissipation).
    pub(super) rolling_stiffness: __m256d,
    pub(super) rolling_trial: __m256d,
    pub(super) rolling_capped: __m256d,
    pub(super) rolling_plastic: __m256d,
    /// With the rolling dashpot, its power `c_r w^2 dt` where it acts (below
    /// the cap; +0 elsewhere): the contact's whole rolling dissipation there.
    pub(super) rolling_power: __m256d,
}

/// The contact law of four pairs without normal and shear dashpots: the
/// sub-models' own code, written once over [`crate::law::real::Real`], called
/// with four lanes ([`F64x4`]): the normal spring
/// ([`LinearSpring::force`]), the shear spring's increment and Coulomb cap
/// ([`ShearSpring::advance`]), the torques ([`shear_torques`]); with
/// `ROLLING`, the rolling sub-model ([`RollingSpring::advance`], with
/// `DASHPOT` (some lane may have one) its dashpot compiled in) where the pair
/// touches and its `mu_r` is not 0; and, for a pair that does not touch, the
/// record [`crate::law::history::forget`] leaves. What is left here is the
/// loop's part: which lanes touch, roll or forget. The test below holds each
/// lane to the scalar law's bits on random contacts.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn law_by_four<const ROLLING: bool, const DASHPOT: bool>(
    c: FourContacts,
    rolling: FourRolling,
    increment_time: __m256d,
    dt: __m256d,
) -> FourLaws {
    let x = |v: __m256d| F64x4::from(v);
    let zero = _mm256_setzero_pd();
    let (increment_time, dt) = (x(increment_time), x(dt));
    let elastic_normal = LinearSpring::force(x(c.kn), x(c.overlap));
    let shear = ShearSpring::advance(
        x(c.ks),
        x(c.mu),
        elastic_normal,
        x(c.tangential_velocity),
        increment_time,
        x(c.spring),
    );
    let slides = _mm256_and_pd(c.touching, shear.at_cap.0);
    // a pair out of contact keeps its record if it is all +-0 and it did not
    // slide, else gets +0 (with the rolling law the record is two wide)
    let mut keeps = _mm256_andnot_pd(c.slid_before, _mm256_cmp_pd::<_CMP_EQ_OQ>(c.spring, zero));
    if ROLLING {
        keeps = _mm256_and_pd(keeps, _mm256_cmp_pd::<_CMP_EQ_OQ>(rolling.spring, zero));
    }
    let idle_spring = _mm256_and_pd(keeps, c.spring);
    let spring = _mm256_blendv_pd(idle_spring, shear.spring.0, c.touching);
    // (no normal or shear dashpot:) the torques of the shear force
    let (torque_i, torque_j) = shear_torques(x(c.radius_i), x(c.radius_j), x(spring));
    let mut laws = FourLaws {
        elastic_normal: elastic_normal.0,
        trial: shear.trial.0,
        capped: shear.capped.0,
        slides,
        spring,
        torque_i: torque_i.0,
        torque_j: torque_j.0,
        rolling_record: zero,
        rolling_spring: zero,
        rolling_moment: zero,
        rolling_energy: zero,
        rolling_stiffness: zero,
        rolling_trial: zero,
        rolling_capped: zero,
        rolling_plastic: zero,
        rolling_power: zero,
    };
    if !ROLLING {
        return laws;
    }
    // rolling: on where the pair touches and its model has mu_r != 0 (the
    // scalar law returns at once for mu_r == 0: slot, torques as they are)
    let r = rolling;
    let on = _mm256_andnot_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(r.mu_r, zero), c.touching);
    let r_star = RollingSpring::effective_radius_of(x(c.radius_i), x(c.radius_j));
    let update = RollingSpring::advance::<F64x4, DASHPOT>(
        x(r.mu_r),
        x(r.k_r),
        x(r.eta_r),
        x(c.kn),
        r_star,
        elastic_normal,
        x(r.rolling_velocity),
        x(r.rolling_inertia),
        increment_time,
        dt,
        x(r.spring),
    );
    // (the plastic work, a division, is booked by the loop for the few
    // contacts at the cap, from `rolling_trial` and `rolling_capped`, as the
    // slip's work is)
    let moment = update.moment.0;
    let (rolled_i, rolled_j) = RollingSpring::with_moment(torque_i, torque_j, update.moment);
    laws.torque_i = _mm256_blendv_pd(torque_i.0, rolled_i.0, on);
    laws.torque_j = _mm256_blendv_pd(torque_j.0, rolled_j.0, on);
    let moment_spring = update.spring.spring.0;
    let idle_rolling = _mm256_and_pd(keeps, r.spring);
    let touching_rolling = _mm256_blendv_pd(r.spring, moment_spring, on);
    laws.rolling_record = _mm256_blendv_pd(idle_rolling, touching_rolling, c.touching);
    laws.rolling_spring = _mm256_and_pd(on, moment_spring);
    laws.rolling_moment = _mm256_and_pd(on, moment);
    laws.rolling_energy = _mm256_and_pd(on, update.energy.0);
    laws.rolling_stiffness = update.stiffness.0;
    laws.rolling_trial = update.spring.trial.0;
    laws.rolling_capped = update.spring.capped.0;
    laws.rolling_plastic = _mm256_and_pd(on, update.spring.at_cap.0);
    if DASHPOT {
        laws.rolling_power = _mm256_and_pd(on, update.power.0);
    }
    laws
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::history::forget;
    use crate::law::{
        contact_law, ContactKinematics, HISTORY_WIDTH, ROLLING_HISTORY, TANGENTIAL_HISTORY,
    };
    use crate::material::ContactModel;

    /// A small deterministic generator (xorshift64*), for reproducible random contacts.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        /// Uniform in [0, 1).
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        /// `10^e` times a unit, `e` uniform in `lo..hi`, with a random sign if `signed`.
        fn magnitude(&mut self, lo: f64, hi: f64, signed: bool) -> f64 {
            let v = 10f64.powf(lo + (hi - lo) * self.unit()) * (0.5 + self.unit());
            if signed && self.next() & 1 == 1 {
                -v
            } else {
                v
            }
        }
        /// A spring before the update against its `cap`: at +0, at -0, at the
        /// cap either way, or anywhere within 1.5 times it.
        fn spring(&mut self, cap: f64) -> f64 {
            match self.next() % 6 {
                0 => 0.0,
                1 => -0.0,
                2 => cap,
                3 => -cap,
                _ => (2.0 * self.unit() - 1.0) * 1.5 * cap,
            }
        }
    }

    /// One random contact as the law reads it: its model, kinematics and record
    /// before the update, and whether it slid.
    struct Contact {
        model: ContactModel,
        kinematics: ContactKinematics,
        record: ContactRecord,
        slid: bool,
    }

    /// A random contact without rolling resistance; some springs sit exactly
    /// at the cap, at +0, at -0.
    fn random_contact(rng: &mut Random) -> Contact {
        let mu = match rng.next() % 5 {
            0 => 0.0,
            _ => rng.unit(),
        };
        let model = ContactModel::linear(
            rng.magnitude(4.0, 9.0, false),
            rng.magnitude(4.0, 9.0, false),
            mu,
        );
        let kinematics = ContactKinematics {
            overlap: rng.magnitude(-9.0, -4.0, false),
            normal_velocity: rng.magnitude(-4.0, 1.0, true),
            tangential_velocity: match rng.next() % 6 {
                0 => 0.0,
                _ => rng.magnitude(-6.0, 1.0, true),
            },
            radius_i: rng.magnitude(-4.0, -2.0, false),
            radius_j: rng.magnitude(-4.0, -2.0, false),
            reduced_mass: 0.0,
            rolling_velocity: 0.0,
            rolling_inertia: 0.0,
        };
        let mut record = [0.0; HISTORY_WIDTH];
        record[TANGENTIAL_HISTORY.start] =
            rng.spring(model.friction * model.normal_stiffness * kinematics.overlap);
        Contact {
            model,
            kinematics,
            record,
            slid: rng.next() % 3 == 0,
        }
    }

    /// A random contact with rolling resistance (`mu_r` 0 in a fifth of them,
    /// the stiffness given or from the rule, a rolling dashpot when `dashpot`
    /// and in two thirds of those), its rolling spring at +-0, at the cap
    /// `mu_r R* F_n`, or within 1.5 times it.
    fn random_rolling_contact(rng: &mut Random, dashpot: bool) -> Contact {
        let mut c = random_contact(rng);
        let m = &mut c.model;
        m.rolling_friction = match rng.next() % 5 {
            0 => 0.0,
            _ => 0.5 * rng.unit(),
        };
        m.rolling_stiffness = match rng.next() % 2 {
            0 => 0.0,
            _ => rng.magnitude(-4.0, 2.0, false),
        };
        m.rolling_damping_ratio = if dashpot && rng.next() % 3 != 0 {
            rng.unit()
        } else {
            0.0
        };
        let k = &mut c.kinematics;
        k.rolling_velocity = match rng.next() % 6 {
            0 => 0.0,
            _ => rng.magnitude(-3.0, 3.0, true),
        };
        k.rolling_inertia = rng.magnitude(-12.0, -6.0, false);
        let r_star = k.radius_i * k.radius_j / (k.radius_i + k.radius_j);
        let cap = m.rolling_friction * r_star * m.normal_stiffness * k.overlap;
        c.record[ROLLING_HISTORY.start] = rng.spring(cap);
        c
    }

    /// What a round of four contacts gave in the lanes, in pair order.
    struct Lanes {
        slides: u32,
        spring: [f64; 4],
        normal: [f64; 4],
        torque_i: [f64; 4],
        torque_j: [f64; 4],
        trial: [f64; 4],
        capped: [f64; 4],
        /// The rolling slot, spring, moment, energy, and the dissipation as
        /// the loop books it.
        rolling: [[f64; 4]; 5],
    }

    /// `law_by_four::<ROLLING, DASHPOT>` on four contacts.
    fn by_four<const ROLLING: bool, const DASHPOT: bool>(
        contacts: &[Contact],
        touching: [bool; 4],
        increment_time: f64,
        dt: f64,
    ) -> Lanes {
        let pick = |f: &dyn Fn(&Contact) -> f64| {
            let v: [f64; 4] = std::array::from_fn(|l| f(&contacts[l]));
            // SAFETY: the callers checked AVX2
            unsafe { lanes(v) }
        };
        let mask = |m: [bool; 4]| {
            let v: [f64; 4] = m.map(|b| if b { f64::from_bits(u64::MAX) } else { 0.0 });
            unsafe { lanes(v) }
        };
        let four = FourContacts {
            kn: pick(&|c| c.model.normal_stiffness),
            ks: pick(&|c| c.model.shear_stiffness),
            mu: pick(&|c| c.model.friction),
            overlap: pick(&|c| c.kinematics.overlap),
            tangential_velocity: pick(&|c| c.kinematics.tangential_velocity),
            radius_i: pick(&|c| c.kinematics.radius_i),
            radius_j: pick(&|c| c.kinematics.radius_j),
            spring: pick(&|c| c.record[TANGENTIAL_HISTORY.start]),
            touching: mask(touching),
            slid_before: mask(std::array::from_fn(|l| contacts[l].slid)),
        };
        let rolling = FourRolling {
            mu_r: pick(&|c| c.model.rolling_friction),
            k_r: pick(&|c| c.model.rolling_stiffness),
            eta_r: pick(&|c| c.model.rolling_damping_ratio),
            rolling_velocity: pick(&|c| c.kinematics.rolling_velocity),
            rolling_inertia: pick(&|c| c.kinematics.rolling_inertia),
            spring: pick(&|c| c.record[ROLLING_HISTORY.start]),
        };
        // SAFETY: the callers checked AVX2
        unsafe {
            let law = law_by_four::<ROLLING, DASHPOT>(
                four,
                rolling,
                _mm256_set1_pd(increment_time),
                _mm256_set1_pd(dt),
            );
            Lanes {
                slides: pair_order(_mm256_movemask_pd(law.slides)),
                spring: in_order(law.spring),
                normal: in_order(law.elastic_normal),
                torque_i: in_order(law.torque_i),
                torque_j: in_order(law.torque_j),
                trial: in_order(law.trial),
                capped: in_order(law.capped),
                rolling: {
                    let [record, spring, moment, energy, k_r, before, trial, capped, power] = [
                        law.rolling_record,
                        law.rolling_spring,
                        law.rolling_moment,
                        law.rolling_energy,
                        law.rolling_stiffness,
                        rolling.spring,
                        law.rolling_trial,
                        law.rolling_capped,
                        law.rolling_power,
                    ]
                    .map(|v| in_order(v));
                    let plastic = pair_order(_mm256_movemask_pd(law.rolling_plastic));
                    // the contact's rolling dissipation as the loop books it
                    let dissipation = std::array::from_fn(|l| {
                        if plastic & (1 << l) != 0 {
                            0.0 + RollingSpring::plastic_work(
                                k_r[l], before[l], trial[l], capped[l],
                            )
                        } else if DASHPOT {
                            0.0 + power[l]
                        } else {
                            0.0
                        }
                    });
                    [record, spring, moment, energy, dissipation]
                },
            }
        }
    }

    /// How often each branch of the law was seen.
    #[derive(Default, Debug)]
    struct Seen {
        sliding: usize,
        sticking: usize,
        apart: usize,
        rolling_plastic: usize,
        rolling_elastic: usize,
        rolling_damped: usize,
        rolling_off: usize,
    }

    /// Compares lane by lane `law_by_four::<ROLLING>` with the scalar law on
    /// `rounds` rounds of four contacts from `draw`, bit for bit: the forces,
    /// torques, the whole record after the update (a pair apart: as `forget`
    /// leaves it), the sliding flag, the slip's work as the loop books it and,
    /// with `ROLLING`, the rolling law's every output.
    fn compare<const ROLLING: bool>(
        seed: u64,
        rounds: usize,
        draw: &dyn Fn(&mut Random, bool) -> Contact,
    ) -> Seen {
        let mut rng = Random(seed);
        let dt = 1.0e-6;
        let mut seen = Seen::default();
        for round in 0..rounds {
            let increment_time = if round % 4 == 0 { 0.0 } else { dt };
            // every other four rounds with rolling dashpots, the rest without
            // (and then the lanes' dashpot path is not taken); with and without
            // an increment both ways (a spring at its cap and no increment: the
            // cap's `>=`, which leaves the dashpot off, decides)
            let dashpot = (round / 4) % 2 == 1;
            let contacts: Vec<Contact> = (0..4).map(|_| draw(&mut rng, dashpot)).collect();
            let touching: [bool; 4] = std::array::from_fn(|_| rng.next() % 8 != 0);
            let out = if dashpot {
                by_four::<ROLLING, true>(&contacts, touching, increment_time, dt)
            } else {
                by_four::<ROLLING, false>(&contacts, touching, increment_time, dt)
            };
            for (l, c) in contacts.iter().enumerate() {
                let mut record = c.record;
                let mut flag = c.slid;
                let what = format!(
                    "round {round}, lane {l}: {:?} {:?} {:?} {}",
                    c.model, c.kinematics, c.record, c.slid
                );
                if !touching[l] {
                    forget(&mut record, &mut flag);
                    assert_eq!(
                        out.spring[l].to_bits(),
                        record[TANGENTIAL_HISTORY.start].to_bits(),
                        "apart: {what}"
                    );
                    if ROLLING {
                        assert_eq!(
                            out.rolling[0][l].to_bits(),
                            record[ROLLING_HISTORY.start].to_bits(),
                            "apart: {what}"
                        );
                    }
                    assert_eq!(out.slides & (1 << l), 0);
                    seen.apart += 1;
                    continue;
                }
                let f =
                    contact_law::<false>(&c.model, &c.kinematics, dt, increment_time, &mut record);
                let lane_sliding = out.slides & (1 << l) != 0;
                assert_eq!(lane_sliding, f.sliding, "{what}");
                let bits = |v: f64| v.to_bits();
                assert_eq!(
                    bits(out.spring[l]),
                    bits(record[TANGENTIAL_HISTORY.start]),
                    "{what}"
                );
                assert_eq!(bits(out.spring[l]), bits(f.shear), "{what}");
                assert_eq!(bits(out.normal[l]), bits(f.normal), "{what}");
                assert_eq!(bits(out.torque_i[l]), bits(f.torque_i), "{what}");
                assert_eq!(bits(out.torque_j[l]), bits(f.torque_j), "{what}");
                // the slip's work as the loop books it, into a sum that starts at +0
                let work = if lane_sliding {
                    ShearSpring::slip_work(
                        &c.model,
                        c.record[TANGENTIAL_HISTORY.start],
                        out.trial[l],
                        out.capped[l],
                    )
                } else {
                    0.0
                };
                assert_eq!(
                    bits(0.0 + work),
                    bits(0.0 + f.dissipation.friction),
                    "{what}"
                );
                if f.sliding {
                    seen.sliding += 1;
                } else {
                    seen.sticking += 1;
                }
                if !ROLLING {
                    continue;
                }
                let [slot, spring, moment, energy, dissipated] = out.rolling.map(|v| v[l]);
                assert_eq!(bits(slot), bits(record[ROLLING_HISTORY.start]), "{what}");
                assert_eq!(bits(spring), bits(f.rolling_spring), "{what}");
                assert_eq!(bits(moment), bits(f.rolling_moment), "{what}");
                assert_eq!(bits(energy), bits(f.rolling_energy), "{what}");
                assert_eq!(bits(dissipated), bits(f.dissipation.rolling), "{what}");
                let m = &c.model;
                let r_star = RollingSpring::effective_radius(&c.kinematics);
                if m.rolling_friction == 0.0 {
                    seen.rolling_off += 1;
                } else if f.rolling_spring.abs() == m.rolling_friction * r_star * f.elastic_normal {
                    seen.rolling_plastic += 1;
                } else {
                    seen.rolling_elastic += 1;
                    if f.rolling_moment != f.rolling_spring {
                        seen.rolling_damped += 1;
                    }
                }
            }
        }
        seen
    }

    #[test]
    fn four_lanes_give_the_contact_laws_bits_on_random_contacts() {
        if !crate::simd::available() {
            eprintln!("no AVX2 on this processor: the four-pair loop never runs");
            return;
        }
        let seen = compare::<false>(0x9e37_79b9_7f4a_7c15, 20_000, &|rng, _| random_contact(rng));
        // the random contacts cover every branch of the law
        assert!(
            seen.sliding > 10_000 && seen.sticking > 10_000 && seen.apart > 5_000,
            "{seen:?}"
        );
    }

    /// The lanes with the rolling law (`ROLLING`) against the scalar law with
    /// rolling resistance: models with and without it side by side, the
    /// stiffness given and from the rule, the rolling spring at its cap and
    /// below it, with and without a rolling dashpot.
    #[test]
    fn four_lanes_with_the_rolling_law_give_the_contact_laws_bits_on_random_contacts() {
        if !crate::simd::available() {
            eprintln!("no AVX2 on this processor: the four-pair loop never runs");
            return;
        }
        let seen = compare::<true>(0x2545_f491_4f6c_dd1d, 20_000, &random_rolling_contact);
        assert!(
            seen.sliding > 10_000 && seen.sticking > 10_000 && seen.apart > 5_000,
            "{seen:?}"
        );
        assert!(
            seen.rolling_plastic > 10_000
                && seen.rolling_elastic > 10_000
                && seen.rolling_damped > 5_000
                && seen.rolling_off > 5_000,
            "{seen:?}"
        );
    }
}
