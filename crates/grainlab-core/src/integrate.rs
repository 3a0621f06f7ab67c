//! Central-difference (leapfrog) integration with PFC local damping (Eq. 5).
//!
//! Per free degree of freedom, with resultant `F` (force or torque) and the
//! half-step velocity `v(n-1/2)`:
//! `F_d = -alpha |F| sign(v(n-1/2))`, `v(n+1/2) = v(n-1/2) + dt (F + F_d) / m`,
//! `x(n+1) = x(n) + dt v(n+1/2)`. A prescribed degree of freedom keeps its
//! velocity. On the first step after velocities were set (full-step values
//! `v(n)`), the kick is `dt/2`, so that `v(1/2) = v(0) + dt/2 a(0)`; this makes
//! leapfrog positions equal velocity-Verlet ones (docs/contact-law.md).
use crate::state::{FIX_ROTATION, FIX_X, FIX_Y, PEBBLE};
use crate::vec2::{mat_vec, sub, Mat2, Vec2};

/// Read-only inputs of the integration of one stripe of particles.
pub struct IntegrationInputs<'a> {
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
    /// Follower loads of pressure chains (N), when there are chains.
    pub boundary_load: Option<&'a [Vec2]>,
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
    /// Whether free particles are integrated two at a time (AVX2; set only
    /// where the processor has it): the same bits as one at a time.
    pub vector: bool,
}

/// The mutable state of one contiguous stripe of particles `lo..lo + len`.
pub struct MotionStripe<'a> {
    /// Index of the stripe's first particle.
    pub lo: usize,
    /// Positions.
    pub position: &'a mut [Vec2],
    /// Velocities.
    pub velocity: &'a mut [Vec2],
    /// Rotations.
    pub rotation: &'a mut [f64],
    /// Angular velocities.
    pub angular_velocity: &'a mut [f64],
    /// Resultant forces of this step (N), complete when integration starts.
    pub force: &'a [Vec2],
    /// Resultant torques (N m).
    pub torque: &'a [f64],
}

/// What the integration of a stripe adds to the step's diagnostics.
#[derive(Debug, Clone, Copy, Default)]
pub struct IntegrationTally {
    /// Energy dissipated by local damping (J).
    pub damping_dissipated: f64,
    /// Work of external forces and gravity (J).
    pub external_work: f64,
    /// Work of the pressure chains' follower loads (J).
    pub boundary_work: f64,
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
    /// Folds another stripe's tally into this one.
    pub fn merge(&mut self, o: &IntegrationTally) {
        self.damping_dissipated += o.damping_dissipated;
        self.external_work += o.external_work;
        self.boundary_work += o.boundary_work;
        self.kinetic += o.kinetic;
        self.unbalanced_force_sum += o.unbalanced_force_sum;
        self.free_count += o.free_count;
        self.max_fluctuation_sq = self.max_fluctuation_sq.max(o.max_fluctuation_sq);
        self.max_displacement_sq = self.max_displacement_sq.max(o.max_displacement_sq);
        self.non_finite |= o.non_finite;
    }
}

/// `sign(v)` with `sign(0) = 0` (and 0 for NaN), without branches: the
/// compiler selects among the three constants.
#[inline(always)]
fn signum0(v: f64) -> f64 {
    // each mask keeps its constant or gives +0
    let positive = f64::from_bits((v > 0.0) as u64 * 1.0f64.to_bits());
    let negative = f64::from_bits((v < 0.0) as u64 * (-1.0f64).to_bits());
    positive + negative
}

/// `max.max(value)` for a running maximum that started at 0: `max` is then
/// never NaN, and a NaN `value` leaves it, as `f64::max` does, but in one
/// instruction on the loop's critical path instead of `f64::max`'s
/// NaN-handling sequence (the same bits: equal values are equal bits, squares
/// being never -0).
#[inline(always)]
pub(crate) fn running_max(max: f64, value: f64) -> f64 {
    if value > max {
        value
    } else {
        max
    }
}

/// One kick of one degree of freedom with local damping; returns `(v_new, F_d)`.
#[inline(always)]
pub(crate) fn kick<const DAMPED: bool>(
    v: f64,
    f: f64,
    inv_m: f64,
    alpha: f64,
    kick: f64,
) -> (f64, f64) {
    let fd = if DAMPED {
        -alpha * f.abs() * signum0(v)
    } else {
        0.0
    };
    (v + kick * (f + fd) * inv_m, fd)
}

/// Integrates one stripe of particles over one step.
pub fn integrate_stripe<const MEASURE: bool>(
    stripe: MotionStripe<'_>,
    inputs: &IntegrationInputs<'_>,
    step: &IntegrationStep,
) -> IntegrationTally {
    match (step.alpha > 0.0, step.step_map.is_some()) {
        (false, false) => integrate_kernel::<MEASURE, false, false>(stripe, inputs, step),
        (false, true) => integrate_kernel::<MEASURE, false, true>(stripe, inputs, step),
        (true, false) => integrate_kernel::<MEASURE, true, false>(stripe, inputs, step),
        (true, true) => integrate_kernel::<MEASURE, true, true>(stripe, inputs, step),
    }
}

