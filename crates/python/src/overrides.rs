//! Python values as scenario overrides: `set={"controller.kp": 40}` is `--set controller.kp=40`.
//!
//! A string value is read exactly as the command line reads `--set key=VALUE` (a TOML literal,
//! else the text itself), so `{"physics.backend": "rapier"}` and `["controller.kp=40"]` mean what
//! they mean there. Booleans, integers, floats, lists and dicts become the TOML value of that type.

use crate::errors::scenario_error;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use tendril_config::Override;

/// The overrides of `set`: a dict of dotted keys to values, or a list of `"key=value"` strings
/// (`None`: none).
pub fn overrides(set: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Override>> {
    let Some(set) = set.filter(|s| !s.is_none()) else { return Ok(Vec::new()) };
    if let Ok(dict) = set.cast::<PyDict>() {
        return dict.iter().map(|(k, v)| entry(&k, &v)).collect();
    }
    if set.is_instance_of::<PyString>() {
        return Err(PyTypeError::new_err(
            "set: expected a dict such as {\"controller.kp\": 40} or a list of \"key=value\" strings, got a str",
        ));
    }
    let items = set.try_iter().map_err(|_| {
        PyTypeError::new_err(format!(
            "set: expected a dict such as {{\"controller.kp\": 40}} or a list of \"key=value\" strings, got {}",
            type_name(set)
        ))
    })?;
    items
        .map(|item| {
            let item = item?;
            let text: String = item.extract().map_err(|_| {
                PyTypeError::new_err(format!("set: list items must be \"key=value\" strings, got {}", type_name(&item)))
            })?;
            text.parse::<Override>().map_err(scenario_error)
        })
        .collect()
}

/// One `key: value` entry.
fn entry(key: &Bound<'_, PyAny>, value: &Bound<'_, PyAny>) -> PyResult<Override> {
    let key: String = key
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("set: keys must be dotted strings, got {}", type_name(key))))?;
    if let Ok(text) = value.cast::<PyString>() {
        // As the command line reads it.
        return format!("{key}={}", text.to_str()?).parse::<Override>().map_err(scenario_error);
    }
    // The key checked as the command line checks it; the value is Python's.
    let checked = format!("{key}=0").parse::<Override>().map_err(scenario_error)?;
    Ok(Override { key: checked.key, value: toml_value(&key, value)? })
}

/// A Python value as TOML (numpy scalars and arrays through their `tolist()`).
fn toml_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if v.is_instance_of::<PyInt>() {
        return match v.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            // Beyond i64 (a seed up to 2^64 - 1): the decimal string scenarios take for it.
            Err(_) => Ok(toml::Value::String(v.str()?.to_str()?.to_string())),
        };
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract::<f64>()?));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_str()?.to_string()));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, item) in d.iter() {
            let k: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("set: key `{key}`: table keys must be strings, got {}", type_name(&k)))
            })?;
            let value = toml_value(&format!("{key}.{k}"), &item)?;
            table.insert(k, value);
        }
        return Ok(toml::Value::Table(table));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let array = v.try_iter()?.map(|item| toml_value(key, &item?)).collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(array));
    }
    if v.hasattr("tolist")? {
        let plain = v.call_method0("tolist")?;
        if !plain.is(v) {
            return toml_value(key, &plain);
        }
    }
    Err(PyTypeError::new_err(format!(
        "set: key `{key}`: a {} cannot be a scenario value (use a bool, int, float, str, list or dict)",
        type_name(v)
    )))
}

/// The Python type name of `v`, for messages.
pub fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "object".into())
}
