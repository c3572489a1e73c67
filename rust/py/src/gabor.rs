//! Binding of `stereovision_core::matching::gabor`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::matching::gabor::{gabor_disparity as core_gabor, GaborParams};

use crate::convert::{image_from_numpy, image_to_numpy};
use crate::errors::guard;

/// Dense Gabor phase disparity. Returns `(disparity, confidence)`, float32 (H, W).
#[pyfunction]
#[pyo3(signature = (left, right, d_min, d_max))]
pub fn gabor_disparity<'py>(
    py: Python<'py>,
    left: PyReadonlyArray2<'py, f32>,
    right: PyReadonlyArray2<'py, f32>,
    d_min: f32,
    d_max: f32,
) -> PyResult<(Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<f32>>)> {
    let l = image_from_numpy(&left, "left")?;
    let r = image_from_numpy(&right, "right")?;
    let params = GaborParams { d_min, d_max };
    let out = py.detach(|| guard("gabor_disparity", || core_gabor(&l, &r, &params)))?;
    Ok((
        image_to_numpy(py, out.disparity)?,
        image_to_numpy(py, out.confidence)?,
    ))
}
