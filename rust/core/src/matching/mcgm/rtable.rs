//! Generalized-Hough R-tables of segments and the GHT comparison of two segments
//! (algorithms.md B.4 steps 6 and 8, with B.8's normalisation by `max(|A|, |A'|)`).
//!
//! The R-table of a segment `A` holds, per orientation bin, the vectors `r = c_A - p` from its
//! pixels `p` to its centroid. Comparing `A'` with `A`: every pixel `q` of `A'` and every `r` in
//! the bins `b(theta_q) +- tol` predict the reference point `q + r`, i.e. the translation
//! `t = c_A - (q + r) = p - q`. Because `p - q` is a difference of integer pixel positions, the
//! votes fall exactly into 1-px cells: the kernel votes with the integer positions stored beside
//! the vectors (bit-identical to rounding the float prediction).

use std::f64::consts::TAU;

use super::tracking::Segment;
use crate::alloc::{try_collect, try_filled, try_zeroed};
use crate::error::Result;

/// R-table of one segment in CSR form over `n_bins` orientation bins.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RTable {
    /// `offsets[b]..offsets[b + 1]` index the entries of bin `b` (`n_bins + 1` values).
    pub offsets: Vec<u32>,
    /// `r = c - p` per entry (px).
    pub vecs: Vec<(f32, f32)>,
    /// The pixel `p` of each entry (integer `(x, y)`), used for exact voting.
    pub px: Vec<(i32, i32)>,
}

/// Orientation bin `floor(K theta / 2 pi)` of a normal direction in `[0, 2 pi)`.
#[inline]
pub fn theta_bin(theta: f32, n_bins: usize) -> usize {
    // floor(theta n / 2 pi) of the rounded f64 quotient. A product by 1 / (2 pi) is within
    // n 2^-50 of it (theta n <= 2 pi n, exact in f64), so for n <= 2^20 it has the same floor
    // unless it lies within 1e-9 of an integer; there, the division itself decides. The quotient is
    // >= 0 (or NaN, giving 0 either way): truncation is its floor, without a libm call.
    let q = theta as f64 * n_bins as f64;
    let r = q * (1.0 / TAU);
    let t = r as usize;
    let frac = r - t as f64;
    let b = if n_bins <= 1 << 20 && (1e-9..1.0 - 1e-9).contains(&frac) {
        t
    } else {
        (q / TAU) as usize
    };
    // `theta < 2 pi` gives a quotient below `n_bins` (or equal to it by rounding): the
    // 64-bit remainder only in that rare case.
    if b >= n_bins {
        b % n_bins
    } else {
        b
    }
}

/// Builds the R-table of `seg` (`theta`: normal directions of the image, `w`: its width). A
/// failed allocation of its tables (24 bytes a pixel at the peak) is
/// [`crate::CoreError::OutOfMemory`]; an image past [`check_positions`]' limit is
/// [`crate::CoreError::TooLarge`].
pub fn build_rtable(seg: &Segment, theta: &[f32], w: usize, n_bins: usize) -> Result<RTable> {
    const WHAT: &str = "an R-table of the MCGM matcher";
    check_positions(&seg.pixels, theta, w, n_bins)?;
    let mut counts = try_zeroed::<u32>(n_bins + 1, WHAT)?;
    let bins = try_collect(
        seg.pixels.len(),
        seg.pixels
            .iter()
            .map(|&i| theta_bin(theta[i as usize], n_bins)),
        WHAT,
    )?;
    for &b in &bins {
        counts[b + 1] += 1;
    }
    for b in 1..=n_bins {
        counts[b] += counts[b - 1];
    }
    let mut fill = try_collect(counts.len(), counts.iter().copied(), WHAT)?;
    let n = seg.pixels.len();
    let mut vecs = try_filled(n, (0.0f32, 0.0f32), WHAT)?;
    let mut px = try_filled(n, (0i32, 0i32), WHAT)?;
    for (k, &i) in seg.pixels.iter().enumerate() {
        let (x, y) = ((i as usize % w) as i32, (i as usize / w) as i32);
        let slot = fill[bins[k]] as usize;
        fill[bins[k]] += 1;
        vecs[slot] = (seg.centroid.0 - x as f32, seg.centroid.1 - y as f32);
        px[slot] = (x, y);
    }
    Ok(RTable {
        offsets: counts,
        vecs,
        px,
    })
}

