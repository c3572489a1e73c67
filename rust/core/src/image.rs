//! A minimal owned single-channel `f32` image, row-major.

use crate::error::{CoreError, Result};

/// Grey image, row-major, `data[y * width + x]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl Image {
    /// Wraps a buffer after checking its size; rejects empty and non-finite images.
    pub fn new(width: usize, height: usize, data: Vec<f32>) -> Result<Self> {
        ImageView::new(width, height, &data)?;
        Ok(Image {
            width,
            height,
            data,
        })
    }

    /// An image filled with one value, or [`CoreError::OutOfMemory`] when it cannot be
    /// allocated (`vec!` aborted the process).
    pub fn filled(width: usize, height: usize, value: f32) -> Result<Self> {
        // Saturated: a size past `usize` is a failed allocation, not a wrapped small image.
        let n = width.saturating_mul(height);
        Ok(Image {
            width,
            height,
            data: crate::alloc::try_filled(n, value, "the filled image")?,
        })
    }

    /// Value at `(x, y)`; the caller guarantees bounds.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// A borrowed grey image (row-major), e.g. a NumPy array's buffer: kernels that only read their
/// input take one instead of a copy.
#[derive(Debug, Clone, Copy)]
pub struct ImageView<'a> {
    pub width: usize,
    pub height: usize,
    pub data: &'a [f32],
}

impl<'a> ImageView<'a> {
    /// Wraps a buffer after checking its size; rejects empty and non-finite images (the checks
    /// of [`Image::new`] too).
    pub fn new(width: usize, height: usize, data: &'a [f32]) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(CoreError::EmptyImage { width, height });
        }
        let expected = width
            .checked_mul(height)
            .ok_or_else(|| CoreError::param("shape", "width * height overflows"))?;
        if data.len() != expected {
            return Err(CoreError::BufferSize {
                got: data.len(),
                expected,
                width,
                height,
            });
        }
        let count = data.iter().filter(|v| !v.is_finite()).count();
        if count > 0 {
            return Err(CoreError::NonFinite { count });
        }
        Ok(ImageView {
            width,
            height,
            data,
        })
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

impl<'a> From<&'a Image> for ImageView<'a> {
    fn from(img: &'a Image) -> Self {
        img.view()
    }
}

impl<'a> From<&ImageView<'a>> for ImageView<'a> {
    fn from(v: &ImageView<'a>) -> Self {
        *v
    }
}

impl ImageView<'_> {
    /// Value at `(x, y)`; the caller guarantees bounds.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }
}

impl Image {
    /// A borrowed view (already checked: an `Image` is valid by construction).
    pub fn view(&self) -> ImageView<'_> {
        ImageView {
            width: self.width,
            height: self.height,
            data: &self.data,
        }
    }
}

/// Most pixels of an image the kernels take: pixel indices `y * w + x` and pixel counts are
/// held in `u32` (MCGM's segments and seeds, the graph and colour segmentations, Gabor's
/// component labels, Hopfield's interest points).
pub const MAX_PIXELS: usize = u32::MAX as usize;
/// Longest side: columns and rows are held in `i32` (MCGM's tracking, Hopfield's matches, the
/// refinement's warp).
pub const MAX_SIDE: usize = i32::MAX as usize;

/// Refuses a `width x height` image whose pixel indices or coordinates would not fit the
/// kernels' 32-bit integers ([`MAX_PIXELS`], [`MAX_SIDE`]): [`CoreError::TooLarge`] instead of
/// indices that wrap silently. Reads the dimensions only (a kernel calls it once, first).
pub fn check_index_range(width: usize, height: usize) -> Result<()> {
    check_index_range_within(width, height, MAX_PIXELS)
}

/// [`check_index_range`] for a kernel whose 32-bit numbers reach fewer pixels than
/// [`MAX_PIXELS`] (the graph segmentation numbers two edges a pixel): at most `max_pixels`.
pub fn check_index_range_within(width: usize, height: usize, max_pixels: usize) -> Result<()> {
    let fits = width <= MAX_SIDE
        && height <= MAX_SIDE
        && width.checked_mul(height).is_some_and(|n| n <= max_pixels);
    if fits {
        Ok(())
    } else {
        Err(CoreError::TooLarge {
            width,
            height,
            max_pixels,
        })
    }
}

