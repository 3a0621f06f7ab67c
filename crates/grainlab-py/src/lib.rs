//! Thin PyO3 glue over grainlab-core, importable as `grainlab._core`.
//!
//! Everything here converts arguments, calls the engine and converts results;
//! validation and physics live in the engine. The friendly Python API is
//! `grainlab.Simulation` (python/grainlab/simulation.py), which wraps [`simulation::Engine`].
use pyo3::prelude::*;

mod analysis;
mod body;
mod convert;
mod simulation;

pyo3::create_exception!(
    _core,
    SimulationUnstableError,
    pyo3::exceptions::PyRuntimeError,
    "The simulation blew up (NaN or runaway overlap); the message names the particles."
);

/// The Eq. 16 density scaling factor `I = strain_rate * sqrt(density * r_min^2 / pressure)`.
#[pyfunction]
fn density_scaling_factor(strain_rate: f64, density: f64, min_radius: f64, pressure: f64) -> f64 {
    grainlab_core::diagnostics::density_scaling_factor(strain_rate, density, min_radius, pressure)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", grainlab_core::VERSION)?;
    // the number of material groups: groups are 0..MAX_GROUPS
    m.add("MAX_GROUPS", grainlab_core::state::MAX_GROUPS)?;
    m.add(
        "SimulationUnstableError",
        m.py().get_type::<SimulationUnstableError>(),
    )?;
    m.add_class::<simulation::Engine>()?;
    m.add_function(wrap_pyfunction!(density_scaling_factor, m)?)?;
    analysis::register(m)?;
    body::register(m)?;
    Ok(())
}
