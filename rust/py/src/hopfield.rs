//! Binding of `stereovision_core::matching::hopfield`.
//!
//! The many tuning parameters travel as one `params` dict (keys = the Python names, documented in
//! `stereovision.matching.hopfield.DEFAULTS`); unknown keys and wrong types are `ValueError`s.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stereovision_core::image::{Image, ImageView};
use stereovision_core::matching::hopfield::{
    best_match as core_best, candidate_neurons, hopfield_match as core_match,
    interest::select_points, moravec, CandidateMode, HopfieldOutput, HopfieldParams,
};
use stereovision_core::parallel::run_hot;

use crate::convert::{grey_from_numpy, image_to_numpy, u8_layout, u8_shape};
use crate::errors::{flat_rows, guard};
use crate::params::{check_keys, get};

const KEYS: [&str; 41] = [
    "fallback",
    "fallback_alt_support",
    "fallback_min_support",
    "fallback_group",
    "compat_grad",
    "rescue_min",
    "rescue_med",
    "tile",
    "floor_rel",
    "agree_share",
    "min_agree_sparse",
    "edge_penalty",
    "edge_margin",
    "min_disparity",
    "max_disparity",
    "rel_threshold",
    "nms_half",
    "candidates",
    "dy_window",
    "s_min",
    "k_cand",
    "A",
    "B",
    "D",
    "theta",
    "nbr_half",
    "compat_theta",
    "compat_slope",
    "s_init",
    "init_best",
    "max_sweeps",
    "seed",
    "tau_y",
    "edge_test",
    "edge_tol",
    "centre_tol",
    "min_agree",
    "agree_tol",
    "subpixel",
    "method",
    "energy",
];

/// Core parameters from the `params` dict (missing keys keep the core defaults).
fn params(d: &Bound<'_, PyDict>) -> PyResult<HopfieldParams> {
    check_keys(d, &KEYS, "Hopfield")?;
    let mut p = HopfieldParams::default();
    get(d, "min_disparity", &mut p.d_min)?;
    get(d, "max_disparity", &mut p.d_max)?;
    get(d, "rel_threshold", &mut p.interest.rel_threshold)?;
    get(d, "nms_half", &mut p.interest.nms_half)?;
    get(d, "tile", &mut p.interest.tile)?;
    get(d, "floor_rel", &mut p.interest.floor_rel)?;
    let mut mode = String::from("row");
    get(d, "candidates", &mut mode)?;
    p.candidates = match mode.as_str() {
        "row" => CandidateMode::Row,
        "points" => CandidateMode::Points,
        other => {
            return Err(PyValueError::new_err(format!(
                "candidates must be 'row' or 'points', got {other:?}"
            )))
        }
    };
    get(d, "dy_window", &mut p.dy_window)?;
    get(d, "s_min", &mut p.s_min)?;
    get(d, "k_cand", &mut p.k_cand)?;
    get(d, "A", &mut p.weights.a)?;
    get(d, "B", &mut p.weights.b)?;
    get(d, "D", &mut p.weights.d)?;
    get(d, "theta", &mut p.weights.theta)?;
    get(d, "nbr_half", &mut p.weights.nbr_half)?;
    get(d, "compat_theta", &mut p.weights.compat_theta)?;
    get(d, "compat_slope", &mut p.weights.compat_slope)?;
    get(d, "compat_grad", &mut p.weights.compat_grad)?;
    get(d, "s_init", &mut p.s_init)?;
    get(d, "init_best", &mut p.init_best)?;
    get(d, "max_sweeps", &mut p.max_sweeps)?;
    get(d, "seed", &mut p.seed)?;
    get(d, "tau_y", &mut p.tau_y)?;
    get(d, "edge_test", &mut p.edge_test)?;
    get(d, "edge_tol", &mut p.edge_tol)?;
    get(d, "edge_margin", &mut p.edge_margin)?;
    get(d, "edge_penalty", &mut p.edge_penalty)?;
    get(d, "centre_tol", &mut p.centre_tol)?;
    get(d, "fallback", &mut p.fallback)?;
    get(d, "fallback_alt_support", &mut p.fallback_alt_support)?;
    get(d, "fallback_min_support", &mut p.fallback_min_support)?;
    get(d, "fallback_group", &mut p.fallback_group)?;
    get(d, "rescue_min", &mut p.rescue_min)?;
    get(d, "rescue_med", &mut p.rescue_med)?;
    get(d, "min_agree", &mut p.min_agree)?;
    get(d, "agree_tol", &mut p.agree_tol)?;
    get(d, "agree_share", &mut p.agree_share)?;
    get(d, "min_agree_sparse", &mut p.min_agree_sparse)?;
    get(d, "subpixel", &mut p.subpixel)?;
    Ok(p)
}