/// Checks that a stereo pair has the same, non-empty size.
pub fn check_pair(left: &Image, right: &Image) -> Result<()> {
    if left.size() != right.size() {
        return Err(CoreError::SizeMismatch {
            left: left.size(),
            right: right.size(),
        });
    }
    Ok(())
}

/// Checks that a disparity map and its confidence both hold `w * h` values.
pub fn check_map_pair(disp: &[f32], conf: &[f32], w: usize, h: usize) -> Result<()> {
    let n = w
        .checked_mul(h)
        .ok_or_else(|| CoreError::param("shape", "width * height overflows"))?;
    if disp.len() != n || conf.len() != n {
        return Err(CoreError::param(
            "disparity",
            format!(
                "disparity ({}) and confidence ({}) must both have {w} x {h} values",
                disp.len(),
                conf.len()
            ),
        ));
    }
    Ok(())
}

/// [`grey_from_u8`] of a stereo pair of one layout, both images in one parallel region.
pub fn grey_pair_from_u8(
    left: &[u8],
    right: &[u8],
    width: usize,
    height: usize,
    channels: usize,
    weights: [f32; 3],
) -> Result<(Vec<f32>, Vec<f32>)> {
    let (l, r) = rayon::join(
        || grey_from_u8(left, width, height, channels, weights),
        || grey_from_u8(right, width, height, channels, weights),
    );
    Ok((l?, r?))
}

