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

/// Four values as lanes, in order (set from registers: a load of four
/// values just stored one by one would wait for the stores).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn four(v: [f64; 4]) -> F64x4 {
    F64x4::from(_mm256_set_pd(v[3], v[2], v[1], v[0]))
}

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
    let bond = |f: fn(&CementBond) -> f64| -> [f64; 4] {
        [f(&quad[0]), f(&quad[1]), f(&quad[2]), f(&quad[3])]
    };
    let disk = |values: &[f64], q: [usize; 4]| -> [f64; 4] {
        [
            *values.get_unchecked(q[0]),
            *values.get_unchecked(q[1]),
            *values.get_unchecked(q[2]),
            *values.get_unchecked(q[3]),
        ]
    };
    let (xi, xj) = (xy_lanes(p.position, i), xy_lanes(p.position, j));
    let (vi, vj) = (xy_lanes(p.velocity, i), xy_lanes(p.velocity, j));
    let input = BondInput {
        branch: [xj[0] - xi[0], xj[1] - xi[1]],
        relative_velocity: [vj[0] - vi[0], vj[1] - vi[1]],
        radius: [four(disk(p.radius, i)), four(disk(p.radius, j))],
        angular_velocity: [
            four(disk(p.angular_velocity, i)),
            four(disk(p.angular_velocity, j)),
        ],
        normal_stiffness: four(bond(|b| b.normal_stiffness)),
        shear_stiffness: four(bond(|b| b.shear_stiffness)),
        bending_stiffness: four(bond(|b| b.bending_stiffness)),
        area: four(bond(|b| b.area)),
        bending_factor: four(bond(|b| b.bending_factor)),
        tensile_strength: four(bond(|b| b.tensile_strength)),
        cohesion: four(bond(|b| b.cohesion)),
        friction_tangent: four(bond(|b| b.friction_tangent)),
        rest_length: four(bond(|b| b.rest_length)),
        shear: four(bond(|b| b.shear)),
        moment: four(bond(|b| b.moment)),
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
