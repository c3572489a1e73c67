//! Tuning parameters passed as one Python dict (keys = the Python names).

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Every key of `d` must be one of `known`; `what` names the channel in the error.
pub fn check_keys(d: &Bound<'_, PyDict>, known: &[&str], what: &str) -> PyResult<()> {
    for k in d.keys() {
        let k: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{what} parameter names must be str, got the key {k} ({})",
                k.get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string())
            ))
        })?;
        if !known.contains(&k.as_str()) {
            return Err(PyValueError::new_err(format!(
                "unknown {what} parameter `{k}`"
            )));
        }
    }
    Ok(())
}

/// Overwrites `slot` with `d[key]` when present; a wrong type is a `ValueError` naming the key.
pub fn get<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    key: &str,
    slot: &mut T,
) -> PyResult<()> {
    if let Some(v) = d.get_item(key)? {
        *slot = v.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            PyValueError::new_err(format!("parameter `{key}`: {e}"))
        })?;
    }
    Ok(())
}

/// `Ok` when `v` is a finite number >= 0, else a `ValueError` naming it.
pub fn non_negative(name: &str, v: f32) -> PyResult<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{name}: expected a non-negative number, got {v}"
        )))
    }
}
