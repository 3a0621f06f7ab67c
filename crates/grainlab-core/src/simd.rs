//! What the engine's AVX2 kernels share (`pipeline/pair_lanes.rs`,
//! `integrate_lanes.rs`): whether the processor has AVX2, and a register's
//! lanes as an array.
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::{__m256d, _mm256_storeu_pd};

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
