//! One place that maps core errors (and stray panics) to Python exceptions.

use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::{PyErr, PyResult};
use stereovision_core::CoreError;

/// Maps each core error to the Python exception class users already catch.
pub fn to_pyerr(err: CoreError) -> PyErr {
    match err {
        CoreError::EmptyImage { .. }
        | CoreError::BufferSize { .. }
        | CoreError::SizeMismatch { .. }
        | CoreError::NonFinite { .. }
        | CoreError::InvalidParameter { .. }
        | CoreError::TooLarge { .. }
        | CoreError::CorruptData { .. } => PyValueError::new_err(err.to_string()),
        CoreError::OutOfMemory { .. } => PyMemoryError::new_err(err.to_string()),
    }
}

/// The core's 32-bit index check ([`check_index_range_within`]) of the argument `name`, a
/// `w x h` `noun` ("image", or "map" for a disparity map), from its shape alone: before any
/// copy. The core's words ("image of WxH pixels is too large") named no argument, and called
/// `plane_fill`'s and `gabor_remove_speckles`' `disp` an image; these are the Python side's
/// (`_validate.check_index_range`): "disp: map of 65536x65536 pixels is too large: ...".
///
/// [`check_index_range_within`]: stereovision_core::image::check_index_range_within
pub fn check_size(w: usize, h: usize, max_pixels: usize, name: &str, noun: &str) -> PyResult<()> {
    stereovision_core::image::check_index_range_within(w, h, max_pixels).map_err(|e| {
        let text = e.to_string();
        let rest = text.strip_prefix("image ").unwrap_or(&text);
        PyValueError::new_err(format!("{name}: {noun} {rest}"))
    })
}

/// A pair's shapes (`(H, W)` each) and the core's 32-bit size ([`check_size`]), from the
/// shapes alone: before either image is copied (a broadcast or strided one is). A broadcast
/// 65536 x 65536 `left` was a 16 GiB copy, a `MemoryError` under a memory limit, before the
/// kernel refused its size or a `right` of another shape. The words are the kernel's; an empty
/// image is left to the copy's own check.
pub fn check_pair_size(left: (usize, usize), right: (usize, usize)) -> PyResult<()> {
    let (lh, lw) = left;
    if lh * lw == 0 || right.0 * right.1 == 0 {
        return Ok(());
    }
    check_pair_shapes(left, right)?;
    check_size(
        lw,
        lh,
        stereovision_core::image::MAX_PIXELS,
        "left",
        "image",
    )
}

/// A pair's shapes (`(H, W)` each) alone, for the kernels without the 32-bit size limit
/// (`sgm_disparity`, `gabor_newton_step`): a broadcast `left` was copied (16 GiB) before a
/// `right` of another shape was refused. The kernel's words; an empty image is left to the
/// copy's own check.
pub fn check_pair_shapes(left: (usize, usize), right: (usize, usize)) -> PyResult<()> {
    let ((lh, lw), (rh, rw)) = (left, right);
    if lh * lw == 0 || rh * rw == 0 || left == right {
        return Ok(());
    }
    Err(to_pyerr(CoreError::SizeMismatch {
        left: (lw, lh),
        right: (rw, rh),
    }))
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

/// `n` rows of `K` values flattened into one vector allocated at once, for an output array:
/// `MemoryError` naming `what` where an unchecked `collect` aborted the process.
pub fn flat_rows<T, const K: usize>(
    n: usize,
    rows: impl Iterator<Item = [T; K]>,
    what: &'static str,
) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    reserve(&mut v, n.saturating_mul(K), what)?;
    v.extend(rows.flatten());
    Ok(v)
}

/// Room for `n` values in all in `v`, or `MemoryError` naming `what` (see [`flat_rows`]).
pub fn reserve<T>(v: &mut Vec<T>, n: usize, what: &'static str) -> PyResult<()> {
    stereovision_core::alloc::try_reserve_len(v, n, what).map_err(to_pyerr)
}
