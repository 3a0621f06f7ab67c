//! `grainlab._core.Engine`: the engine's simulation, method for method.
use grainlab_core::body::GivenMass;
use grainlab_core::cement::{BondBreak, CementBond, CementKind, CementSpec};
use grainlab_core::state::PEBBLE;
use grainlab_core::{
    BodySpec, ContactLaw, ContactModel, Particles, PeriodicCell, ServoControl, Simulation, Wall,
    WallControl, WallShape,
};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::convert::{points, points_to_py, same_length, to_py_err, values, values_to_py};

/// A particle array in external (user) order as a read-only NumPy array:
/// `points` for `(N, 2)` arrays, `values` for `(N,)` ones.
macro_rules! particle_array {
    ($self:ident, $py:ident, points $field:ident) => {
        points_to_py($py, &$self.sim.to_external(&$self.sim.particles().$field))
    };
    ($self:ident, $py:ident, values $field:ident) => {
        values_to_py($py, &$self.sim.to_external(&$self.sim.particles().$field))
    };
}

/// Steps run between checks for Ctrl-C.
const STEPS_PER_SIGNAL_CHECK: u64 = 2000;

/// The engine's simulation state and step.
#[pyclass(module = "grainlab._core")]
pub struct Engine {
    sim: Simulation,
}

fn point(field: &str, v: Vec<f64>) -> PyResult<[f64; 2]> {
    match v.as_slice() {
        [x, y] => Ok([*x, *y]),
        _ => Err(PyValueError::new_err(format!(
            "{field}: expected 2 numbers, got {}",
            v.len()
        ))),
    }
}

/// A setter of the engine that takes one value per particle.
type Setter<T> = fn(&mut Simulation, &[T]) -> grainlab_core::Result<()>;

impl Engine {
    /// The one way a per-particle `(N, 2)` array is set: its shape and length
    /// checked here, its values by the engine (naming the field and the index).
    fn set_points(
        &mut self,
        field: &str,
        array: &PyReadonlyArray2<'_, f64>,
        set: Setter<[f64; 2]>,
    ) -> PyResult<()> {
        let v = points(field, array)?;
        same_length(field, v.len(), self.sim.particles().len())?;
        set(&mut self.sim, &v).map_err(to_py_err)
    }

    /// The one way a per-particle `(N,)` array is set (as [`Engine::set_points`]).
    fn set_values<T: numpy::Element + Copy>(
        &mut self,
        field: &str,
        array: &PyReadonlyArray1<'_, T>,
        set: Setter<T>,
    ) -> PyResult<()> {
        let v = values(array);
        same_length(field, v.len(), self.sim.particles().len())?;
        set(&mut self.sim, &v).map_err(to_py_err)
    }
}

