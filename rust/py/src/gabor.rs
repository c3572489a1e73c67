//! Binding of `stereovision_core::matching::gabor`.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use stereovision_core::matching::gabor::{
    filter::Channel,
    gabor_disparity_view as core_gabor, gabor_newton_step as core_step,
    gabor_responses as core_resp,
    post::{lr_check, remove_speckles},
    GaborParams,
};
use stereovision_core::Image;

use crate::convert::{grey_from_numpy, image_from_numpy, image_to_numpy};
use crate::errors::guard;

type Pair<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<f32>>);

/// Builds the core parameters from the keyword arguments (defaults mirror `GaborParams::default`).
#[allow(clippy::too_many_arguments)]
fn params(
    d_min: f32,
    d_max: f32,
    freq: f32,
    orientations_deg: Vec<f32>,
    bandwidth_oct: f32,
    aspect: f32,
    n_levels: Option<usize>,
    iters_per_level: usize,
    amp_rel_thresh: f32,
    stability_tau: f32,
    smooth_sigma: Option<f32>,
    conf_min: f32,
    research_radius: usize,
    search_pool_radius: usize,
    lr_check: bool,
    lr_tol: f32,
    lr_coarse_levels: usize,
    iters_finest: usize,
    research_finest: bool,
    orientations_finest: usize,
    fine_levels: usize,
    lr_light: bool,
    speckle_size: usize,
    speckle_range: f32,
) -> GaborParams {
    GaborParams {
        d_min,
        d_max,
        freq,
        orientations_deg,
        bandwidth_oct,
        aspect,
        n_levels,
        iters_per_level,
        amp_rel_thresh,
        stability_tau,
        smooth_sigma,
        conf_min,
        research_radius,
        search_pool_radius,
        lr_check,
        lr_tol,
        lr_coarse_levels,
        iters_finest,
        research_finest,
        orientations_finest,
        fine_levels,
        lr_light,
        speckle_size,
        speckle_range,
    }
}

fn to_image(w: usize, h: usize, data: Vec<f32>) -> Image {
    Image {
        width: w,
        height: h,
        data,
    }
}

/// Dense Gabor phase disparity. Returns `(disparity, confidence)`, float32 (H, W).
#[pyfunction]
#[pyo3(signature = (
    left, right, d_min, d_max, *, freq=0.25, orientations_deg=None, bandwidth_oct=1.5, aspect=1.0,
    n_levels=None, iters_per_level=1, amp_rel_thresh=0.02, stability_tau=1.25, smooth_sigma=None,
    conf_min=0.15,
    research_radius=3, search_pool_radius=0, lr_check=true, lr_tol=1.5, lr_coarse_levels=1,
    iters_finest=1, research_finest=true, orientations_finest=1, fine_levels=1, lr_light=false, speckle_size=100,
    speckle_range=1.0
))]
#[allow(clippy::too_many_arguments)]
pub fn gabor_disparity<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = d_min_f32)] d_min: f32,
    #[pyo3(from_py_with = d_max_f32)] d_max: f32,
    #[pyo3(from_py_with = freq_f32)] freq: f32,
    #[pyo3(from_py_with = orientations_deg_arg)] orientations_deg: Option<Vec<f32>>,
    #[pyo3(from_py_with = bandwidth_oct_f32)] bandwidth_oct: f32,
    #[pyo3(from_py_with = aspect_f32)] aspect: f32,
    #[pyo3(from_py_with = n_levels_arg)] n_levels: Option<usize>,
    #[pyo3(from_py_with = iters_per_level_arg)] iters_per_level: usize,
    #[pyo3(from_py_with = amp_rel_thresh_f32)] amp_rel_thresh: f32,
    #[pyo3(from_py_with = stability_tau_f32)] stability_tau: f32,
    #[pyo3(from_py_with = smooth_sigma_opt_f32)] smooth_sigma: Option<f32>,
    #[pyo3(from_py_with = conf_min_f32)] conf_min: f32,
    #[pyo3(from_py_with = research_radius_arg)] research_radius: usize,
    #[pyo3(from_py_with = search_pool_radius_arg)] search_pool_radius: usize,
    lr_check: bool,
    #[pyo3(from_py_with = lr_tol_f32)] lr_tol: f32,
    #[pyo3(from_py_with = lr_coarse_levels_arg)] lr_coarse_levels: usize,
    #[pyo3(from_py_with = iters_finest_arg)] iters_finest: usize,
    research_finest: bool,
    #[pyo3(from_py_with = orientations_finest_arg)] orientations_finest: usize,
    #[pyo3(from_py_with = fine_levels_arg)] fine_levels: usize,
    lr_light: bool,
    #[pyo3(from_py_with = speckle_size_arg)] speckle_size: usize,
    #[pyo3(from_py_with = speckle_range_f32)] speckle_range: f32,
) -> PyResult<Pair<'py>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes and the size before either copy (a broadcast left was copied first)
    crate::errors::check_pair_size(left.as_array().dim(), right.as_array().dim())?;
    // The NumPy buffers themselves (no copy of the pair); read-only borrows held across the call.
    let (lg, rg) = (
        grey_from_numpy(&left, "left")?,
        grey_from_numpy(&right, "right")?,
    );
    let (l, r) = (lg.view(), rg.view());
    let p = params(
        d_min,
        d_max,
        freq,
        orientations_deg.unwrap_or_else(|| GaborParams::default().orientations_deg),
        bandwidth_oct,
        aspect,
        n_levels,
        iters_per_level,
        amp_rel_thresh,
        stability_tau,
        smooth_sigma,
        conf_min,
        research_radius,
        search_pool_radius,
        lr_check,
        lr_tol,
        lr_coarse_levels,
        iters_finest,
        research_finest,
        orientations_finest,
        fine_levels,
        lr_light,
        speckle_size,
        speckle_range,
    );
    let out = crate::workers::detach(py, || guard("gabor_disparity", || core_gabor(l, r, &p)))?;
    Ok((
        image_to_numpy(py, out.disparity)?,
        image_to_numpy(py, out.confidence)?,
    ))
}

