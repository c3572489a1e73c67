//! Binding of `stereovision_core::matching::mcgm`.
//!
//! Parameters travel as one `params` dict (keys = the Python names, documented in
//! `stereovision.matching.mcgm.DEFAULTS`); unknown keys and wrong types are `ValueError`s.

use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use stereovision_core::matching::mcgm::{
    edge_filters, image_curves, log::log_filter, mcgm_match as core_match, ChannelCurves, Match,
    McgmParams,
};
use stereovision_core::Image;

use crate::convert::{image_from_numpy, image_to_numpy};
use crate::errors::{flat_rows, guard, reserve};
use crate::params::{check_keys, get};

const KEYS: [&str; 43] = [
    "min_disparity",
    "max_disparity",
    "sigmas",
    "half_res_sigma",
    "high_quantile",
    "low_ratio",
    "max_turn_deg",
    "min_len",
    "min_len_sigmas",
    "seg_theta_tol_deg",
    "dy_band",
    "n_theta_bins",
    "vote_bin_tol",
    "ght_min_score",
    "k_cand",
    "knn",
    "r_graph",
    "A",
    "B",
    "D",
    "theta",
    "dg_0",
    "dg_slope",
    "max_sweeps",
    "seed",
    "horiz_skip_deg",
    "prior_radius_sigmas",
    "prior_width_sigmas",
    "fill_radius",
    "sides",
    "sides_mad",
    "sides_width",
    "sides_height",
    "sides_gap",
    "sides_best",
    "sides_best_margin",
    "sides_mean_free",
    "disc",
    "disc_dx",
    "disc_dy",
    "disc_tol",
    "zncc_check",
    "zncc_tol",
];

/// Core parameters from the `params` dict (missing keys keep the core defaults).
fn params(d: &Bound<'_, PyDict>) -> PyResult<McgmParams> {
    check_keys(d, &KEYS, "MCGM")?;
    let mut p = McgmParams::default();
    get(d, "min_disparity", &mut p.d_min)?;
    get(d, "max_disparity", &mut p.d_max)?;
    get(d, "sigmas", &mut p.sigmas)?;
    get(d, "half_res_sigma", &mut p.half_res_sigma)?;
    get(d, "high_quantile", &mut p.track.high_quantile)?;
    get(d, "low_ratio", &mut p.track.low_ratio)?;
    get(d, "max_turn_deg", &mut p.track.max_turn_deg)?;
    get(d, "min_len", &mut p.track.min_len)?;
    get(d, "min_len_sigmas", &mut p.min_len_sigmas)?;
    get(d, "seg_theta_tol_deg", &mut p.cand.seg_theta_tol_deg)?;
    get(d, "dy_band", &mut p.cand.dy_band)?;
    get(d, "n_theta_bins", &mut p.cand.n_bins)?;
    get(d, "vote_bin_tol", &mut p.cand.vote_bin_tol)?;
    get(d, "ght_min_score", &mut p.cand.ght_min_score)?;
    get(d, "k_cand", &mut p.cand.k_cand)?;
    get(d, "knn", &mut p.knn)?;
    get(d, "r_graph", &mut p.r_graph)?;
    get(d, "A", &mut p.solver.a)?;
    get(d, "B", &mut p.solver.b)?;
    get(d, "D", &mut p.solver.d)?;
    get(d, "theta", &mut p.solver.theta)?;
    get(d, "dg_0", &mut p.solver.dg_0)?;
    get(d, "dg_slope", &mut p.solver.dg_slope)?;
    get(d, "max_sweeps", &mut p.solver.max_sweeps)?;
    get(d, "seed", &mut p.solver.seed)?;
    get(d, "horiz_skip_deg", &mut p.horiz_skip_deg)?;
    get(d, "prior_radius_sigmas", &mut p.prior_radius_sigmas)?;
    get(d, "prior_width_sigmas", &mut p.prior_width_sigmas)?;
    get(d, "fill_radius", &mut p.fill_radius)?;
    get(d, "sides", &mut p.filters.sides)?;
    get(d, "sides_mad", &mut p.filters.sides_mad)?;
    get(d, "sides_width", &mut p.filters.sides_width)?;
    get(d, "sides_height", &mut p.filters.sides_height)?;
    get(d, "sides_gap", &mut p.filters.sides_gap)?;
    get(d, "sides_best", &mut p.filters.sides_best)?;
    get(d, "sides_best_margin", &mut p.filters.sides_best_margin)?;
    get(d, "sides_mean_free", &mut p.filters.sides_mean_free)?;
    get(d, "disc", &mut p.filters.disc)?;
    get(d, "disc_dx", &mut p.filters.disc_dx)?;
    get(d, "disc_dy", &mut p.filters.disc_dy)?;
    get(d, "disc_tol", &mut p.filters.disc_tol)?;
    get(d, "zncc_check", &mut p.filters.zncc_check)?;
    get(d, "zncc_tol", &mut p.filters.zncc_tol)?;
    Ok(p)
}

