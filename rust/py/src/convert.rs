//! NumPy <-> core image conversion.

use std::borrow::Cow;

use numpy::ndarray::{Array2, ArrayView, Dimension};
use numpy::{
    IntoPyArray, PyArray2, PyArrayDescrMethods, PyReadonlyArray, PyReadonlyArray2,
    PyReadwriteArray, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use stereovision_core::{Image, ImageView};

/// The array's buffer when it is C-contiguous (row-major: what every kernel reads), else None.
/// (`as_slice` alone also hands out a Fortran-ordered buffer, which holds the transpose.)
pub fn c_slice<'a, T: numpy::Element, D: Dimension>(
    a: &'a PyReadonlyArray<'_, T, D>,
) -> Option<&'a [T]> {
    if a.is_c_contiguous() {
        a.as_slice().ok()
    } else {
        None
    }
}

/// The argument `name` as a read-only array of `T` and `D`'s dimensions. A wrong dtype or
/// number of dimensions is a `TypeError` naming the argument and what it should be
/// ("left: expected a float32 array, got float64"), not NumPy's bare "type mismatch".
///
/// An array whose items are not aligned, or whose strides are no multiple of the item size
/// (a float field of a packed structured array, a buffer read at an odd offset), comes back
/// as NumPy's C-ordered copy of it: the views read it as if each stride were rounded down to
/// whole items, and the kernels computed from other pixels than the array's without a word.
pub fn array_arg<'py, T: numpy::Element, D: Dimension>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadonlyArray<'py, T, D>> {
    let err = match obj.extract::<PyReadonlyArray<'py, T, D>>() {
        Ok(a) if whole_items::<T>(a.is_aligned(), a.strides()) => return Ok(a),
        Ok(_) => {
            let copy = obj.call_method1("copy", ("C",))?;
            return copy.extract::<PyReadonlyArray<'py, T, D>>();
        }
        Err(e) => e,
    };
    // An array of the right type that cannot be read: this call writes it through another
    // argument (NumPy's bare "The given array is already borrowed" named neither).
    Err(describe_mismatch::<T, D>(obj, name).unwrap_or_else(|| {
        PyValueError::new_err(format!(
            "{name}: {} (it shares memory with an array this call updates in place)",
            err.value(obj.py())
        ))
    }))
}

/// [`array_arg`] for an array the kernel writes into: no copy can stand for it, so one that
/// is not aligned or whose strides are no multiple of the item size is a `ValueError`.
pub fn array_arg_rw<'py, T: numpy::Element, D: Dimension>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadwriteArray<'py, T, D>> {
    let err = match obj.extract::<PyReadwriteArray<'py, T, D>>() {
        Ok(a) if whole_items::<T>(a.is_aligned(), a.strides()) => return Ok(a),
        Ok(a) => {
            return Err(PyValueError::new_err(format!(
                "{name} must be an aligned array whose strides are whole items (it is updated \
                 in place), got strides {:?} for items of {} bytes",
                a.strides(),
                std::mem::size_of::<T>()
            )))
        }
        Err(e) => e,
    };
    // float32 of the other byte order: describe_mismatch's advice, `.astype(np.float32)` in
    // the call, had the kernel update that copy, the caller's array left as it was unsaid.
    if let Some(e) = swapped_in_place::<T>(obj, name) {
        return Err(e);
    }
    // An array of the right type that cannot be written: read-only, or shared with another
    // argument ("The given array is not writeable" named no argument).
    Err(describe_mismatch::<T, D>(obj, name).unwrap_or_else(|| {
        PyValueError::new_err(format!(
            "{name}: {} (it is updated in place: it must be writeable and share no memory \
             with another argument)",
            err.value(obj.py())
        ))
    }))
}

/// The `TypeError` for an array the kernel writes into that is `T` in the other byte order,
/// saying to keep the converted array: a copy passed in the call is updated, not the array.
fn swapped_in_place<T: numpy::Element>(obj: &Bound<'_, PyAny>, name: &str) -> Option<PyErr> {
    let want = numpy::dtype::<T>(obj.py());
    let got = obj.cast::<PyUntypedArray>().ok()?.dtype();
    let swapped = !got.is_equiv_to(&want)
        && got.is_native_byteorder() == Some(false)
        && got.kind() == want.kind()
        && got.itemsize() == want.itemsize();
    swapped.then(|| {
        PyTypeError::new_err(format!(
            "{name}: expected a {want} array, got {got} ({want} in the other byte order: it is \
             updated in place, so convert the array you keep and pass that: {name} = \
             {name}.astype(np.{want}))"
        ))
    })
}

