//! Binding of `stereovision_core::matching::sgm`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::matching::sgm::{sgm_disparity as core_sgm, SgmParams};
use stereovision_core::Image;

use crate::convert::{grey_from_numpy, image_to_numpy};
use crate::errors::guard;

/// Census semi-global disparity over `[d_min, d_max]`, NaN where rejected (module docs of the core).
#[pyfunction]
#[pyo3(signature = (left, right, d_min, d_max, p1, p2, gamma, uniqueness, lr_tol, edge_margin, paths=8))]
#[allow(clippy::too_many_arguments)]
pub fn sgm_disparity<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    d_min: i32,
    d_max: i32,
    p1: u16,
    p2: u16,
    gamma: f32,
    uniqueness: u32,
    lr_tol: u32,
    edge_margin: u32,
    paths: u8,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    let l = grey_from_numpy(&left, "left")?;
    let r = grey_from_numpy(&right, "right")?;
    let (w, h) = (l.view().width, l.view().height);
    let p = SgmParams {
        p1,
        p2,
        gamma,
        uniqueness,
        lr_tol,
        edge_margin,
        paths,
    };
    let (lv, rv) = (l.view(), r.view());
    let out = crate::workers::detach(py, || {
        guard("sgm_disparity", || core_sgm(lv, rv, d_min, d_max, &p))
    })?;
    image_to_numpy(
        py,
        Image {
            width: w,
            height: h,
            data: out,
        },
    )
}