fn shape_err(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn matches_array<'py>(py: Python<'py>, ms: &[Match]) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let flat = flat_rows(
        ms.len(),
        ms.iter()
            .map(|m| [m.xl, m.yl, m.xr, m.yr, m.score, m.channel as f32]),
        "the matches array",
    )?;
    Ok(Array2::from_shape_vec((ms.len(), 6), flat)
        .map_err(shape_err)?
        .into_pyarray(py))
}

/// Separable zero-mean scale-normalised LoG of one image, `(H, W)` float32.
#[pyfunction]
#[pyo3(signature = (img, sigma))]
pub fn mcgm_log<'py>(
    py: Python<'py>,
    img: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = sigma_f32)] sigma: f32,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let img: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(img, "img")?;
    // Both checks come before the copy below: a huge shape-only (broadcast) image was copied
    // (a MemoryError, or gigabytes taken) before a bad sigma or its size was refused.
    if !(sigma.is_finite() && (0.3..=64.0).contains(&sigma)) {
        return Err(PyValueError::new_err(format!(
            "sigma must lie in [0.3, 64] px, got {sigma}"
        )));
    }
    let (rows, cols) = img.as_array().dim();
    let max = stereovision_core::image::MAX_PIXELS;
    crate::errors::check_size(cols, rows, max, "img", "image")?;
    let im = image_from_numpy(&img, "img")?;
    let (w, h) = im.size();
    let data = crate::workers::detach(py, || guard("mcgm_log", || log_filter(&im, sigma)))?;
    image_to_numpy(
        py,
        Image {
            width: w,
            height: h,
            data,
        },
    )
}

