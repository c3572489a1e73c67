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
                // An int past a double in a float slot: the functions' arguments' words
                // (it was "parameter `sides_mad`: OverflowError: int too large to convert to
                // float").
                _ if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(py) => {
                    match T::check_exact(&v, key) {
                        Err(said) => said,
                        Ok(()) => PyValueError::new_err(format!("parameter `{key}`: {e}")),
                    }
                }
                _ => PyValueError::new_err(format!("parameter `{key}`: {e}")),
            }
        })?;
        // A float slot's value float32 cannot hold, said as for the functions' arguments.
        T::check_exact(&v, key)?;
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

    /// A value the slot holds only approximately beyond its rounding, refused ([`FloatArg`]).
    fn check_exact(_v: &Bound<'_, PyAny>, _key: &str) -> PyResult<()> {
        Ok(())
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

impl Slot for f32 {
    fn check_exact(v: &Bound<'_, PyAny>, key: &str) -> PyResult<()> {
        f32::extract_named(v, key).map(|_| ())
    }
}
impl Slot for f64 {}
impl Slot for bool {}
impl Slot for String {}
/// Each value as a float slot's ([`FloatArg`]): `sigmas: [1e39]` was cut to inf ("each sigma
/// must lie in [0.3, 64] px, got inf"), `[1e-50]` to 0, and `[10**400]` was "parameter
/// `sigmas`: OverflowError: int too large to convert to float".
impl Slot for Vec<f32> {
    fn check_exact(v: &Bound<'_, PyAny>, key: &str) -> PyResult<()> {
        for item in v.try_iter()? {
            f32::extract_named(&item?, key)?;
        }
        Ok(())
    }
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

/// The float arguments of the functions, held as the kernels' `f32`: pyo3's own conversion
/// cut a Python float to `f32` before any check, so 1e39 reached the kernel as inf ("`fb`:
/// must be finite, got inf", `tol=1e39` passed as no tolerance at all) and 1e-50 as 0 ("must
/// be > 0, got 0"), and it named no argument for a value that is no number ("must be real
/// number, not str") or an int past a double ("int too large to convert to float"). A value
/// float32 cannot hold is a `ValueError` naming the argument and the value given now (NaN and
/// inf pass, for the kernels' own checks), one that is no number a `TypeError` naming it.
pub trait FloatArg: Sized {
    /// The argument `name` from `ob`.
    fn extract_named(ob: &Bound<'_, PyAny>, name: &str) -> PyResult<Self>;
}

impl FloatArg for f32 {
    fn extract_named(ob: &Bound<'_, PyAny>, name: &str) -> PyResult<Self> {
        let py = ob.py();
        let got = || {
            ob.repr()
                .map_or_else(|_| "?".to_string(), |r| r.to_string())
        };
        let v: f64 = ob.extract::<f64>().map_err(|e| {
            if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(py) {
                PyValueError::new_err(format!(
                    "invalid parameter `{name}`: expected a number within float32's range, the \
                     kernel's precision, got {}",
                    got()
                ))
            } else {
                PyTypeError::new_err(format!("invalid parameter `{name}`: {}", e.value(py)))
            }
        })?;
        let f = v as f32;
        if v.is_finite() && !f.is_finite() {
            return Err(PyValueError::new_err(format!(
                "invalid parameter `{name}`: expected a number within float32's range, the \
                 kernel's precision, got {}",
                got()
            )));
        }
        if v != 0.0 && f == 0.0 {
            return Err(PyValueError::new_err(format!(
                "invalid parameter `{name}`: {} is 0 in float32, the kernel's precision \
                 (give 0, or a magnitude of at least 1e-45)",
                got()
            )));
        }
        Ok(f)
    }
}

impl FloatArg for Option<f32> {
    fn extract_named(ob: &Bound<'_, PyAny>, name: &str) -> PyResult<Self> {
        if ob.is_none() {
            Ok(None)
        } else {
            f32::extract_named(ob, name).map(Some)
        }
    }
}

/// [`named_ints`]'s float sibling: `named_floats!(tol_f32: f32 = "tol");` defines
/// `tol_f32(ob) -> PyResult<f32>` through [`FloatArg`].
#[macro_export]
macro_rules! named_floats {
    ($($f:ident: $t:ty = $name:literal;)*) => {$(
        fn $f(ob: &pyo3::Bound<'_, pyo3::PyAny>) -> pyo3::PyResult<$t> {
            <$t as $crate::params::FloatArg>::extract_named(ob, $name)
        }
    )*};
}
