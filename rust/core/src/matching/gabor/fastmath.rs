//! Branch-free `atan2`, `sincos` and `ln` polynomials for the per-pixel loops.
//!
//! The libm versions are calls that block vectorisation and dominated the pointwise Newton step;
//! these are written with selects only (no branches, no calls) so whole rows vectorise. Accuracy:
//! atan2 ~1e-5 rad, sincos ~1e-6, ln ~1e-6 -- far below the phase noise of real images (1e-5 rad
//! of phase is 6e-6 px of disparity at F = 1/4).

use std::f32::consts::{FRAC_2_PI, FRAC_PI_2, LN_2, PI};

/// 1.5 * 2^23: adding and subtracting it rounds an f32 of magnitude < 2^22 to the nearest integer
/// with plain SSE2 arithmetic (`f32::round` is a libm call on baseline x86-64).
const ROUND_MAGIC: f32 = 12_582_912.0;

/// Nearest integer (ties to even) for `|x| < 2^22`.
#[inline(always)]
pub fn round_fast(x: f32) -> f32 {
    (x + ROUND_MAGIC) - ROUND_MAGIC
}

/// Largest integer `<= x` for `|x| < 2^22`.
#[inline(always)]
pub fn floor_fast(x: f32) -> f32 {
    let r = round_fast(x);
    if r > x {
        r - 1.0
    } else {
        r
    }
}

/// `atan2(y, x)` in `[-pi, pi]`, max error about 1e-5 rad; `atan2(0, 0) = 0`.
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let ax = x.abs();
    let ay = y.abs();
    let mx = ax.max(ay);
    let mn = ax.min(ay);
    let a = if mx > 0.0 { mn / mx } else { 0.0 };
    let s = a * a;
    let p = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46
                    + s * (-0.116_432_87 + s * (0.052_653_32 + s * -0.011_721_2)))));
    let r = if ay > ax { FRAC_PI_2 - p } else { p };
    let r = if x < 0.0 { PI - r } else { r };
    if y < 0.0 {
        -r
    } else {
        r
    }
}

/// `(sin x, cos x)` for `|x| < 4e6`, max error about 1e-6 for moderate arguments (measured:
/// 2e-7 up to `|x|` = 1e4, 1e-6 at 1e5, but 3e-2 at 1e6 and 0.12 at 4e6: the two-term split of
/// pi/2 is exact only below about 1.3e5).
#[inline(always)]
pub fn sincos(x: f32) -> (f32, f32) {
    // Reduce to r in [-pi/4, pi/4] and a quadrant q (Cody-Waite split of pi/2).
    let t = x * FRAC_2_PI + ROUND_MAGIC;
    let q = t - ROUND_MAGIC;
    // The low mantissa bits of `t` hold `q` modulo 2^22 (two's complement): the quadrant
    // without a float-to-int conversion, which kept this loop from vectorising.
    let qi = t.to_bits();
    let r = (x - q * 1.570_312_5) - q * 4.838_268e-4;
    let r2 = r * r;
    let s = r * (1.0 + r2 * (-0.166_666_55 + r2 * (0.008_332_161 + r2 * -0.000_195_152_96)));
    let c = 1.0 + r2 * (-0.5 + r2 * (0.041_666_42 + r2 * (-0.001_388_676_4 + r2 * 2.443_315_7e-5)));
    let swap = qi & 1 != 0;
    let (a, b) = if swap { (c, s) } else { (s, c) };
    let a = if qi & 2 != 0 { -a } else { a };
    let b = if qi.wrapping_add(1) & 2 != 0 { -b } else { b };
    (a, b)
}

/// Natural log of a positive normal `x` (no check), max error about 1e-6.
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    let bits = x.to_bits() as i32;
    // Split x = m 2^e with m in [sqrt(1/2), sqrt(2)).
    let e0 = ((bits >> 23) & 0xff) - 127;
    let m0 = f32::from_bits(((bits & 0x007f_ffff) | 0x3f80_0000) as u32);
    let big = m0 > std::f32::consts::SQRT_2;
    let m = if big { m0 * 0.5 } else { m0 };
    let e = if big { e0 + 1 } else { e0 };
    let u = (m - 1.0) / (m + 1.0);
    let u2 = u * u;
    let lm = 2.0 * u * (1.0 + u2 * (1.0 / 3.0 + u2 * (0.2 + u2 * (1.0 / 7.0 + u2 / 9.0))));
    e as f32 * LN_2 + lm
}

