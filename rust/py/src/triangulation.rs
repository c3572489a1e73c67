//! Binding of `stereovision_core::triangulation`.

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use stereovision_core::triangulation::{check_params, depth_rectified as core_depth, SigmaModel};

use crate::convert::{image_to_numpy, map_and_confidence};
use crate::errors::{guard, to_pyerr};
use stereovision_core::Image;

type Pair<'py> = (
    Bound<'py, numpy::PyArray2<f32>>,
    Bound<'py, numpy::PyArray2<f32>>,
);

/// Depth and its one-sigma uncertainty from a rectified disparity map (NaN = no disparity; a
/// negative confidence marks a filled pixel, whose disparity sigma is `s_fill`).
#[pyfunction]
#[pyo3(signature = (disp, conf, fb, doffs, s0, slope, s_min, s_fill))]
#[allow(clippy::too_many_arguments)]
pub fn depth_rectified<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    conf: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = fb_f32)] fb: f32,
    #[pyo3(from_py_with = doffs_f32)] doffs: f32,
    #[pyo3(from_py_with = s0_f32)] s0: f32,
    #[pyo3(from_py_with = slope_f32)] slope: f32,
    #[pyo3(from_py_with = s_min_f32)] s_min: f32,
    #[pyo3(from_py_with = s_fill_f32)] s_fill: f32,
) -> PyResult<Pair<'py>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let conf: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(conf, "conf")?;
    let m = SigmaModel {
        s0,
        slope,
        s_min,
        s_fill,
    };
    // The kernel's parameter check before the maps' copies: a broadcast 65536 x 65536 map was
    // a 16 GiB copy (a MemoryError under a memory limit) before a NaN `fb` was refused.
    check_params(fb, doffs, m).map_err(to_pyerr)?;
    let (h, w) = disp.as_array().dim();
    let (d, c) = map_and_confidence(&disp, &conf, (h, w), "disp")?;
    let (z, s) = crate::workers::detach(py, || {
        guard("depth_rectified", || core_depth(&d, &c, w, h, fb, doffs, m))
    })?;
    let img = |data| Image {
        width: w,
        height: h,
        data,
    };
    Ok((image_to_numpy(py, img(z))?, image_to_numpy(py, img(s))?))
}

crate::named_floats! {
    fb_f32: f32 = "fb";
    doffs_f32: f32 = "doffs";
    s0_f32: f32 = "s0";
    slope_f32: f32 = "slope";
    s_min_f32: f32 = "s_min";
    s_fill_f32: f32 = "s_fill";
}
