//! Area properties of a union of disks, exact: Green's theorem over the arcs of
//! the union's boundary.
//!
//! The boundary of a union of disks is made of arcs of their circles: the parts
//! of each circle inside no other disk. Each such arc, traversed
//! counter-clockwise about its own disk's centre, has the union on its left,
//! including the arcs that bound a hole (there the disk is on the left and the
//! hole on the right, so the hole's boundary is traversed clockwise, as Green's
//! theorem wants). So every integral over the union is a sum over the arcs of
//! closed-form line integrals, and an area covered by several disks is counted
//! once: no overlap is ever subtracted. docs/bodies.md writes the formulas out.
use crate::error::{require_finite_points, require_positive, EngineError, Result};
use crate::vec2::{self, Vec2};
use std::f64::consts::{PI, TAU};

/// Area, centroid and polar second moment of area of a plane region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaProperties {
    /// Area (m^2).
    pub area: f64,
    /// Centroid (m).
    pub centroid: Vec2,
    /// Polar second moment of area about the centroid, `int |x - centroid|^2 dA` (m^4).
    pub polar_moment: f64,
}

/// The integrals of `1`, `x`, `y` and `x^2 + y^2` over a region, about an origin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Moments {
    area: f64,
    first: Vec2,
    polar: f64,
}

impl Moments {
    fn add(&mut self, other: Moments) {
        self.area += other.area;
        self.first = vec2::add(self.first, other.first);
        self.polar += other.polar;
    }

    /// A whole disk: `pi r^2`, `pi r^2 c`, `pi r^2 (r^2 / 2 + |c|^2)`.
    fn disk(centre: Vec2, r: f64) -> Moments {
        let area = PI * r * r;
        Moments {
            area,
            first: vec2::scale(centre, area),
            polar: area * (0.5 * r * r + vec2::dot(centre, centre)),
        }
    }

    /// The line integrals along the arc of the circle (`centre`, `r`) from
    /// angle `a` to `b > a`, counter-clockwise: the differences of
    /// [`Moments::antiderivative`].
    fn arc(centre: Vec2, r: f64, a: f64, b: f64) -> Moments {
        let end = Moments::antiderivative(centre, r, b);
        let start = Moments::antiderivative(centre, r, a);
        Moments {
            area: end.area - start.area,
            first: vec2::sub(end.first, start.first),
            polar: end.polar - start.polar,
        }
    }

    /// The antiderivatives in the angle `t` of the four line integrals on the
    /// circle `x = p + r cos t`, `y = q + r sin t`:
    /// area `(x dy - y dx) / 2`, first moments `x^2 dy / 2` and `-y^2 dx / 2`,
    /// polar moment `(x^3 dy - y^3 dx) / 3`.
    fn antiderivative(centre: Vec2, r: f64, t: f64) -> Moments {
        let [p, q] = centre;
        let (s, c) = t.sin_cos();
        let sc = s * c;
        let sin_4t = 4.0 * sc * (c * c - s * s);
        let area = 0.5 * (r * p * s - r * q * c + r * r * t);
        let first_x = 0.5 * r * (p * p * s + p * r * (t + sc) + r * r * (s - s * s * s / 3.0));
        let first_y = 0.5 * r * (-q * q * c + q * r * (t - sc) + r * r * (c * c * c / 3.0 - c));
        let x_terms =
            p * p * p * s + 1.5 * p * p * r * (t + sc) + 3.0 * p * r * r * (s - s * s * s / 3.0);
        let y_terms =
            -q * q * q * c + 1.5 * q * q * r * (t - sc) + 3.0 * q * r * r * (c * c * c / 3.0 - c);
        let both = r * r * r * (0.75 * t + sin_4t / 16.0);
        Moments {
            area,
            first: [first_x, first_y],
            polar: r / 3.0 * (x_terms + y_terms + both),
        }
    }
}

/// What of disk `i`'s circle lies on the union's boundary.
#[derive(Debug, Clone, PartialEq)]
enum Boundary {
    /// The whole circle: no other disk reaches inside it.
    Whole,
    /// These arcs, `(a, b)` with `0 <= a < b <= 2 pi`, counter-clockwise from
    /// the +x axis; none if another disk covers the whole disk.
    Arcs(Vec<(f64, f64)>),
}

/// The arcs of disk `i`'s circle inside no other disk. Of two disks equal to
/// round-off (each inside the other) the later one is covered, so the pair
/// counts once; tangent disks cover only a point of each other's circles.
fn boundary_of(i: usize, centres: &[Vec2], radii: &[f64]) -> Boundary {
    let (ci, ri) = (centres[i], radii[i]);
    let mut covered: Vec<(f64, f64)> = Vec::new();
    for (j, (&cj, &rj)) in centres.iter().zip(radii).enumerate() {
        if j == i {
            continue;
        }
        let between = vec2::sub(cj, ci);
        let d = vec2::norm(between);
        if d + ri <= rj {
            let same = d + rj <= ri;
            if !same || j < i {
                return Boundary::Arcs(Vec::new());
            }
            continue;
        }
        if d >= ri + rj || d + rj <= ri {
            continue; // apart, touching, or disk j inside disk i
        }
        let cos_half = ((d * d + ri * ri - rj * rj) / (2.0 * d * ri)).clamp(-1.0, 1.0);
        let half = cos_half.acos();
        let start = (between[1].atan2(between[0]) - half).rem_euclid(TAU);
        let end = start + 2.0 * half;
        if end > TAU {
            covered.push((start, TAU));
            covered.push((0.0, end - TAU));
        } else {
            covered.push((start, end));
        }
    }
    if covered.is_empty() {
        return Boundary::Whole;
    }
    Boundary::Arcs(uncovered(covered))
}

