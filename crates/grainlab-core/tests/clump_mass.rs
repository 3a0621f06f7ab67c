//! The exact mass properties of a clump (the union of its pebbles) against
//! closed forms and an independent raster count.
use grainlab_core::body::{union_area_properties, AreaProperties, ClumpTemplate, Placement};
use grainlab_core::vec2::Vec2;
use grainlab_core::Particles;
use std::f64::consts::{PI, SQRT_2};

/// Area of the lens where two disks of radius `r`, centres `d` apart, overlap.
fn lens_area(r: f64, d: f64) -> f64 {
    2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * (4.0 * r * r - d * d).sqrt()
}

/// The union's area, first moments and polar moment about the origin counted
/// on a raster refined where the boundary is (a quadtree), with a rigorous
/// bound of the count's error: independent of the arcs, it only asks whether a
/// square is wholly inside some disk, wholly outside all, or neither.
///
/// A square of half-side `s` and centre `x` is wholly inside disk `k` when
/// `|x - c_k| + s sqrt 2 <= r_k`, wholly outside when `|x - c_k| - s sqrt 2 >= r_k`
/// for every `k`; those squares count exactly (the integrals of `1`, `x`, `y`,
/// `x^2 + y^2` over a square are closed forms). Undecided squares are split
/// into four down to `depth` levels; an undecided square of the last level is
/// counted whole if its centre is in the union, and may be wrong by at most
/// the integral of `|f|` over it, which the bound sums. The bound is
/// therefore about `1.3 L h` for the area (`L` the boundary's length, `h` the
/// last level's side): at `depth = 16` a few parts in 10^4 of the area.
struct Raster {
    area: f64,
    first: Vec2,
    polar: f64,
    /// Largest possible |error| of each: area, first moments, polar moment.
    bound: [f64; 3],
}

impl Raster {
    fn count(&mut self, centres: &[Vec2], radii: &[f64], x: Vec2, s: f64, depth: u32) {
        let reach = s * SQRT_2;
        let dist =
            |k: usize| ((x[0] - centres[k][0]).powi(2) + (x[1] - centres[k][1]).powi(2)).sqrt();
        let n = radii.len();
        let inside = (0..n).any(|k| dist(k) + reach <= radii[k]);
        let outside = (0..n).all(|k| dist(k) - reach >= radii[k]);
        if outside {
            return;
        }
        let cell = 4.0 * s * s;
        let polar = cell * (x[0] * x[0] + x[1] * x[1] + 2.0 * s * s / 3.0);
        if inside || depth == 0 {
            if inside || (0..n).any(|k| dist(k) < radii[k]) {
                self.area += cell;
                self.first[0] += cell * x[0];
                self.first[1] += cell * x[1];
                self.polar += polar;
            }
            if !inside {
                let far = x[0].abs().max(x[1].abs()) + s;
                self.bound[0] += cell;
                self.bound[1] += cell * far;
                self.bound[2] += polar;
            }
            return;
        }
        let half = 0.5 * s;
        for (dx, dy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            let corner = [x[0] + dx * half, x[1] + dy * half];
            self.count(centres, radii, corner, half, depth - 1);
        }
    }
}

fn raster(centres: &[Vec2], radii: &[f64], depth: u32) -> Raster {
    let mut r = Raster {
        area: 0.0,
        first: [0.0, 0.0],
        polar: 0.0,
        bound: [0.0; 3],
    };
    let reach = centres
        .iter()
        .zip(radii)
        .map(|(c, r)| c[0].abs().max(c[1].abs()) + r)
        .fold(0.0, f64::max);
    r.count(centres, radii, [0.0, 0.0], reach, depth);
    r
}

