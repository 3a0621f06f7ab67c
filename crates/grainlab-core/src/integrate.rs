//! Central-difference (leapfrog) integration with PFC local damping (Eq. 5).
//!
//! Per free degree of freedom, with resultant `F` (force or torque) and the
//! half-step velocity `v(n-1/2)`:
//! `F_d = -alpha |F| sign(v(n-1/2))`, `v(n+1/2) = v(n-1/2) + dt (F + F_d) / m`,
//! `x(n+1) = x(n) + dt v(n+1/2)`. A prescribed degree of freedom keeps its
//! velocity. On the first step after velocities were set (full-step values
//! `v(n)`), the kick is `dt/2`, so that `v(1/2) = v(0) + dt/2 a(0)`; this makes
//! leapfrog positions equal velocity-Verlet ones (DESIGN §7).
use crate::state::{FIX_ROTATION, FIX_X, FIX_Y};
use crate::vec2::{mat_vec, sub, Mat2, Vec2};

/// Read-only inputs of the integration of one chunk of particles.
pub struct IntegrationInputs<'a> {
    /// Resultant forces (N), whole array.
    pub force: &'a [Vec2],
    /// Resultant torques (N m).
    pub torque: &'a [f64],
    /// `1/m`.
    pub inv_mass: &'a [f64],
    /// `1/I`.
    pub inv_inertia: &'a [f64],
    /// Masses (kg).
    pub mass: &'a [f64],
    /// Moments of inertia (kg m^2).
    pub inertia: &'a [f64],
    /// Fixity bits.
    pub fixity: &'a [u8],
    /// External forces (N) for the work ledger.
    pub external_force: &'a [Vec2],
    /// External torques (N m).
    pub external_torque: &'a [f64],
    /// Positions at the last neighbour-list build.
    pub reference: &'a [Vec2],
}

/// Scalars of the integration step.
#[derive(Clone, Copy)]
pub struct IntegrationStep {
    /// Time step (s).
    pub dt: f64,
    /// Kick length: `dt`, or `dt/2` on a half kick.
    pub kick: f64,
    /// Whether this is a half kick from full-step velocities.
    pub half_kick: bool,
    /// Local damping coefficient alpha.
    pub alpha: f64,
    /// Gravity (m/s^2).
    pub gravity: Vec2,
    /// Whether external forces or gravity act (work is then tallied).
    pub has_external: bool,
    /// Affine map of this step about `origin`, if the cell deforms.
    pub step_map: Option<(Vec2, Mat2)>,
    /// Accumulated map since the neighbour-list build.
    pub accumulated_map: Mat2,
}

/// The mutable state of one contiguous chunk of particles `lo..lo + len`.
pub struct MotionChunk<'a> {
    /// Index of the chunk's first particle.
    pub lo: usize,
    /// Positions.
    pub position: &'a mut [Vec2],
    /// Velocities.
    pub velocity: &'a mut [Vec2],
    /// Rotations.
    pub rotation: &'a mut [f64],
    /// Angular velocities.
    pub angular_velocity: &'a mut [f64],
}

/// What the integration of a chunk adds to the step's diagnostics.
#[derive(Debug, Clone, Copy, Default)]
pub struct IntegrationTally {
    /// Energy dissipated by local damping (J).
    pub damping_dissipated: f64,
    /// Work of external forces and gravity (J).
    pub external_work: f64,
    /// Kinetic energy at the full step (J), `1/2 m v(n-1/2).v(n+1/2)`, measured steps only.
    pub kinetic: f64,
    /// Sum of |resultant force| over free particles, measured steps only.
    pub unbalanced_force_sum: f64,
    /// Number of free particles counted in `unbalanced_force_sum`.
    pub free_count: usize,
    /// Largest squared displacement relative to the homogeneous deformation.
    pub max_fluctuation_sq: f64,
    /// Largest squared total displacement since the build.
    pub max_displacement_sq: f64,
    /// Whether a non-finite position or velocity appeared.
    pub non_finite: bool,
}

impl IntegrationTally {
    /// Folds another chunk's tally into this one.
    pub fn merge(&mut self, o: &IntegrationTally) {
        self.damping_dissipated += o.damping_dissipated;
        self.external_work += o.external_work;
        self.kinetic += o.kinetic;
        self.unbalanced_force_sum += o.unbalanced_force_sum;
        self.free_count += o.free_count;
        self.max_fluctuation_sq = self.max_fluctuation_sq.max(o.max_fluctuation_sq);
        self.max_displacement_sq = self.max_displacement_sq.max(o.max_displacement_sq);
        self.non_finite |= o.non_finite;
    }
}

