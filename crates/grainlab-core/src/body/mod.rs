//! Bodies: a rigid clump of disks ("pebbles") and its mass properties.
//!
//! A body is one disk or a rigid clump of overlapping disks, as PFC2D's and
//! YADE's clumps and LAMMPS's `fix rigid`. A [`ClumpTemplate`] holds the
//! pebbles in the body frame (centred on the body's centroid) and the body's
//! mass and moment of inertia; a [`Placement`] (centroid and angle) puts it in
//! the world. The mass properties are those of the union of the pebbles,
//! computed exactly ([`union_area_properties`]), or given by the user.
//!
//! Per unit thickness, as the engine's disks (`Particles`, thickness 1 m):
//! mass `density * area` (kg per m), moment of inertia `density * J` about the
//! centroid (kg m^2 per m), `J = int |x - centroid|^2 dA` (m^4).
mod clumps;
mod union;

pub(crate) use clumps::ClumpFrame;
pub use clumps::{Clumps, NewClump};
pub use union::{union_area_properties, AreaProperties};

use crate::error::{require_finite_points, require_positive, EngineError, Result};
use crate::vec2::{self, Vec2};

/// Where a body is: its centroid in the world and the angle (radians,
/// counter-clockwise) from its body frame to the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The body's centroid in the world (m).
    pub centroid: Vec2,
    /// Rotation of the body frame, counter-clockwise (rad).
    pub angle: f64,
}

impl Placement {
    /// `offset` (body frame) rotated by the angle: the offset in the world frame.
    pub fn rotate(&self, offset: Vec2) -> Vec2 {
        let (s, c) = self.angle.sin_cos();
        [c * offset[0] - s * offset[1], s * offset[0] + c * offset[1]]
    }
}

/// Mass properties given by the user instead of computed from the pebbles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GivenMass {
    /// Mass per unit thickness (kg per m), finite and > 0.
    pub mass: f64,
    /// Moment of inertia about `centroid` per unit thickness (kg m^2 per m), finite and > 0.
    pub moment_of_inertia: f64,
    /// The body's centroid, in the frame of the pebble centres (m).
    pub centroid: Vec2,
}

/// A rigid clump of pebbles in its body frame, with its mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct ClumpTemplate {
    offsets: Vec<Vec2>,
    radii: Vec<f64>,
    area: f64,
    mass: f64,
    moment_of_inertia: f64,
}

impl ClumpTemplate {
    /// A clump from its pebbles' centres (any frame) and a density (kg/m^3):
    /// the exact mass properties of the pebbles' union. The body frame is
    /// centred on the union's centroid with the given frame's axes, so the
    /// clump sits at that centroid, angle 0 (the returned [`Placement`]).
    /// A single pebble gets exactly the mass and inertia of the engine's disk
    /// (`density pi r^2`, `m r^2 / 2`, in the same operations).
    pub fn from_pebbles(
        centres: &[Vec2],
        radii: &[f64],
        density: f64,
    ) -> Result<(Self, Placement)> {
        require_positive("density", density)?;
        let union = union_area_properties(centres, radii)?;
        let (mass, moment_of_inertia) = if radii.len() == 1 {
            let r = radii[0];
            let m = density * std::f64::consts::PI * r * r;
            (m, 0.5 * m * r * r)
        } else {
            (density * union.area, density * union.polar_moment)
        };
        Ok(Self::centred(
            centres,
            radii,
            union,
            mass,
            moment_of_inertia,
        ))
    }

    /// A clump from its pebbles' centres and mass properties given by the user:
    /// the body frame is centred on `given.centroid`, whatever the pebbles'
    /// union's centroid. The area is still the union's.
    pub fn with_mass(
        centres: &[Vec2],
        radii: &[f64],
        given: GivenMass,
    ) -> Result<(Self, Placement)> {
        require_positive("mass", given.mass)?;
        require_positive("moment_of_inertia", given.moment_of_inertia)?;
        require_finite_points("centroid", &[given.centroid])?;
        let mut union = union_area_properties(centres, radii)?;
        union.centroid = given.centroid;
        Ok(Self::centred(
            centres,
            radii,
            union,
            given.mass,
            given.moment_of_inertia,
        ))
    }

    fn centred(
        centres: &[Vec2],
        radii: &[f64],
        union: AreaProperties,
        mass: f64,
        moment_of_inertia: f64,
    ) -> (Self, Placement) {
        let template = ClumpTemplate {
            offsets: centres
                .iter()
                .map(|&c| vec2::sub(c, union.centroid))
                .collect(),
            radii: radii.to_vec(),
            area: union.area,
            mass,
            moment_of_inertia,
        };
        let placement = Placement {
            centroid: union.centroid,
            angle: 0.0,
        };
        (template, placement)
    }

    /// Pebble centres relative to the centroid, in the body frame (m).
    pub fn offsets(&self) -> &[Vec2] {
        &self.offsets
    }

    /// Pebble radii (m).
    pub fn radii(&self) -> &[f64] {
        &self.radii
    }

    /// Number of pebbles (at least one).
    pub fn pebble_count(&self) -> usize {
        self.radii.len()
    }

    /// Area of the pebbles' union (m^2), each point counted once.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Mass per unit thickness (kg per m).
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Moment of inertia about the centroid per unit thickness (kg m^2 per m).
    pub fn moment_of_inertia(&self) -> f64 {
        self.moment_of_inertia
    }

