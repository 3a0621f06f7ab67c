//! Rigid walls: straight segments or infinite lines, translating under velocity
//! or servo control.
//!
//! Orientation: the particle side of a wall is the side its *inward normal*
//! points to. For a segment `a -> b` that is the left normal `perp(b - a)`; for
//! a line it is the normal given. Segments interact on both sides (and at their
//! end points); lines are one-sided. The inward normal is what servo control
//! and the wall's normal stress refer to.
use serde::{Deserialize, Serialize};

use crate::contact::{line_disk, segment_disk, ContactGeometry};
use crate::error::{require_finite, require_non_negative, require_positive, EngineError, Result};
use crate::vec2::{add, dot, norm, perp, scale, sub, Vec2};

/// Shape of a wall.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WallShape {
    /// Segment from `a` to `b` (m).
    Segment {
        /// Start point.
        a: Vec2,
        /// End point.
        b: Vec2,
    },
    /// Infinite line through `point` with unit `normal` towards the particles.
    Line {
        /// A point of the line.
        point: Vec2,
        /// Unit normal pointing to the particles' side.
        normal: Vec2,
    },
}

/// Servo control of a wall's normal stress (PFC-style).
///
/// Each step the wall's speed along its inward normal is
/// `u = G (sigma_target - sigma)`, with gain `G = relaxation * length / (k_n * dt)`,
/// `k_n` the summed normal stiffness of the wall's contacts, capped at
/// `max_speed`; with no contact the wall advances at `max_speed`. The stress
/// change per step is then `relaxation` times the error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ServoControl {
    /// Target normal stress, compression positive (Pa).
    pub target_stress: f64,
    /// Length over which the wall force is spread to give a stress (m, unit thickness).
    pub loaded_length: f64,
    /// Fraction of the stress error corrected per step, in (0, 1].
    pub relaxation: f64,
    /// Speed cap (m/s).
    pub max_speed: f64,
}

impl ServoControl {
    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        require_non_negative("servo.target_stress", self.target_stress)?;
        require_positive("servo.loaded_length", self.loaded_length)?;
        require_positive("servo.max_speed", self.max_speed)?;
        if !(self.relaxation > 0.0 && self.relaxation <= 1.0) {
            return Err(EngineError::invalid(
                "servo.relaxation",
                format!("must be in (0, 1], got {}", self.relaxation),
            ));
        }
        Ok(())
    }
}

/// How a wall moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WallControl {
    /// Constant prescribed velocity.
    Velocity,
    /// Velocity along the inward normal from a stress servo.
    Servo(ServoControl),
}

/// A rigid wall and what it measured in the last step.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Wall {
    /// Geometry, in current position.
    pub shape: WallShape,
    /// Velocity (m/s).
    pub velocity: Vec2,
    /// Control mode.
    pub control: WallControl,
    /// Material group (for the contact model).
    pub group: u8,
    /// Force exerted by the particles on the wall in the last step (N).
    pub force: Vec2,
    /// Number of particles touching the wall in the last step.
    pub contact_count: u32,
    /// Summed normal stiffness of those contacts (N/m), for the servo gain.
    pub stiffness_sum: f64,
    /// Total displacement since the wall was created (m).
    pub displacement: Vec2,
    /// Displacement made at its velocity in the last step (m; zero before the
    /// first step and while inactive), for the work ledger's trapezoid.
    pub last_step_displacement: Vec2,
    /// An inactive wall has no contacts and does not move (e.g. the rigid side
    /// walls once a flexible boundary replaced them).
    pub active: bool,
}

impl Wall {
    /// A wall at rest under velocity control.
    pub fn new(shape: WallShape, group: u8) -> Result<Self> {
        match shape {
            WallShape::Segment { a, b } => {
                for v in [a, b] {
                    require_finite("wall.a/b", v[0])?;
                    require_finite("wall.a/b", v[1])?;
                }
                if norm(sub(b, a)) == 0.0 {
                    return Err(EngineError::invalid(
                        "wall",
                        "segment end points must differ",
                    ));
                }
            }
            WallShape::Line { point, normal } => {
                require_finite("wall.point", point[0])?;
                require_finite("wall.point", point[1])?;
                let len = norm(normal);
                if !(len.is_finite() && (len - 1.0).abs() < 1e-9) {
                    return Err(EngineError::invalid(
                        "wall.normal",
                        format!("must be a unit vector, got length {len}"),
                    ));
                }
            }
        }
        if group as usize >= crate::state::MAX_GROUPS {
            return Err(EngineError::invalid("wall.group", "out of range 0..16"));
        }
        Ok(Wall {
            shape,
            velocity: [0.0; 2],
            control: WallControl::Velocity,
            group,
            force: [0.0; 2],
            contact_count: 0,
            stiffness_sum: 0.0,
            displacement: [0.0; 2],
            last_step_displacement: [0.0; 2],
            active: true,
        })
    }

    /// Unit normal pointing to the particles' side.
    pub fn inward_normal(&self) -> Vec2 {
        match self.shape {
            WallShape::Segment { a, b } => {
                let p = perp(sub(b, a));
                scale(p, 1.0 / norm(p))
            }
            WallShape::Line { normal, .. } => normal,
        }
    }

    /// Contact geometry against a disk at `x` of radius `r` (normal from wall to disk).
    #[inline(always)]
    pub fn disk_contact(&self, x: Vec2, r: f64) -> ContactGeometry {
        match self.shape {
            WallShape::Segment { a, b } => segment_disk(a, b, x, r),
            WallShape::Line { point, normal } => line_disk(point, normal, x, r),
        }
    }

    /// Moves the wall by `d`.
    pub fn translate(&mut self, d: Vec2) {
        self.shape = match self.shape {
            WallShape::Segment { a, b } => WallShape::Segment {
                a: add(a, d),
                b: add(b, d),
            },
            WallShape::Line { point, normal } => WallShape::Line {
                point: add(point, d),
                normal,
            },
        };
        self.displacement = add(self.displacement, d);
    }

    /// Normal stress on the wall from its last force, compression positive (Pa),
    /// over `length` (m, unit thickness).
    pub fn normal_stress(&self, length: f64) -> f64 {
        -dot(self.force, self.inward_normal()) / length
    }

    /// Sets the servo velocity from the forces of this step.
    pub fn update_servo(&mut self, dt: f64) {
        if let WallControl::Servo(servo) = self.control {
            let error = servo.target_stress - self.normal_stress(servo.loaded_length);
            let speed = if error == 0.0 {
                0.0
            } else if self.stiffness_sum > 0.0 {
                let gain = servo.relaxation * servo.loaded_length / (self.stiffness_sum * dt);
                (gain * error).clamp(-servo.max_speed, servo.max_speed)
            } else {
                servo.max_speed.copysign(error)
            };
            self.velocity = scale(self.inward_normal(), speed);
        }
    }
}
