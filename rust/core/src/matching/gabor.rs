//! Gabor-wavelet phase disparity (algorithms.md section A). PLACEHOLDER: being written.

use crate::error::Result;
use crate::image::{check_pair, Image};

/// Parameters of the Gabor channel.
#[derive(Debug, Clone, PartialEq)]
pub struct GaborParams {
    /// Smallest disparity searched (px).
    pub d_min: f32,
    /// Largest disparity searched (px).
    pub d_max: f32,
}

/// Output of the Gabor channel: disparity (`NaN` = no estimate) and confidence in `[0, 1]`.
#[derive(Debug, Clone)]
pub struct GaborOutput {
    pub disparity: Image,
    pub confidence: Image,
}

/// Dense phase-based disparity of a rectified pair.
pub fn gabor_disparity(left: &Image, right: &Image, params: &GaborParams) -> Result<GaborOutput> {
    check_pair(left, right)?;
    let _ = params;
    Ok(GaborOutput {
        disparity: Image::filled(left.width, left.height, f32::NAN),
        confidence: Image::filled(left.width, left.height, 0.0),
    })
}
