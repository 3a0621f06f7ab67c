//! Cement: breakable bonds between two disks, acting in parallel with the
//! contact law (docs/cemented.md).
//!
//! Two kinds share one law and one code path:
//!
//! - the **parallel bond** (Potyondy and Cundall 2004, in 2D with a unit
//!   thickness `t = 1 m`): a slab of cement of radius `R_b = lambda_b min(R_i, R_j)`,
//!   area `A = 2 R_b t` and second moment `I = (2/3) R_b^3 t`, with normal and
//!   shear stiffnesses per area `kn_bar`, `ks_bar` (Pa/m). It carries a normal
//!   force, a shear force and a moment;
//! - the **contact bond**: the same springs given in N/m, no moment, and
//!   strengths in newtons (its "area" is 1, so its stresses are forces).
//!
//! Signs: the normal force `F_n` is positive in compression, as the contact
//! law's; the bond's normal stress is tension-positive, `sigma = -F_n / A`.
//! `F_n = kn_bar A (L_0 - d)` from the rest length `L_0` (the distance at
//! bonding, so a new bond is stress-free): path-independent, so its energy
//! `F_n^2 / (2 kn_bar A)` is an exact potential. The shear force `F_s` (on `j`
//! along `perp(n)`) and the moment `M` (on `j`; `-M` on `i`) are incremental:
//! `F_s -= ks_bar A v_t dt`, `M -= kn_bar I (omega_j - omega_i) dt`.
//!
//! A bond breaks, at the evaluation where it happens, in **tension** when
//! `sigma_max = sigma + |M| R_b / I >= sigma_c`, else in **shear** when
//! `tau_max = |F_s| / A >= c - sigma tan(phi_b)` (tension lowers the shear
//! strength, compression raises it). A broken bond adds no force from that
//! evaluation on; its stored energy is booked as released and the contact
//! law alone carries the pair.
use serde::{Deserialize, Serialize};

use crate::cell::{nearest_image, PeriodicCell};
use crate::error::{require_non_negative, require_positive, EngineError, Result};
use crate::law::real::Real;
use crate::state::ParticleMotion;
use crate::vec2::{add, scale, sub, Mat2, Vec2};

/// The kind of a cement bond.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CementKind {
    /// A parallel bond: stiffnesses per area (Pa/m), strengths in Pa, a moment.
    Parallel,
    /// A contact bond: stiffnesses in N/m, strengths in N, no moment.
    Contact,
}

impl CementKind {
    /// The kind named `name` (`"parallel"` or `"contact"`).
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "parallel" => Ok(CementKind::Parallel),
            "contact" => Ok(CementKind::Contact),
            _ => Err(EngineError::invalid(
                "cement.kind",
                format!("unknown kind {name:?}; expected \"parallel\" or \"contact\""),
            )),
        }
    }
}

/// What a caller gives for one cement bond; units follow `kind`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CementSpec {
    /// Parallel or contact bond.
    pub kind: CementKind,
    /// `lambda_b` (> 0): the bond's radius over the smaller disk's (parallel bonds).
    pub radius_multiplier: f64,
    /// `kn_bar` (Pa/m) of a parallel bond, `k_n` (N/m) of a contact bond (> 0).
    pub normal_stiffness: f64,
    /// `ks_bar` (Pa/m) of a parallel bond, `k_s` (N/m) of a contact bond (> 0).
    pub shear_stiffness: f64,
    /// `sigma_c` (Pa) or the tensile strength in N (>= 0).
    pub tensile_strength: f64,
    /// `c` (Pa) or the shear strength in N (>= 0).
    pub cohesion: f64,
    /// `phi_b` in degrees, in [0, 90).
    pub friction_angle: f64,
}

