//! Binding of `stereovision_core::fill`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::fill::row_fill as core_row_fill;
use stereovision_core::Image;

use crate::convert::image_to_numpy;

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
    image_to_numpy(
        py,
        Image {
            width: w,
            height: h,
            data: d,
        },
    )
}
