//! The periodic cell: two cell vectors, periodicity per vector, and an imposed
//! homogeneous deformation (velocity gradient) that remaps particles affinely,
//! as LAMMPS `fix deform ... remap x` and YADE's periodic cell do.
//!
//! Particle velocities are fluctuations about the homogeneous flow: each step a
//! particle moves by `dt * v` and is then mapped with the cell by
//! `x <- origin + M (x - origin)`, `M = I + dt L`. The relative velocity of two
//! particles in contact includes the affine part `L d` of their branch vector `d`.
//!
//! A cell sheared without end (simple shear to large strain) would grow ever
//! thinner across its tilted vector; at each neighbour build the engine takes
//! the whole number of `a` off `b` that brings `b`'s tilt along `a` back within
//! half a cell (Lees-Edwards' remap, LAMMPS's box flip). The lattice of images,
//! hence every pair's geometry and force, is the same; only the image shifts
//! of the listed pairs are renamed.
use serde::{Deserialize, Serialize};

use crate::error::{require_finite, EngineError, Result};
use crate::law::real::Real;
use crate::vec2::{add, dot, mat_mul, mat_vec, scale, sub, Mat2, Vec2, IDENTITY};

/// A parallelogram cell spanned by `a` and `b` from `origin`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PeriodicCell {
    /// Lower-left corner (m).
    pub origin: Vec2,
    /// First cell vector (m), along x for an axis-aligned cell.
    pub a: Vec2,
    /// Second cell vector (m), along y for an axis-aligned cell.
    pub b: Vec2,
    /// Whether the cell repeats along `a` and along `b`.
    pub periodic: [bool; 2],
    /// Imposed velocity gradient L (1/s), row-major: `L[i][j] = d v_i / d x_j`.
    pub velocity_gradient: Mat2,
}

impl PeriodicCell {
    /// An axis-aligned rectangle `[x0, x0 + lx) x [y0, y0 + ly)`.
    pub fn rectangle(origin: Vec2, lx: f64, ly: f64, periodic: [bool; 2]) -> Result<Self> {
        let cell = PeriodicCell {
            origin,
            a: [lx, 0.0],
            b: [0.0, ly],
            periodic,
            velocity_gradient: [[0.0; 2]; 2],
        };
        cell.validate()?;
        Ok(cell)
    }

    /// Checks finiteness and a positive, non-degenerate area.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("cell.origin", self.origin),
            ("cell.a", self.a),
            ("cell.b", self.b),
        ] {
            require_finite(name, v[0])?;
            require_finite(name, v[1])?;
        }
        if self.area().is_nan() || self.area() <= 0.0 {
            return Err(EngineError::invalid(
                "cell",
                format!(
                    "cell vectors a={:?}, b={:?} must span a positive area (a x b > 0)",
                    self.a, self.b
                ),
            ));
        }
        for row in &self.velocity_gradient {
            for &v in row {
                require_finite("cell.velocity_gradient", v)?;
            }
        }
        Ok(())
    }

    /// Signed area `a x b` (m^2 per unit thickness).
    pub fn area(&self) -> f64 {
        self.a[0] * self.b[1] - self.a[1] * self.b[0]
    }

    /// Cell matrix H with columns a and b.
    pub fn matrix(&self) -> Mat2 {
        [[self.a[0], self.b[0]], [self.a[1], self.b[1]]]
    }

    /// Fractional coordinates `H^-1 (x - origin)`.
    #[inline(always)]
    pub fn fractional(&self, x: Vec2) -> Vec2 {
        self.fractional_of(x)
    }

    /// [`PeriodicCell::fractional`] over [`Real`] (one point, or four in lanes).
    #[inline(always)]
    fn fractional_of<R: Real>(&self, x: [R; 2]) -> [R; 2] {
        let d = [
            x[0] - R::splat(self.origin[0]),
            x[1] - R::splat(self.origin[1]),
        ];
        let inv_det = R::splat(1.0 / self.area());
        let (a, b) = (self.a, self.b);
        [
            (R::splat(b[1]) * d[0] - R::splat(b[0]) * d[1]) * inv_det,
            (R::splat(-a[1]) * d[0] + R::splat(a[0]) * d[1]) * inv_det,
        ]
    }

    /// Translation of the image with integer shift `s`: `s0 a + s1 b`.
    #[inline(always)]
    pub fn image_offset(&self, s: [i8; 2]) -> Vec2 {
        [
            s[0] as f64 * self.a[0] + s[1] as f64 * self.b[0],
            s[0] as f64 * self.a[1] + s[1] as f64 * self.b[1],
        ]
    }

    /// Width of the cell perpendicular to the other vector, per direction (m).
    pub fn widths(&self) -> [f64; 2] {
        let area = self.area();
        [
            area / crate::vec2::norm(self.b),
            area / crate::vec2::norm(self.a),
        ]
    }

    /// Whether an imposed deformation is active.
    pub fn is_deforming(&self) -> bool {
        self.velocity_gradient.iter().flatten().any(|&v| v != 0.0)
    }

    /// The map `M = I + dt L` of one step.
    pub fn step_map(&self, dt: f64) -> Mat2 {
        let l = &self.velocity_gradient;
        [
            [1.0 + dt * l[0][0], dt * l[0][1]],
            [dt * l[1][0], 1.0 + dt * l[1][1]],
        ]
    }

    /// Applies `M` to the cell vectors (the origin is the fixed point).
    pub fn deform(&mut self, m: &Mat2) {
        self.a = mat_vec(m, self.a);
        self.b = mat_vec(m, self.b);
    }

    /// Affine image of `x` under `M` about the origin.
    #[inline(always)]
    pub fn map_point(&self, m: &Mat2, x: Vec2) -> Vec2 {
        add(self.origin, mat_vec(m, sub(x, self.origin)))
    }

    /// The whole number `k` of `a` to take off `b` so that `b`'s tilt along
    /// `a`, `t = (a . b) / (a . a)`, comes back within half a cell: 0 while
    /// `|t| <= 1/2`, or when the cell does not repeat along `a` (then `b - k a`
    /// would not span the same lattice).
    pub fn tilt_reduction(&self) -> i8 {
        if !self.periodic[0] {
            return 0;
        }
        let t = dot(self.a, self.b) / dot(self.a, self.a);
        if t.abs() <= 0.5 {
            0
        } else {
            t.round() as i8
        }
    }

    /// Replaces `b` by `b - k a`: the same lattice of images, a cell that is
    /// less tilted. An image shift `(s0, s1)` of the old cell is
    /// `(s0 + k s1, s1)` of the new one.
    pub fn reduce_tilt(&mut self, k: i8) {
        self.b = sub(self.b, scale(self.a, k as f64));
    }

    /// Brings `x` into the cell along periodic directions; returns the integer
    /// number of cell vectors added (to correct stored image shifts).
    pub fn wrap(&self, x: &mut Vec2) -> [i8; 2] {
        let f = self.fractional(*x);
        let mut shift = [0i8; 2];
        for k in 0..2 {
            if self.periodic[k] && !(0.0..1.0).contains(&f[k]) {
                shift[k] = (-f[k].floor()) as i8;
            }
        }
        if shift != [0, 0] {
            *x = add(*x, self.image_offset(shift));
        }
        shift
    }

    /// Composes an accumulated map with one more step map: `M_step * M_acc`.
    pub fn accumulate(acc: &Mat2, step: &Mat2) -> Mat2 {
        mat_mul(step, acc)
    }
}

