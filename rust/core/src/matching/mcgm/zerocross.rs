//! Zero crossings of the LoG response, one pixel thick, with sub-pixel x, strength and
//! orientation (algorithms.md B.4 steps 2-3, B.8's reading for vertical-only marks).

use std::f32::consts::TAU;

use rayon::prelude::*;

use crate::alloc::{try_filled, try_zeroed};
use crate::error::Result;
use crate::parallel::ROWS_PER_TASK;
use crate::simd::simd_fn;

/// Names the crossing planes in an out-of-memory error.
const WHAT: &str = "a zero-crossing plane of the MCGM matcher";
/// What a band's candidate columns are called in an [`OutOfMemory`](crate::CoreError::OutOfMemory).
const ROW_SCRATCH: &str = "a zero-crossing row buffer of the MCGM matcher";

/// Mark bit: the pixel holds a crossing found by the horizontal scan (along x).
pub const ZC_H: u8 = 1;
/// Mark bit: the pixel holds a crossing found by the vertical scan (along y).
pub const ZC_V: u8 = 2;
/// Crossings with `|grad L|` below this are dropped: in flat areas the sign of `L` is float
/// rounding noise (gradients ~1e-7), while one 8-bit grey step already gives ~1e-4. Without the
/// floor, thousands of phantom crossings would set the strength percentile (`t_high`) and make
/// the marks depend on the summation order of the filter.
pub const MIN_STRENGTH: f32 = 1e-5;
/// Largest Newton step `-L / L_x` accepted for a vertical-only mark (px): further than one pixel
/// the linear model of `L` is not trusted and the pixel centre is kept.
const MAX_NEWTON_STEP: f32 = 1.0;

/// Zero-crossing maps of one LoG response (row-major, `w * h`).
#[derive(Debug, Clone, PartialEq)]
pub struct ZeroCrossings {
    pub width: usize,
    pub height: usize,
    /// `ZC_H | ZC_V` bits, 0 = no crossing.
    pub mark: Vec<u8>,
    /// Sub-pixel x of the crossing (absolute column), NaN where unmarked.
    pub xsub: Vec<f32>,
    /// `|grad L|` by central differences at marked pixels, 0 elsewhere; [`f32::NAN`] (those
    /// bits) where it is NaN.
    pub strength: Vec<f32>,
    /// Normal direction `atan2(L_y, L_x)` in `[0, 2 pi)` at marked pixels (polarity kept), 0 else.
    pub theta: Vec<f32>,
}

impl ZeroCrossings {
    /// Indices of the marked pixels, raster order.
    pub fn marked(&self) -> impl Iterator<Item = usize> + '_ {
        self.mark
            .iter()
            .enumerate()
            .filter(|(_, &m)| m != 0)
            .map(|(i, _)| i)
    }
}

/// Finds the crossings of `l` (`w x h`). Only interior pixels (1 px from the border) are marked,
/// so the central differences are always defined.
///
/// Rows in parallel bands: every value of row `y` is a function of the LoG rows `y - 1..=y + 1`
/// alone (the vertical scan's marks on row `y` come from the pairs `(y - 1, y)` and `(y, y + 1)`),
/// so the maps are the same whatever the split.
///
/// An image past [`crate::image::check_index_range`] is [`crate::CoreError::TooLarge`].
pub fn zero_crossings(l: &[f32], w: usize, h: usize) -> Result<ZeroCrossings> {
    // Candidate columns are u32 (and `w * h` was unchecked): refused first, not wrapped.
    crate::image::check_index_range(w, h)?;
    let n = w * h;
    let mut mark = try_zeroed::<u8>(n, WHAT)?;
    let mut xsub = try_filled(n, f32::NAN, WHAT)?;
    let mut strength = try_zeroed::<f32>(n, WHAT)?;
    let mut theta = try_zeroed::<f32>(n, WHAT)?;
    // (Images narrower or lower than 3 pixels have no interior: nothing is marked.)
    if w >= 3 && h >= 3 {
        // A band's row scratch (4 bytes a column) allocated checked: a `vec!` aborted the
        // process. The first failure is recorded and the maps are then not returned.
        let failed = std::sync::Mutex::new(None);
        let band = w * ROWS_PER_TASK;
        mark.par_chunks_mut(band)
            .zip(xsub.par_chunks_mut(band))
            .zip(
                strength
                    .par_chunks_mut(band)
                    .zip(theta.par_chunks_mut(band)),
            )
            .enumerate()
            .for_each(|(b, ((mk, xs), (st, th)))| {
                let mut cand = match try_zeroed::<u32>(w + 1, ROW_SCRATCH) {
                    Ok(c) => c,
                    Err(e) => {
                        let mut f = failed.lock().unwrap_or_else(|p| p.into_inner());
                        f.get_or_insert(e);
                        return;
                    }
                };
                let rows = mk
                    .chunks_mut(w)
                    .zip(xs.chunks_mut(w))
                    .zip(st.chunks_mut(w).zip(th.chunks_mut(w)));
                for (k, ((mk, xs), (st, th))) in rows.enumerate() {
                    let y = b * ROWS_PER_TASK + k;
                    if y >= 1 && y + 1 < h {
                        crossings_row(l, w, y, &mut cand, mk, xs, st, th);
                    }
                }
            });
        if let Some(e) = failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
            return Err(e);
        }
    }
    Ok(ZeroCrossings {
        width: w,
        height: h,
        mark,
        xsub,
        strength,
        theta,
    })
}

