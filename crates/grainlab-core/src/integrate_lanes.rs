//! The integration two free particles at a time, their `[x, y]` vectors side
//! by side in one 256-bit AVX2 register, with the same bits as one at a time
//! ([`StripeKernel::one_particle`]).
//!
//! Why the bits are the same: the kick, the drift and the affine map are done
//! lane by lane with the scalar code's IEEE operations in its order (sums of
//! two products are commutative, so `m10 x + m11 y` may be formed as
//! `m11 y + m10 x`), local damping's sign from the same two masked constants;
//! the energy sums are booked afterwards one particle at a time in particle
//! order ([`StripeKernel::book`]); the running maxima are of non-negative
//! values that ignore NaN, so their order does not matter. A particle with a
//! fixed degree of freedom, and the last of an odd stripe, go one at a time.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use crate::integrate::{kick, running_max, StripeKernel, StripeSums};
use crate::simd::spill;

/// The two particles' `[a, b]` as `[a, b, a, b]`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn twice(v: [f64; 2]) -> __m256d {
    _mm256_set_pd(v[1], v[0], v[1], v[0])
}

/// `[m0, m0, m1, m1]`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn per_particle(m: &[f64], k: usize) -> __m256d {
    _mm256_set_pd(m[k + 1], m[k + 1], m[k], m[k])
}

/// `shift + map x` for two points `x` (`[x0, y0, x1, y1]`), as `vec2::mat_vec`
/// and `vec2::add` form it.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn affine(map: &[[f64; 2]; 2], shift: [f64; 2], x: __m256d) -> __m256d {
    let diagonal = _mm256_set_pd(map[1][1], map[0][0], map[1][1], map[0][0]);
    let off_diagonal = _mm256_set_pd(map[1][0], map[0][1], map[1][0], map[0][1]);
    let swapped = _mm256_permute_pd::<0b0101>(x);
    let product = _mm256_add_pd(
        _mm256_mul_pd(diagonal, x),
        _mm256_mul_pd(off_diagonal, swapped),
    );
    _mm256_add_pd(twice(shift), product)
}

/// Each point's squared length, `[d0, d0, d1, d1]`.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn squared_lengths(d: __m256d) -> __m256d {
    let squares = _mm256_mul_pd(d, d);
    _mm256_hadd_pd(squares, squares)
}

impl StripeKernel<'_> {
    /// The stripe two particles at a time where both are free, else one at a time.
    ///
    /// # Safety
    /// The processor has AVX2.
    #[target_feature(enable = "avx2")]
    pub(crate) unsafe fn particles_by_two<
        const MEASURE: bool,
        const DAMPED: bool,
        const DEFORMING: bool,
    >(
        &mut self,
        sums: &mut StripeSums,
    ) {
        let step = self.step;
        let n = self.position.len();
        let dt = _mm256_set1_pd(step.dt);
        let kick_length = _mm256_set1_pd(step.kick);
        let minus_alpha = _mm256_set1_pd(-step.alpha);
        let sign_bit = _mm256_set1_pd(-0.0);
        let (one, minus_one) = (_mm256_set1_pd(1.0), _mm256_set1_pd(-1.0));
        let zero = _mm256_setzero_pd();
        let infinity = _mm256_set1_pd(f64::INFINITY);
        let needs_book =
            DAMPED || MEASURE || step.has_external || self.inputs.boundary_load.is_some();
        let mut max_fluctuation = zero;
        let mut max_displacement = zero;
        let mut k = 0;
        while k + 2 <= n {
            if self.fixity[k] | self.fixity[k + 1] != 0 {
                self.one_particle::<MEASURE, DAMPED, DEFORMING>(k, sums);
                self.one_particle::<MEASURE, DAMPED, DEFORMING>(k + 1, sums);
                k += 2;
                continue;
            }
            let f = _mm256_loadu_pd(self.force.as_ptr().add(k) as *const f64);
            let v_old = _mm256_loadu_pd(self.velocity.as_ptr().add(k) as *const f64);
            // local damping -alpha |F| sign(v), as `kick` forms it
            let fd = if DAMPED {
                let positive = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(v_old, zero), one);
                let negative = _mm256_and_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(v_old, zero), minus_one);
                let sign = _mm256_add_pd(positive, negative);
                _mm256_mul_pd(
                    _mm256_mul_pd(minus_alpha, _mm256_andnot_pd(sign_bit, f)),
                    sign,
                )
            } else {
                zero
            };
            let dv = _mm256_mul_pd(
                _mm256_mul_pd(kick_length, _mm256_add_pd(f, fd)),
                per_particle(self.inv_mass, k),
            );
            let v = _mm256_add_pd(v_old, dv);
            let mut w = [0.0; 2];
            let mut fd_w = [0.0; 2];
            for l in 0..2 {
                let q = k + l;
                (w[l], fd_w[l]) = kick::<DAMPED>(
                    self.angular_velocity[q],
                    self.torque[q],
                    self.inv_inertia[q],
                    step.alpha,
                    step.kick,
                );
            }
            if needs_book {
                let (v_old, v, fd) = (spill(v_old), spill(v), spill(fd));
                for l in 0..2 {
                    let q = k + l;
                    let c = 2 * l;
                    self.book::<MEASURE, DAMPED>(
                        q,
                        [[v_old[c], v_old[c + 1]], [v[c], v[c + 1]]],
                        [self.angular_velocity[q], w[l]],
                        [fd[c], fd[c + 1], fd_w[l]],
                        sums,
                    );
                }
            }
            let position = self.position.as_mut_ptr().add(k) as *mut f64;
            let mut x = _mm256_add_pd(_mm256_loadu_pd(position), _mm256_mul_pd(dt, v));
            let r = _mm256_loadu_pd(self.reference.as_ptr().add(k) as *const f64);
            if DEFORMING {
                x = affine(&self.map, self.map_shift, x);
                let u = _mm256_sub_pd(x, affine(&self.acc, self.acc_shift, r));
                // (value, max): a NaN value leaves the maximum
                max_fluctuation = _mm256_max_pd(squared_lengths(u), max_fluctuation);
            }
            max_displacement =
                _mm256_max_pd(squared_lengths(_mm256_sub_pd(x, r)), max_displacement);
            let finite = _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign_bit, x), infinity);
            sums.non_finite |=
                (_mm256_movemask_pd(finite) != 0b1111) | !(w[0].is_finite() & w[1].is_finite());
            _mm256_storeu_pd(position, x);
            _mm256_storeu_pd(self.velocity.as_mut_ptr().add(k) as *mut f64, v);
            self.angular_velocity[k..k + 2].copy_from_slice(&w);
            for (rotation, w) in self.rotation[k..k + 2].iter_mut().zip(w) {
                *rotation += step.dt * w;
            }
            k += 2;
        }
        if k < n {
            self.one_particle::<MEASURE, DAMPED, DEFORMING>(k, sums);
        }
        for m in spill(max_fluctuation) {
            sums.max_fluctuation_sq = running_max(sums.max_fluctuation_sq, m);
        }
        for m in spill(max_displacement) {
            sums.max_displacement_sq = running_max(sums.max_displacement_sq, m);
        }
    }
}
