//! Binding of `stereovision_core::fill`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::fill::row_fill as core_row_fill;

/// A copy of `disp` with its holes filled by the reference row rule (module docs of the core).
#[pyfunction]
pub fn row_fill<'py>(
    py: Python<'py>,
    disp: PyReadonlyArray2<'py, f32>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let a = disp.as_array();
    let (h, w) = a.dim();
    let mut d: Vec<f32> = a.iter().copied().collect();
    py.detach(|| core_row_fill(&mut d, w));
    let arr = numpy::ndarray::Array2::from_shape_vec((h, w), d)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(numpy::IntoPyArray::into_pyarray(arr, py))
}
