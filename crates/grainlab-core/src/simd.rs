//! What the engine's AVX2 kernels share (`pipeline/pair_lanes.rs`,
//! `integrate_lanes.rs`): whether the processor has AVX2, and a register's
//! lanes as an array.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

/// Whether this processor runs the AVX2 kernels (the check is cached by std).
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}

/// A register's four lanes, in register order.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn spill(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    _mm256_storeu_pd(out.as_mut_ptr(), v);
    out
}

/// Four `f64` side by side in one AVX2 register: the lanes type of the
/// contact laws ([`crate::law::real::Real`]), its comparisons' masks
/// all-ones or all-zero lanes of the same type.
///
/// A value exists only on a processor with AVX2: the only ways to make one,
/// [`F64x4::from`] and the operations on existing ones, run inside the AVX2
/// kernels. Its operations are `#[inline(always)]` so that they are compiled
/// into those kernels with their target features.
#[derive(Clone, Copy)]
pub(crate) struct F64x4(pub(crate) __m256d);

impl F64x4 {
    /// The register `v` as lanes.
    ///
    /// # Safety
    /// The processor has AVX2 ([`available`]).
    #[inline(always)]
    pub(crate) unsafe fn from(v: __m256d) -> F64x4 {
        F64x4(v)
    }
}

/// One binary operator of [`F64x4`] from its AVX intrinsic.
macro_rules! lanes_operator {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl std::ops::$trait for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $method(self, other: F64x4) -> F64x4 {
                // SAFETY: an F64x4 exists only on a processor with AVX2
                F64x4(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    };
}

lanes_operator!(Add, add, _mm256_add_pd);
lanes_operator!(Sub, sub, _mm256_sub_pd);
lanes_operator!(Mul, mul, _mm256_mul_pd);
lanes_operator!(Div, div, _mm256_div_pd);

impl std::ops::Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        // SAFETY: as the operators above; the sign bit flipped, as f64's negation
        F64x4(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl crate::law::real::Real for F64x4 {
    type Mask = F64x4;

    // SAFETY (every method): an F64x4 exists only on a processor with AVX2,
    // and `splat` is called only where one does

    #[inline(always)]
    fn splat(v: f64) -> Self {
        F64x4(unsafe { _mm256_set1_pd(v) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F64x4(unsafe { _mm256_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F64x4(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
    }
    #[inline(always)]
    fn trunc(self) -> Self {
        F64x4(unsafe { _mm256_round_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(self.0) })
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        unsafe {
            let sign_bit = _mm256_set1_pd(-0.0);
            F64x4(_mm256_or_pd(
                _mm256_andnot_pd(sign_bit, self.0),
                _mm256_and_pd(sign_bit, sign.0),
            ))
        }
    }
    #[inline(always)]
    fn ge(self, other: Self) -> Self {
        F64x4(unsafe { _mm256_cmp_pd::<_CMP_GE_OQ>(self.0, other.0) })
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Self {
        F64x4(unsafe { _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, other.0) })
    }
    #[inline(always)]
    fn eq(self, other: Self) -> Self {
        F64x4(unsafe { _mm256_cmp_pd::<_CMP_EQ_OQ>(self.0, other.0) })
    }
    #[inline(always)]
    fn select(mask: Self, if_true: Self, if_false: Self) -> Self {
        F64x4(unsafe { _mm256_blendv_pd(if_false.0, if_true.0, mask.0) })
    }
    #[inline(always)]
    fn not(mask: Self) -> Self {
        F64x4(unsafe { _mm256_xor_pd(mask.0, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))) })
    }
    #[inline(always)]
    fn and(a: Self, b: Self) -> Self {
        F64x4(unsafe { _mm256_and_pd(a.0, b.0) })
    }
}
