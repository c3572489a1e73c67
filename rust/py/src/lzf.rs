//! Binding of `stereovision_core::lzf`: `bytes` in, `bytes` out.

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use stereovision_core::lzf::{check_expansion, lzf_decompress_into};

use crate::errors::{guard, to_pyerr};

/// The `out_len` bytes the LZF stream `data` decompresses to (liblzf's `lzf_decompress`);
/// a damaged or cut stream, or one that decompresses to another length, is a `ValueError`.
#[pyfunction]
#[pyo3(signature = (data, out_len))]
pub fn lzf_decompress<'py>(
    py: Python<'py>,
    data: &[u8],
    #[pyo3(from_py_with = out_len_arg)] out_len: usize,
) -> PyResult<Bound<'py, PyBytes>> {
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

crate::named_ints! {
    out_len_arg: usize = "out_len";
}
