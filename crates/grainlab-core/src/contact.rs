//! Contact geometry: tiny pure functions named after the two shapes.
//!
//! Each returns the unit normal pointing from the first body to the second
//! (from the wall *to the disk* for walls) and the overlap (> 0 in contact).
use crate::vec2::{dot, norm, perp, scale, sub, Vec2};

/// Geometry of a (possible) contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Unit normal from the first body to the second.
    pub normal: Vec2,
    /// Overlap (m): positive when the bodies interpenetrate.
    pub overlap: f64,
}

/// Disk `i` against disk `j` with branch vector `d = x_j - x_i` (image-corrected).
#[inline(always)]
pub fn disk_disk(d: Vec2, r_i: f64, r_j: f64) -> ContactGeometry {
    let dist = norm(d);
    ContactGeometry {
        normal: scale(d, 1.0 / dist),
        overlap: r_i + r_j - dist,
    }
}

/// An infinite line through `point` with unit normal `normal` (pointing to the
/// disks' side) against a disk at `x` of radius `r`. One-sided: a disk that
/// crossed the line is still pushed back to the normal's side.
#[inline(always)]
pub fn line_disk(point: Vec2, normal: Vec2, x: Vec2, r: f64) -> ContactGeometry {
    let signed_distance = dot(sub(x, point), normal);
    ContactGeometry {
        normal,
        overlap: r - signed_distance,
    }
}

/// A segment from `a` to `b` against a disk at `x` of radius `r`; the closest
/// point may be an end point. A disk centred exactly on the segment is pushed
/// along the segment's left normal.
#[inline(always)]
pub fn segment_disk(a: Vec2, b: Vec2, x: Vec2, r: f64) -> ContactGeometry {
    let ab = sub(b, a);
    let t = (dot(sub(x, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
    let closest = [a[0] + t * ab[0], a[1] + t * ab[1]];
    let d = sub(x, closest);
    let dist = norm(d);
    let normal = if dist > 0.0 {
        scale(d, 1.0 / dist)
    } else {
        scale(perp(ab), 1.0 / norm(ab))
    };
    ContactGeometry {
        normal,
        overlap: r - dist,
    }
}

/// Contact point: the middle of the overlap, at distance `r - overlap/2` from the
/// centre `x` of a disk of radius `r`, against the direction `toward` (unit).
#[inline(always)]
pub fn contact_point(x: Vec2, toward: Vec2, r: f64, overlap: f64) -> Vec2 {
    let arm = r - 0.5 * overlap;
    [x[0] + toward[0] * arm, x[1] + toward[1] * arm]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disks_touching_have_zero_overlap() {
        let g = disk_disk([3.0, 4.0], 2.0, 3.0);
        assert_eq!(g.overlap, 0.0);
        assert!((g.normal[0] - 0.6).abs() < 1e-15 && (g.normal[1] - 0.8).abs() < 1e-15);
    }

    #[test]
    fn segment_uses_end_point_beyond_its_ends() {
        let g = segment_disk([0.0, 0.0], [1.0, 0.0], [2.0, 1.0], 1.5);
        let dist = 2.0f64.sqrt();
        assert!((g.overlap - (1.5 - dist)).abs() < 1e-15);
        assert!((g.normal[0] - 1.0 / dist).abs() < 1e-15);
        let g = segment_disk([0.0, 0.0], [1.0, 0.0], [0.5, -0.25], 0.5);
        assert_eq!(g.normal, [0.0, -1.0]);
        assert_eq!(g.overlap, 0.25);
    }

    #[test]
    fn line_is_one_sided() {
        let g = line_disk([0.0, 0.0], [0.0, 1.0], [5.0, -0.1], 0.5);
        assert!((g.overlap - 0.6).abs() < 1e-15);
        assert_eq!(g.normal, [0.0, 1.0]);
    }
}
