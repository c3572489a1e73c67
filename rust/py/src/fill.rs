//! Binding of `stereovision_core::fill`.

use crate::convert::map_copy_in_place;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::fill::row_fill as core_row_fill;

/// A copy of `disp` with its holes filled by the reference row rule (module docs of the core).
#[pyfunction]
pub fn row_fill<'py>(
    py: Python<'py>,
    disp: PyReadonlyArray2<'py, f32>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    Ok(map_copy_in_place(py, &disp, |d, w, _| core_row_fill(d, w))?.0)
}
