//! Depth from a rectified disparity map (algorithms.md E.3), with its predicted uncertainty.
//!
//! `Z = f B / (d + doffs)`, and `sigma_Z = Z sigma_d / (d + doffs)` (`dZ/dd = -Z / (d + doffs)`)
//! with `sigma_d = max(s0 + slope * clamp(conf, 0, 1), s_min)` predicted from the matcher's
//! confidence, or `s_fill` where the confidence is negative (a pixel the refinement filled: its
//! error spread is its own, not on the line). A pixel whose `d + doffs` is not above its
//! `sigma_d` gets no depth: its one-sigma interval reaches infinite depth, so the value says
//! nothing (ETH3D playground: 4880 pixels at 0-1 px, depths up to 56 km for GT of 2-12 m, the
//! dense map's depth RMSE 4066 % -> 31.5 %). One parallel pass in f32: the NumPy form (`tests/reference/depth_ref.py`, the same
//! operations in the same order) allocates and walks half a dozen full-size temporaries, a tenth
//! of a live frame at VGA.

use crate::alloc::try_zeroed;
use crate::error::{CoreError, Result};
use crate::image::check_map_pair;
use crate::parallel::for_each_row2;

/// Disparity uncertainty model (px): `sigma_d(conf) = max(s0 + slope * clamp(conf, 0, 1), s_min)`
/// for `conf >= 0`, `s_fill` for a negative `conf` (a filled pixel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SigmaModel {
    pub s0: f32,
    pub slope: f32,
    pub s_min: f32,
    pub s_fill: f32,
}

/// [`depth_rectified`]'s scalar parameters alone, so a binding can check them before it
/// copies the maps (a broadcast 65536 x 65536 map was a 16 GiB copy before a NaN `fb` was said).
pub fn check_params(fb: f32, doffs: f32, sigma: SigmaModel) -> Result<()> {
    for (name, v) in [
        ("fb", fb),
        ("doffs", doffs),
        ("s0", sigma.s0),
        ("slope", sigma.slope),
        ("s_min", sigma.s_min),
        ("s_fill", sigma.s_fill),
    ] {
        if !v.is_finite() {
            return Err(CoreError::param(name, format!("must be finite, got {v}")));
        }
    }
    // A sigma of zero or below made every pixel's sigma_d (hence its depth sigma) <= 0.
    for (name, v) in [("fb", fb), ("s_min", sigma.s_min), ("s_fill", sigma.s_fill)] {
        if v <= 0.0 {
            return Err(CoreError::param(name, format!("must be > 0, got {v}")));
        }
    }
    Ok(())
}

/// `(depth, sigma)` of a `w` x `h` rectified disparity map: `fb = f B` (px times the output
/// unit), `doffs` the principal-point offset (px). NaN where the disparity is not finite, where
/// `d + doffs <= sigma_d` (or `<= 0`), or where the depth is not finite.
pub fn depth_rectified(
    disp: &[f32],
    conf: &[f32],
    w: usize,
    h: usize,
    fb: f32,
    doffs: f32,
    sigma: SigmaModel,
) -> Result<(Vec<f32>, Vec<f32>)> {
    check_map_pair(disp, conf, w, h)?;
    check_params(fb, doffs, sigma)?;
    let n = w * h;
    // Checked: a failed `vec!` aborted the process.
    let mut depth = try_zeroed::<f32>(n, "the depth map")?;
    let mut sig = try_zeroed::<f32>(n, "the depth sigma map")?;
    if n == 0 {
        return Ok((depth, sig));
    }
    for_each_row2(&mut depth, &mut sig, w, |y, zrow, srow| {
        let (d, c) = (&disp[y * w..(y + 1) * w], &conf[y * w..(y + 1) * w]);
        for x in 0..w {
            let denom = d[x] + doffs;
            let z = fb / denom;
            // A NaN confidence counts as 0 (it got s_min, the smallest sigma, through `max`).
            let cx = if c[x].is_nan() { 0.0 } else { c[x] };
            let sd = if cx < 0.0 {
                sigma.s_fill
            } else {
                (sigma.s0 + sigma.slope * cx.clamp(0.0, 1.0)).max(sigma.s_min)
            };
            // An infinite disparity gave the depth 0 and sigma 0: a point on the camera.
            let ok = denom.is_finite() && denom > 0.0 && denom > sd && z.is_finite();
            zrow[x] = if ok { z } else { f32::NAN };
            srow[x] = if ok { z * sd / denom } else { f32::NAN };
        }
    });
    Ok((depth, sig))
}

#[cfg(test)]
mod tests {
    use super::*;

    const M: SigmaModel = SigmaModel {
        s0: 0.74,
        slope: -0.52,
        s_min: 0.2,
        s_fill: 0.9,
    };

