//! The undamped pair loop four pairs at a time, in the 256-bit registers of
//! AVX2, with the same bits as the scalar loop of `pair_kernel.rs`.
//!
//! The law of four pairs is [`law_by_four`]: the sub-models of
//! [`crate::law::contact_law`] without dashpots (normal spring, shear spring
//! with its cap, no rolling), lane by lane; its test gives both the same
//! random contacts and requires the same bits. The loop runs only while every
//! sub-model of the law has lanes ([`crate::law::LANES`]).
//!
//! Why the bits are the same: every pair's law is computed lane by lane with
//! the operations of the scalar code in its order (IEEE additions,
//! multiplications, one division and one square root per pair, all correctly
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
use crate::law::tangential::ShearSpring;
use crate::law::{elastic_energy, ContactForce, ContactRecord, TANGENTIAL_HISTORY};
use crate::simd::spill;

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
    /// [`PairKernel::pairs`] without dashpots, four pairs at a time and the
    /// rest one at a time.
    ///
    /// # Safety
    /// As [`PairKernel::run`]; the processor has AVX2 ([`crate::simd::available`]).
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn pairs_by_four<
        const MEASURE: bool,
        const DEFORMING: bool,
        const SINGLE: bool,
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
            // the law, lane by lane ([`law_by_four`]); each record starts with
            // the shear spring (`law::LANES`); the rolling slot, off in every
            // model of a table the lanes run for, is left as it is
            let spring_before: [f64; 4] =
                std::array::from_fn(|l| records.get_unchecked(k0 + l)[TANGENTIAL_HISTORY.start]);
            let spring = lanes(spring_before);
            let slid_before = slid_lanes(sliding.as_ptr().add(k0));
            let law = law_by_four(
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
                increment_time,
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
            let (overlap, new_spring) = (in_order(overlap), in_order(new_spring));
            for (l, &after) in new_spring.iter().enumerate() {
                let k = k0 + l;
                if touching_bits & (1 << l) != 0 {
                    records.get_unchecked_mut(k)[TANGENTIAL_HISTORY.start] = after;
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
            // the bookkeeping, one touching pair at a time in pair order
            let mut touched = touching_bits;
            while touched != 0 {
                let l = touched.trailing_zeros() as usize;
                touched &= touched - 1;
                let k = k0 + l;
                let [i, j] = ij[l];
                let model = self.model_of::<SINGLE>(&fixed, &columns, k);
                let slid = sliding_bits & (1 << l) != 0;
                let elastic_normal = model.normal_stiffness * overlap[l];
                let c = ContactForce {
                    normal: elastic_normal,
                    elastic_normal,
                    shear: new_spring[l],
                    shear_spring: new_spring[l],
                    sliding: slid,
                    torque_i: torque_i[l],
                    torque_j: torque_j[l],
                    rolling_spring: 0.0,
                    rolling_moment: 0.0,
                    rolling_energy: 0.0,
                    dissipation: ContactDissipation::default(), // (not read by the record)
                };
                sink.record(k, overlap[l], [nx[l], ny[l]], &c);
                sink.add(k, i, j, [fx[l], fy[l]], torque_i[l], torque_j[l]);
                if slid {
                    // the slip's work (the tangential sub-model's); a sticking
                    // contact adds +0, which leaves the sum (never -0) as it is
                    tally.dissipation.friction +=
                        ShearSpring::slip_work(model, spring_before[l], trial[l], capped[l]);
                }
                if MEASURE {
                    let (en, fs) = (elastic_normal, new_spring[l]);
                    tally.elastic += elastic_energy(model, en, fs);
                    tally.force_sum += (en * en + fs * fs).sqrt();
                    tally.contacts += 1;
                }
            }
            k0 += 4;
        }
        self.pairs_one_at_a_time::<MEASURE, DEFORMING, SINGLE, false, S>(
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
    /// Torques on `i` and `j`, `-r Fs`.
    pub(super) torque_i: __m256d,
    pub(super) torque_j: __m256d,
}

/// The undamped contact law of four pairs, lane by lane with the scalar
/// operations of [`crate::law::contact_law`] in their order: the normal
/// spring, the shear spring's increment and Coulomb cap (branches as selects
/// of the value the branch keeps), the torques; and, for a pair that does not
/// touch, the record [`crate::law::history::forget`] leaves. Every operation is
/// a correctly rounded IEEE one (no fused multiply-add), so each lane has the
/// scalar law's bits (the test below checks it on random contacts).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn law_by_four(c: FourContacts, increment_time: __m256d) -> FourLaws {
    let sign_bit = _mm256_set1_pd(-0.0);
    let zero = _mm256_setzero_pd();
    // normal: the linear spring
    let elastic_normal = _mm256_mul_pd(c.kn, c.overlap);
    // tangential: the shear spring's increment, then its cap
    let trial = _mm256_sub_pd(
        c.spring,
        _mm256_mul_pd(_mm256_mul_pd(c.ks, c.tangential_velocity), increment_time),
    );
    let cap = _mm256_mul_pd(c.mu, elastic_normal);
    let slides = _mm256_and_pd(
        c.touching,
        _mm256_cmp_pd::<_CMP_GE_OQ>(_mm256_andnot_pd(sign_bit, trial), cap),
    );
    // cap.copysign(trial)
    let capped = _mm256_or_pd(
        _mm256_andnot_pd(sign_bit, cap),
        _mm256_and_pd(sign_bit, trial),
    );
    let law_spring = _mm256_blendv_pd(trial, capped, slides);
    // a pair out of contact keeps a spring of +-0 unless it slid, else gets +0
    let keeps = _mm256_andnot_pd(c.slid_before, _mm256_cmp_pd::<_CMP_EQ_OQ>(c.spring, zero));
    let idle_spring = _mm256_and_pd(keeps, c.spring);
    let spring = _mm256_blendv_pd(idle_spring, law_spring, c.touching);
    // (no dashpot, no rolling resistance:) the torques of the shear force
    let torque_i = _mm256_mul_pd(_mm256_xor_pd(c.radius_i, sign_bit), spring);
    let torque_j = _mm256_mul_pd(_mm256_xor_pd(c.radius_j, sign_bit), spring);
    FourLaws {
        elastic_normal,
        trial,
        capped,
        slides,
        spring,
        torque_i,
        torque_j,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::law::history::forget;
    use crate::law::{contact_law, ContactKinematics, HISTORY_WIDTH, TANGENTIAL_HISTORY};
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
    }

    /// One random contact: a model, its kinematics, the spring before and
    /// whether it slid; some springs sit exactly at the cap, at +0, at -0.
    fn random_contact(rng: &mut Random) -> (ContactModel, ContactKinematics, f64, bool) {
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
        let cap = model.friction * model.normal_stiffness * kinematics.overlap;
        let spring = match rng.next() % 6 {
            0 => 0.0,
            1 => -0.0,
            2 => cap,
            3 => -cap,
            _ => (2.0 * rng.unit() - 1.0) * 1.5 * cap,
        };
        (model, kinematics, spring, rng.next() % 3 == 0)
    }

    #[test]
    fn four_lanes_give_the_contact_laws_bits_on_random_contacts() {
        if !crate::simd::available() {
            eprintln!("no AVX2 on this processor: the four-pair loop never runs");
            return;
        }
        let mut rng = Random(0x9e37_79b9_7f4a_7c15);
        let dt = 1.0e-6;
        let (mut sliding_seen, mut sticking_seen, mut apart_seen) = (0, 0, 0);
        // (a width-1 forget, as `law_by_four` keeps it for a pair apart: the
        // loop forgets the whole record with the scalar `forget`)
        for round in 0..20_000 {
            let increment_time = if round % 4 == 0 { 0.0 } else { dt };
            let contacts: Vec<_> = (0..4).map(|_| random_contact(&mut rng)).collect();
            let touching: [bool; 4] = std::array::from_fn(|_| rng.next() % 8 != 0);
            let pick = |f: &dyn Fn(&(ContactModel, ContactKinematics, f64, bool)) -> f64| {
                let v: [f64; 4] = std::array::from_fn(|l| f(&contacts[l]));
                // SAFETY: AVX2 checked above
                unsafe { lanes(v) }
            };
            let mask = |m: [bool; 4]| {
                let v: [f64; 4] = m.map(|b| if b { f64::from_bits(u64::MAX) } else { 0.0 });
                unsafe { lanes(v) }
            };
            let four = FourContacts {
                kn: pick(&|c| c.0.normal_stiffness),
                ks: pick(&|c| c.0.shear_stiffness),
                mu: pick(&|c| c.0.friction),
                overlap: pick(&|c| c.1.overlap),
                tangential_velocity: pick(&|c| c.1.tangential_velocity),
                radius_i: pick(&|c| c.1.radius_i),
                radius_j: pick(&|c| c.1.radius_j),
                spring: pick(&|c| c.2),
                touching: mask(touching),
                slid_before: mask(std::array::from_fn(|l| contacts[l].3)),
            };
            // SAFETY: AVX2 checked above
            let law = unsafe { law_by_four(four, _mm256_set1_pd(increment_time)) };
            let slides = pair_order(unsafe { _mm256_movemask_pd(law.slides) });
            let out = |v: __m256d| unsafe { in_order(v) };
            let (spring, torque_i, torque_j) =
                (out(law.spring), out(law.torque_i), out(law.torque_j));
            let (normal, trial, capped) =
                (out(law.elastic_normal), out(law.trial), out(law.capped));
            for (l, (model, kinematics, before, slid)) in contacts.iter().enumerate() {
                let mut record = [0.0; HISTORY_WIDTH];
                record[TANGENTIAL_HISTORY.start] = *before;
                let mut flag = *slid;
                if !touching[l] {
                    forget(&mut record, &mut flag);
                    assert_eq!(spring[l].to_bits(), record[0].to_bits(), "apart, lane {l}");
                    assert_eq!(slides & (1 << l), 0);
                    apart_seen += 1;
                    continue;
                }
                let c = contact_law::<false>(model, kinematics, dt, increment_time, &mut record);
                let lane_sliding = slides & (1 << l) != 0;
                let what = format!("round {round}, lane {l}: {model:?} {kinematics:?} {before}");
                assert_eq!(lane_sliding, c.sliding, "{what}");
                assert_eq!(spring[l].to_bits(), record[0].to_bits(), "{what}");
                assert_eq!(spring[l].to_bits(), c.shear.to_bits(), "{what}");
                assert_eq!(normal[l].to_bits(), c.normal.to_bits(), "{what}");
                assert_eq!(torque_i[l].to_bits(), c.torque_i.to_bits(), "{what}");
                assert_eq!(torque_j[l].to_bits(), c.torque_j.to_bits(), "{what}");
                // the slip's work as the loop books it, into a sum that starts at +0
                let work = if lane_sliding {
                    ShearSpring::slip_work(model, *before, trial[l], capped[l])
                } else {
                    0.0
                };
                assert_eq!(
                    (0.0 + work).to_bits(),
                    (0.0 + c.dissipation.friction).to_bits()
                );
                if c.sliding {
                    sliding_seen += 1;
                } else {
                    sticking_seen += 1;
                }
            }
        }
        // the random contacts cover every branch of the law
        assert!(sliding_seen > 10_000 && sticking_seen > 10_000 && apart_seen > 5_000);
    }
}
