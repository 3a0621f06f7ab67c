//! The periodic cell: two cell vectors, periodicity per vector, and an imposed
//! homogeneous deformation (velocity gradient) that remaps particles affinely,
//! as LAMMPS `fix deform ... remap x` and YADE's periodic cell do.
//!
//! Particle velocities are fluctuations about the homogeneous flow: each step a
//! particle moves by `dt * v` and is then mapped with the cell by
//! `x <- origin + M (x - origin)`, `M = I + dt L`. The relative velocity of two
//! particles in contact includes the affine part `L d` of their branch vector `d`.
use serde::{Deserialize, Serialize};

use crate::error::{require_finite, EngineError, Result};
use crate::vec2::{add, mat_mul, mat_vec, scale, sub, Mat2, Vec2, IDENTITY};

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
        let d = sub(x, self.origin);
        let inv_det = 1.0 / self.area();
        [
            (self.b[1] * d[0] - self.b[0] * d[1]) * inv_det,
            (-self.a[1] * d[0] + self.a[0] * d[1]) * inv_det,
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
pub fn minimum_image(cell: Option<&PeriodicCell>, d: Vec2) -> Vec2 {
    match cell {
        Some(c) if c.periodic[0] || c.periodic[1] => {
            let zero = c.origin;
            let f = c.fractional(add(zero, d));
            let mut shift = [0i8; 2];
            for k in 0..2 {
                if c.periodic[k] {
                    shift[k] = -(f[k].round() as i8);
                }
            }
            add(d, c.image_offset(shift))
        }
        _ => d,
    }
}