/// Moravec map and interest points: `(M (H, W) float32, xy (N, 2) int32, values (N,) float32)`.
#[pyfunction]
#[pyo3(signature = (img, rel_threshold=1e-3, nms_half=1, tile=64, floor_rel=1e-4))]
#[allow(clippy::type_complexity)]
pub fn hopfield_interest<'py>(
    py: Python<'py>,
    img: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = rel_threshold_f32)] rel_threshold: f32,
    #[pyo3(from_py_with = nms_half_arg)] nms_half: usize,
    #[pyo3(from_py_with = tile_arg)] tile: usize,
    #[pyo3(from_py_with = floor_rel_f32)] floor_rel: f32,
) -> PyResult<(
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<i32>>,
    Bound<'py, PyArray1<f32>>,
)> {
    let img: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(img, "img")?;
    // The points go out as int32 (a column past i32 wrapped): refused from the shape, before
    // the image is copied.
    let (h, w) = img.as_array().dim();
    crate::errors::check_size(w, h, stereovision_core::image::MAX_PIXELS, "img", "image")?;
    let im = grey_from_numpy(&img, "img")?;
    let im = im.view();
    let unit = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
    if !unit(rel_threshold) || !unit(floor_rel) || nms_half == 0 {
        return Err(PyValueError::new_err(
            "rel_threshold and floor_rel must lie in [0, 1] and nms_half be >= 1",
        ));
    }
    let p = stereovision_core::matching::hopfield::InterestParams {
        rel_threshold,
        nms_half,
        tile,
        floor_rel,
    };
    let (m, pts) = crate::workers::detach(py, || {
        guard("hopfield_interest", || {
            let m = moravec(im)?;
            let pts = select_points(&m, w, h, &p)?;
            Ok((m, pts))
        })
    })?;
    let n = pts.len();
    let xy = flat_rows(
        n,
        pts.iter().map(|q| [q.x as i32, q.y as i32]),
        "the points",
    )?;
    let vals = flat_rows(n, pts.iter().map(|q| [q.value]), "the points' values")?;
    let xy = Array2::from_shape_vec((pts.len(), 2), xy)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let mimg = stereovision_core::Image {
        width: w,
        height: h,
        data: m,
    };
    Ok((
        image_to_numpy(py, mimg)?,
        xy.into_pyarray(py),
        Array1::from_vec(vals).into_pyarray(py),
    ))
}

type MatchOut<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyDict>,
);

fn output<'py>(py: Python<'py>, out: HopfieldOutput) -> PyResult<MatchOut<'py>> {
    let n = out.matches.len();
    let flat = flat_rows(
        n,
        out.matches
            .iter()
            .map(|m| [m.xl, m.yl, m.xr, m.yr, m.score]),
        "the matches array",
    )?;
    let arr =
        Array2::from_shape_vec((n, 5), flat).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let stats = PyDict::new(py);
    stats.set_item("n_points", out.n_points)?;
    stats.set_item("n_neurons", out.n_neurons)?;
    stats.set_item("n_weights", out.n_weights)?;
    stats.set_item("sweeps", out.sweeps)?;
    stats.set_item("converged", out.converged)?;
    stats.set_item("n_selected", out.n_selected)?;
    Ok((
        arr.into_pyarray(py),
        Array1::from_vec(out.energy_trace).into_pyarray(py),
        stats,
    ))
}

/// Hopfield matching (`method="hopfield"`) or the best-match reference (`method="best"`).
/// Returns `(matches (N, 5) float32 [xl, yl, xr, yr, score], energy_trace float64, stats dict)`.
#[pyfunction]
#[pyo3(signature = (left, right, params))]
pub fn hopfield_match<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
) -> PyResult<MatchOut<'py>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes and the size before either copy (a broadcast left was copied first)
    crate::errors::check_pair_size(left.as_array().dim(), right.as_array().dim())?;
    // The arrays' own buffers (no copy: the wrappers pass C-contiguous arrays).
    let (l, r) = (
        grey_from_numpy(&left, "left")?,
        grey_from_numpy(&right, "right")?,
    );
    run_match(py, l.view(), r.view(), params)
}

