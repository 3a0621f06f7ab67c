//! Thin PyO3 glue over grainlab-core, importable as `grainlab._core`.
use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", grainlab_core::VERSION)?;
    Ok(())
}
