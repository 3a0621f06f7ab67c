//! Permanent bonds: a linear normal and shear spring between two chosen disks
//! that carries tension and never breaks (the membrane chain uses them).
//! Bonded pairs are excluded from the frictional contact law.
use serde::{Deserialize, Serialize};

use crate::cell::{minimum_image, PeriodicCell};
use crate::state::ParticleMotion;
use crate::vec2::{add, dot, mat_vec, norm, perp, scale, sub, Mat2, Vec2};

/// One bond; forces follow the sign conventions of [`crate::law`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bond {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Normal stiffness (N/m).
    pub normal_stiffness: f64,
    /// Shear stiffness (N/m).
    pub shear_stiffness: f64,
    /// Centre distance at which the normal force is zero (m).
    pub rest_length: f64,
    /// Shear spring force (N), the bond's history.
    pub shear: f64,
}

/// All bonds, plus a sorted pair index for excluding them from contacts.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Bonds {
    /// The bonds, in creation order.
    pub list: Vec<Bond>,
    sorted_pairs: Vec<(u32, u32)>,
}

impl Bonds {
    /// Adds a bond (the caller validates indices and stiffnesses).
    pub fn push(&mut self, bond: Bond) {
        let key = (bond.i.min(bond.j), bond.i.max(bond.j));
        let at = self.sorted_pairs.binary_search(&key).unwrap_or_else(|e| e);
        self.sorted_pairs.insert(at, key);
        self.list.push(bond);
    }

    /// Renumbers the particles: `new_of_old[old] = new`.
    pub fn remap(&mut self, new_of_old: &[u32]) {
        if self.list.is_empty() {
            return;
        }
        for b in self.list.iter_mut() {
            b.i = new_of_old[b.i as usize];
            b.j = new_of_old[b.j as usize];
        }
        self.sorted_pairs = self
            .list
            .iter()
            .map(|b| (b.i.min(b.j), b.i.max(b.j)))
            .collect();
        self.sorted_pairs.sort_unstable();
    }

    /// Whether `i` and `j` are bonded.
    #[inline]
    pub fn contains(&self, i: u32, j: u32) -> bool {
        !self.sorted_pairs.is_empty()
            && self
                .sorted_pairs
                .binary_search(&(i.min(j), i.max(j)))
                .is_ok()
    }

    /// Number of bonds.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// True without bonds.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}

/// A bond's geometry and forces at the current state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BondForce {
    /// Unit normal from `i` to `j`.
    pub normal: Vec2,
    /// Centre distance (m).
    pub distance: f64,
    /// Normal force on `j` (N), positive in compression.
    pub normal_force: f64,
    /// Shear force on `j` along `perp(normal)` (N): the updated spring.
    pub shear_force: f64,
}

/// Evaluates `bond` at the current state, adding `-ks v_t increment_time` to `shear`
/// (its spring: the bond's own, or a copy for a query).
#[inline(always)]
pub(crate) fn bond_force(
    bond: &Bond,
    p: &ParticleMotion<'_>,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
    shear: &mut f64,
) -> BondForce {
    let (i, j) = (bond.i as usize, bond.j as usize);
    let d = minimum_image(cell, sub(p.position[j], p.position[i]));
    let dist = norm(d);
    let n = scale(d, 1.0 / dist);
    let t = perp(n);
    let mut dv = sub(p.velocity[j], p.velocity[i]);
    if let Some(l) = &velocity_gradient {
        dv = add(dv, mat_vec(l, d));
    }
    let (ri, rj) = (p.radius[i], p.radius[j]);
    let vt = dot(dv, t) - (p.angular_velocity[i] * ri + p.angular_velocity[j] * rj);
    *shear -= bond.shear_stiffness * vt * increment_time;
    BondForce {
        normal: n,
        distance: dist,
        normal_force: bond.normal_stiffness * (bond.rest_length - dist),
        shear_force: *shear,
    }
}

/// A bond's forces of this step, computed with the contact phase and added to
/// the particles after it, in bond order.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BondSlot {
    /// Force on `j` (N); its opposite acts on `i`.
    pub force: Vec2,
    /// `r_i` times the shear force (N m), taken from `i`'s torque.
    pub torque_i: f64,
    /// `r_j` times the shear force (N m), taken from `j`'s torque.
    pub torque_j: f64,
    /// Elastic energy of the two springs (J), measured steps only.
    pub elastic: f64,
    /// Magnitude of the force (N), measured steps only.
    pub force_norm: f64,
}

/// Evaluates `bond` at the current state (updating its shear spring over
/// `increment_time`) into the slot its forces wait in.
#[inline]
pub(crate) fn bond_slot<const MEASURE: bool>(
    bond: &mut Bond,
    p: &ParticleMotion<'_>,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
) -> BondSlot {
    let copy = *bond;
    let b = bond_force(
        &copy,
        p,
        cell,
        velocity_gradient,
        increment_time,
        &mut bond.shear,
    );
    let (i, j) = (copy.i as usize, copy.j as usize);
    let f = add(
        scale(b.normal, b.normal_force),
        scale(perp(b.normal), b.shear_force),
    );
    let mut slot = BondSlot {
        force: f,
        torque_i: p.radius[i] * b.shear_force,
        torque_j: p.radius[j] * b.shear_force,
        ..BondSlot::default()
    };
    if MEASURE {
        let (fn_, fs) = (b.normal_force, b.shear_force);
        slot.elastic =
            0.5 * fn_ * fn_ / copy.normal_stiffness + 0.5 * fs * fs / copy.shear_stiffness;
        slot.force_norm = (fn_ * fn_ + fs * fs).sqrt();
    }
    slot
}