simd_fn! {
/// Row `y` (interior: `1 <= y < h - 1`, `w >= 3`) of [`zero_crossings`]' maps, written into the
/// row slices (`cand`: scratch of `w + 1`). Compiled for AVX2 too, used where the CPU has it:
/// the per-pixel loops take fewer, wider instructions; the operations are the same IEEE ones
/// (Rust contracts nothing into FMA), so are the maps.
fn crossings_row(
    l: &[f32],
    w: usize,
    y: usize,
    cand: &mut [u32],
    mark: &mut [u8],
    xsub: &mut [f32],
    strength: &mut [f32],
    theta: &mut [f32],
) {
    // Horizontal scan: the crossing between p and p + (1, 0) is marked on the pixel with the
    // smaller |L| (ties: p); a pixel with L = 0 exactly is marked if its neighbours differ in sign.
    // Candidate positions first (sign change or an exact zero), then the rule at those
    // positions only, in the same order. The positions are listed by a branch-free compaction:
    // about a third of the pixels are crossings, so a test per pixel is often mispredicted.
    let flags = |cand: &mut [u32], a: &[f32], b: &[f32], from: usize| -> usize {
        let mut c = 0;
        for (x, (&a, &b)) in a.iter().zip(b).enumerate().skip(from) {
            cand[c] = x as u32;
            c += usize::from((a * b < 0.0) | (a == 0.0));
        }
        c
    };
    let row = &l[y * w..(y + 1) * w];
    let nc = flags(cand, &row[..w - 1], &row[1..], 0);
    for &x in &cand[..nc] {
        let x = x as usize;
        let (a, b) = (row[x], row[x + 1]);
        let (px, pos) = if a * b < 0.0 {
            let px = if a.abs() <= b.abs() { x } else { x + 1 };
            (px, x as f32 + a / (a - b))
        } else if a == 0.0 && x >= 1 && row[x - 1] * b < 0.0 {
            (x, x as f32)
        } else {
            continue;
        };
        if px < 1 || px + 1 >= w {
            continue;
        }
        // Two crossings on one pixel (both neighbours): keep the nearer one.
        if mark[px] & ZC_H == 0 || (pos - px as f32).abs() < (xsub[px] - px as f32).abs() {
            xsub[px] = pos;
        }
        mark[px] |= ZC_H;
    }
    // Vertical scan, the same rule along y: the pair (y - 1, y) marks this row when its
    // crossing is nearer here; the pair (y, y + 1) when nearer here (ties: here), or when this
    // pixel is an exact zero between opposite signs.
    let (up, down) = (&l[(y - 1) * w..y * w], &l[(y + 1) * w..(y + 2) * w]);
    for x in 1..w - 1 {
        let (u, c, d) = (up[x], row[x], down[x]);
        // (`u * c < 0` holds for no NaN: there `>` is the negation of the scan's `<=`.)
        let from_above = u * c < 0.0 && u.abs() > c.abs();
        let from_below = if c * d < 0.0 {
            c.abs() <= d.abs()
        } else {
            c == 0.0 && u * d < 0.0
        };
        mark[x] |= ZC_V * u8::from(from_above | from_below);
    }
    let mut c = 0;
    for (x, &m) in mark.iter().enumerate() {
        cand[c] = x as u32;
        c += usize::from(m != 0);
    }
    for &x in &cand[..c] {
        let x = x as usize;
        let i = y * w + x;
        let gx = 0.5 * (l[i + 1] - l[i - 1]);
        let gy = 0.5 * (l[i + w] - l[i - w]);
        let st = (gx * gx + gy * gy).sqrt();
        if st < MIN_STRENGTH {
            mark[x] = 0;
            xsub[x] = f32::NAN;
            continue;
        }
        // A NaN (an infinite LoG next to the pixel: inf - inf) stored as the one quiet NaN: an
        // operation's NaN has no set sign or payload (x86's own is negative), and the AVX2 and
        // baseline builds order `gx * gx + gy * gy`'s operands as they like; `strength` is
        // returned (`mcgm_curves`), so both must give the same bits.
        strength[x] = if st.is_nan() { f32::NAN } else { st };
        let t = gy.atan2(gx);
        // `(t + TAU) % TAU` without the fmod call: u = t + TAU lies in [pi, TAU], and
        // u - TAU is exact there (Sterbenz).
        theta[x] = if t < 0.0 {
            let u = t + TAU;
            if u >= TAU {
                u - TAU
            } else {
                u
            }
        } else {
            t
        };
        if mark[x] & ZC_H == 0 {
            // Vertical-only mark: x from the horizontal crossing next to it, else a Newton step.
            let left = x as f32 - 1.0 + l[i - 1] / (l[i - 1] - l[i]);
            let right = x as f32 + l[i] / (l[i] - l[i + 1]);
            xsub[x] = if l[i - 1] * l[i] < 0.0 {
                left
            } else if l[i] * l[i + 1] < 0.0 {
                right
            } else if gx != 0.0 && (l[i] / gx).abs() <= MAX_NEWTON_STEP {
                x as f32 - l[i] / gx
            } else {
                x as f32
            };
        }
    }
}
}

