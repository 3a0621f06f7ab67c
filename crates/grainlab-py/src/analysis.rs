//! The analysis kernels of `grainlab_core::analysis` as `grainlab._core` functions.
//!
//! Each takes NumPy arrays (C-contiguous), releases the GIL, runs the kernel
//! on `threads` workers (0: rayon's global pool) and returns new arrays. The
//! Python callers are `grainlab.snapshot` and `grainlab.analysis`.
use grainlab_core::analysis::{self as kernels, PeriodicAxis};
use grainlab_core::Result as EngineResult;
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{points_to_py, to_py_err, values_to_py};

fn slice<'a, T: numpy::Element>(field: &str, a: &'a PyReadonlyArray1<'_, T>) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{field}: must be a C-contiguous array")))
}

/// An `(N, 2)` C-contiguous float64 array as points, without a copy.
fn point_slice<'a>(field: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [[f64; 2]]> {
    let shape = a.shape();
    if shape[1] != 2 {
        return Err(PyValueError::new_err(format!(
            "{field}: expected shape (N, 2), got {shape:?}"
        )));
    }
    let flat = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{field}: must be a C-contiguous array")))?;
    // SAFETY: `[f64; 2]` has the size of two f64 and the alignment of one, and
    // `flat` holds `2 N` of them in row order.
    Ok(unsafe { std::slice::from_raw_parts(flat.as_ptr().cast::<[f64; 2]>(), flat.len() / 2) })
}

fn indices(field: &str, a: &PyReadonlyArray1<'_, i64>) -> PyResult<Vec<usize>> {
    let values = slice(field, a)?;
    if let Some(k) = values.iter().position(|&v| v < 0) {
        return Err(PyValueError::new_err(format!(
            "{field}: index {} must be >= 0 (at {k})",
            values[k]
        )));
    }
    Ok(values.iter().map(|&v| v as usize).collect())
}

fn to_i64(v: Vec<usize>) -> Vec<i64> {
    v.into_iter().map(|x| x as i64).collect()
}

fn run<T: Send>(
    py: Python<'_>,
    threads: usize,
    work: impl FnOnce() -> EngineResult<T> + Send,
) -> PyResult<T> {
    py.detach(|| kernels::with_threads(threads, work).and_then(|r| r))
        .map_err(to_py_err)
}

/// Contact pairs `(i, j)` from geometry: centre distance `< r_i + r_j + tolerance`.
#[pyfunction]
#[pyo3(signature = (positions, radii, tolerance, x_period, y_period, threads))]
fn detect_contacts<'py>(
    py: Python<'py>,
    positions: PyReadonlyArray2<'py, f64>,
    radii: PyReadonlyArray1<'py, f64>,
    tolerance: f64,
    x_period: Option<(f64, f64)>,
    y_period: Option<(f64, f64)>,
    threads: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let radii = slice("radii", &radii)?;
    let periodic = [x_period, y_period].map(|p| p.map(|(lo, length)| PeriodicAxis { lo, length }));
    let shape = positions.shape().to_vec();
    let pairs = if shape[1] == 3 {
        let view = positions.as_array();
        let xy: Vec<[f64; 2]> = view.rows().into_iter().map(|r| [r[0], r[1]]).collect();
        let z: Vec<f64> = view.column(2).iter().copied().collect();
        run(py, threads, || {
            kernels::detect_contacts(&xy, Some(&z), radii, tolerance, periodic)
        })?
    } else {
        let xy = point_slice("positions", &positions)?;
        run(py, threads, || {
            kernels::detect_contacts(xy, None, radii, tolerance, periodic)
        })?
    };
    Ok((
        PyArray1::from_vec(py, to_i64(pairs.i)).into_any(),
        PyArray1::from_vec(py, to_i64(pairs.j)).into_any(),
    ))
}

/// Unit normals `(Nc, 2)` from `i` towards `j` and their angles `(Nc,)` in `[0, 2 pi)`.
#[pyfunction]
#[pyo3(signature = (positions, contact_i, contact_j, x_length, y_length, threads))]
fn contact_normals<'py>(
    py: Python<'py>,
    positions: PyReadonlyArray2<'py, f64>,
    contact_i: PyReadonlyArray1<'py, i64>,
    contact_j: PyReadonlyArray1<'py, i64>,
    x_length: Option<f64>,
    y_length: Option<f64>,
    threads: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let xy = point_slice("positions", &positions)?;
    let i = indices("contact_i", &contact_i)?;
    let j = indices("contact_j", &contact_j)?;
    let (normals, angles) = run(py, threads, || {
        kernels::contact_normals(xy, &i, &j, [x_length, y_length])
    })?;
    Ok((
        points_to_py(py, &normals)?,
        PyArray1::from_vec(py, angles).into_any(),
    ))
}

