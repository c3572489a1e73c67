//! Foreground fattening at depth edges: the pixels a window matcher carried past an object's
//! outline (the fused dense map's step 7 and the members' edge check; NumPy reference:
//! `tests/reference/edges_ref.py`, bit-identical).
//!
//! Along each row, and along each column, a disparity jump of more than `jump` between
//! neighbours of the row-filled map (so across holes too) looks `radius` pixels either side for
//! the strongest intensity step of the guide image (the first of equal ones). If that step is at
//! least `ratio` times the step at the jump and lies on the background side, the pixels from the
//! jump up to it, on the foreground's side, are marked: the outline is there, and what lies
//! between is background that took the foreground's disparity.

use rayon::prelude::*;

use crate::alloc::{try_zeroed, ZeroBits};
use crate::error::{CoreError, Result};
use crate::fill::fill_row;

/// Thresholds of [`fattened`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FattenParams {
    /// Columns (rows) searched either side of a jump for the image's edge.
    pub radius: usize,
    /// How much stronger than the step at the jump the image's edge must be.
    pub ratio: f32,
    /// Smallest disparity difference between neighbours that is a jump (px).
    pub jump: f32,
}

/// The fattened pixels of a row-major `(h, w)` disparity map `d` (NaN = hole) with the grey
/// `guide` image of the same size: marked along the rows or along the columns (module docs).
/// Rows (and columns) run in parallel, each independent of the others. A failed allocation of
/// an image-sized buffer is [`OutOfMemory`](crate::CoreError::OutOfMemory) (a `vec!` aborted
/// the process); a `w x h` past `usize` is
/// [`InvalidParameter`](crate::CoreError::InvalidParameter) `shape`.
///
/// # Panics
/// If `d` or `guide` does not hold `w * h` values.
pub fn fattened(
    d: &[f32],
    guide: &[f32],
    w: usize,
    h: usize,
    p: &FattenParams,
) -> Result<Vec<bool>> {
    // Unchecked, the product wrapped: a debug build panicked, a release build took a
    // 2^32 x 2^32 shape with empty buffers as 0 pixels and returned an empty mask.
    let n = w
        .checked_mul(h)
        .ok_or_else(|| CoreError::param("shape", format!("{w} x {h} pixels overflow usize")))?;
    assert_eq!(d.len(), n, "d must hold w * h values");
    assert_eq!(guide.len(), n, "guide must hold w * h values");
    let mut out = try_zeroed::<bool>(n, "the fattened-edge check's marks")?;
    if w == 0 || h == 0 {
        return Ok(out);
    }
    mark_rows(d, guide, w, p, &mut out);
    // The columns: the same rule on the transposed map, marks transposed back.
    let what = "the fattened-edge check's transposed maps";
    let (dt, gt) = (transpose(d, w, h, what)?, transpose(guide, w, h, what)?);
    let mut cols = try_zeroed::<bool>(w * h, what)?;
    mark_rows(&dt, &gt, h, p, &mut cols);
    drop((dt, gt));
    for (o, c) in out.iter_mut().zip(transpose(&cols, h, w, what)?) {
        *o |= c;
    }
    Ok(out)
}

/// The `(w, h)` transpose of a row-major `(h, w)` map: bands of `TILE` output rows (input
/// columns) in parallel, each read row by row, so both sides stay in the cache.
fn transpose<T: ZeroBits + Send + Sync>(
    a: &[T],
    w: usize,
    h: usize,
    what: &'static str,
) -> Result<Vec<T>> {
    const TILE: usize = 32;
    let mut t = try_zeroed::<T>(w * h, what)?;
    t.par_chunks_mut(TILE * h)
        .enumerate()
        .for_each(|(b, band)| {
            let x0 = b * TILE;
            let n = band.len() / h;
            for (y, row) in a.chunks_exact(w).enumerate() {
                for (i, &v) in row[x0..x0 + n].iter().enumerate() {
                    band[i * h + y] = v;
                }
            }
        });
    Ok(t)
}

/// Marks the fattened pixels along the rows of width `w` into `out` (same layout).
fn mark_rows(d: &[f32], guide: &[f32], w: usize, p: &FattenParams, out: &mut [bool]) {
    if w < 3 {
        return;
    }
    out.par_chunks_mut(w)
        .zip(d.par_chunks(w).zip(guide.par_chunks(w)))
        .for_each_init(
            || {
                (
                    vec![0.0f32; w],
                    vec![0.0f32; w],
                    vec![0i32; w + 1],
                    vec![0.0f32; w],
                )
            },
            |(f, step, marks, scratch), (o, (dr, gr))| {
                mark_row(dr, gr, p, f, step, marks, scratch, o)
            },
        );
}

