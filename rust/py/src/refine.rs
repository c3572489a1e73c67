//! Binding of `stereovision_core::refine`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use stereovision_core::image::MAX_PIXELS;
use stereovision_core::refine::{refine_disparity as core_refine, FillPass, RefineParams};
use stereovision_core::Image;

use crate::convert::{check_map_shapes, grey_from_numpy, image_to_numpy, map_and_confidence};
use crate::errors::guard;

type Refined<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<f32>>, usize);

/// Refined disparity, its confidence and the number of filled pixels (module docs of the core).
#[pyfunction]
#[pyo3(signature = (left, right, disp, conf, d_min, d_max, base_sigma, win_sigma, win_radius,
                    search, step, fill_search, fill_step, var_floor, fills, fill_confidence, fill_plane, fill_max_residual))]
#[allow(clippy::too_many_arguments)]
pub fn refine_disparity<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    disp: &Bound<'py, PyAny>,
    conf: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = d_min_f32)] d_min: f32,
    #[pyo3(from_py_with = d_max_f32)] d_max: f32,
    #[pyo3(from_py_with = base_sigma_f32)] base_sigma: f32,
    #[pyo3(from_py_with = win_sigma_f32)] win_sigma: f32,
    #[pyo3(from_py_with = win_radius_arg)] win_radius: usize,
    #[pyo3(from_py_with = search_arg)] search: usize,
    #[pyo3(from_py_with = step_f32)] step: f32,
    #[pyo3(from_py_with = fill_search_arg)] fill_search: usize,
    #[pyo3(from_py_with = fill_step_f32)] fill_step: f32,
    #[pyo3(from_py_with = var_floor_f32)] var_floor: f32,
    #[pyo3(from_py_with = fills_arg)] fills: Vec<(f32, f32)>,
    #[pyo3(from_py_with = fill_confidence_f32)] fill_confidence: f32,
    fill_plane: bool,
    #[pyo3(from_py_with = fill_max_residual_f32)] fill_max_residual: f32,
) -> PyResult<Refined<'py>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let conf: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(conf, "conf")?;
    // The maps' shapes are checked before `left` and `right` are copied (a broadcast or
    // strided `left` was copied, or its copy's MemoryError said, before a `disp` of another
    // shape was refused).
    let (h, w) = left.as_array().dim();
    check_map_shapes(&disp, &conf, (h, w), "left")?;
    // So are `right`'s shape (the kernel's "left and right images differ in size" came after
    // both copies) and the size the kernel's 32-bit warp columns reach: a broadcast 65536 x
    // 65536 `left` was a 16 GiB copy (a MemoryError under a memory limit) before it was refused.
    if right.as_array().dim() != (h, w) {
        return Err(PyValueError::new_err(format!(
            "right: expected shape {:?} like left, got {:?}",
            (h, w),
            right.as_array().dim()
        )));
    }
    crate::errors::check_size(w, h, MAX_PIXELS, "left", "image")?;
    let l = grey_from_numpy(&left, "left")?;
    let r = grey_from_numpy(&right, "right")?;
    let (d, c) = map_and_confidence(&disp, &conf, (h, w), "left")?;
    let p = RefineParams {
        base_sigma,
        win_sigma,
        win_radius,
        search,
        step,
        fill_search,
        fill_step,
        var_floor,
        fills: fills
            .into_iter()
            .map(|(sigma, min_score)| FillPass { sigma, min_score })
            .collect(),
        fill_confidence,
        fill_plane,
        fill_max_residual,
    };
    let (lv, rv) = (l.view(), r.view());
    let (out, oc, filled) = crate::workers::detach(py, || {
        guard("refine_disparity", || {
            core_refine(lv, rv, &d, &c, d_min, d_max, &p)
        })
    })?;
    let img = |data| Image {
        width: w,
        height: h,
        data,
    };
    Ok((
        image_to_numpy(py, img(out))?,
        image_to_numpy(py, img(oc))?,
        filled,
    ))
}

crate::named_ints! {
    win_radius_arg: usize = "win_radius";
    search_arg: usize = "search";
    fill_search_arg: usize = "fill_search";
}

crate::named_floats! {
    d_min_f32: f32 = "d_min";
    d_max_f32: f32 = "d_max";
    base_sigma_f32: f32 = "base_sigma";
    win_sigma_f32: f32 = "win_sigma";
    step_f32: f32 = "step";
    fill_step_f32: f32 = "fill_step";
    var_floor_f32: f32 = "var_floor";
    fill_confidence_f32: f32 = "fill_confidence";
    fill_max_residual_f32: f32 = "fill_max_residual";
}

/// `fills`, a sequence of `(sigma, min_score)` pairs, each value through
/// [`FloatArg`](crate::params::FloatArg) as the scalar arguments are, named as the kernel names
/// it: pyo3's own conversion cut `(1e-50, 0.3)` to a sigma of 0 ("`fill sigma`: must be > 0,
/// got 0", of a sigma given > 0), `(16, 1e39)` to a min_score of inf, and `(10**400, 0.3)` was
/// a bare "OverflowError: int too large to convert to float".
fn fills_arg(ob: &Bound<'_, PyAny>) -> PyResult<Vec<(f32, f32)>> {
    use crate::params::FloatArg;
    let repr = |o: &Bound<'_, PyAny>| o.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
    let not_pairs = || {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid parameter `fills`: expected a sequence of (sigma, min_score) pairs, got {}",
            repr(ob)
        ))
    };
    if ob.is_instance_of::<pyo3::types::PyString>() {
        return Err(not_pairs());
    }
    let mut out = Vec::new();
    for (i, item) in ob.try_iter().map_err(|_| not_pairs())?.enumerate() {
        let item = item?;
        // any sequence of two, not a tuple alone: a list pair ([[16, 0.3]], JSON's) was
        // "element 0 ([16, 0.3]): expected a (sigma, min_score) pair" of a pair
        // bytes (b"\x10\x00": 16, 0) and a dict ({0: 16, 1: 0.3}) index as two numbers but
        // are no pair: taken since the list pair was, refused before as the tuple alone read
        let pair = || -> Option<(Bound<'_, PyAny>, Bound<'_, PyAny>)> {
            use pyo3::types::{PyByteArray, PyBytes, PyDict, PyString};
            if item.is_instance_of::<PyString>()
                || item.is_instance_of::<PyBytes>()
                || item.is_instance_of::<PyByteArray>()
                || item.is_instance_of::<PyDict>()
                || item.len().ok()? != 2
            {
                return None;
            }
            Some((item.get_item(0).ok()?, item.get_item(1).ok()?))
        };
        let (sigma, min_score) = pair().ok_or_else(|| {
            PyValueError::new_err(format!(
                "invalid parameter `fills`: element {i} ({}): expected a (sigma, min_score) pair",
                repr(&item)
            ))
        })?;
        out.push((
            f32::extract_named(&sigma, "fill sigma")?,
            f32::extract_named(&min_score, "fill min_score")?,
        ));
    }
    Ok(out)
}