/// Complex response `y = h * img` of one zero-DC Gabor channel, as `(re, im)` float32 (H, W).
#[pyfunction]
#[pyo3(signature = (img, freq=0.25, theta_deg=0.0, bandwidth_oct=1.5, aspect=1.0))]
pub fn gabor_responses<'py>(
    py: Python<'py>,
    img: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = freq_f32)] freq: f32,
    #[pyo3(from_py_with = theta_deg_f32)] theta_deg: f32,
    #[pyo3(from_py_with = bandwidth_oct_f32)] bandwidth_oct: f32,
    #[pyo3(from_py_with = aspect_f32)] aspect: f32,
) -> PyResult<Pair<'py>> {
    let img: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(img, "img")?;
    // The core checks the angle as one of `orientations_deg`, the name its error gave here.
    if !(theta_deg.is_finite() && theta_deg.abs() < 90.0) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "theta_deg: expected an angle in (-90, 90) degrees (a horizontal carrier), got \
             {theta_deg}"
        )));
    }
    // The channel's own checks before the image's copy: a broadcast 65536 x 65536 image was a
    // 16 GiB copy (a MemoryError under a memory limit) before a NaN `freq` was refused.
    Channel::new(freq, theta_deg, bandwidth_oct, aspect).map_err(crate::errors::to_pyerr)?;
    let im = image_from_numpy(&img, "img")?;
    let (w, h) = im.size();
    let (re, imag) = crate::workers::detach(py, || {
        guard("gabor_responses", || {
            core_resp(&im, freq, theta_deg, bandwidth_oct, aspect)
        })
    })?;
    Ok((
        image_to_numpy(py, to_image(w, h, re))?,
        image_to_numpy(py, to_image(w, h, imag))?,
    ))
}

/// One raw Newton step at full resolution for a given disparity map: `(delta, conf)` before
/// smoothing (parity tests of the phase-difference / local-frequency / confidence stage).
#[pyfunction]
#[pyo3(signature = (
    left, right, disp, *, freq=0.25, orientations_deg=None, bandwidth_oct=1.5, aspect=1.0,
    amp_rel_thresh=0.02, stability_tau=1.25
))]
#[allow(clippy::too_many_arguments)]
pub fn gabor_newton_step<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    disp: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = freq_f32)] freq: f32,
    #[pyo3(from_py_with = orientations_deg_arg)] orientations_deg: Option<Vec<f32>>,
    #[pyo3(from_py_with = bandwidth_oct_f32)] bandwidth_oct: f32,
    #[pyo3(from_py_with = aspect_f32)] aspect: f32,
    #[pyo3(from_py_with = amp_rel_thresh_f32)] amp_rel_thresh: f32,
    #[pyo3(from_py_with = stability_tau_f32)] stability_tau: f32,
) -> PyResult<Pair<'py>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    // The core names the second image of a size mismatch "right"; here it may be the map.
    let (map_dim, img_dim) = (disp.as_array().dim(), left.as_array().dim());
    if map_dim != img_dim {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "disp: map is {map_dim:?} (rows, columns), the images are {img_dim:?}"
        )));
    }
    // right's shape too before either copy (a broadcast left was copied first)
    crate::errors::check_pair_shapes(img_dim, right.as_array().dim())?;
    let p = GaborParams {
        freq,
        orientations_deg: orientations_deg
            .unwrap_or_else(|| GaborParams::default().orientations_deg),
        bandwidth_oct,
        aspect,
        amp_rel_thresh,
        stability_tau,
        ..GaborParams::default()
    };
    // The kernel's parameter checks before the three copies too (a NaN `freq` was refused
    // only after 48 GiB of broadcast 65536 x 65536 arrays were copied).
    p.validate()
        .and_then(|()| p.channels())
        .map_err(crate::errors::to_pyerr)?;
    let l = image_from_numpy(&left, "left")?;
    let r = image_from_numpy(&right, "right")?;
    let d = image_from_numpy(&disp, "disp")?;
    let (w, h) = l.size();
    let (delta, conf) = crate::workers::detach(py, || {
        guard("gabor_newton_step", || core_step(&l, &r, &d, &p))
    })?;
    Ok((
        image_to_numpy(py, to_image(w, h, delta))?,
        image_to_numpy(py, to_image(w, h, conf))?,
    ))
}