/// lambda `(N,)` and contact counts `(N,)` from contact ends (owner, angle).
#[pyfunction]
#[pyo3(signature = (owner, angles, n_particles, threads))]
fn stability_index<'py>(
    py: Python<'py>,
    owner: PyReadonlyArray1<'py, i64>,
    angles: PyReadonlyArray1<'py, f64>,
    n_particles: usize,
    threads: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let owner = indices("owner", &owner)?;
    let angles = slice("angles", &angles)?;
    let (lambda, counts) = run(py, threads, || {
        kernels::stability_index(&owner, angles, n_particles)
    })?;
    Ok((
        PyArray1::from_vec(py, lambda).into_any(),
        PyArray1::from_vec(py, to_i64(counts)).into_any(),
    ))
}

/// lambda `(N,)` and contact counts `(N,)` from particle–particle contacts and their angles on `i`.
#[pyfunction]
#[pyo3(signature = (contact_i, contact_j, angles, n_particles, threads))]
fn stability_index_of_contacts<'py>(
    py: Python<'py>,
    contact_i: PyReadonlyArray1<'py, i64>,
    contact_j: PyReadonlyArray1<'py, i64>,
    angles: PyReadonlyArray1<'py, f64>,
    n_particles: usize,
    threads: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let ci = indices("contact_i", &contact_i)?;
    let cj = indices("contact_j", &contact_j)?;
    let angles = slice("angles", &angles)?;
    let (lambda, counts) = run(py, threads, || {
        kernels::stability_index_of_contacts(&ci, &cj, angles, n_particles)
    })?;
    Ok((
        PyArray1::from_vec(py, lambda).into_any(),
        PyArray1::from_vec(py, to_i64(counts)).into_any(),
    ))
}

/// Histogram `(bins,)` of contact normals, each counted in both directions.
#[pyfunction]
#[pyo3(signature = (angles, weights, bins, edge_tolerance, threads))]
fn angular_histogram<'py>(
    py: Python<'py>,
    angles: PyReadonlyArray1<'py, f64>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    bins: usize,
    edge_tolerance: f64,
    threads: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let angles = slice("angles", &angles)?;
    let weights = weights.as_ref().map(|w| slice("weights", w)).transpose()?;
    let values = run(py, threads, || {
        kernels::angular_histogram(angles, weights, bins, edge_tolerance)
    })?;
    Ok(PyArray1::from_vec(py, values).into_any())
}

/// `(sum w sin 2 theta, sum w cos 2 theta, sum w)`.
#[pyfunction]
#[pyo3(signature = (angles, weights, threads))]
fn fourier_moment(
    py: Python<'_>,
    angles: PyReadonlyArray1<'_, f64>,
    weights: Option<PyReadonlyArray1<'_, f64>>,
    threads: usize,
) -> PyResult<(f64, f64, f64)> {
    let angles = slice("angles", &angles)?;
    let weights = weights.as_ref().map(|w| slice("weights", w)).transpose()?;
    let m = run(py, threads, || kernels::fourier_moment(angles, weights))?;
    Ok((m.sin_sum, m.cos_sum, m.total))
}

/// The fabric tensor `(2, 2)` and the weight total.
#[pyfunction]
#[pyo3(signature = (normals, weights, threads))]
fn fabric_tensor<'py>(
    py: Python<'py>,
    normals: PyReadonlyArray2<'py, f64>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    threads: usize,
) -> PyResult<(Bound<'py, PyAny>, f64)> {
    let normals = point_slice("normals", &normals)?;
    let weights = weights.as_ref().map(|w| slice("weights", w)).transpose()?;
    let (phi, total) = run(py, threads, || kernels::fabric_tensor(normals, weights))?;
    Ok((points_to_py(py, &phi)?, total))
}

/// `(N,)` bool mask of the rattlers, removed iteratively.
#[pyfunction]
#[pyo3(signature = (contact_i, contact_j, n_particles, min_contacts, candidates, threads))]
fn rattlers<'py>(
    py: Python<'py>,
    contact_i: PyReadonlyArray1<'py, i64>,
    contact_j: PyReadonlyArray1<'py, i64>,
    n_particles: usize,
    min_contacts: usize,
    candidates: Option<PyReadonlyArray1<'py, bool>>,
    threads: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let ci = slice("contact_i", &contact_i)?;
    let cj = slice("contact_j", &contact_j)?;
    let candidates = candidates
        .as_ref()
        .map(|c| slice("candidates", c))
        .transpose()?;
    let removed = run(py, threads, || {
        kernels::rattlers(ci, cj, n_particles, min_contacts, candidates)
    })?;
    Ok(values_to_py(py, &removed))
}

/// Adds the analysis functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(detect_contacts, m)?)?;
    m.add_function(wrap_pyfunction!(contact_normals, m)?)?;
    m.add_function(wrap_pyfunction!(stability_index, m)?)?;
    m.add_function(wrap_pyfunction!(stability_index_of_contacts, m)?)?;
    m.add_function(wrap_pyfunction!(angular_histogram, m)?)?;
    m.add_function(wrap_pyfunction!(fourier_moment, m)?)?;
    m.add_function(wrap_pyfunction!(fabric_tensor, m)?)?;
    m.add_function(wrap_pyfunction!(rattlers, m)?)?;
    Ok(())
}
