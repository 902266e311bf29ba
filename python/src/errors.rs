//! The package's exceptions, and the library's errors turned into them: nothing panics across the
//! boundary, every failure reaches Python as an exception with the library's message.

use polydem::run::RunError as LibRunError;
use polydem::scene::SceneError as LibSceneError;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    polydem,
    SceneError,
    PyValueError,
    "A scene that cannot be run: the message names the file, line and key (attributes `file`, \
     `line`, `key`; None where unknown) and what is allowed."
);
pyo3::create_exception!(
    polydem,
    RunError,
    PyRuntimeError,
    "A run that stopped before its end: it blew up, its output could not be written, or a \
     checkpoint could not be written, read or resumed."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    Ok(())
}

/// A scene error as `polydem.SceneError`, with where it is as attributes.
pub fn scene_error(py: Python<'_>, e: &LibSceneError) -> PyErr {
    let err = SceneError::new_err(e.to_string());
    let (file, line, key) = match e {
        LibSceneError::Read { file, .. } | LibSceneError::Override { file, .. } => {
            (Some(file), None, None)
        }
        LibSceneError::Syntax { file, line, .. } => (Some(file), Some(*line), None),
        LibSceneError::Invalid {
            file, line, key, ..
        } => (Some(file), *line, Some(key.to_string())),
    };
    let value = err.value(py);
    // Setting attributes on a fresh exception object cannot fail short of memory exhaustion;
    // the message carries the same facts anyway.
    let _ = value.setattr("file", file.map(|f| f.display().to_string()));
    let _ = value.setattr("line", line);
    let _ = value.setattr("key", key);
    err
}

/// A run error as `polydem.RunError`, or `KeyboardInterrupt` for a run stopped by Ctrl-C (its
/// message says where the checkpoint is).
pub fn run_error(e: LibRunError) -> PyErr {
    match e {
        LibRunError::Interrupted {
            checkpoint: Some(_),
            ..
        } => PyKeyboardInterrupt::new_err(format!(
            "{e} (from Python: polydem.Simulation.resume(OUT))"
        )),
        LibRunError::Interrupted { .. } => PyKeyboardInterrupt::new_err(e.to_string()),
        e => RunError::new_err(e.to_string()),
    }
}

/// A wrong argument.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
