//! Binding of `stereovision_core::lzf`: bytes-like in, `bytes` out.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyMemoryView};
use stereovision_core::lzf::{check_expansion, lzf_decompress_into};

use crate::errors::{guard, to_pyerr};

/// The `out_len` bytes the LZF stream `data` (any bytes-like object) decompresses to (liblzf's
/// `lzf_decompress`); a damaged or cut stream, or one that decompresses to another length, is a
/// `ValueError`.
#[pyfunction]
#[pyo3(signature = (data, out_len))]
pub fn lzf_decompress<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = data_arg)] data: Bound<'py, PyBytes>,
    #[pyo3(from_py_with = out_len_arg)] out_len: usize,
) -> PyResult<Bound<'py, PyBytes>> {
    let data = data.as_bytes();
    // An out_len the data cannot reach (a header's size is untrusted) is refused before the
    // output is allocated.
    check_expansion(data.len(), out_len).map_err(to_pyerr)?;
    // Decoded straight into the bytes object: no copy of the output.
    PyBytes::new_with(py, out_len, |buf| {
        crate::workers::detach(py, || {
            guard("lzf_decompress", || lzf_decompress_into(data, buf))
        })
    })
}

/// `data` as `bytes`: itself, or the bytes of any other bytes-like object (a `bytearray`, a
/// `memoryview`, a NumPy buffer: a message's payload), copied (a `bytearray` may change while
/// the GIL is released), as `zlib.decompress` takes them. Only `bytes` was taken: a bytearray
/// was pyo3's "'bytearray' object is not an instance of 'bytes'", naming no argument.
fn data_arg<'py>(ob: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyBytes>> {
    if let Ok(b) = ob.cast::<PyBytes>() {
        return Ok(b.clone());
    }
    let view = PyMemoryView::from(ob).map_err(|e| {
        // A bytes-like object Python itself refuses to read (a released memoryview: "operation
        // forbidden on released memoryview object") says why; it was "expected a bytes-like
        // object (bytes, bytearray, memoryview), got memoryview".
        let py = ob.py();
        if !e.is_instance_of::<PyTypeError>(py) {
            return PyValueError::new_err(format!("invalid parameter `data`: {}", e.value(py)));
        }
        let got = ob
            .get_type()
            .name()
            .map_or_else(|_| "another type".to_string(), |n| n.to_string());
        PyTypeError::new_err(format!(
            "invalid parameter `data`: expected a bytes-like object (bytes, bytearray, \
             memoryview), got {got}"
        ))
    })?;
    Ok(view.call_method0("tobytes")?.cast_into::<PyBytes>()?)
}

crate::named_ints! {
    out_len_arg: usize = "out_len";
}