#[inline(always)]
fn signum0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// One damped kick of one degree of freedom; returns `(v_new, damping power * dt)`.
#[inline(always)]
fn kick(v: f64, f: f64, inv_m: f64, alpha: f64, kick: f64) -> (f64, f64) {
    let fd = -alpha * f.abs() * signum0(v);
    let v_new = v + kick * (f + fd) * inv_m;
    (v_new, fd)
}

/// Integrates one chunk of particles over one step.
pub fn integrate_chunk<const MEASURE: bool>(
    chunk: MotionChunk<'_>,
    inputs: &IntegrationInputs<'_>,
    step: &IntegrationStep,
) -> IntegrationTally {
    let mut tally = IntegrationTally::default();
    let dt = step.dt;
    let alpha = step.alpha;
    for k in 0..chunk.position.len() {
        let p = chunk.lo + k;
        let fix = inputs.fixity[p];
        let f = inputs.force[p];
        let v_old = chunk.velocity[k];
        let w_old = chunk.angular_velocity[k];
        let mut v = v_old;
        let mut w = w_old;
        let mut damping_work = 0.0;
        let inv_m = inputs.inv_mass[p];
        if fix & FIX_X == 0 {
            let (vn, fd) = kick(v_old[0], f[0], inv_m, alpha, step.kick);
            v[0] = vn;
            damping_work += fd
                * if step.half_kick {
                    v_old[0]
                } else {
                    0.5 * (v_old[0] + vn)
                };
        }
        if fix & FIX_Y == 0 {
            let (vn, fd) = kick(v_old[1], f[1], inv_m, alpha, step.kick);
            v[1] = vn;
            damping_work += fd
                * if step.half_kick {
                    v_old[1]
                } else {
                    0.5 * (v_old[1] + vn)
                };
        }
        if fix & FIX_ROTATION == 0 {
            let tq = inputs.torque[p];
            let (wn, td) = kick(w_old, tq, inputs.inv_inertia[p], alpha, step.kick);
            w = wn;
            damping_work += td
                * if step.half_kick {
                    w_old
                } else {
                    0.5 * (w_old + wn)
                };
        }
        tally.damping_dissipated -= damping_work * dt;
        let (v_full, w_full) = if step.half_kick {
            (v_old, w_old)
        } else {
            (
                [0.5 * (v_old[0] + v[0]), 0.5 * (v_old[1] + v[1])],
                0.5 * (w_old + w),
            )
        };
        if step.has_external {
            let m = inputs.mass[p];
            let fe = inputs.external_force[p];
            let fx = if fix & FIX_X == 0 {
                fe[0] + m * step.gravity[0]
            } else {
                0.0
            };
            let fy = if fix & FIX_Y == 0 {
                fe[1] + m * step.gravity[1]
            } else {
                0.0
            };
            let te = if fix & FIX_ROTATION == 0 {
                inputs.external_torque[p]
            } else {
                0.0
            };
            tally.external_work += (fx * v_full[0] + fy * v_full[1] + te * w_full) * dt;
        }
        if MEASURE {
            // 1/2 m v(n-1/2).v(n+1/2): with the elastic energy of linear springs this
            // sum is exactly conserved by leapfrog (away from contact onsets)
            let (vk, wk) = if step.half_kick {
                (v_old, w_old)
            } else {
                (v, w)
            };
            tally.kinetic += 0.5 * inputs.mass[p] * (v_old[0] * vk[0] + v_old[1] * vk[1])
                + 0.5 * inputs.inertia[p] * w_old * wk;
            if fix == 0 {
                tally.unbalanced_force_sum += (f[0] * f[0] + f[1] * f[1]).sqrt();
                tally.free_count += 1;
            }
        }
        let mut x = chunk.position[k];
        x[0] += dt * v[0];
        x[1] += dt * v[1];
        let reference = inputs.reference[p];
        if let Some((origin, m)) = step.step_map {
            x = crate::vec2::add(origin, mat_vec(&m, sub(x, origin)));
            let affine = crate::vec2::add(
                origin,
                mat_vec(&step.accumulated_map, sub(reference, origin)),
            );
            let u = sub(x, affine);
            tally.max_fluctuation_sq = tally.max_fluctuation_sq.max(u[0] * u[0] + u[1] * u[1]);
        }
        let d = sub(x, reference);
        let d2 = d[0] * d[0] + d[1] * d[1];
        tally.max_displacement_sq = tally.max_displacement_sq.max(d2);
        if step.step_map.is_none() {
            tally.max_fluctuation_sq = tally.max_fluctuation_sq.max(d2);
        }
        tally.non_finite |= !(x[0].is_finite() && x[1].is_finite() && w.is_finite());
        chunk.position[k] = x;
        chunk.velocity[k] = v;
        chunk.angular_velocity[k] = w;
        chunk.rotation[k] += dt * w;
    }
    tally
}