/// Refuses an image (`theta`, `w` wide) whose pixel positions would not fit the i32 columns and
/// rows of an R-table or a voter ([`crate::image::check_index_range`]): they wrapped silently
/// (a pixel on row 2^31 of a 1-wide image became row -2^31). Once per call, not per pixel:
/// every pixel indexes `theta`, so its row is below `ceil(len / w)`. `n_pixels` pixels need a
/// width and a bin count of at least 1 (`% w`, `% n_bins`: a division by zero panicked); with
/// no pixel the result is empty, as [`super::zerocross::zero_crossings`]' for a 0-wide image.
/// A pixel index past `theta` (a public caller's bad input) is refused too: `theta[i]`
/// panicked (one pass over the indices, next to the tables' own passes).
fn check_positions(pixels: &[u32], theta: &[f32], w: usize, n_bins: usize) -> Result<()> {
    let n_pixels = pixels.len();
    if n_pixels > 0 && w == 0 {
        return Err(crate::CoreError::param(
            "w",
            format!("must be at least 1 for {n_pixels} pixels, got 0"),
        ));
    }
    if n_pixels > 0 && n_bins == 0 {
        return Err(crate::CoreError::param(
            "n_bins",
            format!("must be at least 1 for {n_pixels} pixels, got 0"),
        ));
    }
    if let Some(&i) = pixels.iter().max().filter(|&&i| i as usize >= theta.len()) {
        return Err(crate::CoreError::param(
            "pixels",
            format!(
                "index {i} is past the image's {} pixels (theta)",
                theta.len()
            ),
        ));
    }
    crate::image::check_index_range(w, theta.len().div_ceil(w.max(1)))
}

/// GHT comparison result: normalised peak and the vote-weighted translation `t = p - q`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ght {
    pub score: f32,
    pub tx: f32,
    pub ty: f32,
    /// Votes in the peak cell.
    pub peak: u32,
}

/// A segment's pixels as voters of [`ght_vote`]: integer position and orientation bin of each
/// (computed once per segment instead of once per comparison). `theta`: the image's normal
/// directions, `w` its width. A failed allocation (12 bytes a pixel) is
/// [`crate::CoreError::OutOfMemory`]; an image past [`check_positions`]' limit is
/// [`crate::CoreError::TooLarge`].
pub fn voters(
    pixels: &[u32],
    theta: &[f32],
    w: usize,
    n_bins: usize,
) -> Result<Vec<(i32, i32, u32)>> {
    check_positions(pixels, theta, w, n_bins)?;
    let it = pixels.iter().map(|&q| {
        let (x, y) = ((q as usize % w) as i32, (q as usize / w) as i32);
        (x, y, theta_bin(theta[q as usize], n_bins) as u32)
    });
    try_collect(pixels.len(), it, "the MCGM matcher's GHT voters")
}

/// Votes `A'` (its [`voters`]: pixel positions and orientation bins) against the R-table of `A`
/// over translations `tx in [lo, hi]`, `ty in [-dy, dy]`; `acc` is scratch space. `None` when the
/// window is empty or nothing voted. The caller guarantees `2 tol + 1 <= n_bins`. The plain
/// form, scanning whole orientation bins: the matcher uses [`ght_vote_rows`], tested equal.
#[allow(clippy::too_many_arguments)]
pub fn ght_vote(
    rt: &RTable,
    len_a: usize,
    right: &[(i32, i32, u32)],
    lo: i32,
    hi: i32,
    dy: i32,
    n_bins: usize,
    tol: usize,
    acc: &mut Vec<u32>,
) -> Option<Ght> {
    let (nx, ny) = cleared(acc, len_a, right, lo, hi, dy)?;
    for &(qx, qy, b) in right {
        let b = b as usize;
        for db in 0..=2 * tol {
            let bin = (b + n_bins + db - tol) % n_bins;
            let (s, e) = (rt.offsets[bin] as usize, rt.offsets[bin + 1] as usize);
            for &(px, py) in &rt.px[s..e] {
                let (tx, ty) = (px - qx, py - qy);
                if tx >= lo && tx <= hi && ty.abs() <= dy {
                    acc[(ty + dy) as usize * nx + (tx - lo) as usize] += 1;
                }
            }
        }
    }
    peak(acc, nx, ny, lo, dy, len_a.max(right.len()))
}

/// The accumulator of a vote over `tx in [lo, hi]`, `ty in [-dy, dy]`, zeroed and sized:
/// `(nx, ny)`, or `None` when the window is empty or a segment has no pixel.
fn cleared(
    acc: &mut Vec<u32>,
    len_a: usize,
    right: &[(i32, i32, u32)],
    lo: i32,
    hi: i32,
    dy: i32,
) -> Option<(usize, usize)> {
    if hi < lo || right.is_empty() || len_a == 0 {
        return None;
    }
    let (nx, ny) = ((hi - lo + 1) as usize, (2 * dy + 1) as usize);
    acc.clear();
    acc.resize(nx * ny, 0);
    Some((nx, ny))
}

