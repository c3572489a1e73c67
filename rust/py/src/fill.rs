//! Binding of `stereovision_core::fill` and `stereovision_core::edges`.

use crate::convert::{map_copy_in_place, row_major, vec_to_numpy};
use crate::errors::guard;
use crate::params::non_negative;
use numpy::{PyArray2, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use stereovision_core::edges::{fattened as core_fattened, FattenParams};
use stereovision_core::fill::{row_fill as core_row_fill, side_fill as core_side_fill};

/// A copy of `disp` with its holes filled by the reference row rule (module docs of the core).
#[pyfunction]
pub fn row_fill<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let (out, done) = map_copy_in_place(py, &disp, "disp", |d, w, _| {
        guard("row_fill", || {
            core_row_fill(d, w);
            Ok(())
        })
    })?;
    done?;
    Ok(out)
}

/// A copy of `disp` with the colour side rule applied (`(H, W, 3)` `lab`; core docs).
#[pyfunction]
#[pyo3(signature = (disp, lab, tau))]
pub fn side_fill<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    lab: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = tau_f32)] tau: f32,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let lab: PyReadonlyArray3<'py, f32> = crate::convert::array_arg(lab, "lab")?;
    non_negative("tau", tau)?;
    let (h, w) = disp.as_array().dim();
    if lab.shape() != [h, w, 3] {
        return Err(PyValueError::new_err(format!(
            "lab: expected shape ({h}, {w}, 3) like disp, got {:?}",
            lab.shape()
        )));
    }
    let lab = row_major(&lab, "lab")?;
    let (out, done) = map_copy_in_place(py, &disp, "disp", |d, w, _| {
        guard("side_fill", || {
            core_side_fill(d, &lab, w, tau);
            Ok(())
        })
    })?;
    done?;
    Ok(out)
}

/// The pixels of `disp` a matcher carried past an edge of `guide` (`(H, W)` bool; core docs).
#[pyfunction]
#[pyo3(signature = (disp, guide, radius, ratio, jump))]
pub fn fattened<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    guide: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = radius_arg)] radius: usize,
    #[pyo3(from_py_with = ratio_f32)] ratio: f32,
    #[pyo3(from_py_with = jump_f32)] jump: f32,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let guide: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(guide, "guide")?;
    non_negative("ratio", ratio)?;
    non_negative("jump", jump)?;
    let (h, w) = disp.as_array().dim();
    if guide.as_array().dim() != (h, w) {
        return Err(PyValueError::new_err(format!(
            "guide: expected shape ({h}, {w}) like disp, got {:?}",
            guide.as_array().dim()
        )));
    }
    let (d, g) = (row_major(&disp, "disp")?, row_major(&guide, "guide")?);
    // A NaN step never beats another in the kernel's search, where NumPy's argmax (the
    // reference) stops at it: the two marked different pixels. A guide is an image.
    let bad = g.iter().filter(|v| !v.is_finite()).count();
    if bad > 0 {
        return Err(PyValueError::new_err(format!(
            "guide: expected finite values (an image), got {bad} NaN or inf"
        )));
    }
    let p = FattenParams {
        radius,
        ratio,
        jump,
    };
    let mask =
        crate::workers::detach(py, || guard("fattened", || core_fattened(&d, &g, w, h, &p)))?;
    vec_to_numpy(py, (h, w), mask)
}

crate::named_ints! {
    radius_arg: usize = "radius";
}

crate::named_floats! {
    tau_f32: f32 = "tau";
    ratio_f32: f32 = "ratio";
    jump_f32: f32 = "jump";
}