impl CementSpec {
    /// Checks every value, naming the field with `at` (e.g. `[3]`).
    pub fn validate(&self, at: &str) -> Result<()> {
        require_positive(
            &format!("cement.radius_multiplier{at}"),
            self.radius_multiplier,
        )?;
        require_positive(
            &format!("cement.normal_stiffness{at}"),
            self.normal_stiffness,
        )?;
        require_positive(&format!("cement.shear_stiffness{at}"), self.shear_stiffness)?;
        require_non_negative(
            &format!("cement.tensile_strength{at}"),
            self.tensile_strength,
        )?;
        require_non_negative(&format!("cement.cohesion{at}"), self.cohesion)?;
        let phi = self.friction_angle;
        if !(phi.is_finite() && (0.0..90.0).contains(&phi)) {
            return Err(EngineError::invalid(
                format!("cement.friction_angle{at}"),
                format!("must be in [0, 90) degrees, got {phi}"),
            ));
        }
        Ok(())
    }
}

/// One intact cement bond: its section, stiffnesses, strengths and springs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CementBond {
    /// First particle.
    pub i: u32,
    /// Second particle.
    pub j: u32,
    /// Parallel or contact bond.
    pub kind: CementKind,
    /// `kn_bar A` (N/m).
    pub normal_stiffness: f64,
    /// `ks_bar A` (N/m).
    pub shear_stiffness: f64,
    /// `kn_bar I` (N m/rad); 0 for a contact bond.
    pub bending_stiffness: f64,
    /// `A` (m^2 per m of thickness); 1 for a contact bond.
    pub area: f64,
    /// `R_b / I` (1/m^3); 0 for a contact bond.
    pub bending_factor: f64,
    /// `R_b` (m); 0 for a contact bond.
    pub bond_radius: f64,
    /// `sigma_c` (Pa; N for a contact bond).
    pub tensile_strength: f64,
    /// `c` (Pa; N for a contact bond).
    pub cohesion: f64,
    /// `tan(phi_b)`.
    pub friction_tangent: f64,
    /// Centre distance at which the normal force is zero (m).
    pub rest_length: f64,
    /// Shear force `F_s` (N), history.
    pub shear: f64,
    /// Moment `M` on `j` (N m), history.
    pub moment: f64,
}

impl CementBond {
    /// A stress-free bond between `i` and `j` (radii `ri`, `rj`) at centre
    /// distance `rest_length`, from a validated `spec`.
    pub fn new(i: u32, j: u32, ri: f64, rj: f64, rest_length: f64, spec: &CementSpec) -> Self {
        let (area, bond_radius, inertia) = match spec.kind {
            CementKind::Parallel => {
                let rb = spec.radius_multiplier * ri.min(rj);
                (2.0 * rb, rb, 2.0 / 3.0 * rb * rb * rb)
            }
            CementKind::Contact => (1.0, 0.0, 0.0),
        };
        let stiffness_area = match spec.kind {
            CementKind::Parallel => area,
            CementKind::Contact => 1.0,
        };
        CementBond {
            i,
            j,
            kind: spec.kind,
            normal_stiffness: spec.normal_stiffness * stiffness_area,
            shear_stiffness: spec.shear_stiffness * stiffness_area,
            bending_stiffness: spec.normal_stiffness * inertia,
            area,
            bending_factor: if inertia > 0.0 {
                bond_radius / inertia
            } else {
                0.0
            },
            bond_radius,
            tensile_strength: spec.tensile_strength,
            cohesion: spec.cohesion,
            friction_tangent: spec.friction_angle.to_radians().tan(),
            rest_length,
            shear: 0.0,
            moment: 0.0,
        }
    }

    /// Strain energy (J per m) of normal force `fn_` and the bond's own
    /// shear force and moment: `F_n^2/(2 k_n) + F_s^2/(2 k_s) + M^2/(2 kn_bar I)`.
    #[inline]
    pub fn energy(&self, fn_: f64) -> f64 {
        let bending = if self.bending_stiffness > 0.0 {
            0.5 * self.moment * self.moment / self.bending_stiffness
        } else {
            0.0
        };
        0.5 * fn_ * fn_ / self.normal_stiffness
            + 0.5 * self.shear * self.shear / self.shear_stiffness
            + bending
    }