/// The first maximum of a GHT accumulator (scan order: `ty`, then `tx` ascending), scored by
/// `norm` votes, its translation the vote-weighted centroid of the 3x3 cells around it.
fn peak(acc: &[u32], nx: usize, ny: usize, lo: i32, dy: i32, norm: usize) -> Option<Ght> {
    let (mut best, mut bi) = (0u32, 0usize);
    for (i, &v) in acc.iter().enumerate() {
        if v > best {
            best = v;
            bi = i;
        }
    }
    if best == 0 {
        return None;
    }
    let (cx, cy) = ((bi % nx) as i32, (bi / nx) as i32);
    let (mut sw, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for yy in (cy - 1).max(0)..=(cy + 1).min(ny as i32 - 1) {
        for xx in (cx - 1).max(0)..=(cx + 1).min(nx as i32 - 1) {
            let v = acc[yy as usize * nx + xx as usize] as f64;
            sw += v;
            sx += v * (xx + lo) as f64;
            sy += v * (yy - dy) as f64;
        }
    }
    Some(Ght {
        score: best as f32 / norm as f32,
        tx: (sx / sw) as f32,
        ty: (sy / sw) as f32,
        peak: best,
    })
}

/// The entries of an R-table listed by row (integer `x` and orientation bin each): a voter of
/// [`ght_vote_rows`] only meets the entries within `dy` rows of its own, where [`ght_vote`]
/// scans whole orientation bins.
#[derive(Debug, Clone, PartialEq)]
pub struct RowIndex {
    y_min: i32,
    /// `offsets[r]..offsets[r + 1]` index the entries of row `y_min + r`.
    offsets: Vec<u32>,
    ents: Vec<(i32, u32)>,
}

impl RowIndex {
    /// Indexes `rt`'s entries by row. A failed allocation (8 bytes an entry, 4 a row) is
    /// [`crate::CoreError::OutOfMemory`].
    pub fn new(rt: &RTable) -> Result<Self> {
        const WHAT: &str = "an R-table's row index of the MCGM matcher";
        let y_min = rt.px.iter().map(|p| p.1).min().unwrap_or(0);
        let y_max = rt.px.iter().map(|p| p.1).max().unwrap_or(-1);
        let rows = (y_max - y_min + 1).max(0) as usize;
        let mut offsets = try_zeroed::<u32>(rows + 1, WHAT)?;
        for &(_, y) in &rt.px {
            offsets[(y - y_min) as usize + 1] += 1;
        }
        for r in 1..=rows {
            offsets[r] += offsets[r - 1];
        }
        let mut fill = try_collect(offsets.len(), offsets.iter().copied(), WHAT)?;
        let mut ents = try_filled(rt.px.len(), (0i32, 0u32), WHAT)?;
        for b in 0..rt.offsets.len().saturating_sub(1) {
            for &(x, y) in &rt.px[rt.offsets[b] as usize..rt.offsets[b + 1] as usize] {
                let r = (y - y_min) as usize;
                ents[fill[r] as usize] = (x, b as u32);
                fill[r] += 1;
            }
        }
        Ok(RowIndex {
            y_min,
            offsets,
            ents,
        })
    }
}

/// [`ght_vote`] through a [`RowIndex`] of the same R-table: the same votes (each pair of a
/// voter and an entry within `tol` bins and `dy` rows counts once, in any order), so the same
/// result.
#[allow(clippy::too_many_arguments)]
pub fn ght_vote_rows(
    ix: &RowIndex,
    len_a: usize,
    right: &[(i32, i32, u32)],
    lo: i32,
    hi: i32,
    dy: i32,
    n_bins: usize,
    tol: usize,
    acc: &mut Vec<u32>,
) -> Option<Ght> {
    let (nx, ny) = cleared(acc, len_a, right, lo, hi, dy)?;
    let rows = ix.offsets.len() as i32 - 1;
    let (nb, tol) = (n_bins as i32, tol as i32);
    for &(qx, qy, b) in right {
        let r0 = (qy - dy - ix.y_min).max(0);
        let r1 = (qy + dy - ix.y_min).min(rows - 1);
        for r in r0..=r1 {
            let base = (r + ix.y_min - qy + dy) as usize * nx;
            let (s, e) = (ix.offsets[r as usize] as usize, ix.offsets[r as usize + 1]);
            for &(px, pb) in &ix.ents[s..e as usize] {
                let tx = px - qx;
                let mut db = pb as i32 - b as i32;
                if db < 0 {
                    db += nb;
                }
                if tx >= lo && tx <= hi && (db <= tol || db >= nb - tol) {
                    acc[base + (tx - lo) as usize] += 1;
                }
            }
        }
    }
    peak(acc, nx, ny, lo, dy, len_a.max(right.len()))
}
