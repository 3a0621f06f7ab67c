//! Conversions between NumPy arrays and the engine's `Vec`s, and engine errors to Python.
use grainlab_core::vec2::Vec2;
use grainlab_core::EngineError;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::SimulationUnstableError;

/// Engine errors: bad input becomes `ValueError`, a blow-up `SimulationUnstableError`.
pub fn to_py_err(e: EngineError) -> PyErr {
    match e {
        EngineError::InvalidInput { .. } => PyValueError::new_err(e.to_string()),
        EngineError::Unstable { .. } => SimulationUnstableError::new_err(e.to_string()),
    }
}

/// An `(N, 2)` array as points, checking the shape.
pub fn points(field: &str, a: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Vec2>> {
    let view = a.as_array();
    if view.ncols() != 2 {
        return Err(PyValueError::new_err(format!(
            "{field}: expected shape (N, 2), got {:?}",
            view.shape()
        )));
    }
    Ok(view.rows().into_iter().map(|r| [r[0], r[1]]).collect())
}

/// A 1D array as a `Vec`.
pub fn values<T: numpy::Element + Copy>(a: &PyReadonlyArray1<'_, T>) -> Vec<T> {
    a.as_array().iter().copied().collect()
}

/// Checks a length against the particle count.
pub fn same_length(field: &str, len: usize, n: usize) -> PyResult<()> {
    if len != n {
        return Err(PyValueError::new_err(format!(
            "{field}: has {len} entries but there are {n} particles"
        )));
    }
    Ok(())
}

/// Points as a new `(N, 2)` float64 array.
pub fn points_to_py<'py>(py: Python<'py>, v: &[Vec2]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = v.iter().flat_map(|p| [p[0], p[1]]).collect();
    Ok(PyArray1::from_vec(py, flat)
        .reshape([v.len(), 2])?
        .into_any())
}

/// A slice as a new 1D array.
pub fn values_to_py<'py, T: numpy::Element + Copy>(py: Python<'py>, v: &[T]) -> Bound<'py, PyAny> {
    PyArray1::from_slice(py, v).into_any()
}