fn curves_dict<'py>(py: Python<'py>, c: ChannelCurves) -> PyResult<Bound<'py, PyDict>> {
    let (w, h) = (c.width, c.height);
    let d = PyDict::new(py);
    let img = |data: Vec<f32>| {
        image_to_numpy(
            py,
            Image {
                width: w,
                height: h,
                data,
            },
        )
    };
    d.set_item("sigma", c.sigma)?;
    d.set_item("scale", c.scale)?;
    d.set_item("t_high", c.curves.t_high)?;
    d.set_item("t_low", c.curves.t_low)?;
    d.set_item("log", img(c.log)?)?;
    d.set_item("xsub", img(c.zc.xsub)?)?;
    d.set_item("strength", img(c.zc.strength)?)?;
    d.set_item("theta", img(c.zc.theta)?)?;
    let mark = Array2::from_shape_vec((h, w), c.zc.mark).map_err(shape_err)?;
    d.set_item("mark", mark.into_pyarray(py))?;
    let labels = Array2::from_shape_vec((h, w), c.curves.labels).map_err(shape_err)?;
    d.set_item("labels", labels.into_pyarray(py))?;
    let segs = &c.curves.segments;
    // Reserved first (the curves' pixels are up to one a pixel of the image): the pushes below
    // do not grow them, so a failed allocation is a MemoryError, not an abort.
    let n_pix: usize = segs.iter().map(|s| s.pixels.len()).sum();
    let mut offsets = vec![0i64];
    let mut pix: Vec<i32> = Vec::new();
    let mut cen: Vec<f32> = Vec::new();
    let mut mt: Vec<f32> = Vec::new();
    reserve(&mut offsets, segs.len() + 1, "the curves' offsets")?;
    reserve(&mut pix, n_pix.saturating_mul(2), "the curves' pixels")?;
    reserve(&mut cen, segs.len() * 2, "the curves' centroids")?;
    reserve(&mut mt, segs.len(), "the curves' mean orientations")?;
    for s in segs {
        for &i in &s.pixels {
            pix.push((i as usize % w) as i32);
            pix.push((i as usize / w) as i32);
        }
        offsets.push(offsets[offsets.len() - 1] + s.pixels.len() as i64);
        cen.extend([s.centroid.0, s.centroid.1]);
        mt.push(s.mean_theta);
    }
    let n = segs.len();
    let npix = pix.len() / 2;
    d.set_item("seg_offsets", Array1::from_vec(offsets).into_pyarray(py))?;
    d.set_item(
        "seg_pixels",
        Array2::from_shape_vec((npix, 2), pix)
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    d.set_item(
        "centroids",
        Array2::from_shape_vec((n, 2), cen)
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    d.set_item("mean_theta", Array1::from_vec(mt).into_pyarray(py))?;
    let k = c.rtables.first().map_or(0, |r| r.offsets.len());
    let (mut rt_off, mut rt_vec): (Vec<i32>, Vec<f32>) = (Vec::new(), Vec::new());
    reserve(&mut rt_off, n.saturating_mul(k), "the R-tables' offsets")?;
    let n_vec: usize = c.rtables.iter().map(|r| r.vecs.len()).sum();
    reserve(
        &mut rt_vec,
        n_vec.saturating_mul(2),
        "the R-tables' vectors",
    )?;
    for r in &c.rtables {
        rt_off.extend(r.offsets.iter().map(|&o| o as i32));
        for &(vx, vy) in &r.vecs {
            rt_vec.extend([vx, vy]);
        }
    }
    d.set_item(
        "rtable_offsets",
        Array2::from_shape_vec((n, k), rt_off)
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    d.set_item(
        "rtable_vecs",
        Array2::from_shape_vec((rt_vec.len() / 2, 2), rt_vec)
            .map_err(shape_err)?
            .into_pyarray(py),
    )?;
    Ok(d)
}

/// Zero crossings, curves and R-tables of every channel of one image (list of dicts).
#[pyfunction]
#[pyo3(signature = (img, params))]
pub fn mcgm_curves<'py>(
    py: Python<'py>,
    img: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyList>> {
    let img: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(img, "img")?;
    // The kernel's 32-bit size check, from the shape before the copy, as `mcgm_log` does: a
    // broadcast 65536 x 65536 image was copied first (16 GiB taken, or a MemoryError under a
    // memory limit), a (2**30, 2**30) one a MemoryError instead of the size's ValueError.
    let (rows, cols) = img.as_array().dim();
    let max = stereovision_core::image::MAX_PIXELS;
    crate::errors::check_size(cols, rows, max, "img", "image")?;
    let im = image_from_numpy(&img, "img")?;
    let p = self::params(params)?;
    let chans = crate::workers::detach(py, || guard("mcgm_curves", || image_curves(&im, &p)))?;
    let out = PyList::empty(py);
    for c in chans {
        out.append(curves_dict(py, c)?)?;
    }
    Ok(out)
}

type MatchOut<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyDict>,
    Bound<'py, PyList>,
);

/// The MCGM channel: `(matches (N, 6) float32 [xl, yl, xr, yr, score, channel], stats dict,
/// per-channel list of dicts with the candidates, network state, chosen pairs, graph edges,
/// disparity windows and the channel's own per-pixel matches)`.
#[pyfunction]
#[pyo3(signature = (left, right, params))]
pub fn mcgm_match<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
) -> PyResult<MatchOut<'py>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes and the size before either copy (a broadcast left was copied first)
    crate::errors::check_pair_size(left.as_array().dim(), right.as_array().dim())?;
    let l = image_from_numpy(&left, "left")?;
    let r = image_from_numpy(&right, "right")?;
    let p = self::params(params)?;
    let out = crate::workers::detach(py, || guard("mcgm_match", || core_match(&l, &r, &p)))?;
    let stats = PyDict::new(py);
    stats.set_item("n_combined", out.n_combined)?;
    stats.set_item("n_sides", out.n_sides)?;
    stats.set_item("n_disc", out.n_disc)?;
    stats.set_item("n_matches", out.matches.len())?;
    let chans = PyList::empty(py);
    let (mut n_cand, mut n_pairs) = (0usize, 0usize);
    for c in &out.channels {
        n_cand += c.candidates.len();
        n_pairs += c.chosen.len();
        let d = PyDict::new(py);
        d.set_item("sigma", c.sigma)?;
        d.set_item("scale", c.scale)?;
        d.set_item("n_left", c.n_left)?;
        d.set_item("n_right", c.n_right)?;
        let flat = flat_rows(
            c.candidates.len(),
            c.candidates
                .iter()
                .map(|k| [k.left as f32, k.right as f32, k.score, k.tx, k.ty]),
            "the candidates array",
        )?;
        d.set_item(
            "candidates",
            Array2::from_shape_vec((c.candidates.len(), 5), flat)
                .map_err(shape_err)?
                .into_pyarray(py),
        )?;
        let state = flat_rows(c.state.len(), c.state.iter().map(|&s| [s]), "the states")?;
        d.set_item("state", Array1::from_vec(state).into_pyarray(py))?;
        let chosen = flat_rows(
            c.chosen.len(),
            c.chosen.iter().map(|&i| [i as i64]),
            "the chosen candidates",
        )?;
        d.set_item("chosen", Array1::from_vec(chosen).into_pyarray(py))?;
        let edges = flat_rows(
            c.edges.len(),
            c.edges.iter().map(|&(a, b)| [a as i32, b as i32]),
            "the edges array",
        )?;
        d.set_item(
            "edges",
            Array2::from_shape_vec((c.edges.len(), 2), edges)
                .map_err(shape_err)?
                .into_pyarray(py),
        )?;
        let win = flat_rows(
            c.windows.len(),
            c.windows.iter().map(|w| w.map_or([1, 0], |(a, b)| [a, b])),
            "the windows array",
        )?;
        d.set_item(
            "windows",
            Array2::from_shape_vec((c.windows.len(), 2), win)
                .map_err(shape_err)?
                .into_pyarray(py),
        )?;
        d.set_item("n_weights", c.n_weights)?;
        d.set_item("sweeps", c.sweeps)?;
        d.set_item("converged", c.converged)?;
        d.set_item("matches", matches_array(py, &c.matches)?)?;
        chans.append(d)?;
    }
    stats.set_item("n_candidates", n_cand)?;
    stats.set_item("n_pairs", n_pairs)?;
    Ok((matches_array(py, &out.matches)?, stats, chans))
}