    /// The tension-positive normal stress `sigma = -F_n / A` and the largest
    /// normal stress at the periphery, `sigma + |M| R_b / I`.
    #[inline]
    pub fn normal_stresses(&self, fn_: f64) -> (f64, f64) {
        let sigma = -fn_ / self.area;
        (sigma, sigma + self.moment.abs() * self.bending_factor)
    }

    /// How the bond breaks under normal force `fn_` and its own shear force
    /// and moment, if it does: tension first, then shear.
    ///
    /// Both criteria are taken over the section, in newtons, so that a step
    /// divides nothing: `-F_n + |M| A R_b / I >= sigma_c A` and
    /// `|F_s| >= c A + F_n tan(phi_b)`.
    #[inline]
    pub fn rupture_mode(&self, fn_: f64) -> Option<BreakMode> {
        match criteria(&BondInput::of_springs(self), fn_) {
            (true, _) => Some(BreakMode::Tension),
            (false, true) => Some(BreakMode::Shear),
            (false, false) => None,
        }
    }
}

/// How a bond broke.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BreakMode {
    /// `sigma_max >= sigma_c`.
    Tension,
    /// `tau_max >= c - sigma tan(phi_b)`.
    Shear,
}

impl BreakMode {
    /// `"tension"` or `"shear"`.
    pub fn name(self) -> &'static str {
        match self {
            BreakMode::Tension => "tension",
            BreakMode::Shear => "shear",
        }
    }
}

/// One break, as the step that saw it records it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BondBreak {
    /// Step count at the evaluation that broke the bond (the state at that step's start).
    pub step: u64,
    /// Simulated time of that state (s).
    pub time: f64,
    /// External (user) indices of the two particles.
    pub i: u32,
    /// Second particle (external index).
    pub j: u32,
    /// The bond's centre: the contact point, mid-gap on the line of centres
    /// (in `i`'s image of a periodic cell; it may lie just outside the cell).
    pub position: Vec2,
    /// Unit normal from `i` to `j`.
    pub normal: Vec2,
    /// Tension or shear.
    pub mode: BreakMode,
    /// The strain energy the bond held, released by the break (J per m).
    pub energy: f64,
    /// Normal force (N, compression positive), shear force (N) and moment
    /// (N m) at the break.
    pub normal_force: f64,
    /// Shear force at the break (N).
    pub shear_force: f64,
    /// Moment at the break (N m).
    pub moment: f64,
}

/// The cement bonds and the log of their breaks.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Cement {
    /// The intact bonds, in creation order (broken ones removed, the others' order kept).
    pub bonds: Vec<CementBond>,
    /// Breaks not yet taken by the caller, in the order they happened.
    pub breaks: Vec<BondBreak>,
}

impl Cement {
    /// Renumbers the particles: `new_of_old[old] = new`.
    pub fn remap(&mut self, new_of_old: &[u32]) {
        for b in self.bonds.iter_mut() {
            b.i = new_of_old[b.i as usize];
            b.j = new_of_old[b.j as usize];
        }
    }
}

/// A bond's geometry at the current state, after its springs took the
/// increment: the normal `i -> j`, the distance, the lever arms, and the
/// relative motion the increment was made with (one bond's `f64`, or four
/// bonds' lanes, [`Real`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CementGeometry<R = f64> {
    pub normal: [R; 2],
    pub distance: R,
    /// Distances from `i`'s and `j`'s centres to the contact point (they sum to `distance`).
    pub arm_i: R,
    pub arm_j: R,
    /// Relative normal velocity `(v_j - v_i) . n` (m/s).
    pub normal_velocity: R,
    /// Relative tangential velocity of the contact point `v_t` (m/s).
    pub shear_velocity: R,
    /// `omega_j - omega_i` (rad/s).
    pub spin: R,
}

