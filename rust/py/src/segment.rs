//! Binding of `stereovision_core::segment`.

use numpy::{PyArray2, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use stereovision_core::segment::{
    fill_planes as core_fill_planes, graph_segments as core_segments,
    plane_fill as core_plane_fill, quantised_regions as core_regions,
};

use crate::convert::{map_copy_in_place, row_major, vec_to_numpy};
use crate::errors::guard;
use crate::params::{non_negative, IntRange};
use stereovision_core::image::MAX_PIXELS;

/// Felzenszwalb-Huttenlocher segments of an `(H, W, C)` float32 image: `(H, W)` uint32 labels
/// numbered in raster order of each segment's first pixel.
#[pyfunction]
#[pyo3(signature = (image, k, min_size))]
pub fn graph_segments<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = k_f32)] k: f32,
    #[pyo3(from_py_with = graph_segments_min_size)] min_size: usize,
) -> PyResult<Bound<'py, PyArray2<u32>>> {
    let image: PyReadonlyArray3<'py, f32> = crate::convert::array_arg(image, "image")?;
    non_negative("k", k)?;
    let a = image.as_array();
    let (h, w, c) = a.dim();
    if c == 0 || h == 0 || w == 0 {
        return Err(PyValueError::new_err(format!(
            "image: expected (H, W, C) with no zero size, got ({h}, {w}, {c})"
        )));
    }
    // Refused from the shape, then copied (a MemoryError for a huge one), then scanned: the
    // scan came first, over the view with the GIL held: a broadcast (1, 2**40, 3) image kept
    // the process reading 3.3e12 values, deaf to Ctrl-C, before the kernel's size check.
    crate::errors::check_size(
        w,
        h,
        stereovision_core::segment::GRAPH_MAX_PIXELS,
        "image",
        "image",
    )?;
    let img = row_major(&image, "image")?;
    let labels = crate::workers::detach(py, || {
        if img.iter().any(|v| !v.is_finite()) {
            return Err(PyValueError::new_err("image: contains NaN or inf"));
        }
        guard("graph_segments", || {
            core_segments(&img, w, h, c, k, min_size)
        })
    })?;
    vec_to_numpy(py, (h, w), labels)
}

/// A copy of `disp` whose holes took their segment's plane (core docs), with the number of
/// planes used and of holes filled.
#[pyfunction]
#[pyo3(signature = (disp, labels, min_pixels, max_residual, lo, hi))]
#[allow(clippy::type_complexity)]
pub fn plane_fill<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    labels: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = min_pixels_arg)] min_pixels: usize,
    #[pyo3(from_py_with = max_residual_f32)] max_residual: f32,
    #[pyo3(from_py_with = lo_f32)] lo: f32,
    #[pyo3(from_py_with = hi_f32)] hi: f32,
) -> PyResult<(Bound<'py, PyArray2<f32>>, usize, usize)> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let labels: PyReadonlyArray2<'py, u32> = crate::convert::array_arg(labels, "labels")?;
    let a = disp.as_array();
    let (h, w) = a.dim();
    // The kernel lists pixels and counts them in u32, and has no check of its own: refused
    // from the shape, before the arrays are copied.
    crate::errors::check_size(w, h, MAX_PIXELS, "disp", "map")?;
    if labels.as_array().dim() != (h, w) {
        return Err(PyValueError::new_err(format!(
            "labels: expected shape ({h}, {w}) like disp, got {:?}",
            labels.as_array().dim()
        )));
    }
    non_negative("max_residual", max_residual)?;
    if lo.is_nan() || hi.is_nan() {
        return Err(PyValueError::new_err(format!(
            "lo and hi: expected numbers, got {lo}, {hi}"
        )));
    }
    // An empty range filled nothing, without a word.
    if lo > hi {
        return Err(PyValueError::new_err(format!(
            "lo and hi: expected lo <= hi, got lo = {lo}, hi = {hi}"
        )));
    }
    let l = row_major(&labels, "labels")?;
    // The kernel sizes its tables by the largest label: one per pixel at most.
    if l.iter().any(|&v| v as usize >= h * w) {
        return Err(PyValueError::new_err(format!(
            "labels: expected values below H * W = {}, as segments() numbers them",
            h * w
        )));
    }
    let (out, s) = map_copy_in_place(py, &disp, "disp", |d, w, _| {
        guard("plane_fill", || {
            core_plane_fill(d, &l, w, min_pixels, max_residual, lo, hi)
        })
    })?;
    let s = s?;
    Ok((out, s.planes, s.filled))
}

