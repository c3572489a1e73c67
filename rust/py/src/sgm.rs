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
    #[pyo3(from_py_with = d_min_arg)] d_min: i32,
    #[pyo3(from_py_with = d_max_arg)] d_max: i32,
    #[pyo3(from_py_with = p1_arg)] p1: u16,
    #[pyo3(from_py_with = p2_arg)] p2: u16,
    #[pyo3(from_py_with = gamma_f32)] gamma: f32,
    #[pyo3(from_py_with = uniqueness_arg)] uniqueness: u32,
    #[pyo3(from_py_with = lr_tol_arg)] lr_tol: u32,
    #[pyo3(from_py_with = edge_margin_arg)] edge_margin: u32,
    #[pyo3(from_py_with = paths_arg)] paths: u8,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes before either copy (a broadcast left was copied first)
    crate::errors::check_pair_shapes(left.as_array().dim(), right.as_array().dim())?;
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

crate::named_ints! {
    d_min_arg: i32 = "d_min";
    d_max_arg: i32 = "d_max";
    p1_arg: u16 = "p1";
    p2_arg: u16 = "p2";
    uniqueness_arg: u32 = "uniqueness";
    lr_tol_arg: u32 = "lr_tol";
    edge_margin_arg: u32 = "edge_margin";
}

/// `paths`: the kernel takes 8 or 3; any other integer (-1, 256, 4) is a `ValueError` saying
/// so (a value outside `u8` named "an integer from 0 to 255", which the kernel does not take).
fn paths_arg(ob: &Bound<'_, PyAny>) -> PyResult<u8> {
    let py = ob.py();
    let bad = || {
        let got = ob
            .repr()
            .map_or_else(|_| "?".to_string(), |r| r.to_string());
        pyo3::exceptions::PyValueError::new_err(format!(
            "invalid parameter `paths`: expected 8 or 3, got {got}"
        ))
    };
    match crate::params::int_arg::<u8>(ob, "paths") {
        Ok(v) if v == 3 || v == 8 => Ok(v),
        Ok(_) => Err(bad()),
        Err(e) if e.is_instance_of::<pyo3::exceptions::PyValueError>(py) => Err(bad()),
        Err(e) => Err(e),
    }
}

crate::named_floats! {
    gamma_f32: f32 = "gamma";
}
