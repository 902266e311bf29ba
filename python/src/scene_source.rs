//! Where a scene comes from: a TOML file, or a Python dict with the same keys. A dict is written
//! as TOML text and then read exactly as a file is, so it gets the same checks and the same
//! messages (naming `<dict>` as its file, and the line of the TOML text it became).

// A scene error is built once, when loading fails (as in the library's `scene` module).
#![allow(clippy::result_large_err)]

use polydem::scene::overrides::Override;
use polydem::scene::Scene;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::{Path, PathBuf};

/// The name a scene given as a dict has in messages and checkpoints.
pub const DICT_FILE: &str = "<dict>";

/// Reads the scene `source` (a path or a dict) with the `--set`-style overrides applied.
pub fn load(py: Python<'_>, source: &Bound<'_, PyAny>, overrides: &[Override]) -> PyResult<Scene> {
    let loaded = if let Ok(dict) = source.cast::<PyDict>() {
        let text = toml::to_string(&table(dict, "")?)
            .map_err(|e| crate::errors::value_error(format!("the scene dict: {e}")))?;
        let file = Path::new(DICT_FILE);
        polydem::scene::overrides::apply(&text, overrides)
            .map_err(|message| polydem::scene::SceneError::Override {
                file: file.to_path_buf(),
                message,
            })
            .and_then(|text| Scene::parse(file, text))
    } else {
        let file: PathBuf = source.extract().map_err(|_| {
            crate::errors::value_error("a scene is a path to a TOML file or a dict of its keys")
        })?;
        Scene::load_with(&file, overrides)
    };
    loaded.map_err(|e| crate::errors::scene_error(py, &e))
}

/// `KEY=VALUE` overrides from a dict `{"simulation.duration": 2.0, "material[0].friction": 0.3}`.
pub fn overrides(set: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<Override>> {
    let Some(set) = set else {
        return Ok(Vec::new());
    };
    set.iter()
        .map(|(key, value)| {
            let key: String = key.extract()?;
            let value = toml_value(&value, &key)?;
            Ok(Override {
                key,
                value: value.to_string(),
            })
        })
        .collect()
}

fn table(dict: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (key, value) in dict.iter() {
        let key: String = key.extract().map_err(|_| {
            crate::errors::value_error(format!("{at}: scene keys are strings, not {key}"))
        })?;
        if value.is_none() {
            continue; // a key left out
        }
        let path = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        table.insert(key, toml_value(&value, &path)?);
    }
    Ok(table)
}

/// A Python value as TOML: dicts, lists and tuples, bools, ints, floats, strings, and anything
/// with `tolist()` (NumPy arrays and scalars).
fn toml_value(value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    if let Ok(dict) = value.cast::<PyDict>() {
        return Ok(toml::Value::Table(table(dict, at)?));
    }
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(value.extract()?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, item)| toml_value(&item?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if value.hasattr("tolist")? {
        return toml_value(&value.call_method0("tolist")?, at);
    }
    if let Ok(path) = value.extract::<PathBuf>() {
        return Ok(toml::Value::String(path.display().to_string()));
    }
    Err(crate::errors::value_error(format!(
        "{at}: {} cannot be a scene value (use numbers, strings, bools, lists and dicts)",
        value.get_type().name()?
    )))
}