/// The complement in `[0, 2 pi]` of a union of intervals within it.
fn uncovered(mut covered: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    covered.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut arcs = Vec::new();
    let mut reached = 0.0_f64;
    for (start, end) in covered {
        if start > reached {
            arcs.push((reached, start));
        }
        reached = reached.max(end);
    }
    if reached < TAU {
        arcs.push((reached, TAU));
    }
    arcs
}

/// Checks pebble centres and radii: at least one pebble, as many radii as
/// centres, finite centres, finite positive radii.
pub(crate) fn check_pebbles(field: &str, centres: &[Vec2], radii: &[f64]) -> Result<()> {
    if radii.is_empty() {
        return Err(EngineError::invalid(
            "radii",
            "a clump needs at least one pebble, got none",
        ));
    }
    if centres.len() != radii.len() {
        return Err(EngineError::invalid(
            field,
            format!(
                "has {} entries but radii has {}",
                centres.len(),
                radii.len()
            ),
        ));
    }
    require_finite_points(field, centres)?;
    for (k, &r) in radii.iter().enumerate() {
        require_positive(&format!("radii[{k}]"), r)?;
    }
    Ok(())
}

/// The exact area, centroid and polar second moment of the union of the disks
/// (`centres[k]`, `radii[k]`), however they overlap: each point of the plane
/// covered by any number of disks counts once. A hole (a region enclosed by
/// the disks but covered by none) is not part of the union.
///
/// The sums are taken about the mean of the centres, so that moving the disks
/// together changes the result only by round-off. One disk gives
/// `pi r^2`, its centre and `pi r^4 / 2` exactly as written.
pub fn union_area_properties(centres: &[Vec2], radii: &[f64]) -> Result<AreaProperties> {
    check_pebbles("centres", centres, radii)?;
    let n = centres.len() as f64;
    let sum = centres.iter().fold([0.0, 0.0], |s, &c| vec2::add(s, c));
    let origin = vec2::scale(sum, 1.0 / n);
    let local: Vec<Vec2> = centres.iter().map(|&c| vec2::sub(c, origin)).collect();
    let mut total = Moments::default();
    for (i, (&c, &r)) in local.iter().zip(radii).enumerate() {
        match boundary_of(i, &local, radii) {
            Boundary::Whole => total.add(Moments::disk(c, r)),
            Boundary::Arcs(arcs) => {
                for (a, b) in arcs {
                    total.add(Moments::arc(c, r, a, b));
                }
            }
        }
    }
    let offset = vec2::scale(total.first, 1.0 / total.area);
    Ok(AreaProperties {
        area: total.area,
        centroid: vec2::add(origin, offset),
        polar_moment: total.polar - total.area * vec2::dot(offset, offset),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    #[test]
    fn a_whole_circle_by_arcs_is_the_disk() {
        let c = [0.3, -0.7];
        let r = 0.9;
        let by_arc = Moments::arc(c, r, 0.0, TAU);
        let disk = Moments::disk(c, r);
        assert!(close(by_arc.area, disk.area, 1e-14));
        assert!(close(by_arc.first[0], disk.first[0], 1e-14));
        assert!(close(by_arc.first[1], disk.first[1], 1e-14));
        assert!(close(by_arc.polar, disk.polar, 1e-14));
    }

    #[test]
    fn half_circles_and_their_chords_give_half_disks() {
        // the upper half-disk of the unit circle at the origin: boundary = the
        // arc 0..pi and the chord along the x axis, on which x dy = y dx = 0,
        // so the arc alone gives the half-disk: area pi/2, centroid y 4/(3 pi),
        // polar moment about the origin pi/4
        let m = Moments::arc([0.0, 0.0], 1.0, 0.0, PI);
        assert!(close(m.area, PI / 2.0, 1e-15));
        assert!(m.first[0].abs() < 1e-15);
        assert!(close(m.first[1] / m.area, 4.0 / (3.0 * PI), 1e-15));
        assert!(close(m.polar, PI / 4.0, 1e-15));
    }

    #[test]
    fn overlapping_pair_leaves_each_circle_its_far_arc() {
        let centres = [[0.0, 0.0], [1.0, 0.0]];
        let radii = [1.0, 1.0];
        // the second disk covers the first circle's arc within 60 degrees of +x
        let Boundary::Arcs(arcs) = boundary_of(0, &centres, &radii) else {
            panic!("the circle is partly covered")
        };
        assert_eq!(arcs.len(), 1);
        assert!(close(arcs[0].0, PI / 3.0, 1e-15) && close(arcs[0].1, 5.0 * PI / 3.0, 1e-15));
    }

    #[test]
    fn disk_inside_another_and_equal_disks_count_once() {
        let centres = [[0.0, 0.0], [0.2, 0.1], [0.0, 0.0]];
        let radii = [1.0, 0.5, 1.0];
        assert_eq!(boundary_of(1, &centres, &radii), Boundary::Arcs(Vec::new()));
        assert_eq!(boundary_of(2, &centres, &radii), Boundary::Arcs(Vec::new()));
        // the first of the equal pair keeps its whole circle: the inner disk
        // and the later copy do not cut it
        assert_eq!(boundary_of(0, &centres, &radii), Boundary::Whole);
    }

    #[test]
    fn complement_of_wrapped_intervals() {
        let arcs = uncovered(vec![(5.0, TAU), (0.0, 0.5), (1.0, 2.0), (1.5, 3.0)]);
        assert_eq!(arcs, vec![(0.5, 1.0), (3.0, 5.0)]);
    }
}
