//! The mass properties of a clump (`grainlab_core::body`) as a `grainlab._core` function.
use grainlab_core::body::{union_area_properties, ClumpTemplate};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, points_to_py, to_py_err, values};

/// Area, mass, centroid, moment of inertia, body-frame offsets.
type Properties<'py> = (f64, f64, (f64, f64), f64, Bound<'py, PyAny>);

/// The clump's union area (m^2), mass (kg per m), centroid (m), moment of
/// inertia about it (kg m^2 per m) and its pebbles' offsets from the centroid.
#[pyfunction]
#[pyo3(signature = (offsets, radii, density))]
fn clump_mass_properties<'py>(
    py: Python<'py>,
    offsets: PyReadonlyArray2<'py, f64>,
    radii: PyReadonlyArray1<'py, f64>,
    density: f64,
) -> PyResult<Properties<'py>> {
    let centres = points("offsets", &offsets)?;
    let radii = values(&radii);
    let (template, at) =
        ClumpTemplate::from_pebbles(&centres, &radii, density).map_err(to_py_err)?;
    let union = union_area_properties(&centres, &radii).map_err(to_py_err)?;
    Ok((
        union.area,
        template.mass(),
        (at.centroid[0], at.centroid[1]),
        template.moment_of_inertia(),
        points_to_py(py, template.offsets())?,
    ))
}

/// Adds this file's functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(clump_mass_properties, m)?)
}
