//! `read_vtp`: a frame a run wrote (`particles_NNNNNN.vtp`, `walls_…`, `polyhedra_…`,
//! `contacts_…`), read back with the library's own reader, as NumPy arrays.

use crate::arrays::{rows, vectors};
use numpy::PyArray1;
use polydem::io::vtk_read::{read_vtp as read, DataArray};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Reads a `.vtp` file written by polydem: a dict with `time` (float or None), `points` (N, 3)
/// and `point_data` and `cell_data`, each a dict of arrays by name ((N,) for one component,
/// (N, k) for k).
#[pyfunction]
pub fn read_vtp(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let data = read(&path).map_err(|e| PyOSError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("time", data.time)?;
    d.set_item("points", vectors(py, &data.points)?)?;
    d.set_item("point_data", arrays(py, &data.point_data)?)?;
    d.set_item("cell_data", arrays(py, &data.cell_data)?)?;
    Ok(d)
}

fn arrays<'py>(py: Python<'py>, arrays: &[DataArray]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for a in arrays {
        if a.components == 1 {
            d.set_item(&a.name, PyArray1::from_vec(py, a.values.clone()))?;
        } else {
            d.set_item(&a.name, rows(py, a.values.clone(), a.components)?)?;
        }
    }
    Ok(d)
}