#[cfg(test)]
mod tests {
    #[test]
    fn atan2_matches_std() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            let t = i as f32 * 0.0131 - 13.0;
            for r in [1e-3f32, 0.7, 3.0] {
                let (y, x) = (r * t.sin(), r * t.cos());
                let d = (super::atan2(y, x) - y.atan2(x)).abs();
                worst = worst.max(d.min((d - 2.0 * std::f32::consts::PI).abs()));
            }
        }
        assert!(worst < 2e-5, "worst {worst}");
        assert_eq!(super::atan2(0.0, 0.0), 0.0);
    }

    #[test]
    fn sincos_matches_std() {
        for i in 0..20000 {
            let x = i as f32 * 0.0173 - 170.0;
            let (s, c) = super::sincos(x);
            assert!((s - x.sin()).abs() < 3e-6, "sin {x}");
            assert!((c - x.cos()).abs() < 3e-6, "cos {x}");
        }
    }

    #[test]
    fn ln_and_rounding_match_std() {
        for i in 1..5000 {
            let x = i as f32 * 0.37e-3 * (i as f32).powf(1.7);
            assert!(
                (super::ln(x) - x.ln()).abs() < 2e-6 * x.ln().abs().max(1.0),
                "ln {x}"
            );
        }
        for v in [-2.5f32, -1.2, -0.5, 0.0, 0.49, 0.5, 1.5, 3.7, 1e5 + 0.3] {
            assert_eq!(super::floor_fast(v), v.floor(), "floor {v}");
        }
        assert_eq!(super::round_fast(2.4), 2.0);
        assert_eq!(super::round_fast(-2.6), -3.0);
    }

    #[test]
    fn atan2_within_its_bound_in_every_quadrant_at_every_scale() {
        use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        // Documented: about 1e-5 rad; measured 2e-6 for any magnitude, bound at twice that so a
        // changed coefficient shows.
        let mut worst = 0.0f64;
        for i in 0..20_000 {
            let t = i as f32 * 3.2e-4 - 3.2;
            for r in [1e-30f32, 1e-3, 1.0, 1e30] {
                let (y, x) = (r * t.sin(), r * t.cos());
                let d = (super::atan2(y, x) as f64 - (y as f64).atan2(x as f64)).abs();
                worst = worst.max(d.min((d - 2.0 * std::f64::consts::PI).abs()));
                // Odd in y, exactly.
                if y != 0.0 {
                    assert_eq!(super::atan2(-y, x), -super::atan2(y, x));
                }
            }
        }
        assert!(worst < 4e-6, "worst {worst}");
        // The axes and diagonals as std gives them (pi, not -pi, on the negative x axis).
        assert_eq!(super::atan2(0.0, 2.0), 0.0);
        assert_eq!(super::atan2(0.0, -2.0), PI);
        assert_eq!(super::atan2(2.0, 0.0), FRAC_PI_2);
        assert_eq!(super::atan2(-2.0, 0.0), -FRAC_PI_2);
        assert!((super::atan2(1.0, 1.0) - FRAC_PI_4).abs() < 1e-5);
        assert!((super::atan2(-1.0, -1.0) + 3.0 * FRAC_PI_4).abs() < 1e-5);
    }

    #[test]
    fn sincos_within_its_bound_for_moderate_arguments() {
        use std::f32::consts::FRAC_PI_2;
        // Measured: under 2.2e-7 for |x| <= 1e4, 1.1e-6 at 1e5 (the two-term split of pi/2 stops
        // being exact above about 1.3e5). The kernel's arguments are phases of a few thousand.
        let mut worst = 0.0f64;
        let mut check = |x: f32| {
            let (s, c) = super::sincos(x);
            let d = (s as f64 - (x as f64).sin())
                .abs()
                .max((c as f64 - (x as f64).cos()).abs());
            worst = worst.max(d);
        };
        for i in 0..=100_000 {
            check((i as f32 / 50_000.0 - 1.0) * 1e4);
        }
        // Either side of each quadrant boundary, where the quadrant bits change.
        for k in -200..=200 {
            let b = k as f32 * FRAC_PI_2;
            for e in [-1e-3f32, -1e-6, 0.0, 1e-6, 1e-3, 0.7, -0.7] {
                check(b + e);
            }
        }
        assert!(worst < 1e-6, "worst {worst}");
        assert_eq!(super::sincos(0.0), (0.0, 1.0));
    }

    #[test]
    fn ln_within_its_bound_over_every_normal_exponent() {
        use std::f32::consts::{LN_2, SQRT_2};
        // Documented: about 1e-6 (relative to max(|ln x|, 1); measured 1.2e-7).
        for e in -126..=127 {
            for k in 0..200 {
                let x = 2f32.powi(e) * (1.0 + k as f32 / 200.0);
                if !x.is_normal() {
                    continue;
                }
                let want = (x as f64).ln();
                let d = (super::ln(x) as f64 - want).abs();
                assert!(d < 1e-6 * want.abs().max(1.0), "ln {x}: {d}");
            }
        }
        // Exact where the polynomial term is zero; continuous across the sqrt(2) fold.
        assert_eq!(super::ln(1.0), 0.0);
        assert_eq!(super::ln(2.0), LN_2);
        assert_eq!(super::ln(0.25), -2.0 * LN_2);
        for x in [
            SQRT_2,
            f32::from_bits(SQRT_2.to_bits() + 1),
            f32::from_bits(SQRT_2.to_bits() - 1),
        ] {
            assert!(
                (super::ln(x) as f64 - (x as f64).ln()).abs() < 1e-7,
                "ln {x}"
            );
        }
    }

    #[test]
    fn round_and_floor_fast_are_std_over_their_range() {
        // Ties to even, both signs.
        for (v, r) in [
            (0.5f32, 0.0f32),
            (1.5, 2.0),
            (2.5, 2.0),
            (-0.5, 0.0),
            (-1.5, -2.0),
            (-2.5, -2.0),
        ] {
            assert_eq!(super::round_fast(v), r, "round {v}");
        }
        // Integers, halves and fractions up to 2^22 either side.
        let mut v = 0.25f32;
        while v < 4_194_000.0 {
            for x in [
                v,
                -v,
                v.floor(),
                -v.floor(),
                v + 0.5,
                -(v + 0.5),
                v.floor() + 0.5,
            ] {
                assert_eq!(super::floor_fast(x), x.floor(), "floor {x}");
                assert_eq!(super::round_fast(x), x.round_ties_even(), "round {x}");
            }
            v = v * 1.37 + 0.11;
        }
        assert_eq!(super::floor_fast(4_194_303.5), 4_194_303.0);
        assert_eq!(super::floor_fast(-4_194_303.5), -4_194_304.0);
    }
}