/// What the law of a bond reads: the motion of its two disks and the bond's
/// own values, as one bond's `f64` or four bonds' lanes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BondInput<R> {
    /// `x_j - x_i`, before the nearest image.
    pub branch: [R; 2],
    /// `v_j - v_i`.
    pub relative_velocity: [R; 2],
    pub radius: [R; 2],
    pub angular_velocity: [R; 2],
    pub normal_stiffness: R,
    pub shear_stiffness: R,
    pub bending_stiffness: R,
    pub area: R,
    pub bending_factor: R,
    pub tensile_strength: R,
    pub cohesion: R,
    pub friction_tangent: R,
    pub rest_length: R,
    pub shear: R,
    pub moment: R,
}

impl BondInput<f64> {
    /// `bond`'s input at the motion `p`.
    #[inline(always)]
    pub(crate) fn of(bond: &CementBond, p: &ParticleMotion<'_>) -> Self {
        let (i, j) = (bond.i as usize, bond.j as usize);
        BondInput {
            branch: sub(p.position[j], p.position[i]),
            relative_velocity: sub(p.velocity[j], p.velocity[i]),
            radius: [p.radius[i], p.radius[j]],
            angular_velocity: [p.angular_velocity[i], p.angular_velocity[j]],
            ..BondInput::of_springs(bond)
        }
    }

    /// `bond`'s own values, the disks' motion left at zero.
    #[inline(always)]
    fn of_springs(bond: &CementBond) -> Self {
        BondInput {
            branch: [0.0; 2],
            relative_velocity: [0.0; 2],
            radius: [0.0; 2],
            angular_velocity: [0.0; 2],
            normal_stiffness: bond.normal_stiffness,
            shear_stiffness: bond.shear_stiffness,
            bending_stiffness: bond.bending_stiffness,
            area: bond.area,
            bending_factor: bond.bending_factor,
            tensile_strength: bond.tensile_strength,
            cohesion: bond.cohesion,
            friction_tangent: bond.friction_tangent,
            rest_length: bond.rest_length,
            shear: bond.shear,
            moment: bond.moment,
        }
    }
}

/// The law of a bond at one evaluation: its springs after the increment,
/// its geometry, its forces and whether it breaks (masks of lanes for
/// four bonds).
#[derive(Debug, Clone, Copy)]
pub(crate) struct BondLaw<R: Real> {
    pub geometry: CementGeometry<R>,
    /// The shear force `F_s` and the moment `M` after the increment.
    pub shear: R,
    pub moment: R,
    /// `F_n = k_n (L_0 - d)` (N, compression positive).
    pub normal_force: R,
    /// The force on `j` (its opposite on `i`) and what each torque loses
    /// (the slot's values, [`CementSlot`]).
    pub force: [R; 2],
    pub torque_i: R,
    pub torque_j: R,
    /// Breaks in tension; else, in shear (see [`CementBond::rupture_mode`]).
    pub tension: R::Mask,
    pub sheared: R::Mask,
    /// With `MEASURE` only (else zeros): the strain energy
    /// ([`CementBond::energy`]) and the magnitude of the force.
    pub elastic: R,
    pub force_norm: R,
}