/// Connected regions of equal quantised colour of an `(H, W, C)` uint8 image (`C` 1-3; bin
/// `(value + offset) // step`): `(H, W)` uint32 labels in raster order of first pixels.
#[pyfunction]
#[pyo3(signature = (image, step, offset))]
pub fn quantised_regions<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = step_arg)] step: u32,
    #[pyo3(from_py_with = offset_arg)] offset: u32,
) -> PyResult<Bound<'py, PyArray2<u32>>> {
    let image: PyReadonlyArray3<'py, u8> = crate::convert::array_arg(image, "image")?;
    let (h, w, c) = (image.shape()[0], image.shape()[1], image.shape()[2]);
    if !(1..=3).contains(&c) || h == 0 || w == 0 {
        return Err(PyValueError::new_err(format!(
            "image: expected (H, W, C) with C in 1-3 and no zero size, got ({h}, {w}, {c})"
        )));
    }
    if step == 0 || step > 255 || offset > 255 {
        return Err(PyValueError::new_err(format!(
            "step must be in 1-255 and offset in 0-255, got step={step}, offset={offset}"
        )));
    }
    // The kernel's size check came after the copy: a broadcast 65536 x 65536 image was a
    // 12 GiB MemoryError (a (1, 2**31 + 1) one 2 GiB copied in 7 s) before the size's
    // ValueError. Refused from the shape now, as `graph_segments` and `plane_fill` do.
    crate::errors::check_size(w, h, MAX_PIXELS, "image", "image")?;
    let img = row_major(&image, "image")?;
    let labels = crate::workers::detach(py, || {
        guard("quantised_regions", || {
            core_regions(&img, w, h, c, step, offset)
        })
    })?;
    vec_to_numpy(py, (h, w), labels)
}

/// A copy of `disp` with the plane fill's passes run (core `fill_planes`) on the already
/// blurred `(H, W, C)` uint8 image.
#[pyfunction]
#[pyo3(signature = (disp, image, passes, max_residual))]
pub fn fill_planes<'py>(
    py: Python<'py>,
    disp: &Bound<'py, PyAny>,
    image: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = passes_arg)] passes: Vec<(u32, usize)>,
    #[pyo3(from_py_with = max_residual_f32)] max_residual: f32,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let disp: PyReadonlyArray2<'py, f32> = crate::convert::array_arg(disp, "disp")?;
    let image: PyReadonlyArray3<'py, u8> = crate::convert::array_arg(image, "image")?;
    let (h, w, c) = (image.shape()[0], image.shape()[1], image.shape()[2]);
    if disp.as_array().dim() != (h, w) || !(1..=3).contains(&c) {
        return Err(PyValueError::new_err(format!(
            "image: expected (H, W, C) with C in 1-3 and (H, W) = {:?} like disp, got \
             ({h}, {w}, {c})",
            disp.as_array().dim()
        )));
    }
    non_negative("max_residual", max_residual)?;
    // The kernel (`quantised_regions`) refused the size only after the image and the map were
    // copied (a 12 GiB MemoryError for a broadcast 65536 x 65536 pair): from the shape now.
    crate::errors::check_size(w, h, MAX_PIXELS, "image", "image")?;
    let img = row_major(&image, "image")?;
    let (out, done) = map_copy_in_place(py, &disp, "disp", |d, w, _| {
        guard("fill_planes", || {
            core_fill_planes(d, &img, w, c, &passes, max_residual)
        })
    })?;
    done?;
    Ok(out)
}

crate::named_ints! {
    graph_segments_min_size: usize = "min_size";
    min_pixels_arg: usize = "min_pixels";
    step_arg: u32 = "step";
    offset_arg: u32 = "offset";
}

/// `passes`, a sequence of `(step, min_pixels)` pairs: a bad element was named by the whole
/// list ("expected a list of (step, min_pixels) pairs, ...") or by its step alone; the error
/// names the element's index and value now, and the range of the part that is wrong.
fn passes_arg(ob: &Bound<'_, PyAny>) -> PyResult<Vec<(u32, usize)>> {
    let repr = |o: &Bound<'_, PyAny>| o.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
    if ob.is_instance_of::<pyo3::types::PyString>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid parameter `passes`: expected a sequence of (step, min_pixels) pairs, got {}",
            repr(ob)
        )));
    }
    let items = ob.try_iter().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid parameter `passes`: expected a sequence of (step, min_pixels) pairs, got {}",
            repr(ob)
        ))
    })?;
    let mut out = Vec::new();
    for (i, item) in items.enumerate() {
        let item = item?;
        let bad = |what: String| {
            PyValueError::new_err(format!(
                "invalid parameter `passes`: element {i} ({}): {what}",
                repr(&item)
            ))
        };
        let (step, min_pixels): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item
            .extract()
            .map_err(|_| bad("expected a (step, min_pixels) pair".to_string()))?;
        let step = match step.extract::<u32>() {
            Ok(s) if (1..=255).contains(&s) => s,
            _ => return Err(bad("step must be an integer in 1-255".to_string())),
        };
        let min_pixels = min_pixels
            .extract::<usize>()
            .map_err(|_| bad(format!("min_pixels must be {}", usize::range())))?;
        out.push((step, min_pixels));
    }
    Ok(out)
}

crate::named_floats! {
    k_f32: f32 = "k";
    max_residual_f32: f32 = "max_residual";
    lo_f32: f32 = "lo";
    hi_f32: f32 = "hi";
}