/// Left-right consistency mask: `True` where `|d_l(x) - d_r(round(x - d_l(x)))| <= tol`.
#[pyfunction]
#[pyo3(signature = (disp_left, disp_right, tol=1.0))]
pub fn gabor_lr_check<'py>(
    py: Python<'py>,
    disp_left: &Bound<'py, PyAny>,
    disp_right: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = tol_f32)] tol: f32,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    let disp_left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp_left, "disp_left")?;
    let disp_right: PyReadonlyArray2<'py, f32> =
        crate::convert::array_arg(disp_right, "disp_right")?;
    // A negative or NaN tolerance passed no pixel, without a word; infinity passes every
    // finite one.
    if tol.is_nan() || tol < 0.0 {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "tol: expected a number >= 0, got {tol}"
        )));
    }
    // NaN is allowed here (it means "no estimate"), so no Image validation of finiteness.
    let a = disp_left.as_array();
    let b = disp_right.as_array();
    if a.dim() != b.dim() {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "disp_left {:?} and disp_right {:?} differ in shape",
            a.dim(),
            b.dim()
        )));
    }
    let (h, w) = a.dim();
    // The arrays' own buffers when C-contiguous, else checked copies: an unchecked collect of a
    // huge (broadcast) map aborted the process where the other kernels raise MemoryError.
    let dl = crate::convert::row_major(&disp_left, "disp_left")?;
    let dr = crate::convert::row_major(&disp_right, "disp_right")?;
    let ok = crate::workers::detach(py, || {
        guard("gabor_lr_check", || lr_check(&dl, &dr, w, h, tol))
    })?;
    crate::convert::vec_to_numpy(py, (h, w), ok)
}

/// A copy of `disp` with the 4-connected regions smaller than `min_size` pixels (neighbours within
/// `max_diff` px) set to NaN: the Gabor channel's speckle step (OpenCV's `filterSpeckles` rule on
/// float disparities), for maps made elsewhere (the fused dense map).
#[pyfunction]
#[pyo3(signature = (disp, min_size, max_diff))]
pub fn gabor_remove_speckles<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = gabor_remove_speckles_min_size)] min_size: usize,
    #[pyo3(from_py_with = max_diff_f32)] max_diff: f32,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    crate::params::non_negative("max_diff", max_diff)?;
    // The kernel's own check comes after the copy below: refused from the shape first.
    let (h, w) = disp.as_array().dim();
    crate::errors::check_size(w, h, stereovision_core::image::MAX_PIXELS, "disp", "map")?;
    let kernel = |d: &mut [f32], w, h| {
        guard("gabor_remove_speckles", || {
            remove_speckles(d, w, h, min_size, max_diff)
        })
    };
    let (out, done) = crate::convert::map_copy_in_place(py, &disp, "disp", kernel)?;
    done?;
    Ok(out)
}

crate::named_ints! {
    n_levels_arg: Option<usize> = "n_levels";
    iters_per_level_arg: usize = "iters_per_level";
    research_radius_arg: usize = "research_radius";
    search_pool_radius_arg: usize = "search_pool_radius";
    lr_coarse_levels_arg: usize = "lr_coarse_levels";
    iters_finest_arg: usize = "iters_finest";
    orientations_finest_arg: usize = "orientations_finest";
    fine_levels_arg: usize = "fine_levels";
    speckle_size_arg: usize = "speckle_size";
    gabor_remove_speckles_min_size: usize = "min_size";
}

crate::named_floats! {
    d_min_f32: f32 = "d_min";
    d_max_f32: f32 = "d_max";
    freq_f32: f32 = "freq";
    bandwidth_oct_f32: f32 = "bandwidth_oct";
    aspect_f32: f32 = "aspect";
    amp_rel_thresh_f32: f32 = "amp_rel_thresh";
    stability_tau_f32: f32 = "stability_tau";
    smooth_sigma_opt_f32: Option<f32> = "smooth_sigma";
    conf_min_f32: f32 = "conf_min";
    lr_tol_f32: f32 = "lr_tol";
    speckle_range_f32: f32 = "speckle_range";
    theta_deg_f32: f32 = "theta_deg";
    tol_f32: f32 = "tol";
    max_diff_f32: f32 = "max_diff";
}

/// `orientations_deg`, each angle through [`FloatArg`](crate::params::FloatArg) as the scalar
/// arguments are: `[1e39]` was cut to inf ("each must be in (-90, 90) degrees ..., got inf") and
/// `[10**400]` a bare "OverflowError: int too large to convert to float".
fn orientations_deg_arg(ob: &Bound<'_, PyAny>) -> PyResult<Option<Vec<f32>>> {
    if ob.is_none() {
        return Ok(None);
    }
    let items: Vec<Bound<'_, PyAny>> = ob.extract()?;
    items
        .iter()
        .map(|v| <f32 as crate::params::FloatArg>::extract_named(v, "orientations_deg"))
        .collect::<PyResult<Vec<f32>>>()
        .map(Some)
}