/// Grey levels in `[0, 1]` of an 8-bit image of `channels` interleaved channels (1 = grey,
/// 3 = BGR, 4 = BGRA, alpha ignored), row-major: `v / 255` per channel, then for colour
/// `clamp((wb b + wg g) + wr r, 0, 1)` with `weights = (wb, wg, wr)`. The `f32` operations and
/// their order are NumPy's in `stereovision._validate.as_gray_float`, so the result is
/// bit-identical to it.
pub fn grey_from_u8(
    data: &[u8],
    width: usize,
    height: usize,
    channels: usize,
    weights: [f32; 3],
) -> Result<Vec<f32>> {
    use rayon::prelude::*;
    if !matches!(channels, 1 | 3 | 4) {
        return Err(CoreError::param(
            "channels",
            format!("must be 1, 3 or 4, got {channels}"),
        ));
    }
    if width == 0 || height == 0 {
        return Err(CoreError::EmptyImage { width, height });
    }
    // checked: a shape whose product wraps (a release build) matched a short buffer, then
    // indexed past it
    let expected = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels));
    if expected != Some(data.len()) {
        return Err(CoreError::param(
            "image",
            format!(
                "buffer of {} bytes does not hold {height}x{width}x{channels}",
                data.len()
            ),
        ));
    }
    // Per-level tables: `v / 255` and each channel's `w * (v / 255)`, the same f32 values the
    // per-pixel arithmetic would give (a division per channel and pixel is the slow part).
    let unit: [f32; 256] = std::array::from_fn(|v| v as f32 / 255.0);
    let [tb, tg, tr] = weights.map(|w| unit.map(|u| w * u));
    // Checked: a failed `vec!` aborted the process.
    let mut out = crate::alloc::try_zeroed::<f32>(width * height, "the grey image")?;
    out.par_chunks_mut(width)
        .zip(data.par_chunks(width * channels))
        .for_each(|(o, px)| {
            if channels == 1 {
                for (v, &p) in o.iter_mut().zip(px) {
                    *v = unit[p as usize];
                }
                return;
            }
            for (v, p) in o.iter_mut().zip(px.chunks_exact(channels)) {
                let g = tb[p[0] as usize] + tg[p[1] as usize] + tr[p[2] as usize];
                *v = g.clamp(0.0, 1.0);
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_buffers() {
        assert!(matches!(
            Image::new(0, 3, vec![]),
            Err(CoreError::EmptyImage { .. })
        ));
        assert!(matches!(
            Image::new(2, 2, vec![0.0; 3]),
            Err(CoreError::BufferSize {
                got: 3,
                expected: 4,
                ..
            })
        ));
        assert!(matches!(
            Image::new(2, 1, vec![0.0, f32::NAN]),
            Err(CoreError::NonFinite { count: 1 })
        ));
        let a = Image::filled(2, 2, 0.5).unwrap();
        let b = Image::filled(3, 2, 0.5).unwrap();
        assert!(matches!(
            check_pair(&a, &b),
            Err(CoreError::SizeMismatch { .. })
        ));
        assert_eq!(Image::new(2, 1, vec![0.25, 0.5]).unwrap().at(1, 0), 0.5);
    }

    #[test]
    fn checks_the_exact_size_every_non_finite_value_and_both_sides() {
        // A longer buffer is as wrong as a shorter one; infinities count as NaN does.
        assert!(matches!(
            ImageView::new(2, 2, &[0.0; 5]),
            Err(CoreError::BufferSize {
                got: 5,
                expected: 4,
                ..
            })
        ));
        assert_eq!(
            Image::new(3, 1, vec![f32::INFINITY, 0.0, f32::NEG_INFINITY]),
            Err(CoreError::NonFinite { count: 2 })
        );
        // Sizes that differ in height only.
        let (a, b) = (
            Image::filled(3, 2, 0.0).unwrap(),
            Image::filled(3, 4, 0.0).unwrap(),
        );
        assert_eq!(
            check_pair(&a, &b),
            Err(CoreError::SizeMismatch {
                left: (3, 2),
                right: (3, 4)
            })
        );
        assert_eq!(Image::filled(3, 2, 0.5).unwrap().data, vec![0.5; 6]);
        // Too large for any address space (or past `usize`): an error naming it, not an abort.
        for (w, h) in [(1usize << 31, 1usize << 31), (usize::MAX, 3)] {
            assert!(matches!(
                Image::filled(w, h, 0.5),
                Err(CoreError::OutOfMemory {
                    what: "the filled image",
                    ..
                })
            ));
        }
        // A confidence of the wrong length, with a disparity of the right one.
        assert!(check_map_pair(&[0.0; 6], &[0.0; 6], 3, 2).is_ok());
        assert!(check_map_pair(&[0.0; 6], &[0.0; 5], 3, 2).is_err());
        assert!(check_map_pair(&[0.0; 5], &[0.0; 6], 3, 2).is_err());
    }

    #[test]
    fn at_is_row_major_on_a_non_square_image() {
        let img = Image::new(3, 2, (0..6).map(|v| v as f32).collect()).unwrap();
        let view = ImageView::from(&img);
        for y in 0..2 {
            for x in 0..3 {
                assert_eq!(img.at(x, y), (y * 3 + x) as f32);
                assert_eq!(view.at(x, y), (y * 3 + x) as f32);
            }
        }
        assert_eq!(view.size(), (3, 2));
    }

    /// The documented per-pixel formula, written out without the tables.
    fn grey_reference(px: &[u8], w: [f32; 3]) -> f32 {
        if px.len() == 1 {
            return px[0] as f32 / 255.0;
        }
        let (b, g, r) = (
            px[0] as f32 / 255.0,
            px[1] as f32 / 255.0,
            px[2] as f32 / 255.0,
        );
        ((w[0] * b + w[1] * g) + w[2] * r).clamp(0.0, 1.0)
    }

    #[test]
    fn grey_from_u8_refuses_a_shape_whose_size_overflows() {
        // 2^63 x 2 wraps to 0 in a release build, which matched an empty buffer
        let w = 1usize << (usize::BITS - 1);
        for (width, height, channels) in [(w, 2, 1), (w, 1, 4), (usize::MAX, usize::MAX, 3)] {
            let r = grey_from_u8(&[], width, height, channels, [0.114, 0.587, 0.299]);
            assert!(r.is_err(), "{width}x{height}x{channels}");
        }
    }

    #[test]
    fn grey_from_u8_is_the_documented_formula_bit_for_bit() {
        let (width, height) = (7, 3);
        let mut seed = 12345u32;
        let mut bytes = |n: usize| -> Vec<u8> {
            (0..n)
                .map(|_| {
                    seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12345);
                    (seed >> 16) as u8
                })
                .collect()
        };
        // BT.601 (BGR order), and weights that leave [0, 1] on both sides (the clamp).
        for weights in [[0.114, 0.587, 0.299], [0.9, 0.8, -0.6], [-0.2, 0.3, 0.1]] {
            for channels in [1usize, 3, 4] {
                let data = bytes(width * height * channels);
                let got = grey_from_u8(&data, width, height, channels, weights).unwrap();
                let want: Vec<f32> = data
                    .chunks(channels)
                    .map(|px| grey_reference(&px[..channels.min(3)], weights))
                    .collect();
                assert_eq!(got.len(), width * height);
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(g.to_bits(), w.to_bits(), "{channels} channels, pixel {i}");
                }
            }
        }
        // Hand-computed: grey 51 is 0.2; white with weights summing past 1 is 1; alpha ignored.
        let w = [0.5, 0.5, 0.5];
        assert_eq!(grey_from_u8(&[51, 0], 2, 1, 1, w).unwrap(), [0.2, 0.0]);
        assert_eq!(grey_from_u8(&[255; 4], 1, 1, 4, w).unwrap(), [1.0]);
        assert_eq!(
            grey_from_u8(&[0, 0, 0, 255, 255, 0, 0, 0], 2, 1, 4, w).unwrap(),
            [0.0, 0.5]
        );
        // Only 1, 3 or 4 channels.
        assert!(matches!(
            grey_from_u8(&[0; 4], 1, 2, 2, w),
            Err(CoreError::InvalidParameter {
                name: "channels",
                ..
            })
        ));
        // A pair: each side from its own buffer.
        let (l, r) = grey_pair_from_u8(&[0, 51], &[255, 102], 2, 1, 1, w).unwrap();
        assert_eq!((l, r), (vec![0.0, 0.2], vec![1.0, 0.4]));
    }

    #[test]
    fn an_empty_8_bit_image_is_an_empty_image() {
        // It said "buffer of 0 bytes does not hold 0x5x3".
        let w = [1.0 / 3.0; 3];
        assert_eq!(
            grey_from_u8(&[], 5, 0, 3, w),
            Err(CoreError::EmptyImage {
                width: 5,
                height: 0
            })
        );
        assert_eq!(
            grey_from_u8(&[], 0, 4, 1, w),
            Err(CoreError::EmptyImage {
                width: 0,
                height: 4
            })
        );
        assert!(matches!(
            grey_from_u8(&[0; 5], 2, 2, 1, w),
            Err(CoreError::InvalidParameter { name: "image", .. })
        ));
    }

    /// Shapes at and past the 32-bit limits of [`check_index_range`].
    const TOO_LARGE: [(usize, usize); 4] = [
        (1 << 16, 1 << 16), // 2^32 pixels: one more than u32 holds
        (MAX_SIDE + 1, 1),  // a row past i32
        (1, MAX_SIDE + 1),  // a column past i32
        (usize::MAX, 2),    // a product past usize
    ];

    #[test]
    fn check_index_range_refuses_indices_past_32_bits() {
        for (w, h) in [(1, 1), (3, MAX_PIXELS / 3), (MAX_SIDE, 2), (65535, 65537)] {
            assert_eq!(check_index_range(w, h), Ok(()), "{w}x{h}");
        }
        for (w, h) in TOO_LARGE {
            assert_eq!(
                check_index_range(w, h),
                Err(CoreError::TooLarge {
                    width: w,
                    height: h,
                    max_pixels: MAX_PIXELS
                })
            );
        }
        assert_eq!(
            CoreError::TooLarge {
                width: 65536,
                height: 65536,
                max_pixels: MAX_PIXELS
            }
            .to_string(),
            "image of 65536x65536 pixels is too large: the kernels index pixels with 32-bit \
             integers (at most 4294967295 pixels, 2147483647 per side)"
        );
    }

    #[test]
    fn kernels_refuse_images_past_32_bit_indices_before_reading_them() {
        // Their pixel indices (u32) or coordinates (i32) wrapped silently past the limits
        // (or the kernel indexed past its buffers). The shape alone is checked first: the
        // buffers here are empty, an image that size cannot be allocated in a test.
        use crate::matching::{gabor, hopfield, mcgm};
        let too_large = |w, h| {
            Err::<(), _>(CoreError::TooLarge {
                width: w,
                height: h,
                max_pixels: MAX_PIXELS,
            })
        };
        for (w, h) in TOO_LARGE {
            let img = Image {
                width: w,
                height: h,
                data: Vec::new(),
            };
            let ok = |r: Result<()>| assert_eq!(r, too_large(w, h), "{w}x{h}");
            let mp = mcgm::McgmParams::default();
            ok(mcgm::mcgm_match(&img, &img, &mp).map(|_| ()));
            ok(mcgm::image_curves(&img, &mp).map(|_| ()));
            // Reached alone through the binding (mcgm_filter).
            let r = mcgm::edge_filters(&img, &img, &[], &mp.filters, (0, 16));
            ok(r.map(|_| ()));
            let zc = mcgm::zerocross::ZeroCrossings {
                width: w,
                height: h,
                mark: Vec::new(),
                xsub: Vec::new(),
                strength: Vec::new(),
                theta: Vec::new(),
            };
            ok(mcgm::tracking::track(&zc, &mp.track).map(|_| ()));
            let hp = hopfield::HopfieldParams::default();
            ok(hopfield::hopfield_match(&img, &img, &hp).map(|_| ()));
            ok(hopfield::best_match(&img, &img, &hp).map(|_| ()));
            let gp = gabor::GaborParams::default();
            ok(gabor::gabor_disparity(&img, &img, &gp).map(|_| ()));
            // Reached alone through the binding (gabor_remove_speckles).
            ok(gabor::post::remove_speckles(&mut [], w, h, 1, 1.0));
            let rp = crate::refine::RefineParams::default();
            let r =
                crate::refine::refine_disparity(img.view(), img.view(), &[], &[], 0.0, 1.0, &rp);
            ok(r.map(|_| ()));
            // Its own, lower limit (two edge numbers a pixel).
            assert_eq!(
                crate::segment::graph_segments(&[], w, h, 1, 1.0, 1).map(|_| ()),
                Err(CoreError::TooLarge {
                    width: w,
                    height: h,
                    max_pixels: crate::segment::GRAPH_MAX_PIXELS,
                }),
                "{w}x{h}"
            );
            ok(crate::segment::quantised_regions(&[], w, h, 1, 8, 0).map(|_| ()));
        }
    }

    #[test]
    fn public_sub_stages_refuse_images_past_32_bit_indices() {
        // Public stages a Rust caller reaches alone (the binding checks the shape before
        // select_points): they held columns, rows or pixel numbers in u32 unchecked. On the
        // old code select_points and high_threshold returned Ok on these empty maps (or
        // panicked: `tile * w` overflowed), zero_crossings overflowed `w * h` or tried to
        // allocate the maps (16 GiB and more). Now TooLarge first, from the shape alone.
        use crate::matching::{hopfield, mcgm};
        for (w, h) in TOO_LARGE {
            let too_large = Err(CoreError::TooLarge {
                width: w,
                height: h,
                max_pixels: MAX_PIXELS,
            });
            let ip = hopfield::HopfieldParams::default().interest;
            let r = hopfield::interest::select_points(&[], w, h, &ip);
            assert_eq!(r.map(|_| ()), too_large, "select_points {w}x{h}");
            let zc = mcgm::zerocross::ZeroCrossings {
                width: w,
                height: h,
                mark: Vec::new(),
                xsub: Vec::new(),
                strength: Vec::new(),
                theta: Vec::new(),
            };
            let r = mcgm::tracking::high_threshold(&zc, 0.5);
            assert_eq!(r.map(|_| ()), too_large, "high_threshold {w}x{h}");
            let r = mcgm::zerocross::zero_crossings(&[], w, h);
            assert_eq!(r.map(|_| ()), too_large, "zero_crossings {w}x{h}");
        }
    }
}