    /// The pebbles' centres in the world: `centroid + R(angle) offset`.
    pub fn pebble_positions(&self, placement: &Placement) -> Vec<Vec2> {
        self.offsets
            .iter()
            .map(|&o| vec2::add(placement.centroid, placement.rotate(o)))
            .collect()
    }

    /// The placement that puts this clump's pebbles at `positions` (world),
    /// the inverse of [`ClumpTemplate::pebble_positions`]: the rotation and
    /// translation closest to them in least squares (exact for a rigidly
    /// moved clump), angle in `(-pi, pi]`. A clump whose pebbles share one
    /// centre has no angle to read, and is refused.
    pub fn placement_of(&self, positions: &[Vec2]) -> Result<Placement> {
        if positions.len() != self.offsets.len() {
            return Err(EngineError::invalid(
                "positions",
                format!(
                    "has {} entries but the clump has {} pebbles",
                    positions.len(),
                    self.offsets.len()
                ),
            ));
        }
        require_finite_points("positions", positions)?;
        let n = positions.len() as f64;
        let mean = |points: &[Vec2]| {
            vec2::scale(
                points.iter().fold([0.0, 0.0], |s, &p| vec2::add(s, p)),
                1.0 / n,
            )
        };
        let (body_mean, world_mean) = (mean(&self.offsets), mean(positions));
        let (mut along, mut across, mut spread) = (0.0, 0.0, 0.0);
        for (&o, &p) in self.offsets.iter().zip(positions) {
            let (o, p) = (vec2::sub(o, body_mean), vec2::sub(p, world_mean));
            along += vec2::dot(o, p);
            across += vec2::cross(o, p);
            spread += vec2::dot(o, o);
        }
        if spread == 0.0 {
            return Err(EngineError::invalid(
                "positions",
                "the pebbles share one centre, so the clump's angle is undefined",
            ));
        }
        let mut placement = Placement {
            centroid: [0.0, 0.0],
            angle: across.atan2(along),
        };
        placement.centroid = vec2::sub(world_mean, placement.rotate(body_mean));
        Ok(placement)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_input_names_the_field() {
        let field = |r: Result<(ClumpTemplate, Placement)>| match r {
            Err(EngineError::InvalidInput { field, .. }) => field,
            other => panic!("expected bad input, got {other:?}"),
        };
        let c = [[0.0, 0.0], [1.0, 0.0]];
        assert_eq!(field(ClumpTemplate::from_pebbles(&[], &[], 1.0)), "radii");
        assert_eq!(
            field(ClumpTemplate::from_pebbles(&c, &[1.0, 0.0], 1.0)),
            "radii[1]"
        );
        assert_eq!(
            field(ClumpTemplate::from_pebbles(&c, &[1.0, f64::NAN], 1.0)),
            "radii[1]"
        );
        assert_eq!(
            field(ClumpTemplate::from_pebbles(&c, &[1.0], 1.0)),
            "centres"
        );
        let bad = [[0.0, 0.0], [f64::INFINITY, 0.0]];
        assert_eq!(
            field(ClumpTemplate::from_pebbles(&bad, &[1.0, 1.0], 1.0)),
            "centres[1]"
        );
        assert_eq!(
            field(ClumpTemplate::from_pebbles(&c, &[1.0, 1.0], -2.0)),
            "density"
        );
        let given = |mass, moment_of_inertia| GivenMass {
            mass,
            moment_of_inertia,
            centroid: [0.5, 0.0],
        };
        assert_eq!(
            field(ClumpTemplate::with_mass(&c, &[1.0, 1.0], given(0.0, 1.0))),
            "mass"
        );
        assert_eq!(
            field(ClumpTemplate::with_mass(&c, &[1.0, 1.0], given(1.0, -1.0))),
            "moment_of_inertia"
        );
        let mut nan_centroid = given(1.0, 1.0);
        nan_centroid.centroid = [f64::NAN, 0.0];
        assert_eq!(
            field(ClumpTemplate::with_mass(&c, &[1.0, 1.0], nan_centroid)),
            "centroid[0]"
        );
    }

    #[test]
    fn given_mass_sets_the_body_frame() {
        let c = [[0.0, 0.0], [1.0, 0.0]];
        let given = GivenMass {
            mass: 3.0,
            moment_of_inertia: 0.25,
            centroid: [0.25, 0.5],
        };
        let (template, placement) = ClumpTemplate::with_mass(&c, &[0.6, 0.6], given).unwrap();
        assert_eq!(placement.centroid, [0.25, 0.5]);
        assert_eq!(template.offsets(), &[[-0.25, -0.5], [0.75, -0.5]]);
        assert_eq!((template.mass(), template.moment_of_inertia()), (3.0, 0.25));
        assert_eq!(template.pebble_positions(&placement), c.to_vec());
    }

    #[test]
    fn placement_of_a_single_pebble_is_refused() {
        let (template, _) = ClumpTemplate::from_pebbles(&[[1.0, 2.0]], &[0.5], 1.0).unwrap();
        assert!(matches!(
            template.placement_of(&[[0.0, 0.0]]),
            Err(EngineError::InvalidInput { .. })
        ));
        assert!(template.placement_of(&[[0.0, 0.0], [1.0, 1.0]]).is_err());
    }
}
