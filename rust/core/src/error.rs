//! The error type of the core. Every user-reachable failure is a variant here, never a panic.

use thiserror::Error;

/// Errors returned by the kernels. The binding maps each variant to one Python exception class.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CoreError {
    /// An image has a zero dimension.
    #[error("image is empty: got {width}x{height} pixels")]
    EmptyImage { width: usize, height: usize },
    /// Buffer length does not match `width * height`.
    #[error("image buffer has {got} values, expected {expected} ({width}x{height})")]
    BufferSize {
        got: usize,
        expected: usize,
        width: usize,
        height: usize,
    },
    /// The two images of a pair differ in size.
    #[error(
        "left and right images differ in size: left {left:?}, right {right:?} (width, height)"
    )]
    SizeMismatch {
        left: (usize, usize),
        right: (usize, usize),
    },
    /// An image holds NaN or infinite values.
    #[error("image contains non-finite values (NaN or inf) at {count} pixels")]
    NonFinite { count: usize },
    /// A parameter is out of its valid range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter { name: &'static str, reason: String },
    /// An image has more pixels, or a longer side, than the kernels' 32-bit pixel indices and
    /// coordinates reach ([`crate::image::check_index_range`]); they would wrap silently.
    /// `max_pixels` is the kernel's own limit ([`crate::image::MAX_PIXELS`] for most).
    #[error(
        "image of {width}x{height} pixels is too large: the kernels index pixels with 32-bit \
         integers (at most {max_pixels} pixels, {} per side)",
        crate::image::MAX_SIDE
    )]
    TooLarge {
        width: usize,
        height: usize,
        max_pixels: usize,
    },
    /// A buffer could not be allocated (the binding raises `MemoryError` instead of the
    /// process aborting).
    #[error("out of memory: {what} needs {} and the allocation failed", crate::alloc::human_bytes(*.bytes))]
    OutOfMemory { bytes: usize, what: &'static str },
    /// Compressed data that does not decompress (a damaged or cut stream, see [`crate::lzf`]).
    #[error("corrupt {format} data: {reason}")]
    CorruptData {
        format: &'static str,
        reason: String,
    },
}

/// Result alias used across the core.
pub type Result<T> = std::result::Result<T, CoreError>;

impl CoreError {
    /// Convenience constructor for [`CoreError::InvalidParameter`].
    pub fn param(name: &'static str, reason: impl Into<String>) -> Self {
        CoreError::InvalidParameter {
            name,
            reason: reason.into(),
        }
    }

    /// Convenience constructor for [`CoreError::OutOfMemory`].
    pub fn oom(bytes: usize, what: &'static str) -> Self {
        CoreError::OutOfMemory { bytes, what }
    }
}