/// Adds to the bond's springs the increment of the relative motion over
/// `increment_time` (`-ks v_t dt` and `-kn_bar I (omega_j - omega_i) dt`) and
/// returns its geometry, written once over [`Real`] so that the four-bond
/// pass gives the same bits. The lever arms reach the contact point mid-gap,
/// so a rigid rotation of the pair adds no shear.
#[inline(always)]
fn advance<R: Real>(
    b: &mut BondInput<R>,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
) -> CementGeometry<R> {
    let d = match cell {
        Some(c) => nearest_image(c, b.branch),
        None => b.branch,
    };
    let distance = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let inverse = R::splat(1.0) / distance;
    let normal = [d[0] * inverse, d[1] * inverse];
    let mut dv = b.relative_velocity;
    if let Some(l) = &velocity_gradient {
        let (l00, l01) = (R::splat(l[0][0]), R::splat(l[0][1]));
        let (l10, l11) = (R::splat(l[1][0]), R::splat(l[1][1]));
        dv = [
            dv[0] + (l00 * d[0] + l01 * d[1]),
            dv[1] + (l10 * d[0] + l11 * d[1]),
        ];
    }
    let [ri, rj] = b.radius;
    let half_overlap = R::splat(0.5) * (ri + rj - distance);
    let (arm_i, arm_j) = (ri - half_overlap, rj - half_overlap);
    let [wi, wj] = b.angular_velocity;
    // perp(n) = (-n_y, n_x)
    let vt = (dv[0] * -normal[1] + dv[1] * normal[0]) - (wi * arm_i + wj * arm_j);
    let dt = R::splat(increment_time);
    b.shear = b.shear - b.shear_stiffness * vt * dt;
    b.moment = b.moment - b.bending_stiffness * (wj - wi) * dt;
    CementGeometry {
        normal,
        distance,
        arm_i,
        arm_j,
        normal_velocity: dv[0] * normal[0] + dv[1] * normal[1],
        shear_velocity: vt,
        spin: wj - wi,
    }
}

/// Whether the bond `b` (its springs as they are) breaks under normal force
/// `fn_` in tension, and in shear, over the section in newtons (see
/// [`CementBond::rupture_mode`]).
#[inline(always)]
fn criteria<R: Real>(b: &BondInput<R>, fn_: R) -> (R::Mask, R::Mask) {
    let a = b.area;
    (
        (b.moment.abs() * b.bending_factor * a - fn_).ge(b.tensile_strength * a),
        b.shear.abs().ge(b.cohesion * a + fn_ * b.friction_tangent),
    )
}

/// The law of the bond `b` at the current state (its springs take the
/// increment over `increment_time`), over [`Real`].
#[inline(always)]
pub(crate) fn bond_law<R: Real, const MEASURE: bool>(
    mut b: BondInput<R>,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
) -> BondLaw<R> {
    let g = advance(&mut b, cell, velocity_gradient, increment_time);
    let fn_ = b.normal_stiffness * (b.rest_length - g.distance);
    let (fs, m) = (b.shear, b.moment);
    let (tension, sheared) = criteria(&b, fn_);
    let [nx, ny] = g.normal;
    let (elastic, force_norm) = if MEASURE {
        let half = R::splat(0.5);
        let zero = R::splat(0.0);
        let bending = R::select(
            b.bending_stiffness.gt(zero),
            half * m * m / b.bending_stiffness,
            zero,
        );
        (
            half * fn_ * fn_ / b.normal_stiffness + half * fs * fs / b.shear_stiffness + bending,
            (fn_ * fn_ + fs * fs).sqrt(),
        )
    } else {
        (R::splat(0.0), R::splat(0.0))
    };
    BondLaw {
        geometry: g,
        shear: fs,
        moment: m,
        normal_force: fn_,
        force: [nx * fn_ + -ny * fs, ny * fn_ + nx * fs],
        torque_i: g.arm_i * fs + m,
        torque_j: g.arm_j * fs - m,
        tension,
        sheared,
        elastic,
        force_norm,
    }
}

/// Adds to `bond`'s springs the increment of the relative motion over
/// `increment_time` and returns its geometry ([`advance`]).
#[inline(always)]
pub(crate) fn advance_springs(
    bond: &mut CementBond,
    p: &ParticleMotion<'_>,
    cell: Option<&PeriodicCell>,
    velocity_gradient: Option<Mat2>,
    increment_time: f64,
) -> CementGeometry {
    let mut input = BondInput::of(bond, p);
    let g = advance(&mut input, cell, velocity_gradient, increment_time);
    (bond.shear, bond.moment) = (input.shear, input.moment);
    g
}

