//! One place that maps core errors (and stray panics) to Python exceptions.

use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::PyErr;
use stereovision_core::CoreError;

/// Maps each core error to the Python exception class users already catch.
pub fn to_pyerr(err: CoreError) -> PyErr {
    match err {
        CoreError::EmptyImage { .. }
        | CoreError::BufferSize { .. }
        | CoreError::SizeMismatch { .. }
        | CoreError::NonFinite { .. }
        | CoreError::InvalidParameter { .. } => PyValueError::new_err(err.to_string()),
        CoreError::OutOfMemory { .. } => PyMemoryError::new_err(err.to_string()),
    }
}

/// `MemoryError` for a copy of `n` values of `T` the binding could not allocate.
pub fn copy_oom<T>(n: usize, what: &str) -> PyErr {
    let bytes = n.saturating_mul(std::mem::size_of::<T>());
    PyMemoryError::new_err(format!(
        "out of memory: a copy of {what} needs {} and the allocation failed",
        stereovision_core::alloc::human_bytes(bytes)
    ))
}

/// Runs a kernel, turning a panic into a `RuntimeError` so no `PanicException` (a
/// `BaseException`) ever reaches the user.
pub fn guard<T>(name: &str, f: impl FnOnce() -> Result<T, CoreError>) -> Result<T, PyErr> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_pyerr(e)),
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(PyRuntimeError::new_err(format!(
                "internal error in {name}: {msg} (please report this)"
            )))
        }
    }
}