/// The loop of [`integrate_stripe`], specialised on local damping and on the
/// periodic cell's deformation so that neither costs anything when absent;
/// two particles at a time where the step allows it ([`IntegrationStep::vector`]).
#[inline(always)]
fn integrate_kernel<const MEASURE: bool, const DAMPED: bool, const DEFORMING: bool>(
    stripe: MotionStripe<'_>,
    inputs: &IntegrationInputs<'_>,
    step: &IntegrationStep,
) -> IntegrationTally {
    let mut kernel = StripeKernel::new(stripe, inputs, step);
    let mut sums = StripeSums::default();
    let n = kernel.position.len();
    #[cfg(target_arch = "x86_64")]
    if step.vector {
        // SAFETY: `vector` is set only where the processor has AVX2
        unsafe { kernel.particles_by_two::<MEASURE, DAMPED, DEFORMING>(&mut sums) };
        return sums.finish::<DEFORMING>(step);
    }
    for k in 0..n {
        kernel.one_particle::<MEASURE, DAMPED, DEFORMING>(k, &mut sums);
    }
    sums.finish::<DEFORMING>(step)
}

/// What the integration of one stripe reads and writes, cut to the stripe, and
/// the step's constants.
pub(crate) struct StripeKernel<'a> {
    pub(crate) lo: usize,
    pub(crate) force: &'a [Vec2],
    pub(crate) torque: &'a [f64],
    pub(crate) velocity: &'a mut [Vec2],
    pub(crate) angular_velocity: &'a mut [f64],
    pub(crate) rotation: &'a mut [f64],
    pub(crate) position: &'a mut [Vec2],
    pub(crate) mass: &'a [f64],
    pub(crate) inv_mass: &'a [f64],
    pub(crate) inv_inertia: &'a [f64],
    pub(crate) fixity: &'a [u8],
    pub(crate) reference: &'a [Vec2],
    pub(crate) inputs: &'a IntegrationInputs<'a>,
    pub(crate) step: &'a IntegrationStep,
    /// The step's affine map and its shift: `x -> map_shift + map x`.
    pub(crate) map: Mat2,
    pub(crate) map_shift: Vec2,
    /// The accumulated map and its shift, for the reference points.
    pub(crate) acc: Mat2,
    pub(crate) acc_shift: Vec2,
}

/// The running sums of one stripe's integration.
#[derive(Default)]
pub(crate) struct StripeSums {
    pub(crate) tally: IntegrationTally,
    pub(crate) damping_work: f64,
    pub(crate) max_fluctuation_sq: f64,
    pub(crate) max_displacement_sq: f64,
    /// Whether a non-finite position or angular velocity appeared.
    pub(crate) non_finite: bool,
}

impl StripeSums {
    /// The stripe's tally.
    fn finish<const DEFORMING: bool>(mut self, step: &IntegrationStep) -> IntegrationTally {
        self.tally.damping_dissipated = -self.damping_work * step.kick;
        self.tally.max_displacement_sq = self.max_displacement_sq;
        self.tally.max_fluctuation_sq = if DEFORMING {
            self.max_fluctuation_sq
        } else {
            self.max_displacement_sq
        };
        self.tally.non_finite = self.non_finite;
        self.tally
    }
}

impl<'a> StripeKernel<'a> {
    fn new(
        stripe: MotionStripe<'a>,
        inputs: &'a IntegrationInputs<'a>,
        step: &'a IntegrationStep,
    ) -> Self {
        let (origin, map) = step
            .step_map
            .unwrap_or(([0.0; 2], [[1.0, 0.0], [0.0, 1.0]]));
        let acc = step.accumulated_map;
        let n = stripe.position.len();
        let lo = stripe.lo;
        StripeKernel {
            lo,
            force: &stripe.force[..n],
            torque: &stripe.torque[..n],
            velocity: &mut stripe.velocity[..n],
            angular_velocity: &mut stripe.angular_velocity[..n],
            rotation: &mut stripe.rotation[..n],
            position: &mut stripe.position[..n],
            mass: &inputs.mass[lo..lo + n],
            inv_mass: &inputs.inv_mass[lo..lo + n],
            inv_inertia: &inputs.inv_inertia[lo..lo + n],
            fixity: &inputs.fixity[lo..lo + n],
            reference: &inputs.reference[lo..lo + n],
            inputs,
            step,
            map,
            // affine image of a reference point: origin + M_acc (x_ref - origin) = shift + M_acc x_ref
            map_shift: sub(origin, mat_vec(&map, origin)),
            acc,
            acc_shift: sub(origin, mat_vec(&acc, origin)),
        }
    }

