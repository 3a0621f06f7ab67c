//! The undamped pair loop four pairs at a time, in the 256-bit registers of
//! AVX2, with the same bits as the scalar loop of `pair_kernel.rs`.
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
use crate::law::{elastic_energy, ContactForce};
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
        shear: &mut [f64],
        sliding: &mut [bool],
        sink: &mut S,
    ) -> ContactTally {
        let mut tally = ContactTally::default();
        let fixed = self.loop_constants();
        let columns = self.columns(first, shear.len().min(sliding.len()));
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
        let zero = _mm256_setzero_pd();
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
                        shear.get_unchecked_mut(k),
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
            // the law (`law::shear_spring_update`, `linear_coulomb_with::<false>`)
            let elastic_normal = _mm256_mul_pd(kn, overlap);
            let spring_ptr = shear.as_mut_ptr().add(k0);
            let spring = _mm256_permute4x64_pd::<SWAP_MIDDLE>(_mm256_loadu_pd(spring_ptr));
            let trial = _mm256_sub_pd(spring, _mm256_mul_pd(_mm256_mul_pd(ks, vt), increment_time));
            let cap = _mm256_mul_pd(mu, elastic_normal);
            let slides = _mm256_and_pd(
                touching,
                _mm256_cmp_pd::<_CMP_GE_OQ>(_mm256_andnot_pd(sign_bit, trial), cap),
            );
            // cap.copysign(trial)
            let capped = _mm256_or_pd(
                _mm256_andnot_pd(sign_bit, cap),
                _mm256_and_pd(sign_bit, trial),
            );
            let law_spring = _mm256_blendv_pd(trial, capped, slides);
            // a pair out of contact keeps a spring of +-0 unless it slid, else gets +0
            let slid_before = slid_lanes(sliding.as_ptr().add(k0));
            let keeps = _mm256_andnot_pd(slid_before, _mm256_cmp_pd::<_CMP_EQ_OQ>(spring, zero));
            let idle_spring = _mm256_and_pd(keeps, spring);
            let new_spring = _mm256_blendv_pd(idle_spring, law_spring, touching);
            let fx = _mm256_add_pd(
                _mm256_mul_pd(elastic_normal, nx),
                _mm256_mul_pd(new_spring, tx),
            );
            let fy = _mm256_add_pd(
                _mm256_mul_pd(elastic_normal, ny),
                _mm256_mul_pd(new_spring, ty),
            );
            let torque_i = _mm256_mul_pd(_mm256_xor_pd(r_i, sign_bit), new_spring);
            let torque_j = _mm256_mul_pd(_mm256_xor_pd(r_j, sign_bit), new_spring);
            let too_deep = _mm256_and_pd(
                touching,
                _mm256_cmp_pd::<_CMP_GT_OQ>(
                    overlap,
                    _mm256_mul_pd(max_overlap_ratio, _mm256_min_pd(r_i, r_j)),
                ),
            );
            tally.overlap_violation |= _mm256_movemask_pd(too_deep) != 0;
            // the springs and sliding flags back in pair order
            let spring_before = spill(_mm256_loadu_pd(spring_ptr));
            _mm256_storeu_pd(spring_ptr, _mm256_permute4x64_pd::<SWAP_MIDDLE>(new_spring));
            let sliding_bits = pair_order(_mm256_movemask_pd(slides));
            for l in 0..4 {
                *sliding.get_unchecked_mut(k0 + l) = sliding_bits & (1 << l) != 0;
            }
            let touching_bits = pair_order(touching_bits as i32);
            let mut idle = !touching_bits & 0b1111;
            while idle != 0 {
                let l = idle.trailing_zeros() as usize;
                idle &= idle - 1;
                sink.skip(k0 + l);
            }
            let (fx, fy) = (in_order(fx), in_order(fy));
            let (torque_i, torque_j) = (in_order(torque_i), in_order(torque_j));
            let (overlap, new_spring) = (in_order(overlap), in_order(new_spring));
            let (trial, capped) = (in_order(trial), in_order(capped));
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
                    sliding: slid,
                    friction_dissipation: 0.0, // (not read by the record)
                    viscous_dissipation: 0.0,
                };
                sink.record(k, overlap[l], [nx[l], ny[l]], &c, new_spring[l]);
                sink.add(k, i, j, [fx[l], fy[l]], torque_i[l], torque_j[l]);
                if slid {
                    // the slip's work (`law::shear_spring_update`); a sticking
                    // contact adds +0, which leaves the sum (never -0) as it is
                    tally.friction += 0.5 * (spring_before[l] + capped[l]) * (trial[l] - capped[l])
                        / model.shear_stiffness;
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
            shear,
            sliding,
            sink,
            &mut tally,
        );
        tally
    }
}