/// What a breaking bond leaves for the step's record.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rupture {
    pub mode: BreakMode,
    pub position: Vec2,
    pub normal: Vec2,
    pub energy: f64,
    /// What the ledger books: `energy` plus half a step of the bond's work
    /// at the half-step velocities (see [`evaluate_cement`]).
    pub booked: f64,
    pub normal_force: f64,
    pub shear_force: f64,
    pub moment: f64,
}

/// A cement bond's forces of this step, added as [`crate::bond::BondSlot`]s
/// are (a broken bond's slot holds zeros). Kept to the forces alone: the
/// slots are written and read at every step.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CementSlot {
    /// Force on `j` (N); its opposite acts on `i`.
    pub force: Vec2,
    /// Taken from `i`'s torque: `a_i F_s + M` (N m).
    pub torque_i: f64,
    /// Taken from `j`'s torque: `a_j F_s - M` (N m).
    pub torque_j: f64,
}

/// What one evaluation of a cement bond gives.
#[derive(Debug, Clone, Copy)]
pub(crate) enum CementEvaluation {
    /// The bond holds: its forces, and (measured steps only, else zeros) its
    /// strain energy (J) and the magnitude of its force (N).
    Holds {
        slot: CementSlot,
        elastic: f64,
        force_norm: f64,
    },
    /// The bond broke at this evaluation; it adds no force.
    Breaks(Rupture),
}

/// What `law`, evaluated for `bond`, means: the bond takes its new springs
/// and holds with its forces, or breaks with its record.
#[inline(always)]
pub(crate) fn conclude(
    bond: &mut CementBond,
    p: &ParticleMotion<'_>,
    law: &BondLaw<f64>,
    increment_time: f64,
) -> CementEvaluation {
    (bond.shear, bond.moment) = (law.shear, law.moment);
    let mode = if law.tension {
        BreakMode::Tension
    } else if law.sheared {
        BreakMode::Shear
    } else {
        return CementEvaluation::Holds {
            slot: CementSlot {
                force: law.force,
                torque_i: law.torque_i,
                torque_j: law.torque_j,
            },
            elastic: law.elastic,
            force_norm: law.force_norm,
        };
    };
    let g = &law.geometry;
    CementEvaluation::Breaks(rupture(bond, p, g, mode, law.normal_force, increment_time))
}