/// [`hopfield_match`] on 8-bit images (`(H, W)` grey or `(H, W, C)` BGR/BGRA, any layout):
/// the grey conversion (`weights`: BGR luma weights, bit-identical to `_validate.as_gray_float`)
/// runs in the same call, without NumPy intermediates.
#[pyfunction]
#[pyo3(signature = (left, right, weights, params))]
pub fn hopfield_match_u8<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = crate::convert::weights_arg)] weights: (f32, f32, f32),
    params: &Bound<'py, PyDict>,
) -> PyResult<MatchOut<'py>> {
    let left: numpy::PyReadonlyArrayDyn<'py, u8> = crate::convert::array_arg(left, "left")?;
    let right: numpy::PyReadonlyArrayDyn<'py, u8> = crate::convert::array_arg(right, "right")?;
    // Both shapes before either copy: `left` was copied (4 GiB for a broadcast one) before a
    // `right` of another shape was refused.
    let (h, w, c) = u8_shape(&left, "left")?;
    if u8_shape(&right, "right")? != (h, w, c) {
        return Err(PyValueError::new_err(format!(
            "left and right images must have the same shape, got left {:?} and right {:?}",
            left.shape(),
            right.shape()
        )));
    }
    // The kernel's 32-bit size check before the copies, as `hopfield_match` makes it: a
    // broadcast (2**30, 2**30) pair was a MemoryError for left's copy, a 65536 x 65536 x 3 one
    // two 12 GiB copies (and their grey images) before the refusal.
    crate::errors::check_size(w, h, stereovision_core::image::MAX_PIXELS, "left", "image")?;
    let wts = crate::convert::luma_weights(weights)?;
    let (p, best) = parse_match(params)?;
    let (_, _, _, ld) = u8_layout(&left, "left")?;
    let (_, _, _, rd) = u8_layout(&right, "right")?;
    // Grey conversion and matcher in one hot region of the pool (`run_hot`): one wake-up of
    // the workers per call instead of one per parallel region.
    let out = crate::workers::detach(py, || {
        guard("hopfield_match_u8", || {
            run_hot(|| {
                let (lg, rg) = stereovision_core::image::grey_pair_from_u8(&ld, &rd, w, h, c, wts)?;
                // Finite by construction (levels / 255): no check needed.
                let image = |data| Image {
                    width: w,
                    height: h,
                    data,
                };
                let (l, r) = (image(lg), image(rg));
                run_matcher(l.view(), r.view(), &p, best)
            })
        })
    })?;
    output(py, out)
}

/// The matcher's parameters and whether `params["method"]` is the best-match reference.
fn parse_match(params: &Bound<'_, PyDict>) -> PyResult<(HopfieldParams, bool)> {
    let p = self::params(params)?;
    let mut method = String::from("hopfield");
    get(params, "method", &mut method)?;
    let mut energy = String::from("recommended");
    get(params, "energy", &mut energy)?;
    if energy != "recommended" {
        return Err(PyValueError::new_err(format!(
            "energy must be 'recommended', got {energy:?}"
        )));
    }
    match method.as_str() {
        "hopfield" => Ok((p, false)),
        "best" => Ok((p, true)),
        other => Err(PyValueError::new_err(format!(
            "method must be 'hopfield' or 'best', got {other:?}"
        ))),
    }
}

/// `best_match` or `hopfield_match` on a grey pair.
fn run_matcher(
    l: ImageView<'_>,
    r: ImageView<'_>,
    p: &HopfieldParams,
    best: bool,
) -> stereovision_core::Result<HopfieldOutput> {
    if best {
        core_best(l, r, p)
    } else {
        core_match(l, r, p)
    }
}

/// The matcher of `params["method"]` on a grey pair.
fn run_match<'py>(
    py: Python<'py>,
    l: ImageView<'_>,
    r: ImageView<'_>,
    params: &Bound<'py, PyDict>,
) -> PyResult<MatchOut<'py>> {
    let (p, best) = parse_match(params)?;
    let out = crate::workers::detach(py, || {
        guard("hopfield_match", || run_matcher(l, r, &p, best))
    })?;
    output(py, out)
}

/// Candidate neurons: `(N, 6) float32 [point, xl, yl, xr, yr, zncc]` (parity tests).
#[pyfunction]
#[pyo3(signature = (left, right, params))]
pub fn hopfield_candidates<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes and the size before either copy (a broadcast left was copied first)
    crate::errors::check_pair_size(left.as_array().dim(), right.as_array().dim())?;
    // The arrays' own buffers (no copy: the wrappers pass C-contiguous arrays).
    let (l, r) = (
        grey_from_numpy(&left, "left")?,
        grey_from_numpy(&right, "right")?,
    );
    let (l, r) = (l.view(), r.view());
    let p = self::params(params)?;
    let (_, neurons) = crate::workers::detach(py, || {
        guard("hopfield_candidates", || candidate_neurons(l, r, &p))
    })?;
    let flat = flat_rows(
        neurons.len(),
        neurons.iter().map(|n| {
            [
                n.point as f32,
                n.xl as f32,
                n.yl as f32,
                n.xr as f32,
                n.yr as f32,
                n.sim,
            ]
        }),
        "the candidates array",
    )?;
    let arr = Array2::from_shape_vec((neurons.len(), 6), flat)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

crate::named_ints! {
    nms_half_arg: usize = "nms_half";
    tile_arg: usize = "tile";
}

crate::named_floats! {
    rel_threshold_f32: f32 = "rel_threshold";
    floor_rel_f32: f32 = "floor_rel";
}