/// Whether the array's items are aligned and its strides whole items: what rust-numpy's views
/// need to read it as NumPy does.
fn whole_items<T>(aligned: bool, strides: &[isize]) -> bool {
    let size = std::mem::size_of::<T>() as isize;
    aligned && strides.iter().all(|s| s % size == 0)
}

/// The `TypeError` for `obj` not being an array of `T` with `D`'s dimensions; None when it is
/// one (the extraction failed for another reason: a borrow conflict, a read-only array).
fn describe_mismatch<T: numpy::Element, D: Dimension>(
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> Option<PyErr> {
    let py = obj.py();
    let want = numpy::dtype::<T>(py);
    let Ok(arr) = obj.cast::<PyUntypedArray>() else {
        let got = obj
            .get_type()
            .name()
            .map_or_else(|_| "another type".to_string(), |n| n.to_string());
        return Some(PyTypeError::new_err(format!(
            "{name}: expected a {want} array, got {got}"
        )));
    };
    let got = arr.dtype();
    if !got.is_equiv_to(&want) {
        // ">f4" alone read as another type than the float32 asked for: it is float32 in the
        // other byte order (a big-endian file's, a PFM's), which the kernels do not read.
        let swapped = got.is_native_byteorder() == Some(false)
            && got.kind() == want.kind()
            && got.itemsize() == want.itemsize();
        let hint = if swapped {
            format!(" ({want} in the other byte order: convert it with .astype(np.{want}))")
        } else {
            String::new()
        };
        return Some(PyTypeError::new_err(format!(
            "{name}: expected a {want} array, got {got}{hint}"
        )));
    }
    match D::NDIM {
        Some(nd) if nd != arr.ndim() => Some(PyTypeError::new_err(format!(
            "{name}: expected a {nd}-D {want} array, got {} dimensions (shape {:?})",
            arr.ndim(),
            arr.shape()
        ))),
        _ => None,
    }
}

/// The view's values in row-major order in a new vector; a failed allocation is a
/// `MemoryError` naming the size (a huge broadcast array aborted the process).
fn copy_row_major<T: Copy, D: Dimension>(
    view: ArrayView<'_, T, D>,
    what: &str,
) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(view.len())
        .map_err(|_| crate::errors::copy_oom::<T>(view.len(), what))?;
    match view.as_slice() {
        Some(s) => v.extend_from_slice(s),
        None => v.extend(view.iter().copied()),
    }
    Ok(v)
}

/// The array's values in row-major order: its own buffer when C-contiguous, else a copy
/// (`what` names the array in a `MemoryError`).
pub fn row_major<'a, T: numpy::Element + Copy, D: Dimension>(
    a: &'a PyReadonlyArray<'_, T, D>,
    what: &str,
) -> PyResult<Cow<'a, [T]>> {
    Ok(match c_slice(a) {
        Some(s) => Cow::Borrowed(s),
        None => Cow::Owned(copy_row_major(a.as_array(), what)?),
    })
}

/// Copies a 2-D float32 array into a core [`Image`] (validated: non-empty, finite).
pub fn image_from_numpy(arr: &PyReadonlyArray2<'_, f32>, what: &str) -> PyResult<Image> {
    let view = arr.as_array();
    let (h, w) = view.dim();
    let data = copy_row_major(view, what)?;
    Image::new(w, h, data).map_err(|e| PyValueError::new_err(format!("{what}: {e}")))
}

/// A validated grey image from a 2-D float32 array: the array's own buffer when it is
/// C-contiguous (no copy: the Python wrappers make it so), else a copy.
pub enum GreyInput<'a> {
    View(ImageView<'a>),
    Owned(Image),
}

impl GreyInput<'_> {
    /// The image, borrowed.
    pub fn view(&self) -> ImageView<'_> {
        match self {
            GreyInput::View(v) => *v,
            GreyInput::Owned(i) => i.view(),
        }
    }
}