/// The record of `bond` breaking in `mode` under normal force `fn_`, at
/// geometry `g`.
#[cold]
#[inline(never)]
fn rupture(
    bond: &CementBond,
    p: &ParticleMotion<'_>,
    g: &CementGeometry,
    mode: BreakMode,
    fn_: f64,
    increment_time: f64,
) -> Rupture {
    let (fs, m) = (bond.shear, bond.moment);
    let energy = bond.energy(fn_);
    // Leapfrog conserves 1/2 m v(n-1/2).v(n+1/2) + U(x(n)) (the ledger's
    // kinetic and elastic lines); a force that stops at step n misses the
    // half of its trapezoid of work that step n's kick would have given,
    // 1/2 dt F(x(n)) . v(n-1/2): booking it with U makes the ledger
    // balance to round-off through the break.
    let power = fn_ * g.normal_velocity + fs * g.shear_velocity + m * g.spin;
    Rupture {
        mode,
        position: add(p.position[bond.i as usize], scale(g.normal, g.arm_i)),
        normal: g.normal,
        energy,
        booked: energy + 0.5 * increment_time * power,
        normal_force: fn_,
        shear_force: fs,
        moment: m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(kind: CementKind) -> CementSpec {
        CementSpec {
            kind,
            radius_multiplier: 0.5,
            normal_stiffness: 2.0e12,
            shear_stiffness: 1.0e12,
            tensile_strength: 1.0e6,
            cohesion: 2.0e6,
            friction_angle: 30.0,
        }
    }

    #[test]
    fn a_parallel_bond_has_the_section_of_a_unit_thick_slab() {
        let b = CementBond::new(0, 1, 2.0e-3, 1.0e-3, 3.0e-3, &spec(CementKind::Parallel));
        let rb = 0.5e-3;
        assert_eq!(b.bond_radius, rb);
        assert_eq!(b.area, 2.0 * rb);
        assert!((b.normal_stiffness - 2.0e12 * 2.0 * rb).abs() < 1e-6);
        assert!((b.shear_stiffness - 1.0e12 * 2.0 * rb).abs() < 1e-6);
        let inertia = 2.0 / 3.0 * rb.powi(3);
        assert!((b.bending_stiffness / (2.0e12 * inertia) - 1.0).abs() < 1e-14);
        assert!((b.bending_factor * inertia / rb - 1.0).abs() < 1e-14);
    }

    #[test]
    fn a_contact_bond_has_no_moment_and_strengths_in_newtons() {
        let b = CementBond::new(0, 1, 2.0e-3, 1.0e-3, 3.0e-3, &spec(CementKind::Contact));
        assert_eq!(
            (b.bending_stiffness, b.bending_factor, b.area),
            (0.0, 0.0, 1.0)
        );
        assert_eq!(b.normal_stiffness, 2.0e12);
        // a tension of 1e6 N breaks it, 0.99e6 N does not
        assert_eq!(b.rupture_mode(-1.0e6), Some(BreakMode::Tension));
        assert_eq!(b.rupture_mode(-0.99e6), None);
    }

    #[test]
    fn compression_raises_the_shear_strength_and_tension_lowers_it() {
        let mut b = CementBond::new(0, 1, 1.0, 1.0, 2.0, &spec(CementKind::Parallel));
        let a = b.area;
        let tan = 30f64.to_radians().tan();
        // c = 2 MPa; under sigma = -1 MPa (compression) the strength is 2 + tan30 MPa
        b.shear = (2.0e6 + 1.0e6 * tan) * a * 0.999;
        assert_eq!(b.rupture_mode(1.0e6 * a), None);
        b.shear = (2.0e6 + 1.0e6 * tan) * a * 1.001;
        assert_eq!(b.rupture_mode(1.0e6 * a), Some(BreakMode::Shear));
        // under sigma = +0.5 MPa (tension, below sigma_c) it is 2 - 0.5 tan30 MPa
        b.shear = (2.0e6 - 0.5e6 * tan) * a * 1.001;
        assert_eq!(b.rupture_mode(-0.5e6 * a), Some(BreakMode::Shear));
        b.shear = (2.0e6 - 0.5e6 * tan) * a * 0.999;
        assert_eq!(b.rupture_mode(-0.5e6 * a), None);
    }

    #[test]
    fn a_moment_adds_its_peripheral_stress_to_the_tension() {
        let mut b = CementBond::new(0, 1, 1.0, 1.0, 2.0, &spec(CementKind::Parallel));
        let inertia = 2.0 / 3.0 * b.bond_radius.powi(3);
        let m_c = 1.0e6 * inertia / b.bond_radius;
        b.moment = -0.999 * m_c;
        assert_eq!(b.rupture_mode(0.0), None);
        b.moment = -1.001 * m_c;
        assert_eq!(b.rupture_mode(0.0), Some(BreakMode::Tension));
        assert!((b.energy(0.0) - 0.5 * b.moment.powi(2) / b.bending_stiffness).abs() < 1e-9);
    }

    #[test]
    fn bad_specs_are_refused_naming_the_field() {
        let mut s = spec(CementKind::Parallel);
        s.tensile_strength = -1.0;
        let e = s.validate("[2]").unwrap_err().to_string();
        assert!(e.starts_with("cement.tensile_strength[2]:"), "{e}");
        let mut s = spec(CementKind::Parallel);
        s.radius_multiplier = 0.0;
        assert!(s.validate("").is_err());
        s = spec(CementKind::Parallel);
        s.friction_angle = f64::NAN;
        assert!(s.validate("").is_err());
        assert!(CementKind::from_name("glue").is_err());
    }
}