/// Identity map, the accumulated deformation right after a neighbour-list build.
pub const NO_DEFORMATION: Mat2 = IDENTITY;

/// Affine velocity `L d` of a branch vector `d`.
#[inline(always)]
pub fn affine_velocity(l: &Mat2, d: Vec2) -> Vec2 {
    mat_vec(l, d)
}

/// `x + s * v`, a helper for integration.
#[inline(always)]
pub fn advance(x: Vec2, v: Vec2, s: f64) -> Vec2 {
    add(x, scale(v, s))
}

/// Nearest-image branch vector for bonds.
#[inline(always)]
pub fn minimum_image(cell: Option<&PeriodicCell>, d: Vec2) -> Vec2 {
    match cell {
        Some(c) => nearest_image(c, d),
        None => d,
    }
}

/// The image of branch vector `d` nearest to zero in cell `c`, over
/// [`Real`] (one bond, or four in the cement's lanes, with the same bits):
/// `d` shifted by the whole cell vectors that bring its fractional
/// coordinates (of `origin + d`) to within a half, along each periodic
/// direction.
#[inline(always)]
pub(crate) fn nearest_image<R: Real>(c: &PeriodicCell, d: [R; 2]) -> [R; 2] {
    if !(c.periodic[0] || c.periodic[1]) {
        return d;
    }
    let f = c.fractional_of([R::splat(c.origin[0]) + d[0], R::splat(c.origin[1]) + d[1]]);
    // `0 - n`, not `-n`: no shift is +0, as an integer shift of 0 would be
    // (no closures here: the lanes' operations must inline into the AVX2 kernel)
    let zero = R::splat(0.0);
    let mut shift = [zero; 2];
    if c.periodic[0] {
        shift[0] = zero - nearest_whole(f[0]);
    }
    if c.periodic[1] {
        shift[1] = zero - nearest_whole(f[1]);
    }
    let (a, b) = (c.a, c.b);
    [
        d[0] + (shift[0] * R::splat(a[0]) + shift[1] * R::splat(b[0])),
        d[1] + (shift[0] * R::splat(a[1]) + shift[1] * R::splat(b[1])),
    ]
}

/// `x` rounded to the nearest whole number, halves away from zero, held
/// within +-127 images: the truncation and the remainder `x - trunc(x)` are
/// exact, so no call to the C library's `round` (which the baseline x86-64
/// target makes, and which costs a bond's evaluation its registers).
#[inline(always)]
fn nearest_whole<R: Real>(x: R) -> R {
    let whole = x.trunc();
    let rest = x - whole;
    let (zero, one, half) = (R::splat(0.0), R::splat(1.0), R::splat(0.5));
    let up = R::select(rest.ge(half), one, zero);
    let down = R::select((-half).ge(rest), one, zero);
    let n = whole + up - down;
    let limit = R::splat(127.0);
    let n = R::select(n.gt(limit), limit, n);
    R::select((-limit).gt(n), -limit, n)
}

#[cfg(test)]
mod tests {
    use super::nearest_whole;

    #[test]
    fn nearest_whole_rounds_as_the_library_does_within_127_images() {
        let edges = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
            126.5,
            127.5,
            -128.5,
            -129.0,
            1.0e20,
            -1.0e20,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1.0e-300,
        ];
        let steps = (-4000..4000).map(|k| k as f64 * 0.0373);
        for x in edges.into_iter().chain(steps) {
            let n: f64 = nearest_whole(x);
            if x.is_nan() {
                assert!(n.is_nan());
            } else {
                // the C library's rounding, held within +-127 images
                assert_eq!(
                    n.to_bits(),
                    (x.round().clamp(-127.0, 127.0) + 0.0).to_bits(),
                    "{x}"
                );
            }
        }
    }
}
