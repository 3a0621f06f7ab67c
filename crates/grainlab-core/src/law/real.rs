//! The number type the contact laws are written over: one contact's `f64`, or
//! four contacts' lanes ([`crate::simd::F64x4`], AVX2).
//!
//! Each sub-model writes its arithmetic once, generic over [`Real`]; the
//! scalar law calls it with `f64`, the four-pair loop (`pipeline/pair_lanes.rs`)
//! with `F64x4`. A branch of the law is a [`Real::select`] of the value the
//! branch keeps, and every operation is a correctly rounded IEEE one (no fused
//! multiply-add, which Rust never forms on its own), so the two give the same
//! bits: the test of `pair_lanes.rs` checks it on random contacts.
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A real number, or several computed side by side (lanes).
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The outcome of a comparison: a `bool`, or a mask of lanes.
    type Mask: Copy;

    /// The value `v` (in every lane).
    fn splat(v: f64) -> Self;
    /// The correctly rounded square root.
    fn sqrt(self) -> Self;
    /// The magnitude (the sign bit cleared).
    fn abs(self) -> Self;
    /// The whole part, rounded toward zero (`f64::trunc`).
    fn trunc(self) -> Self;
    /// The magnitude of `self` with the sign of `sign` (`f64::copysign`).
    fn copysign(self, sign: Self) -> Self;
    /// `self >= other`, false when either is NaN.
    fn ge(self, other: Self) -> Self::Mask;
    /// `self > other`, false when either is NaN.
    fn gt(self, other: Self) -> Self::Mask;
    /// `self == other`, false when either is NaN (`+0 == -0`).
    fn eq(self, other: Self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Where `mask` does not hold.
    fn not(mask: Self::Mask) -> Self::Mask;
    /// Where both hold.
    fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
}

impl Real for f64 {
    type Mask = bool;

    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn trunc(self) -> Self {
        f64::trunc(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask {
            if_true
        } else {
            if_false
        }
    }
    #[inline(always)]
    fn not(mask: bool) -> bool {
        !mask
    }
    #[inline(always)]
    fn and(a: bool, b: bool) -> bool {
        a && b
    }
}