/// [`image_from_numpy`] without the copy when the array is C-contiguous.
pub fn grey_from_numpy<'a>(
    arr: &'a PyReadonlyArray2<'_, f32>,
    what: &str,
) -> PyResult<GreyInput<'a>> {
    let (h, w) = arr.as_array().dim();
    match c_slice(arr) {
        Some(s) => ImageView::new(w, h, s)
            .map(GreyInput::View)
            .map_err(|e| PyValueError::new_err(format!("{what}: {e}"))),
        None => image_from_numpy(arr, what).map(GreyInput::Owned),
    }
}

/// Moves a core [`Image`] into a new NumPy array without copying.
pub fn image_to_numpy<'py>(py: Python<'py>, img: Image) -> PyResult<Bound<'py, PyArray2<f32>>> {
    vec_to_numpy(py, (img.height, img.width), img.data)
}

/// A copy of a 2-D float32 map changed by `kernel(data, w, h)` with the GIL released, and what
/// the kernel returned: the bindings of the kernels that work on a map in place.
pub fn map_copy_in_place<'py, R: Send>(
    py: Python<'py>,
    map: &PyReadonlyArray2<'py, f32>,
    what: &str,
    kernel: impl FnOnce(&mut [f32], usize, usize) -> R + Send,
) -> PyResult<(Bound<'py, PyArray2<f32>>, R)> {
    let a = map.as_array();
    let (h, w) = a.dim();
    let mut d = copy_row_major(a, what)?;
    let r = crate::workers::detach(py, || kernel(&mut d, w, h));
    Ok((vec_to_numpy(py, (h, w), d)?, r))
}

/// Moves a row-major vector into a new `(rows, cols)` NumPy array without copying.
pub fn vec_to_numpy<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: (usize, usize),
    data: Vec<T>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let arr =
        Array2::from_shape_vec(shape, data).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// Row-major values: an array's own buffer, or a copy.
pub type RowMajor<'a, T> = Cow<'a, [T]>;

/// The values of the arguments `disp` and `conf` in row-major order, both checked to be
/// `(h, w)`, the shape of the argument `like`, before either is copied: their own buffers when
/// C-contiguous (the Python wrappers make them so), else copies (a strided, reversed or
/// Fortran-ordered view was refused with "must be C-contiguous"). The error names the
/// argument: it said "confidence shape ... differs from the expected shape", of an argument
/// called `conf`, and the shape expected came from nowhere it named.
pub fn map_and_confidence<'a>(
    disp: &'a PyReadonlyArray2<'_, f32>,
    conf: &'a PyReadonlyArray2<'_, f32>,
    (h, w): (usize, usize),
    like: &str,
) -> PyResult<(RowMajor<'a, f32>, RowMajor<'a, f32>)> {
    check_map_shapes(disp, conf, (h, w), like)?;
    Ok((row_major(disp, "disp")?, row_major(conf, "conf")?))
}

/// The shape check of [`map_and_confidence`] alone, for a caller that copies other arrays
/// first (`refine_disparity` copied `left` and `right` before `disp`'s shape was checked).
pub fn check_map_shapes(
    disp: &PyReadonlyArray2<'_, f32>,
    conf: &PyReadonlyArray2<'_, f32>,
    (h, w): (usize, usize),
    like: &str,
) -> PyResult<()> {
    for (a, name) in [(disp, "disp"), (conf, "conf")] {
        if a.as_array().dim() != (h, w) {
            return Err(PyValueError::new_err(format!(
                "{name}: expected shape {:?} like {like}, got {:?}",
                (h, w),
                a.as_array().dim()
            )));
        }
    }
    Ok(())
}

