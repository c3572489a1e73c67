//! `stereovision._core`: the thin PyO3 layer over `stereovision-core`.
//!
//! Each file wraps one core module with the same function names; arrays come in as read-only
//! NumPy views, the GIL is released around every kernel, and core errors become Python exceptions
//! (`errors.rs`). No algorithm lives here.

use pyo3::prelude::*;
use stereovision_core::matching::gabor::pool;
use stereovision_core::matching::sgm as sgm_kept;

mod convert;
mod errors;
mod fill;
mod gabor;
mod hopfield;
mod lzf;
mod mcgm;
mod params;
mod refine;
mod segment;
mod sgm;
mod temporal;
mod triangulation;
mod workers;

/// Freed image-sized blocks are kept for the next call instead of being returned to the system
/// and faulted in again (`stereovision_core::alloc`); only the extension's allocations use it.
#[global_allocator]
static ALLOC: stereovision_core::alloc::BlockCache = stereovision_core::alloc::BlockCache::new();

/// Returns the memory kept for the next call to the system (the Gabor planes' pool and the
/// census matcher's buffers, then the allocator's blocks, which the pool's buffers pass
/// through); the number of bytes released.
#[pyfunction]
fn release_memory() -> usize {
    let held = pool::held_bytes() + sgm_kept::kept_bytes() + ALLOC.kept().1;
    pool::release();
    sgm_kept::release_kept();
    ALLOC.clear();
    held
}

/// `(blocks, bytes)` the allocator keeps, and the bytes the kernels' own pools keep (the Gabor
/// planes and the census matcher's cost volume and rows).
#[pyfunction]
fn kept_memory() -> ((usize, usize), usize) {
    (ALLOC.kept(), pool::held_bytes() + sgm_kept::kept_bytes())
}

#[pymodule(gil_used = false)]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(gabor::gabor_disparity, m)?)?;
    m.add_function(wrap_pyfunction!(gabor::gabor_responses, m)?)?;
    m.add_function(wrap_pyfunction!(gabor::gabor_newton_step, m)?)?;
    m.add_function(wrap_pyfunction!(gabor::gabor_lr_check, m)?)?;
    m.add_function(wrap_pyfunction!(gabor::gabor_remove_speckles, m)?)?;
    m.add_function(wrap_pyfunction!(hopfield::hopfield_interest, m)?)?;
    m.add_function(wrap_pyfunction!(hopfield::hopfield_match, m)?)?;
    m.add_function(wrap_pyfunction!(hopfield::hopfield_match_u8, m)?)?;
    m.add_function(wrap_pyfunction!(hopfield::hopfield_candidates, m)?)?;
    m.add_function(wrap_pyfunction!(mcgm::mcgm_log, m)?)?;
    m.add_function(wrap_pyfunction!(mcgm::mcgm_curves, m)?)?;
    m.add_function(wrap_pyfunction!(mcgm::mcgm_match, m)?)?;
    m.add_function(wrap_pyfunction!(mcgm::mcgm_filter, m)?)?;
    m.add_function(wrap_pyfunction!(triangulation::depth_rectified, m)?)?;
    m.add_function(wrap_pyfunction!(refine::refine_disparity, m)?)?;
    m.add_function(wrap_pyfunction!(sgm::sgm_disparity, m)?)?;
    m.add_function(wrap_pyfunction!(fill::row_fill, m)?)?;
    m.add_function(wrap_pyfunction!(fill::side_fill, m)?)?;
    m.add_function(wrap_pyfunction!(fill::fattened, m)?)?;
    m.add_function(wrap_pyfunction!(segment::graph_segments, m)?)?;
    m.add_function(wrap_pyfunction!(segment::plane_fill, m)?)?;
    m.add_function(wrap_pyfunction!(segment::fill_planes, m)?)?;
    m.add_function(wrap_pyfunction!(segment::quantised_regions, m)?)?;
    m.add_function(wrap_pyfunction!(convert::gray_u8, m)?)?;
    m.add_function(wrap_pyfunction!(temporal::temporal_grey_difference, m)?)?;
    m.add_function(wrap_pyfunction!(temporal::temporal_running_mean, m)?)?;
    m.add_function(wrap_pyfunction!(lzf::lzf_decompress, m)?)?;
    m.add_function(wrap_pyfunction!(release_memory, m)?)?;
    m.add_function(wrap_pyfunction!(kept_memory, m)?)?;
    Ok(())
}