    #[test]
    fn depth_and_sigma_on_a_few_pixels() {
        // f B = 50 (500 px, 0.1 m), doffs 2 px.
        let disp = [8.0, f32::NAN, -2.0, -5.0, 3.0, 48.0, 8.0, 8.0];
        let conf = [1.0, 1.0, 0.5, 0.5, 0.0, 2.0, -1.0, 0.5];
        let (z, s) = depth_rectified(&disp, &conf, 4, 2, 50.0, 2.0, M).unwrap();
        assert_eq!(z[0], 5.0);
        assert!((s[0] - 5.0 * 0.22 / 10.0).abs() < 1e-7);
        assert!(z[1].is_nan() && z[2].is_nan() && z[3].is_nan());
        assert!(s[1].is_nan() && s[2].is_nan() && s[3].is_nan());
        assert_eq!(z[4], 10.0);
        assert!(
            (s[4] - 10.0 * 0.74 / 5.0).abs() < 1e-6,
            "confidence 0: sigma_d 0.74"
        );
        assert!(
            (s[5] - 1.0 * 0.22 / 50.0).abs() < 1e-7,
            "confidence clamped to 1"
        );
        assert!((s[6] - 5.0 * 0.9 / 10.0).abs() < 1e-7, "negative: a fill");
        assert!((s[7] - 5.0 * 0.48 / 10.0).abs() < 1e-7);
    }

    #[test]
    fn no_depth_for_an_infinite_disparity() {
        // +inf gave the depth 0 and sigma 0 (a point on the camera), as a finite 1e30 does not.
        let disp = [f32::INFINITY, f32::NEG_INFINITY, 1e30, 8.0];
        let (z, s) = depth_rectified(&disp, &[0.5; 4], 4, 1, 50.0, 2.0, M).unwrap();
        assert!(z[0].is_nan() && s[0].is_nan() && z[1].is_nan() && s[1].is_nan());
        assert!(z[2] > 0.0 && z[2] < 1e-28);
        assert_eq!(z[3], 5.0);
    }

    #[test]
    fn no_depth_where_the_disparity_is_within_its_sigma() {
        // doffs 0: sigma_d 0.74 at confidence 0, 0.22 at 1, 0.9 for a fill.
        let disp = [0.7, 0.8, 0.2, 0.25, 0.9, 0.95];
        let conf = [0.0, 0.0, 1.0, 1.0, -1.0, -1.0];
        let (z, s) = depth_rectified(&disp, &conf, 6, 1, 50.0, 0.0, M).unwrap();
        for i in [0, 2, 4] {
            assert!(z[i].is_nan() && s[i].is_nan(), "pixel {i}");
        }
        for i in [1, 3, 5] {
            assert_eq!(z[i], 50.0 / disp[i]);
            assert!(s[i] < z[i], "pixel {i}: sigma below the depth");
        }
    }

    #[test]
    fn rejects_bad_calibration_and_shapes() {
        assert!(depth_rectified(&[1.0; 4], &[1.0; 4], 2, 2, 0.0, 0.0, M).is_err());
        assert!(depth_rectified(&[1.0; 4], &[1.0; 4], 2, 2, f32::NAN, 0.0, M).is_err());
        assert!(depth_rectified(&[1.0; 4], &[1.0; 3], 2, 2, 1.0, 0.0, M).is_err());
    }

    #[test]
    fn rejects_bad_sigma_models() {
        let bad = [
            ("s0", SigmaModel { s0: f32::NAN, ..M }),
            (
                "slope",
                SigmaModel {
                    slope: f32::INFINITY,
                    ..M
                },
            ),
            (
                "s_min",
                SigmaModel {
                    s_min: f32::NAN,
                    ..M
                },
            ),
            ("s_min", SigmaModel { s_min: -0.2, ..M }),
            ("s_min", SigmaModel { s_min: 0.0, ..M }),
            ("s_fill", SigmaModel { s_fill: -0.9, ..M }),
            (
                "s_fill",
                SigmaModel {
                    s_fill: f32::NAN,
                    ..M
                },
            ),
        ];
        for (name, m) in bad {
            match depth_rectified(&[8.0; 4], &[0.5; 4], 2, 2, 50.0, 0.0, m) {
                Err(CoreError::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                other => panic!("{name}: {other:?}"),
            }
        }
        // A negative s0 alone is fine: s_min bounds sigma_d from below.
        let (_, s) = depth_rectified(
            &[8.0],
            &[0.0],
            1,
            1,
            50.0,
            0.0,
            SigmaModel { s0: -1.0, ..M },
        )
        .unwrap();
        assert!((s[0] - 6.25 * 0.2 / 8.0).abs() < 1e-7);
    }

    #[test]
    fn a_nan_confidence_counts_as_zero() {
        // It got s_min (0.2), the smallest sigma; confidence 0 gives s0 = 0.74.
        let (z, s) = depth_rectified(&[8.0, 8.0], &[f32::NAN, 0.0], 2, 1, 50.0, 2.0, M).unwrap();
        assert_eq!(z[0], 5.0);
        assert_eq!(s[0], s[1]);
        assert!((s[0] - 5.0 * 0.74 / 10.0).abs() < 1e-7);
    }

    /// A depth that overflows `f32` (a huge `f B` over a small disparity) is no depth, though
    /// the disparity itself passes its sigma test.
    #[test]
    fn no_depth_where_the_depth_overflows() {
        let (z, s) = depth_rectified(&[0.5, 4.0], &[1.0, 1.0], 2, 1, f32::MAX, 0.0, M).unwrap();
        assert!(z[0].is_nan() && s[0].is_nan(), "{} {}", z[0], s[0]);
        assert_eq!(z[1], f32::MAX / 4.0);
    }
}