/// The exact properties agree with the raster within its error bound; the
/// raster is about the origin, so the exact moments are moved there.
fn assert_matches_raster(centres: &[Vec2], radii: &[f64], depth: u32) -> AreaProperties {
    let exact = union_area_properties(centres, radii).unwrap();
    let r = raster(centres, radii, depth);
    let c = exact.centroid;
    let first = [exact.area * c[0], exact.area * c[1]];
    let polar = exact.polar_moment + exact.area * (c[0] * c[0] + c[1] * c[1]);
    let report = format!(
        "exact {exact:?}, raster area {} first {:?} polar {} bound {:?}",
        r.area, r.first, r.polar, r.bound
    );
    assert!((exact.area - r.area).abs() <= r.bound[0], "area: {report}");
    assert!(
        (first[0] - r.first[0]).abs() <= r.bound[1],
        "first x: {report}"
    );
    assert!(
        (first[1] - r.first[1]).abs() <= r.bound[1],
        "first y: {report}"
    );
    assert!((polar - r.polar).abs() <= r.bound[2], "polar: {report}");
    exact
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn two_equal_disks_are_two_disks_less_their_lens() {
    let r = 1.5e-3;
    for d in [0.1 * r, 0.8 * r, 1.3 * r, 1.999 * r] {
        let c = [[-0.5 * d, 0.0], [0.5 * d, 0.0]];
        let u = union_area_properties(&c, &[r, r]).unwrap();
        let expected = 2.0 * PI * r * r - lens_area(r, d);
        assert!(
            rel(u.area, expected) < 1e-13,
            "d = {d}: {} vs {expected}",
            u.area
        );
        // the midpoint by symmetry
        assert!(
            u.centroid[0].abs() < 1e-15 * r && u.centroid[1].abs() < 1e-15 * r,
            "{u:?}"
        );
    }
}

#[test]
fn disks_of_different_radii_against_a_raster() {
    let pair = ([[0.0, 0.0], [1.1, 0.4]], [1.0, 0.6]);
    let u = assert_matches_raster(&pair.0, &pair.1, 16);
    // the pair overlaps: less than the two disks, more than the larger one
    assert!(u.area < PI * (1.0 + 0.36) - 0.1 && u.area > PI);
    // three disks with a region common to all three (the origin is in every one)
    let trio = ([[0.0, 0.5], [0.45, -0.3], [-0.5, -0.35]], [0.8, 0.7, 0.9]);
    assert_matches_raster(&trio.0, &trio.1, 16);
}

#[test]
fn a_ring_of_pebbles_leaves_its_hole_out() {
    // eight pebbles on a circle of radius 2 r: neighbours overlap (chord
    // 1.53 r < 2 r), the next but one do not (2.83 r), and the centre is
    // covered by none: a hole of about 2 r^2
    let (r, ring) = (1.0, 2.0);
    let centres: Vec<Vec2> = (0..8)
        .map(|k| {
            let t = k as f64 * PI / 4.0 + 0.1;
            [3.0 + ring * t.cos(), -1.0 + ring * t.sin()]
        })
        .collect();
    let radii = vec![r; 8];
    let u = assert_matches_raster(&centres, &radii, 16);
    // exact by inclusion-exclusion, neighbours' lenses only
    let chord = 2.0 * ring * (PI / 8.0).sin();
    let expected = 8.0 * (PI * r * r - lens_area(r, chord));
    assert!(rel(u.area, expected) < 1e-13, "{} vs {expected}", u.area);
    // the ring's centre by symmetry
    assert!((u.centroid[0] - 3.0).abs() < 1e-13 && (u.centroid[1] + 1.0).abs() < 1e-13);
    // the hole holds at least the disk of radius ring - r about the centre;
    // counted as material it would be far outside the raster's bound
    let hole = PI * (ring - r) * (ring - r);
    assert!(raster(&centres, &radii, 16).bound[0] < 0.01 * hole);
}

#[test]
fn a_disk_inside_another_is_the_outer_disk() {
    let outer = union_area_properties(&[[0.2, 0.3]], &[1.0]).unwrap();
    for (inner, radius) in [([0.4, 0.1], 0.5), ([0.7, 0.3], 0.5), ([0.2, 0.3], 1.0)] {
        // strictly inside, touching the outer circle from inside, identical
        for centres in [[[0.2, 0.3], inner], [inner, [0.2, 0.3]]] {
            let radii = if centres[0] == inner {
                [radius, 1.0]
            } else {
                [1.0, radius]
            };
            let u = union_area_properties(&centres, &radii).unwrap();
            assert!(rel(u.area, outer.area) < 1e-15, "{u:?}");
            assert!((u.centroid[0] - 0.2).abs() < 1e-15 && (u.centroid[1] - 0.3).abs() < 1e-15);
            assert!(rel(u.polar_moment, PI / 2.0) < 1e-14, "{u:?}");
        }
    }
    // three identical pebbles are one
    let same = union_area_properties(&[[1.0, 1.0]; 3], &[0.3; 3]).unwrap();
    assert!(rel(same.area, PI * 0.09) < 1e-15 && rel(same.polar_moment, PI * 0.0081 / 2.0) < 1e-14);
}

#[test]
fn apart_or_touching_disks_add_with_the_parallel_axis_theorem() {
    let radii = [1.0, 0.5];
    for gap in [2.0, 0.0] {
        // the second touches the first at one point when the gap is zero
        let centres = [[0.0, 0.0], [1.5 + gap, 0.0]];
        let u = union_area_properties(&centres, &radii).unwrap();
        let (a1, a2) = (PI, PI * 0.25);
        let area = a1 + a2;
        let cx = a2 * centres[1][0] / area;
        let polar = a1 * 0.5 + a1 * cx * cx + a2 * 0.125 + a2 * (centres[1][0] - cx).powi(2);
        assert!(rel(u.area, area) < 1e-15, "{u:?}");
        assert!(
            rel(u.centroid[0], cx) < 1e-14 && u.centroid[1] == 0.0,
            "{u:?}"
        );
        assert!(rel(u.polar_moment, polar) < 1e-14, "{u:?} vs {polar}");
    }
    // a hair's overlap changes the area by about the lens only, continuously
    let d = 2.0 * (1.0 - 1e-9);
    let u = union_area_properties(&[[0.0, 0.0], [d, 0.0]], &[1.0, 1.0]).unwrap();
    assert!(rel(u.area, 2.0 * PI - lens_area(1.0, d)) < 1e-14);
}

#[test]
fn moving_a_clump_moves_its_centroid_and_keeps_area_and_moment() {
    let centres = [[0.0, 0.5], [0.45, -0.3], [-0.5, -0.35], [1.2, 0.2]];
    let radii = [0.8, 0.7, 0.9, 0.4];
    let base = union_area_properties(&centres, &radii).unwrap();
    for (angle, shift) in [
        (0.3, [10.0, -4.0]),
        (2.9, [-1e-3, 2e-3]),
        (-1.7, [0.0, 0.0]),
    ] {
        let placement = Placement {
            centroid: shift,
            angle,
        };
        let moved: Vec<Vec2> = centres
            .iter()
            .map(|&c| {
                let p = placement.rotate(c);
                [p[0] + shift[0], p[1] + shift[1]]
            })
            .collect();
        let u = union_area_properties(&moved, &radii).unwrap();
        assert!(rel(u.area, base.area) < 1e-13, "{u:?} vs {base:?}");
        assert!(
            rel(u.polar_moment, base.polar_moment) < 1e-12,
            "{u:?} vs {base:?}"
        );
        let expected = placement.rotate(base.centroid);
        for k in 0..2 {
            assert!(
                (u.centroid[k] - expected[k] - shift[k]).abs() < 1e-12,
                "{u:?}"
            );
        }
    }
}

#[test]
fn a_template_is_centred_and_placed_and_found_again() {
    let centres = [[2.0, 1.0], [2.9, 1.2], [2.3, 1.8]];
    let radii = [0.5, 0.4, 0.45];
    let density = 2650.0;
    let (template, at) = ClumpTemplate::from_pebbles(&centres, &radii, density).unwrap();
    let u = union_area_properties(&centres, &radii).unwrap();
    assert_eq!(
        at,
        Placement {
            centroid: u.centroid,
            angle: 0.0
        }
    );
    assert_eq!(template.mass(), density * u.area);
    assert_eq!(template.moment_of_inertia(), density * u.polar_moment);
    // the body frame is centred: the offsets' union has its centroid at 0
    let centred = union_area_properties(template.offsets(), template.radii()).unwrap();
    assert!(centred.centroid[0].abs() < 1e-15 && centred.centroid[1].abs() < 1e-15);
    // placed at angle 0 the pebbles are where they were given
    for (p, c) in template.pebble_positions(&at).iter().zip(&centres) {
        assert!((p[0] - c[0]).abs() < 1e-15 && (p[1] - c[1]).abs() < 1e-15);
    }
    for angle in [0.0, 1.0, -3.0, 3.1] {
        let placement = Placement {
            centroid: [-7.0, 0.25],
            angle,
        };
        let found = template
            .placement_of(&template.pebble_positions(&placement))
            .unwrap();
        assert!((found.angle - angle).abs() < 1e-14, "{found:?} vs {angle}");
        assert!(
            (found.centroid[0] + 7.0).abs() < 1e-14 && (found.centroid[1] - 0.25).abs() < 1e-14
        );
    }
}

#[test]
fn a_one_pebble_clump_has_the_engines_disk_mass_to_the_bit() {
    for (r, density) in [(1e-3, 2650.0), (0.37e-3, 2e8), (2.5, 1.0)] {
        let (template, at) = ClumpTemplate::from_pebbles(&[[0.1, -0.2]], &[r], density).unwrap();
        let disk = Particles::new(vec![[0.1, -0.2]], vec![r], vec![density]).unwrap();
        assert_eq!(template.mass().to_bits(), disk.mass[0].to_bits());
        assert_eq!(
            template.moment_of_inertia().to_bits(),
            disk.inertia[0].to_bits()
        );
        assert_eq!(at.centroid, [0.1, -0.2]);
        assert_eq!(template.offsets(), &[[0.0, 0.0]]);
        // and the union's closed form agrees with it to round-off
        assert!(rel(template.area(), PI * r * r) < 1e-15);
    }
}
