//! Plain 2D vector arithmetic on `[f64; 2]`, kept tiny so kernels inline it.

/// A 2D vector (x, y) in SI units.
pub type Vec2 = [f64; 2];

/// `a + b`.
#[inline(always)]
pub fn add(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] + b[0], a[1] + b[1]]
}

/// `a - b`.
#[inline(always)]
pub fn sub(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] - b[0], a[1] - b[1]]
}

/// `s * a`.
#[inline(always)]
pub fn scale(a: Vec2, s: f64) -> Vec2 {
    [a[0] * s, a[1] * s]
}

/// Dot product.
#[inline(always)]
pub fn dot(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// z-component of the cross product `a x b`.
#[inline(always)]
pub fn cross(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Euclidean length.
#[inline(always)]
pub fn norm(a: Vec2) -> f64 {
    dot(a, a).sqrt()
}

/// `a` rotated by +90 degrees: the tangent `t` of a contact with normal `n` is `perp(n)`.
#[inline(always)]
pub fn perp(a: Vec2) -> Vec2 {
    [-a[1], a[0]]
}

/// A 2x2 matrix, row-major: `m[row][col]`.
pub type Mat2 = [[f64; 2]; 2];

/// Identity matrix.
pub const IDENTITY: Mat2 = [[1.0, 0.0], [0.0, 1.0]];

/// `m * v`.
#[inline(always)]
pub fn mat_vec(m: &Mat2, v: Vec2) -> Vec2 {
    [
        m[0][0] * v[0] + m[0][1] * v[1],
        m[1][0] * v[0] + m[1][1] * v[1],
    ]
}

/// `a * b`.
pub fn mat_mul(a: &Mat2, b: &Mat2) -> Mat2 {
    let mut out = [[0.0; 2]; 2];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, value) in row.iter_mut().enumerate() {
            *value = a[r][0] * b[0][c] + a[r][1] * b[1][c];
        }
    }
    out
}

/// Frobenius norm of `m - I`, an upper bound of the spectral norm of the strain it carries.
pub fn distance_from_identity(m: &Mat2) -> f64 {
    let d = [[m[0][0] - 1.0, m[0][1]], [m[1][0], m[1][1] - 1.0]];
    (d[0][0] * d[0][0] + d[0][1] * d[0][1] + d[1][0] * d[1][0] + d[1][1] * d[1][1]).sqrt()
}