/// B.8's occlusion filters on arbitrary matches `(N, 4) float32 [xl, yl, xr, yr]`: the kept
/// flags `(N,)` bool (used by the ZNCC reference).
#[pyfunction]
#[pyo3(signature = (left, right, matches, params))]
pub fn mcgm_filter<'py>(
    py: Python<'py>,
    left: &Bound<'py, PyAny>,
    right: &Bound<'py, PyAny>,
    matches: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let left: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(left, "left")?;
    let right: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(right, "right")?;
    // both shapes and the size before either copy (a broadcast left was copied first)
    crate::errors::check_pair_size(left.as_array().dim(), right.as_array().dim())?;
    let matches: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(matches, "matches")?;
    let l = image_from_numpy(&left, "left")?;
    let r = image_from_numpy(&right, "right")?;
    let p = self::params(params)?;
    // mcgm_match refuses this range (core validate_params); the filter used it as given and
    // returned flags for an empty range without a word.
    if p.d_max < p.d_min {
        return Err(PyValueError::new_err(format!(
            "invalid parameter `max_disparity`: must be >= min_disparity ({}), got {}",
            p.d_min, p.d_max
        )));
    }
    let view = matches.as_array();
    if view.ncols() != 4 {
        return Err(PyValueError::new_err(format!(
            "matches: expected shape (N, 4), got {:?}",
            view.shape()
        )));
    }
    // Reserved first: an unchecked collect of a huge (broadcast) `matches` aborted the process,
    // and the row check before it read every row with the GIL held: (2**40, 4) broadcast rows
    // kept the process reading 4.4e12 values, deaf to Ctrl-C, before the copy's MemoryError.
    let mut ms: Vec<Match> = Vec::new();
    ms.try_reserve_exact(view.nrows())
        .map_err(|_| crate::errors::copy_oom::<Match>(view.nrows(), "matches"))?;
    check_match_rows(&view, l.width, l.height)?;
    ms.extend(view.rows().into_iter().map(|row| Match {
        xl: row[0],
        yl: row[1],
        xr: row[2],
        yr: row[3],
        score: 0.0,
        channel: 0,
    }));
    let (keep, _) = crate::workers::detach(py, || {
        guard("mcgm_filter", || {
            edge_filters(
                &l,
                &r,
                &ms,
                &p.filters,
                (p.d_min.min(l.width) as i32, p.d_max.min(l.width) as i32),
            )
        })
    })?;
    Ok(Array1::from_vec(keep).into_pyarray(py))
}