/// One row: `f`, `step`, `marks` and `scratch` are buffers of the row's length (`marks` one
/// more).
#[allow(clippy::too_many_arguments)]
fn mark_row(
    d: &[f32],
    g: &[f32],
    p: &FattenParams,
    f: &mut [f32],
    step: &mut [f32],
    marks: &mut [i32],
    scratch: &mut [f32],
    out: &mut [bool],
) {
    let w = d.len();
    f.copy_from_slice(d);
    fill_row(f, scratch);
    // step[x]: the intensity step between x - 1 and x (0 at x = 0).
    step[0] = 0.0;
    for x in 1..w {
        step[x] = (g[x] - g[x - 1]).abs();
    }
    marks.fill(0);
    // A radius beyond the row reaches its ends as the row's length does (the columns are
    // clipped): 2**31 px took minutes, and one of 2**63 or more wrapped to a negative isize.
    let r = p.radius.min(w) as isize;
    for j in 1..w {
        // NaN (a row with no value) is no jump.
        let is_jump = (f[j] - f[j - 1]).abs() > p.jump;
        if !is_jump {
            continue;
        }
        // The strongest step within the radius (columns clipped to [1, w - 1]; the first of
        // equal ones).
        let mut e = (j as isize - r).clamp(1, w as isize - 1) as usize;
        for t in -r..=r {
            let x = (j as isize + t).clamp(1, w as isize - 1) as usize;
            if step[x] > step[e] {
                e = x;
            }
        }
        let strong = step[e] >= p.ratio * step[j];
        if !strong {
            continue;
        }
        // Foreground on the right carried leftwards: [j, e) with e > j; on the left: [e, j).
        let (lo, hi) = if f[j] > f[j - 1] { (j, e) } else { (e, j) };
        if hi > lo {
            marks[lo] += 1;
            marks[hi] -= 1;
        }
    }
    let mut run = 0i32;
    for (o, &m) in out.iter_mut().zip(marks.iter()) {
        run += m;
        *o = run > 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: FattenParams = FattenParams {
        radius: 3,
        ratio: 2.0,
        jump: 2.0,
    };

    #[test]
    fn marks_the_foreground_carried_past_the_image_edge() {
        // Background 1 on columns 0-5, foreground 9 from column 3 on (carried 3 px left); the
        // image's edge lies between columns 5 and 6.
        let w = 10;
        let d: Vec<f32> = (0..w).map(|x| if x < 3 { 1.0 } else { 9.0 }).collect();
        let g: Vec<f32> = (0..w).map(|x| if x < 6 { 0.2 } else { 0.8 }).collect();
        let m = fattened(&d, &g, w, 1, &P).unwrap();
        let marked: Vec<usize> = (0..w).filter(|&x| m[x]).collect();
        assert_eq!(marked, vec![3, 4, 5]);
    }

    #[test]
    fn leaves_a_jump_on_the_image_edge_alone() {
        let w = 10;
        let d: Vec<f32> = (0..w).map(|x| if x < 6 { 1.0 } else { 9.0 }).collect();
        let g: Vec<f32> = (0..w).map(|x| if x < 6 { 0.2 } else { 0.8 }).collect();
        assert!(fattened(&d, &g, w, 1, &P).unwrap().iter().all(|&m| !m));
    }

    #[test]
    fn columns_are_checked_too() {
        // The same profile down a column of a 1-wide map.
        let h = 10;
        let d: Vec<f32> = (0..h).map(|y| if y < 3 { 1.0 } else { 9.0 }).collect();
        let g: Vec<f32> = (0..h).map(|y| if y < 6 { 0.2 } else { 0.8 }).collect();
        let m = fattened(&d, &g, 1, h, &P).unwrap();
        assert_eq!((0..h).filter(|&y| m[y]).collect::<Vec<_>>(), vec![3, 4, 5]);
    }

    #[test]
    fn a_radius_beyond_the_image_is_the_whole_row() {
        // It looped over every offset of the radius: 2**31 px took minutes on a 10 px row,
        // and a radius of 2**63 or more wrapped to a negative one.
        let w = 10;
        let d: Vec<f32> = (0..w).map(|x| if x < 3 { 1.0 } else { 9.0 }).collect();
        let g: Vec<f32> = (0..w).map(|x| if x < 6 { 0.2 } else { 0.8 }).collect();
        let whole = FattenParams { radius: w, ..P };
        let want = fattened(&d, &g, w, 1, &whole).unwrap();
        assert_eq!(
            (0..w).filter(|&x| want[x]).collect::<Vec<_>>(),
            vec![3, 4, 5]
        );
        for radius in [w + 1, 1 << 40, usize::MAX] {
            assert_eq!(
                fattened(&d, &g, w, 1, &FattenParams { radius, ..P }).unwrap(),
                want
            );
        }
    }

    #[test]
    fn a_shape_past_usize_is_an_error() {
        // w * h was unchecked: it panicked ("attempt to multiply with overflow") in a debug
        // build, and in release 2^32 x 2^32 wrapped to 0 pixels: an empty mask, Ok.
        for (w, h) in [(usize::MAX, 2), (1 << 32, 1 << 32), (2, usize::MAX / 2 + 1)] {
            let e = fattened(&[], &[], w, h, &P).unwrap_err();
            assert_eq!(
                e,
                CoreError::param("shape", format!("{w} x {h} pixels overflow usize"))
            );
        }
        assert_eq!(
            fattened(&[], &[], 1 << 32, 1 << 32, &P)
                .unwrap_err()
                .to_string(),
            "invalid parameter `shape`: 4294967296 x 4294967296 pixels overflow usize"
        );
        // At the edge of usize no overflow: an empty shape is an empty mask.
        assert_eq!(fattened(&[], &[], usize::MAX, 0, &P), Ok(Vec::new()));
    }

    #[test]
    fn a_transpose_too_large_to_allocate_is_an_error() {
        // It was a `vec!`: a failed allocation aborted the process.
        let e = transpose::<f32>(&[], 1 << 62, 2, "the test's transpose").unwrap_err();
        assert!(matches!(
            e,
            crate::CoreError::OutOfMemory {
                what: "the test's transpose",
                ..
            }
        ));
    }

    /// The rule along the rows written out plainly (`tests/reference/edges_ref.py`): the row
    /// filled (nearest finite value each side, the smaller; one side only: that one), a jump
    /// where neighbours differ by more than `jump`, the first strongest guide step among the
    /// columns `j - r ..= j + r` clipped to `[1, w - 1]`, and `[j, e)` or `[e, j)` marked.
    fn rows_brute(d: &[f32], g: &[f32], w: usize, h: usize, p: &FattenParams) -> Vec<bool> {
        let mut out = vec![false; w * h];
        if w < 3 {
            return out;
        }
        for y in 0..h {
            let (d, g) = (&d[y * w..(y + 1) * w], &g[y * w..(y + 1) * w]);
            let f: Vec<f32> = (0..w)
                .map(|x| {
                    if d[x].is_finite() {
                        return d[x];
                    }
                    let l = (0..x).rev().map(|i| d[i]).find(|v| v.is_finite());
                    let r = (x + 1..w).map(|i| d[i]).find(|v| v.is_finite());
                    match (l, r) {
                        (Some(a), Some(b)) => a.min(b),
                        (Some(a), None) | (None, Some(a)) => a,
                        (None, None) => f32::NAN,
                    }
                })
                .collect();
            let step = |x: usize| if x == 0 { 0.0 } else { (g[x] - g[x - 1]).abs() };
            let r = p.radius.min(w) as isize;
            for j in 1..w {
                // NaN (a row without values) is no jump.
                let is_jump = (f[j] - f[j - 1]).abs() > p.jump;
                if !is_jump {
                    continue;
                }
                let mut e = None;
                for t in -r..=r {
                    let x = (j as isize + t).clamp(1, w as isize - 1) as usize;
                    if e.is_none_or(|e| step(x) > step(e)) {
                        e = Some(x);
                    }
                }
                let e = e.expect("r >= 0");
                if step(e) >= p.ratio * step(j) {
                    let (lo, hi) = if f[j] > f[j - 1] { (j, e) } else { (e, j) };
                    for x in lo..hi {
                        out[y * w + x] = true;
                    }
                }
            }
        }
        out
    }

    /// Random maps (holes, infinite values, plateaus; guide steps in eighths, so equal steps
    /// occur) of several shapes against the plain rule on the rows and on the columns.
    #[test]
    fn marks_equal_the_plain_rule_on_random_maps() {
        let mut rng = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        let mut next = move |n: u64| rng() % n;
        let transpose = |a: &[f32], w: usize, h: usize| -> Vec<f32> {
            (0..w * h).map(|i| a[(i % h) * w + i / h]).collect()
        };
        let mut marked = 0;
        for (w, h) in [(23, 17), (17, 23), (2, 9), (3, 4), (1, 12), (40, 6)] {
            for _ in 0..6 {
                // Disparity: blocks of 1-6 equal values, a few holes and infinities.
                let mut d = Vec::with_capacity(w * h);
                let mut v = 1.0;
                for _ in 0..w * h {
                    if next(4) == 0 {
                        v = next(12) as f32 * 0.75;
                    }
                    d.push(match next(12) {
                        0 | 1 => f32::NAN,
                        2 => f32::INFINITY,
                        _ => v,
                    });
                }
                let g: Vec<f32> = (0..w * h).map(|_| next(9) as f32 / 8.0).collect();
                for radius in [0, 1, 3, 7, 40] {
                    for (ratio, jump) in [(1.0, 2.0), (0.5, 0.5), (2.0, 1.5), (1.5, 0.75)] {
                        let p = FattenParams {
                            radius,
                            ratio,
                            jump,
                        };
                        let rows = rows_brute(&d, &g, w, h, &p);
                        let cols = rows_brute(&transpose(&d, w, h), &transpose(&g, w, h), h, w, &p);
                        let want: Vec<bool> = (0..w * h)
                            .map(|i| rows[i] || cols[(i % w) * h + i / w])
                            .collect();
                        assert_eq!(fattened(&d, &g, w, h, &p).unwrap(), want, "{w}x{h} {p:?}");
                        marked += want.iter().filter(|&&m| m).count();
                    }
                }
            }
        }
        assert!(marked > 1000, "{marked}");
    }
}
