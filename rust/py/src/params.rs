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
/// An integer outside the slot's type (a negative `min_disparity`) was "parameter
/// `min_disparity`: OverflowError: can't convert negative int to unsigned"; it names the
/// allowed range now, as [`int_arg`] does.
pub fn get<'py, T: pyo3::conversion::FromPyObjectOwned<'py> + Slot>(
    d: &Bound<'py, PyDict>,
    key: &str,
    slot: &mut T,
) -> PyResult<()> {
    if let Some(v) = d.get_item(key)? {
        *slot = v.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            let py = v.py();
            match T::int_range() {
                Some(range) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(py) => {
                    let got = v.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
                    PyValueError::new_err(format!(
                        "invalid parameter `{key}`: expected {range}, got {got}"
                    ))
                }
                _ => PyValueError::new_err(format!("parameter `{key}`: {e}")),
            }
        })?;
    }
    Ok(())
}

/// The types of the parameter dicts' slots. An integer slot names its range in the error for
/// a value outside it; this was read off `std::any::type_name`, whose text Rust does not
/// promise, so a trait says it now and a slot type without an impl does not compile.
pub trait Slot {
    /// The range an integer slot's error names; `None` for other types.
    fn int_range() -> Option<String> {
        None
    }
}

macro_rules! int_slot {
    ($($t:ty),*) => {$(
        impl Slot for $t {
            fn int_range() -> Option<String> {
                Some(<$t as IntRange>::range())
            }
        }
    )*};
}
int_slot!(u8, u16, u32, u64, i32, i64, usize);

impl Slot for f32 {}
impl Slot for f64 {}
impl Slot for bool {}
impl Slot for String {}
impl Slot for Vec<f32> {}

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

/// The integer types of the functions' integer arguments, with the range their error names.
pub trait IntRange {
    /// `"from MIN to MAX"`, or what the argument holds when it is not a plain integer.
    fn range() -> String;
}

macro_rules! int_range {
    ($($t:ty),*) => {$(
        impl IntRange for $t {
            fn range() -> String {
                format!("an integer from {} to {}", <$t>::MIN, <$t>::MAX)
            }
        }
    )*};
}
int_range!(u8, u16, u32, u64, i32, i64, usize);

impl<T: IntRange> IntRange for Option<T> {
    fn range() -> String {
        format!("None or {}", T::range())
    }
}

/// The integer argument `name` of a function: an integer outside its Rust type's range was a
/// bare `OverflowError` ("can't convert negative int to unsigned", "int too big to convert")
/// naming neither the argument nor its range; it is a `ValueError` naming both now, and a value
/// that is no integer a `TypeError` naming the argument.
pub fn int_arg<'py, T>(ob: &Bound<'py, PyAny>, name: &str) -> PyResult<T>
where
    T: pyo3::conversion::FromPyObjectOwned<'py> + IntRange,
{
    ob.extract::<T>().map_err(|e| {
        let e: PyErr = e.into();
        let py = ob.py();
        let got = ob
            .repr()
            .map_or_else(|_| "?".to_string(), |r| r.to_string());
        if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(py) {
            PyValueError::new_err(format!(
                "invalid parameter `{name}`: expected {}, got {got}",
                T::range()
            ))
        } else {
            PyTypeError::new_err(format!("invalid parameter `{name}`: {}", e.value(py)))
        }
    })
}

/// Named extractors for `#[pyo3(from_py_with = ...)]` (which takes a path, not a closure):
/// `named_ints!(radius_arg: usize = "radius");` defines `radius_arg(ob) -> PyResult<usize>`.
#[macro_export]
macro_rules! named_ints {
    ($($f:ident: $t:ty = $name:literal;)*) => {$(
        fn $f(ob: &pyo3::Bound<'_, pyo3::PyAny>) -> pyo3::PyResult<$t> {
            $crate::params::int_arg(ob, $name)
        }
    )*};
}