/// `(H, W, C)` of an 8-bit image array `(H, W)` (C = 1) or `(H, W, C)` (C 1, 3 or 4), read
/// from its shape alone: the callers check the other arguments' shapes against it before
/// [`u8_layout`] copies anything (a frame or left image was copied, 4 GiB for a broadcast
/// one, before a mean or right image of another shape was refused).
pub fn u8_shape(
    a: &numpy::PyReadonlyArrayDyn<'_, u8>,
    what: &str,
) -> PyResult<(usize, usize, usize)> {
    let shape = a.shape();
    let (h, w, c) = match shape {
        [h, w] => (*h, *w, 1),
        [h, w, c] => (*h, *w, *c),
        _ => {
            return Err(PyValueError::new_err(format!(
                "{what} must have 2 or 3 dimensions, got shape {shape:?}"
            )))
        }
    };
    // Every kernel taking 8-bit images reads 1, 3 or 4 channels: said before the copy, which
    // came first (4 GiB for a broadcast (1, 1, 2**32) image, a MemoryError under a memory
    // limit), and naming the array ("invalid parameter `channels`" named no argument).
    if !matches!(c, 1 | 3 | 4) {
        return Err(PyValueError::new_err(format!(
            "{what}: expected 1, 3 or 4 channels, got {c} (shape {shape:?})"
        )));
    }
    // Named, and by its own size: the kernels' "image is empty" named no argument (which of
    // hopfield_match_u8's left and right?), and the temporal ones know only a pixel count.
    if h == 0 || w == 0 {
        let e = stereovision_core::CoreError::EmptyImage {
            width: w,
            height: h,
        };
        return Err(PyValueError::new_err(format!("{what}: {e}")));
    }
    Ok((h, w, c))
}

/// `(H, W, C, data)` of an 8-bit image array ([`u8_shape`]), its values in row-major order:
/// its own buffer when C-contiguous, else a copy (a strided, reversed or Fortran-ordered
/// view, e.g. one channel of a colour image, was refused with "must be C-contiguous").
pub fn u8_layout<'a>(
    a: &'a numpy::PyReadonlyArrayDyn<'_, u8>,
    what: &str,
) -> PyResult<(usize, usize, usize, Cow<'a, [u8]>)> {
    let (h, w, c) = u8_shape(a, what)?;
    Ok((h, w, c, row_major(a, what)?))
}

/// The argument `weights`, three numbers (B, G, R), each through
/// [`FloatArg`](crate::params::FloatArg) as the scalar arguments are: pyo3's own conversion cut
/// 1e39 to inf ("expected three finite non-negative numbers (B, G, R), got [inf, ...]", a
/// value not given) and 10**400 was a bare "OverflowError: int too large to convert to float".
pub fn weights_arg(ob: &Bound<'_, PyAny>) -> PyResult<(f32, f32, f32)> {
    use crate::params::FloatArg;
    let (b, g, r): (Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyAny>) =
        ob.extract().map_err(|_| {
            let got = ob
                .repr()
                .map_or_else(|_| "?".to_string(), |r| r.to_string());
            PyTypeError::new_err(format!(
                "invalid parameter `weights`: expected a tuple of three numbers (B, G, R), got \
                 {got}"
            ))
        })?;
    let f = |v: &Bound<'_, PyAny>| f32::extract_named(v, "weights");
    Ok((f(&b)?, f(&g)?, f(&r)?))
}

/// The B, G, R grey weights as an array, checked to be finite and non-negative (a NaN weight
/// made every grey level NaN, and the matcher found nothing, without a word).
pub fn luma_weights(weights: (f32, f32, f32)) -> PyResult<[f32; 3]> {
    let wts = [weights.0, weights.1, weights.2];
    if wts.iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(wts)
    } else {
        Err(PyValueError::new_err(format!(
            "weights: expected three finite non-negative numbers (B, G, R), got {wts:?}"
        )))
    }
}

/// `stereovision._validate.as_gray_float` for 8-bit images, in Rust: `(H, W)` grey or
/// `(H, W, C)` with `C` in 1, 3, 4 (BGR order), any memory layout; bit-identical to the NumPy
/// path.
#[pyfunction]
#[pyo3(signature = (image, weights))]
pub fn gray_u8<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = weights_arg)] weights: (f32, f32, f32),
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let image: numpy::PyReadonlyArrayDyn<'py, u8> = crate::convert::array_arg(image, "image")?;
    let (h, w, c, data) = u8_layout(&image, "image")?;
    let wts = luma_weights(weights)?;
    let grey = crate::workers::detach(py, || {
        crate::errors::guard("gray_u8", || {
            stereovision_core::image::grey_from_u8(&data, w, h, c, wts)
        })
    })?;
    image_to_numpy(
        py,
        Image {
            width: w,
            height: h,
            data: grey,
        },
    )
}
