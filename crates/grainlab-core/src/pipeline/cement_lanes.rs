//! The cement bonds' law four bonds at a time, in the 256-bit registers of
//! AVX2, with the same bits as one bond at a time.
//!
//! The law is [`crate::cement::bond_law`], written once over
//! [`crate::law::real::Real`]: here it runs on four bonds' lanes
//! ([`F64x4`]), gathered from the bonds and their disks. Every operation is
//! a correctly rounded IEEE one and every branch a select, so a lane holds
//! the bits the one-bond law gives (`pair_lanes.rs` says why). When all four
//! hold (nearly always), their springs, slots and measured terms are written
//! straight from the lanes, the terms added in bond order; when one breaks,
//! nothing is written and the one-bond path books the four
//! (`cement_pass.rs`, whose test requires the same bits from both paths).
#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use super::pair_kernel::ContactTally;
use crate::cell::PeriodicCell;
use crate::cement::{bond_law, BondInput, CementBond, CementSlot};
use crate::simd::{spill, F64x4};
use crate::state::ParticleMotion;
use crate::vec2::Mat2;

/// The vectors `values[q]` of four particles `q` as their x and y lanes, in
/// order (two 128-bit loads per register, unpacked).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn xy_lanes(values: &[[f64; 2]], q: [usize; 4]) -> [F64x4; 2] {
    debug_assert!(q.iter().all(|&k| k < values.len()));
    let at = values.as_ptr() as *const f64;
    let a0 = _mm_loadu_pd(at.add(2 * q[0]));
    let a1 = _mm_loadu_pd(at.add(2 * q[1]));
    let a2 = _mm_loadu_pd(at.add(2 * q[2]));
    let a3 = _mm_loadu_pd(at.add(2 * q[3]));
    // [x0 y0 x2 y2] and [x1 y1 x3 y3]: their unpacks are x and y in order
    let even = _mm256_insertf128_pd(_mm256_castpd128_pd256(a0), a2, 1);
    let odd = _mm256_insertf128_pd(_mm256_castpd128_pd256(a1), a3, 1);
    [
        F64x4::from(_mm256_unpacklo_pd(even, odd)),
        F64x4::from(_mm256_unpackhi_pd(even, odd)),
    ]
}

/// A register's lanes, in order.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn lanes(v: F64x4) -> [f64; 4] {
    spill(v.0)
}

/// Evaluates the four bonds `quad` at the motion `p`, as the one-bond pass
/// would: if all four hold, writes their springs and `slots` and adds their
/// measured terms to `tally` in bond order, and returns `true`; if one
/// breaks, writes nothing and returns `false`.
///
/// # Safety
/// The processor has AVX2 ([`crate::simd::available`]); the bonds' disks
/// exist in `p`.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn evaluate_four<const MEASURE: bool>(
    quad: &mut [CementBond],
    slots: &mut [CementSlot],
    p: &ParticleMotion<'_>,
    (cell, velocity_gradient, increment_time): (Option<&PeriodicCell>, Option<Mat2>, f64),
    tally: &mut ContactTally,
) -> bool {
    debug_assert!(quad.len() == 4 && slots.len() == 4);
    // (the closures below touch no lanes: an intrinsic inside a closure is
    // not inlined into this AVX2 function, and costs a call per operation)
    let (i, j) = (
        [quad[0].i, quad[1].i, quad[2].i, quad[3].i].map(|q| q as usize),
        [quad[0].j, quad[1].j, quad[2].j, quad[3].j].map(|q| q as usize),
    );
    // each lane set from its value where it lies (an array built first
    // would be stored one value at a time and loaded whole, which waits)
    macro_rules! bond {
        ($field:ident) => {
            F64x4::from(_mm256_set_pd(
                quad.get_unchecked(3).$field,
                quad.get_unchecked(2).$field,
                quad.get_unchecked(1).$field,
                quad.get_unchecked(0).$field,
            ))
        };
    }
    macro_rules! disk {
        ($values:expr, $q:expr) => {
            F64x4::from(_mm256_set_pd(
                *$values.get_unchecked($q[3]),
                *$values.get_unchecked($q[2]),
                *$values.get_unchecked($q[1]),
                *$values.get_unchecked($q[0]),
            ))
        };
    }
    let (xi, xj) = (xy_lanes(p.position, i), xy_lanes(p.position, j));
    let (vi, vj) = (xy_lanes(p.velocity, i), xy_lanes(p.velocity, j));
    let input = BondInput {
        branch: [xj[0] - xi[0], xj[1] - xi[1]],
        relative_velocity: [vj[0] - vi[0], vj[1] - vi[1]],
        radius: [disk!(p.radius, i), disk!(p.radius, j)],
        angular_velocity: [disk!(p.angular_velocity, i), disk!(p.angular_velocity, j)],
        normal_stiffness: bond!(normal_stiffness),
        shear_stiffness: bond!(shear_stiffness),
        bending_stiffness: bond!(bending_stiffness),
        area: bond!(area),
        bending_factor: bond!(bending_factor),
        tensile_strength: bond!(tensile_strength),
        cohesion: bond!(cohesion),
        friction_tangent: bond!(friction_tangent),
        rest_length: bond!(rest_length),
        shear: bond!(shear),
        moment: bond!(moment),
    };
    let law = bond_law::<F64x4, MEASURE>(input, cell, velocity_gradient, increment_time);
    if _mm256_movemask_pd(_mm256_or_pd(law.tension.0, law.sheared.0)) != 0 {
        return false;
    }
    let (shear, moment) = (lanes(law.shear), lanes(law.moment));
    let (fx, fy) = (lanes(law.force[0]), lanes(law.force[1]));
    let (torque_i, torque_j) = (lanes(law.torque_i), lanes(law.torque_j));
    for l in 0..4 {
        let b = quad.get_unchecked_mut(l);
        (b.shear, b.moment) = (shear[l], moment[l]);
        *slots.get_unchecked_mut(l) = CementSlot {
            force: [fx[l], fy[l]],
            torque_i: torque_i[l],
            torque_j: torque_j[l],
        };
    }
    if MEASURE {
        let (elastic, force_norm) = (lanes(law.elastic), lanes(law.force_norm));
        for l in 0..4 {
            tally.elastic += elastic[l];
            tally.force_sum += force_norm[l];
            tally.contacts += 1;
            tally.cement_holding += 1;
        }
    }
    true
}
