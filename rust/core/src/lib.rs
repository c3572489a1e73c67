//! Pure-Rust core of `stereovision`: the hot kernels of the pipeline, with no Python in sight.
//!
//! Layout mirrors the pipeline (see `docs/architecture.md`):
//! * [`image`]: a minimal owned grey image and validation of inputs;
//! * [`alloc`]: the allocator the extension installs (freed large blocks kept for the next call);
//! * [`error`]: the one error type every kernel returns (mapped to Python exceptions by `rust/py`);
//! * [`matching`]: the correspondence channels (`gabor`, `mcgm`, `hopfield`);
//! * [`refine`]: sub-pixel refinement and validated completion of a disparity map;
//! * [`fill`]: the evaluation's reference row fill of a map's holes;
//! * [`edges`]: foreground fattened past depth edges (the fused dense map's edge step);
//! * [`temporal`]: a still rig's frames averaged over time (less sensor noise);
//! * [`triangulation`]: depth and its uncertainty from a rectified disparity map;
//! * [`lzf`]: LZF decompression of PCL's `binary_compressed` point clouds.
//!
//! Conventions (algorithms.md section 0): images are `f32` in `[0, 1]`, row-major `(H, W)`;
//! `x` = column, `y` = row; disparity `d = x_left - x_right`, stored at left-image pixels,
//! `NaN` = no estimate.

pub mod alloc;
pub mod edges;
pub mod error;
pub mod fill;
pub mod image;
pub mod lzf;
pub mod matching;
pub mod parallel;
pub mod refine;
pub mod segment;
pub(crate) mod simd;
pub mod temporal;

/// Helpers shared by the unit tests.
#[cfg(test)]
pub(crate) mod testing {
    /// Xorshift64 (13, 7, 17): a deterministic stream of `u64`s from a non-zero `seed`, for
    /// test images and maps that must be the same on every run and platform.
    pub(crate) fn xorshift(mut s: u64) -> impl FnMut() -> u64 {
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        }
    }
}
pub mod triangulation;

pub use error::{CoreError, Result};
pub use image::{Image, ImageView};