    /// Particle `k` of the stripe over the step.
    #[inline(always)]
    pub(crate) fn one_particle<const MEASURE: bool, const DAMPED: bool, const DEFORMING: bool>(
        &mut self,
        k: usize,
        sums: &mut StripeSums,
    ) {
        let step = self.step;
        let (dt, alpha) = (step.dt, step.alpha);
        let fix = self.fixity[k];
        let f = self.force[k];
        let v_old = self.velocity[k];
        let w_old = self.angular_velocity[k];
        let (mut v, mut w) = (v_old, w_old);
        let mut fd = [0.0; 3];
        let inv_m = self.inv_mass[k];
        if fix == 0 {
            (v[0], fd[0]) = kick::<DAMPED>(v_old[0], f[0], inv_m, alpha, step.kick);
            (v[1], fd[1]) = kick::<DAMPED>(v_old[1], f[1], inv_m, alpha, step.kick);
            (w, fd[2]) =
                kick::<DAMPED>(w_old, self.torque[k], self.inv_inertia[k], alpha, step.kick);
        } else {
            if fix & PEBBLE != 0 {
                // moved with its clump (`body::clumps`)
                return;
            }
            if fix & FIX_X == 0 {
                (v[0], fd[0]) = kick::<DAMPED>(v_old[0], f[0], inv_m, alpha, step.kick);
            }
            if fix & FIX_Y == 0 {
                (v[1], fd[1]) = kick::<DAMPED>(v_old[1], f[1], inv_m, alpha, step.kick);
            }
            if fix & FIX_ROTATION == 0 {
                (w, fd[2]) =
                    kick::<DAMPED>(w_old, self.torque[k], self.inv_inertia[k], alpha, step.kick);
            }
        }
        self.book::<MEASURE, DAMPED>(k, [v_old, v], [w_old, w], fd, sums);
        let mut x = self.position[k];
        x[0] += dt * v[0];
        x[1] += dt * v[1];
        let r = self.reference[k];
        if DEFORMING {
            x = crate::vec2::add(self.map_shift, mat_vec(&self.map, x));
            let u = sub(x, crate::vec2::add(self.acc_shift, mat_vec(&self.acc, r)));
            sums.max_fluctuation_sq =
                running_max(sums.max_fluctuation_sq, u[0] * u[0] + u[1] * u[1]);
        }
        let d = sub(x, r);
        let d2 = d[0] * d[0] + d[1] * d[1];
        sums.max_displacement_sq = running_max(sums.max_displacement_sq, d2);
        sums.non_finite |= !(x[0].is_finite() & x[1].is_finite() & w.is_finite());
        self.position[k] = x;
        self.velocity[k] = v;
        self.angular_velocity[k] = w;
        self.rotation[k] += dt * w;
    }

    /// The energy sums of particle `k` (in particle order): the work of local
    /// damping, external forces, gravity and follower loads, and on a measured
    /// step the kinetic energy and the unbalanced force; `v` and `w` are the
    /// velocities before and after the kick, `fd` the damping forces.
    #[inline(always)]
    pub(crate) fn book<const MEASURE: bool, const DAMPED: bool>(
        &self,
        k: usize,
        [v_old, v]: [Vec2; 2],
        [w_old, w]: [f64; 2],
        fd: [f64; 3],
        sums: &mut StripeSums,
    ) {
        let step = self.step;
        let inputs = self.inputs;
        let fix = self.fixity[k];
        // the work of a force F(n) in leapfrog's exact energy identity (with the
        // kinetic energy below) is F(n) . (v(n-1/2) + v(n+1/2)) / 2 * kick, where the
        // kick is dt, or dt/2 on the first step from full-step velocities
        let v_full = [0.5 * (v_old[0] + v[0]), 0.5 * (v_old[1] + v[1])];
        let w_full = 0.5 * (w_old + w);
        if DAMPED {
            sums.damping_work += fd[0] * v_full[0] + fd[1] * v_full[1] + fd[2] * w_full;
        }
        let tally = &mut sums.tally;
        if step.has_external {
            let p = self.lo + k;
            let m = self.mass[k];
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
            tally.external_work += (fx * v_full[0] + fy * v_full[1] + te * w_full) * step.kick;
        }
        if MEASURE {
            // 1/2 m v(n-1/2).v(n+1/2): with the elastic energy of linear springs this
            // sum is exactly conserved by leapfrog (away from contact onsets)
            let (vk, wk) = if step.half_kick {
                (v_old, w_old)
            } else {
                (v, w)
            };
            tally.kinetic += 0.5 * self.mass[k] * (v_old[0] * vk[0] + v_old[1] * vk[1])
                + 0.5 * inputs.inertia[self.lo + k] * w_old * wk;
            if fix == 0 {
                let f = self.force[k];
                tally.unbalanced_force_sum += (f[0] * f[0] + f[1] * f[1]).sqrt();
                tally.free_count += 1;
            }
        }
        if let Some(load) = inputs.boundary_load {
            let fb = load[self.lo + k];
            let fx = if fix & FIX_X == 0 { fb[0] } else { 0.0 };
            let fy = if fix & FIX_Y == 0 { fb[1] } else { 0.0 };
            tally.boundary_work += (fx * v_full[0] + fy * v_full[1]) * step.kick;
        }
    }
}