#[cfg(test)]
mod tests {
    //! `crossings_row` as dispatched (its AVX2 build on a CPU that has AVX2) against the
    //! pixel-by-pixel rule of the channel's tests (plain scalar code, baseline x86-64), on values
    //! real scenes do not hold: NaN of either sign, infinities, signed zeros, denormals, exact ties.
    use super::*;
    use crate::matching::mcgm::tests::zero_crossings_reference;

    #[test]
    fn dispatched_crossings_equal_the_baseline_build_bit_for_bit() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let specials = [
            0.0,
            -0.0,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e-40,
            -1e-40,
            f32::MIN_POSITIVE,
            f32::MAX,
            -f32::MAX,
            1.0,
            -1.0,
            1e-5,
            -1e-5,
            f32::from_bits(1),
        ];
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let (mut n_marked, mut n_nan) = (0, 0);
        for (k, &(w, h)) in [
            (3, 3),
            (1, 9),
            (9, 1),
            (2, 2),
            (4, 5),
            (17, 9),
            (33, 7),
            (67, 13),
        ]
        .iter()
        .enumerate()
        {
            for mode in 0..4 {
                let l: Vec<f32> = (0..w * h)
                    .map(|_| {
                        let r = next();
                        let u = (r >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
                        match mode {
                            // Random bit patterns (every class of value), specials among
                            // small values, few levels (exact zeros and ties), smooth values.
                            0 => f32::from_bits(r as u32),
                            1 if r % 3 == 0 => specials[(r >> 8) as usize % specials.len()],
                            1 => u * 1e-4,
                            2 => ((r >> 8) % 5) as f32 - 2.0,
                            _ => u,
                        }
                    })
                    .collect();
                let new = zero_crossings(&l, w, h).unwrap();
                let old = zero_crossings_reference(&l, w, h);
                let what = format!("{w}x{h} mode {mode} case {k}");
                assert_eq!(new.mark, old.mark, "{what}");
                assert_eq!(bits(&new.xsub), bits(&old.xsub), "{what} xsub");
                assert_eq!(bits(&new.strength), bits(&old.strength), "{what} strength");
                for s in new.strength.iter().filter(|s| s.is_nan()) {
                    assert_eq!(s.to_bits(), f32::NAN.to_bits(), "{what} NaN strength");
                    n_nan += 1;
                }
                assert_eq!(bits(&new.theta), bits(&old.theta), "{what} theta");
                n_marked += new.mark.iter().filter(|&&m| m != 0).count();
            }
        }
        assert!(
            n_marked > 300 && n_nan > 10,
            "{n_marked} marked, {n_nan} NaN strengths"
        );
    }
}
