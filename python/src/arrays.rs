//! Library values as NumPy arrays, and NumPy-like arguments as library values. The arrays are
//! copies taken when asked for: the run renumbers its bodies in space order and grows its
//! arrays as bodies come, so views into them would change meaning or dangle under the caller;
//! a copy of N×3 numbers costs far less than one step.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::math::{DQuat, DVec3};
use pyo3::prelude::*;

/// N vectors as an (N, 3) float64 array.
pub fn vectors<'py>(py: Python<'py>, values: &[DVec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = values.iter().flat_map(|v| v.to_array()).collect();
    PyArray1::from_vec(py, flat).reshape([values.len(), 3])
}

/// N quaternions as an (N, 4) float64 array, scalar first (w, x, y, z) as in the VTK output.
pub fn quaternions<'py>(py: Python<'py>, values: &[DQuat]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = values.iter().flat_map(|q| [q.w, q.x, q.y, q.z]).collect();
    PyArray1::from_vec(py, flat).reshape([values.len(), 4])
}

/// Rows of `k` numbers as an (N, k) float64 array.
pub fn rows<'py>(py: Python<'py>, flat: Vec<f64>, k: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = flat.len().checked_div(k).unwrap_or(0);
    PyArray1::from_vec(py, flat).reshape([n, k])
}

/// A sequence of three numbers (a tuple, list or array) as a vector.
pub fn vector(value: &Bound<'_, PyAny>, what: &str) -> PyResult<DVec3> {
    let v: Vec<f64> = value
        .extract()
        .map_err(|_| crate::errors::value_error(format!("{what}: give three numbers")))?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(x, y, z)),
        _ => Err(crate::errors::value_error(format!(
            "{what}: give three finite numbers, not {v:?}"
        ))),
    }
}

/// Three numbers, or zero when not given.
pub fn optional_vector(value: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<DVec3> {
    value.map_or(Ok(DVec3::ZERO), |v| vector(v, what))
}

/// An (N, 3) array or a list of N triples as vectors.
pub fn vector_rows(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let value = if value.hasattr("tolist")? {
        value.call_method0("tolist")?
    } else {
        value.clone()
    };
    value.try_iter()?.map(|row| vector(&row?, what)).collect()
}
