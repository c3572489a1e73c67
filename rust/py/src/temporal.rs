//! Binding of `stereovision_core::temporal`.

use std::borrow::Cow;

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{
    IntoPyArray, PyArray2, PyArrayDyn, PyReadonlyArray2, PyReadonlyArrayDyn, PyReadwriteArray2,
    PyReadwriteArrayDyn, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use stereovision_core::temporal::{grey_difference, running_mean};

use crate::convert::{row_major, u8_layout, u8_shape, vec_to_numpy};
use crate::errors::guard;

/// The mean's values in row-major order, checked to have the frame's shape: its own buffer
/// when C-contiguous, else a copy.
fn mean_values<'a>(
    mean: &'a PyReadonlyArrayDyn<'_, f32>,
    frame_shape: &[usize],
) -> PyResult<Cow<'a, [f32]>> {
    if mean.shape() != frame_shape {
        return Err(PyValueError::new_err(format!(
            "mean shape {:?} differs from the frame's {:?}",
            mean.shape(),
            frame_shape
        )));
    }
    row_major(mean, "mean")
}

/// Grey value of `frame - mean` per pixel, `(H, W)` float32 (module docs of the core).
#[pyfunction]
pub fn temporal_grey_difference<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    mean: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let frame: PyReadonlyArrayDyn<'py, u8> = crate::convert::array_arg(frame, "frame")?;
    let mean: PyReadonlyArrayDyn<'py, f32> = crate::convert::array_arg(mean, "mean")?;
    // The mean's shape before the frame's copy: the frame was copied (4 GiB for a broadcast
    // one) before a mean of another shape was refused.
    u8_shape(&frame, "frame")?;
    let m = mean_values(&mean, frame.shape())?;
    let (h, w, c, f) = u8_layout(&frame, "frame")?;
    let d = crate::workers::detach(py, || {
        guard("temporal_grey_difference", || {
            grey_difference(&f, &m, h * w, c)
        })
    })?;
    vec_to_numpy(py, (h, w), d)
}

/// One more frame into the running mean, in place (`mean` and `count`); returns the mean
/// rounded to uint8, the frame's shape.
#[pyfunction]
#[pyo3(signature = (frame, mean, count, diff, ks, max_frames))]
pub fn temporal_running_mean<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    mean: &Bound<'py, PyAny>,
    count: &Bound<'py, PyAny>,
    diff: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = ks_f32)] ks: f32,
    #[pyo3(from_py_with = max_frames_arg)] max_frames: u8,
) -> PyResult<Bound<'py, PyArrayDyn<u8>>> {
    let mut mean: PyReadwriteArrayDyn<'py, f32> = crate::convert::array_arg_rw(mean, "mean")?;
    let mut count: PyReadwriteArray2<'py, u8> = crate::convert::array_arg_rw(count, "count")?;
    let frame: PyReadonlyArrayDyn<'py, u8> = crate::convert::array_arg(frame, "frame")?;
    let diff: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(diff, "diff")?;
    let (h, w, _) = u8_shape(&frame, "frame")?;
    let shape = frame.shape().to_vec();
    if mean.shape() != shape.as_slice() {
        return Err(PyValueError::new_err(format!(
            "mean shape {:?} differs from the frame's {:?}",
            mean.shape(),
            shape
        )));
    }
    for (name, dims) in [("count", count.shape()), ("diff", diff.shape())] {
        if dims != [h, w] {
            return Err(PyValueError::new_err(format!(
                "{name} shape {dims:?} differs from the frame's {:?}",
                [h, w]
            )));
        }
    }
    // `mean` and `count` are written in place: no copy can stand for them. The error names
    // the one that is not C-contiguous (it named both).
    for (name, ok) in [
        ("mean", mean.is_c_contiguous()),
        ("count", count.is_c_contiguous()),
    ] {
        if !ok {
            return Err(PyValueError::new_err(format!(
                "{name} must be C-contiguous: it is updated in place"
            )));
        }
    }
    // Copied once every shape and layout is checked: the frame was copied (4 GiB for a
    // broadcast one) before a mean, count or diff of another shape was refused.
    let (_, _, c, f) = u8_layout(&frame, "frame")?;
    let d = row_major(&diff, "diff")?;
    let (Ok(m), Ok(n)) = (mean.as_slice_mut(), count.as_slice_mut()) else {
        return Err(PyValueError::new_err("mean and count must be C-contiguous"));
    };
    let out = crate::workers::detach(py, || {
        guard("temporal_running_mean", || {
            running_mean(&f, m, n, &d, c, ks, max_frames)
        })
    })?;
    let out = ArrayD::from_shape_vec(IxDyn(&shape), out)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(out.into_pyarray(py))
}

crate::named_ints! {
    max_frames_arg: u8 = "max_frames";
}

crate::named_floats! {
    ks_f32: f32 = "ks";
}