/// `matches` rows are matches of this pair: finite, and within the images (beyond the outer
/// pixels' edges, `-0.5 .. W - 0.5` and `-0.5 .. H - 0.5`), as `matching.mcgm.filter_matches`
/// checks. The kernel's window arithmetic overflowed on a coordinate of 2**31 or more
/// (`RuntimeError: internal error in mcgm_filter: index out of bounds`); a NaN or another
/// point outside was dropped without a word.
fn check_match_rows(view: &ArrayView2<'_, f32>, w: usize, h: usize) -> PyResult<()> {
    let row = |i: usize| {
        let v: Vec<String> = view.row(i).iter().map(|x| format!("{x}")).collect();
        format!("(xl, yl, xr, yr) = ({})", v.join(", "))
    };
    let n = view.nrows();
    // The first bad row and a count, not a list of them: a huge (broadcast) `matches` of NaN
    // rows made that list N-sized, and its unchecked growth aborted the process.
    let non_finite = |i: &usize| view.row(*i).iter().any(|v| !v.is_finite());
    if let Some(i) = (0..n).find(non_finite) {
        return Err(PyValueError::new_err(format!(
            "matches: {} of {n} rows have a NaN or infinite coordinate (row {i}: {})",
            (i..n).filter(non_finite).count(),
            row(i)
        )));
    }
    let (wf, hf) = (w as f64 - 0.5, h as f64 - 0.5);
    let outside = |i: usize| {
        let r = view.row(i);
        let x_out = |x: f32| (x as f64) < -0.5 || (x as f64) > wf;
        let y_out = |y: f32| (y as f64) < -0.5 || (y as f64) > hf;
        x_out(r[0]) || x_out(r[2]) || y_out(r[1]) || y_out(r[3])
    };
    if let Some(i) = (0..n).find(|&i| outside(i)) {
        return Err(PyValueError::new_err(format!(
            "matches: {} of {n} rows lie outside the {w}x{h} images (row {i}: {})",
            (i..n).filter(|&i| outside(i)).count(),
            row(i)
        )));
    }
    Ok(())
}

crate::named_floats! {
    sigma_f32: f32 = "sigma";
}