#[pymethods]
impl Engine {
    #[new]
    #[pyo3(signature = (positions, radii, density, normal_stiffness, shear_stiffness, friction, time_step, threads))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        positions: PyReadonlyArray2<'_, f64>,
        radii: PyReadonlyArray1<'_, f64>,
        density: PyReadonlyArray1<'_, f64>,
        normal_stiffness: f64,
        shear_stiffness: f64,
        friction: f64,
        time_step: f64,
        threads: usize,
    ) -> PyResult<Self> {
        let particles = Particles::new(
            points("positions", &positions)?,
            values(&radii),
            values(&density),
        )
        .map_err(to_py_err)?;
        let model = ContactModel::linear(normal_stiffness, shear_stiffness, friction);
        let sim = Simulation::new(particles, model, time_step, threads).map_err(to_py_err)?;
        Ok(Engine { sim })
    }

    fn add_particles(
        &mut self,
        positions: PyReadonlyArray2<'_, f64>,
        radii: PyReadonlyArray1<'_, f64>,
        density: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        self.sim
            .add_particles(
                points("positions", &positions)?,
                values(&radii),
                values(&density),
            )
            .map_err(to_py_err)
    }

    // ---- running ----

    /// Runs `steps` steps with the GIL released; the last step is measured.
    fn run(&mut self, py: Python<'_>, steps: u64) -> PyResult<()> {
        let mut left = steps;
        while left > 0 {
            let chunk = left.min(STEPS_PER_SIGNAL_CHECK);
            let last = chunk == left;
            let sim = &mut self.sim;
            py.detach(|| {
                if last {
                    sim.run(chunk)
                } else {
                    sim.advance(chunk)
                }
            })
            .map_err(to_py_err)?;
            left -= chunk;
            py.check_signals()?;
        }
        Ok(())
    }

    fn critical_time_step(&mut self, safety: f64) -> PyResult<f64> {
        self.sim.critical_time_step(safety).map_err(to_py_err)
    }

    #[getter]
    fn step_count(&self) -> u64 {
        self.sim.step_count()
    }

    #[getter]
    fn time(&self) -> f64 {
        self.sim.time()
    }

    #[getter]
    fn threads(&self) -> usize {
        self.sim.threads()
    }

    fn set_threads(&mut self, threads: usize) -> PyResult<()> {
        self.sim.set_threads(threads).map_err(to_py_err)
    }

    #[getter]
    fn neighbor_builds(&self) -> u64 {
        self.sim.neighbors().build_count
    }

    #[getter]
    fn n_particles(&self) -> usize {
        self.sim.particles().len()
    }

    // ---- parameters ----

    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = self.sim.params();
        let d = PyDict::new(py);
        d.set_item("time_step", p.time_step)?;
        d.set_item("local_damping", p.local_damping)?;
        d.set_item("gravity", (p.gravity[0], p.gravity[1]))?;
        d.set_item("max_overlap_ratio", p.max_overlap_ratio)?;
        d.set_item("skin", self.sim.neighbors().skin)?;
        Ok(d)
    }

    #[pyo3(signature = (time_step, local_damping, gravity, max_overlap_ratio))]
    fn set_parameters(
        &mut self,
        time_step: f64,
        local_damping: f64,
        gravity: Vec<f64>,
        max_overlap_ratio: f64,
    ) -> PyResult<()> {
        let params = grainlab_core::StepParameters {
            time_step,
            local_damping,
            gravity: point("gravity", gravity)?,
            max_overlap_ratio,
        };
        self.sim.set_params(params).map_err(to_py_err)
    }

    fn set_skin(&mut self, skin: f64) -> PyResult<()> {
        self.sim.set_skin(skin).map_err(to_py_err)
    }

    #[pyo3(signature = (group_a, group_b, normal_stiffness, shear_stiffness, friction, normal_damping_ratio, shear_damping_ratio, rolling_friction=0.0, rolling_stiffness=0.0, rolling_damping_ratio=0.0, enabled=true, law="linear", youngs_modulus=0.0, poisson_ratio=0.0, restitution=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn set_contact_model(
        &mut self,
        group_a: usize,
        group_b: usize,
        normal_stiffness: f64,
        shear_stiffness: f64,
        friction: f64,
        normal_damping_ratio: f64,
        shear_damping_ratio: f64,
        rolling_friction: f64,
        rolling_stiffness: f64,
        rolling_damping_ratio: f64,
        enabled: bool,
        law: &str,
        youngs_modulus: f64,
        poisson_ratio: f64,
        restitution: f64,
    ) -> PyResult<()> {
        let law = ContactLaw::from_name(law).map_err(to_py_err)?;
        let model = ContactModel {
            normal_stiffness,
            shear_stiffness,
            friction,
            normal_damping_ratio,
            shear_damping_ratio,
            rolling_friction,
            rolling_stiffness,
            rolling_damping_ratio,
            enabled,
            law,
            youngs_modulus,
            poisson_ratio,
            restitution,
        };
        self.sim
            .set_contact_model(group_a, group_b, model)
            .map_err(to_py_err)
    }

    fn contact_model<'py>(
        &self,
        py: Python<'py>,
        group_a: u8,
        group_b: u8,
    ) -> PyResult<Bound<'py, PyDict>> {
        if group_a as usize >= grainlab_core::state::MAX_GROUPS
            || group_b as usize >= grainlab_core::state::MAX_GROUPS
        {
            return Err(PyValueError::new_err(format!(
                "group: out of range 0..{}",
                grainlab_core::state::MAX_GROUPS
            )));
        }
        let m = self.sim.materials().get(group_a, group_b);
        let d = PyDict::new(py);
        d.set_item("normal_stiffness", m.normal_stiffness)?;
        d.set_item("shear_stiffness", m.shear_stiffness)?;
        d.set_item("friction", m.friction)?;
        d.set_item("normal_damping_ratio", m.normal_damping_ratio)?;
        d.set_item("shear_damping_ratio", m.shear_damping_ratio)?;
        d.set_item("rolling_friction", m.rolling_friction)?;
        d.set_item("rolling_stiffness", m.rolling_stiffness)?;
        d.set_item("rolling_damping_ratio", m.rolling_damping_ratio)?;
        d.set_item("enabled", m.enabled)?;
        d.set_item("law", m.law.name())?;
        d.set_item("youngs_modulus", m.youngs_modulus)?;
        d.set_item("poisson_ratio", m.poisson_ratio)?;
        d.set_item("restitution", m.restitution)?;
        Ok(d)
    }

    // ---- particle state ----

    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        particle_array!(self, py, points position)
    }
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        particle_array!(self, py, points velocity)
    }
    #[getter]
    fn forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        particle_array!(self, py, points force)
    }
    #[getter]
    fn external_forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        particle_array!(self, py, points external_force)
    }
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values rotation)
    }
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values angular_velocity)
    }
    #[getter]
    fn torques<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values torque)
    }
    #[getter]
    fn external_torques<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values external_torque)
    }
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values radius)
    }
    #[getter]
    fn densities<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values density)
    }
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values mass)
    }
    #[getter]
    fn inertias<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values inertia)
    }
    #[getter]
    fn groups<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        particle_array!(self, py, values group)
    }
    #[getter]
    fn fixity<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        // the engine's own pebble bit is not the user's
        let fixity: Vec<u8> = self
            .sim
            .particles()
            .fixity
            .iter()
            .map(|f| f & !PEBBLE)
            .collect();
        values_to_py(py, &self.sim.to_external(&fixity))
    }

    // (each through `set_points` / `set_values`)
    fn set_positions(&mut self, positions: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        self.set_points("positions", &positions, Simulation::set_positions)
    }

    fn set_velocities(&mut self, velocities: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        self.set_points("velocities", &velocities, Simulation::set_velocities)
    }

    fn set_external_forces(&mut self, external_forces: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        self.set_points(
            "external_forces",
            &external_forces,
            Simulation::set_external_forces,
        )
    }

    fn set_rotations(&mut self, rotations: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        self.set_values("rotations", &rotations, Simulation::set_rotations)
    }

    fn set_angular_velocities(
        &mut self,
        angular_velocities: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        self.set_values(
            "angular_velocities",
            &angular_velocities,
            Simulation::set_angular_velocities,
        )
    }

    fn set_external_torques(
        &mut self,
        external_torques: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        self.set_values(
            "external_torques",
            &external_torques,
            Simulation::set_external_torques,
        )
    }

    fn set_radii(&mut self, radii: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        self.set_values("radii", &radii, Simulation::set_radii)
    }

    fn set_densities(&mut self, densities: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        self.set_values("densities", &densities, Simulation::set_densities)
    }

    fn set_groups(&mut self, groups: PyReadonlyArray1<'_, u8>) -> PyResult<()> {
        self.set_values("groups", &groups, Simulation::set_groups)
    }

    fn set_fixity(&mut self, fixity: PyReadonlyArray1<'_, u8>) -> PyResult<()> {
        self.set_values("fixity", &fixity, Simulation::set_fixity)
    }

    // ---- periodic cell ----

    #[pyo3(signature = (origin, a, b, periodic))]
    fn set_cell(
        &mut self,
        origin: Vec<f64>,
        a: Vec<f64>,
        b: Vec<f64>,
        periodic: (bool, bool),
    ) -> PyResult<()> {
        let cell = PeriodicCell {
            origin: point("cell.origin", origin)?,
            a: point("cell.a", a)?,
            b: point("cell.b", b)?,
            periodic: [periodic.0, periodic.1],
            velocity_gradient: self
                .sim
                .cell()
                .map_or([[0.0; 2]; 2], |c| c.velocity_gradient),
        };
        self.sim.set_cell(Some(cell)).map_err(to_py_err)
    }

    fn clear_cell(&mut self) -> PyResult<()> {
        self.sim.set_cell(None).map_err(to_py_err)
    }

    fn set_velocity_gradient(&mut self, gradient: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let g = gradient.as_array();
        if g.shape() != [2, 2] {
            return Err(PyValueError::new_err(format!(
                "velocity_gradient: expected shape (2, 2), got {:?}",
                g.shape()
            )));
        }
        self.sim
            .set_velocity_gradient([[g[[0, 0]], g[[0, 1]]], [g[[1, 0]], g[[1, 1]]]])
            .map_err(to_py_err)
    }

    #[getter]
    fn cell<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(c) = self.sim.cell() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("origin", (c.origin[0], c.origin[1]))?;
        d.set_item("a", (c.a[0], c.a[1]))?;
        d.set_item("b", (c.b[0], c.b[1]))?;
        d.set_item("periodic", (c.periodic[0], c.periodic[1]))?;
        let l = c.velocity_gradient;
        d.set_item(
            "velocity_gradient",
            ((l[0][0], l[0][1]), (l[1][0], l[1][1])),
        )?;
        d.set_item("area", c.area())?;
        Ok(Some(d))
    }

    // ---- walls ----

    fn add_segment_wall(&mut self, a: Vec<f64>, b: Vec<f64>, group: u8) -> PyResult<usize> {
        let shape = WallShape::Segment {
            a: point("a", a)?,
            b: point("b", b)?,
        };
        Ok(self
            .sim
            .add_wall(Wall::new(shape, group).map_err(to_py_err)?))
    }

    fn add_line_wall(
        &mut self,
        point_on_line: Vec<f64>,
        normal: Vec<f64>,
        group: u8,
    ) -> PyResult<usize> {
        let shape = WallShape::Line {
            point: point("point", point_on_line)?,
            normal: point("normal", normal)?,
        };
        Ok(self
            .sim
            .add_wall(Wall::new(shape, group).map_err(to_py_err)?))
    }

    #[getter]
    fn n_walls(&self) -> usize {
        self.sim.walls().len()
    }

    fn set_wall_velocity(&mut self, wall_id: usize, velocity: Vec<f64>) -> PyResult<()> {
        let v = point("velocity", velocity)?;
        self.sim.set_wall_velocity(wall_id, v).map_err(to_py_err)
    }

    fn set_wall_servo(
        &mut self,
        wall_id: usize,
        target_stress: f64,
        loaded_length: f64,
        relaxation: f64,
        max_speed: f64,
    ) -> PyResult<()> {
        let servo = ServoControl {
            target_stress,
            loaded_length,
            relaxation,
            max_speed,
        };
        self.sim
            .set_wall_control(wall_id, WallControl::Servo(servo))
            .map_err(to_py_err)
    }

    fn move_wall(&mut self, wall_id: usize, displacement: Vec<f64>) -> PyResult<()> {
        let d = point("displacement", displacement)?;
        self.sim.translate_wall(wall_id, d).map_err(to_py_err)
    }

    fn wall_state<'py>(&self, py: Python<'py>, wall_id: usize) -> PyResult<Bound<'py, PyDict>> {
        let wall = self.sim.wall(wall_id).map_err(to_py_err)?;
        let d = PyDict::new(py);
        match wall.shape {
            WallShape::Segment { a, b } => {
                d.set_item("kind", "segment")?;
                d.set_item("a", (a[0], a[1]))?;
                d.set_item("b", (b[0], b[1]))?;
            }
            WallShape::Line { point, normal } => {
                d.set_item("kind", "line")?;
                d.set_item("point", (point[0], point[1]))?;
                d.set_item("normal", (normal[0], normal[1]))?;
            }
        }
        let n = wall.inward_normal();
        d.set_item("inward_normal", (n[0], n[1]))?;
        d.set_item("velocity", (wall.velocity[0], wall.velocity[1]))?;
        d.set_item("force", (wall.force[0], wall.force[1]))?;
        d.set_item("contact_count", wall.contact_count)?;
        d.set_item("displacement", (wall.displacement[0], wall.displacement[1]))?;
        d.set_item("group", wall.group)?;
        d.set_item("active", wall.active)?;
        match wall.control {
            WallControl::Velocity => d.set_item("control", "velocity")?,
            WallControl::Servo(s) => {
                d.set_item("control", "servo")?;
                d.set_item("target_stress", s.target_stress)?;
                d.set_item("loaded_length", s.loaded_length)?;
                d.set_item("relaxation", s.relaxation)?;
                d.set_item("max_speed", s.max_speed)?;
            }
        }
        Ok(d)
    }

    fn set_wall_active(&mut self, wall_id: usize, active: bool) -> PyResult<()> {
        self.sim.set_wall_active(wall_id, active).map_err(to_py_err)
    }

    // ---- pressure chains ----

    #[pyo3(signature = (particles, pressure, start_wall=None, end_wall=None))]
    fn add_pressure_chain(
        &mut self,
        particles: Vec<usize>,
        pressure: f64,
        start_wall: Option<usize>,
        end_wall: Option<usize>,
    ) -> PyResult<usize> {
        self.sim
            .add_pressure_chain(&particles, pressure, start_wall, end_wall)
            .map_err(to_py_err)
    }

    #[pyo3(signature = (chain_id, particles, pressure, start_wall=None, end_wall=None))]
    fn set_pressure_chain(
        &mut self,
        chain_id: usize,
        particles: Vec<usize>,
        pressure: f64,
        start_wall: Option<usize>,
        end_wall: Option<usize>,
    ) -> PyResult<()> {
        self.sim
            .set_pressure_chain(chain_id, &particles, pressure, start_wall, end_wall)
            .map_err(to_py_err)
    }

    fn pressure_chain<'py>(
        &self,
        py: Python<'py>,
        chain_id: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let chain = self.sim.pressure_chain(chain_id).map_err(to_py_err)?;
        let d = PyDict::new(py);
        d.set_item("particles", chain.particles)?;
        d.set_item("pressure", chain.pressure)?;
        d.set_item("start_wall", chain.start_wall)?;
        d.set_item("end_wall", chain.end_wall)?;
        Ok(d)
    }

    #[getter]
    fn n_pressure_chains(&self) -> usize {
        self.sim.pressure_chain_count()
    }

    // ---- bonds ----

    #[pyo3(signature = (i, j, normal_stiffness, shear_stiffness, rest_length=None))]
    fn add_bond(
        &mut self,
        i: usize,
        j: usize,
        normal_stiffness: f64,
        shear_stiffness: f64,
        rest_length: Option<f64>,
    ) -> PyResult<()> {
        self.sim
            .add_bond(i, j, normal_stiffness, shear_stiffness, rest_length)
            .map_err(to_py_err)
    }

    #[getter]
    fn n_bonds(&self) -> usize {
        self.sim.bonds().len()
    }

    // ---- cement (breakable bonds) ----

    /// Cement bonds between `i[k]` and `j[k]` (external indices); every
    /// parameter array has one value per pair (the Python layer broadcasts).
    #[pyo3(signature = (i, j, kind, radius_multiplier, normal_stiffness, shear_stiffness, tensile_strength, cohesion, friction_angle))]
    #[allow(clippy::too_many_arguments)]
    fn add_cement_bonds(
        &mut self,
        i: PyReadonlyArray1<'_, i64>,
        j: PyReadonlyArray1<'_, i64>,
        kind: &str,
        radius_multiplier: PyReadonlyArray1<'_, f64>,
        normal_stiffness: PyReadonlyArray1<'_, f64>,
        shear_stiffness: PyReadonlyArray1<'_, f64>,
        tensile_strength: PyReadonlyArray1<'_, f64>,
        cohesion: PyReadonlyArray1<'_, f64>,
        friction_angle: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let kind = CementKind::from_name(kind).map_err(to_py_err)?;
        let (i, j) = (values(&i), values(&j));
        let n = i.len();
        let per_pair = |field: &str, a: &PyReadonlyArray1<'_, f64>| -> PyResult<Vec<f64>> {
            let v = values(a);
            if v.len() != n {
                return Err(PyValueError::new_err(format!(
                    "cement.{field}: has {} entries for {n} pairs",
                    v.len()
                )));
            }
            Ok(v)
        };
        let lambda = per_pair("radius_multiplier", &radius_multiplier)?;
        let kn = per_pair("normal_stiffness", &normal_stiffness)?;
        let ks = per_pair("shear_stiffness", &shear_stiffness)?;
        let sigma_c = per_pair("tensile_strength", &tensile_strength)?;
        let c = per_pair("cohesion", &cohesion)?;
        let phi = per_pair("friction_angle", &friction_angle)?;
        if j.len() != n {
            return Err(PyValueError::new_err(format!(
                "cement.j: has {} entries for {n} pairs",
                j.len()
            )));
        }
        let index = |field: &str, k: usize, x: i64| -> PyResult<usize> {
            usize::try_from(x).map_err(|_| {
                PyValueError::new_err(format!(
                    "cement.{field}[{k}]: particle index {x} out of range"
                ))
            })
        };
        let mut pairs = Vec::with_capacity(n);
        for k in 0..n {
            pairs.push((index("i", k, i[k])?, index("j", k, j[k])?));
        }
        let specs: Vec<CementSpec> = (0..n)
            .map(|k| CementSpec {
                kind,
                radius_multiplier: lambda[k],
                normal_stiffness: kn[k],
                shear_stiffness: ks[k],
                tensile_strength: sigma_c[k],
                cohesion: c[k],
                friction_angle: phi[k],
            })
            .collect();
        self.sim.add_cement_bonds(&pairs, &specs).map_err(to_py_err)
    }

    #[getter]
    fn n_cement_bonds(&self) -> usize {
        self.sim.cement().bonds.len()
    }

    /// The intact cement bonds: external indices, kind, forces and strengths.
    fn cement_bonds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let bonds = &self.sim.cement().bonds;
        let column = |f: fn(&CementBond) -> f64| -> Vec<f64> { bonds.iter().map(f).collect() };
        let ext = |q: u32| self.sim.external_index(q as usize) as u32;
        let d = PyDict::new(py);
        d.set_item(
            "i",
            values_to_py(py, &bonds.iter().map(|b| ext(b.i)).collect::<Vec<_>>()),
        )?;
        d.set_item(
            "j",
            values_to_py(py, &bonds.iter().map(|b| ext(b.j)).collect::<Vec<_>>()),
        )?;
        let kinds: Vec<&str> = bonds
            .iter()
            .map(|b| match b.kind {
                CementKind::Parallel => "parallel",
                CementKind::Contact => "contact",
            })
            .collect();
        d.set_item("kind", kinds)?;
        d.set_item(
            "normal_force",
            values_to_py(py, &self.sim.cement_normal_forces()),
        )?;
        d.set_item("shear_force", values_to_py(py, &column(|b| b.shear)))?;
        d.set_item("moment", values_to_py(py, &column(|b| b.moment)))?;
        d.set_item("area", values_to_py(py, &column(|b| b.area)))?;
        d.set_item("bond_radius", values_to_py(py, &column(|b| b.bond_radius)))?;
        d.set_item(
            "tensile_strength",
            values_to_py(py, &column(|b| b.tensile_strength)),
        )?;
        d.set_item("cohesion", values_to_py(py, &column(|b| b.cohesion)))?;
        Ok(d)
    }

    /// The breaks since the last call, as arrays (the engine's log is emptied).
    fn take_bond_breaks<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let breaks = self.sim.take_bond_breaks();
        let column = |f: fn(&BondBreak) -> f64| -> Vec<f64> { breaks.iter().map(f).collect() };
        let d = PyDict::new(py);
        d.set_item(
            "step",
            values_to_py(py, &breaks.iter().map(|b| b.step).collect::<Vec<_>>()),
        )?;
        d.set_item("time", values_to_py(py, &column(|b| b.time)))?;
        d.set_item(
            "i",
            values_to_py(py, &breaks.iter().map(|b| b.i).collect::<Vec<_>>()),
        )?;
        d.set_item(
            "j",
            values_to_py(py, &breaks.iter().map(|b| b.j).collect::<Vec<_>>()),
        )?;
        d.set_item(
            "position",
            points_to_py(py, &breaks.iter().map(|b| b.position).collect::<Vec<_>>())?,
        )?;
        d.set_item(
            "normal",
            points_to_py(py, &breaks.iter().map(|b| b.normal).collect::<Vec<_>>())?,
        )?;
        d.set_item(
            "mode",
            breaks.iter().map(|b| b.mode.name()).collect::<Vec<_>>(),
        )?;
        d.set_item("energy", values_to_py(py, &column(|b| b.energy)))?;
        d.set_item(
            "normal_force",
            values_to_py(py, &column(|b| b.normal_force)),
        )?;
        d.set_item("shear_force", values_to_py(py, &column(|b| b.shear_force)))?;
        d.set_item("moment", values_to_py(py, &column(|b| b.moment)))?;
        Ok(d)
    }

    // ---- bodies ----

    /// Bodies of particles: `pebbles[b]` the particle indices of body `b`,
    /// `angles[b]` its frame's angle, `masses[b]` None or (mass, moment of
    /// inertia, centroid x, centroid y).
    fn add_bodies(
        &mut self,
        pebbles: Vec<Vec<usize>>,
        angles: Vec<f64>,
        masses: Vec<Option<(f64, f64, f64, f64)>>,
    ) -> PyResult<()> {
        same_length("angles", angles.len(), pebbles.len())?;
        same_length("masses", masses.len(), pebbles.len())?;
        let bodies: Vec<BodySpec> = pebbles
            .into_iter()
            .zip(angles.into_iter().zip(masses))
            .map(|(pebbles, (angle, mass))| BodySpec {
                pebbles,
                angle,
                given: mass.map(|(mass, moment_of_inertia, x, y)| GivenMass {
                    mass,
                    moment_of_inertia,
                    centroid: [x, y],
                }),
            })
            .collect();
        self.sim.add_bodies(&bodies).map_err(to_py_err)
    }

    #[getter]
    fn body_of_particles<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        values_to_py(py, &self.sim.body_of_particles())
    }

    /// The clumps' state in id order.
    #[getter]
    fn clumps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.sim.clumps();
        let d = PyDict::new(py);
        d.set_item("centroid", points_to_py(py, &c.in_id_order(&c.centroid))?)?;
        d.set_item("velocity", points_to_py(py, &c.in_id_order(&c.velocity))?)?;
        d.set_item("force", points_to_py(py, &c.in_id_order(&c.force))?)?;
        for (name, v) in [
            ("angle", &c.angle),
            ("angular_velocity", &c.angular_velocity),
            ("mass", &c.mass),
            ("moment_of_inertia", &c.inertia),
            ("torque", &c.torque),
        ] {
            d.set_item(name, values_to_py(py, &c.in_id_order(v)))?;
        }
        d.set_item("fixity", values_to_py(py, &c.in_id_order(&c.fixity)))?;
        Ok(d)
    }

    fn set_clump_velocities(
        &mut self,
        velocities: PyReadonlyArray2<'_, f64>,
        angular_velocities: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let v = points("clump_velocities", &velocities)?;
        self.sim
            .set_clump_velocities(&v, &values(&angular_velocities))
            .map_err(to_py_err)
    }

    fn scale_clumps(&mut self, factors: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        self.sim.scale_clumps(&values(&factors)).map_err(to_py_err)
    }

    // ---- contacts and diagnostics ----

    fn contacts<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.sim.contacts().map_err(to_py_err)?;
        let d = PyDict::new(py);
        d.set_item("i", values_to_py(py, &c.i))?;
        d.set_item("j", values_to_py(py, &c.j))?;
        d.set_item("point", points_to_py(py, &c.point)?)?;
        d.set_item("normal", points_to_py(py, &c.normal)?)?;
        d.set_item("overlap", values_to_py(py, &c.overlap))?;
        d.set_item("normal_force", values_to_py(py, &c.normal_force))?;
        d.set_item("shear_force", values_to_py(py, &c.shear_force))?;
        d.set_item("sliding", values_to_py(py, &c.sliding))?;
        d.set_item("bonded", values_to_py(py, &c.bonded))?;
        d.set_item("rolling_moment", values_to_py(py, &c.rolling_moment))?;
        d.set_item("normal_stiffness", values_to_py(py, &c.normal_stiffness))?;
        Ok(d)
    }

    fn wall_contacts<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.sim.wall_contacts().map_err(to_py_err)?;
        let d = PyDict::new(py);
        d.set_item("wall", values_to_py(py, &c.wall))?;
        d.set_item("particle", values_to_py(py, &c.particle))?;
        d.set_item("point", points_to_py(py, &c.point)?)?;
        d.set_item("normal", points_to_py(py, &c.normal)?)?;
        d.set_item("overlap", values_to_py(py, &c.overlap))?;
        d.set_item("normal_force", values_to_py(py, &c.normal_force))?;
        d.set_item("shear_force", values_to_py(py, &c.shear_force))?;
        d.set_item("sliding", values_to_py(py, &c.sliding))?;
        d.set_item("rolling_moment", values_to_py(py, &c.rolling_moment))?;
        d.set_item("normal_stiffness", values_to_py(py, &c.normal_stiffness))?;
        Ok(d)
    }

    #[getter]
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let m = self.sim.measurements();
        let d = PyDict::new(py);
        d.set_item("step", m.step)?;
        d.set_item("contact_count", m.contact_count)?;
        d.set_item("wall_contact_count", m.wall_contact_count)?;
        d.set_item("mean_unbalanced_force_ratio", m.mean_unbalanced_force_ratio)?;
        Ok(d)
    }

    #[getter]
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = self.sim.energy();
        let d = PyDict::new(py);
        d.set_item("kinetic", e.kinetic)?;
        d.set_item("elastic", e.elastic)?;
        d.set_item("friction_dissipated", e.friction_dissipated)?;
        d.set_item("viscous_dissipated", e.viscous_dissipated)?;
        d.set_item("rolling_dissipated", e.rolling_dissipated)?;
        d.set_item("damping_dissipated", e.damping_dissipated)?;
        d.set_item("wall_work", e.wall_work)?;
        d.set_item("external_work", e.external_work)?;
        d.set_item("boundary_work", e.boundary_work)?;
        d.set_item("bond_released", e.bond_released)?;
        d.set_item("balance", e.balance())?;
        Ok(d)
    }

    // ---- state ----

    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.sim.to_bytes().map_err(to_py_err)?;
        Ok(PyBytes::new(py, &bytes))
    }

    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<Self> {
        Ok(Engine {
            sim: Simulation::from_bytes(data).map_err(to_py_err)?,
        })
    }
}
