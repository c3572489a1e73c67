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

/// R-table of one segment in CSR form over `n_bins` orientation bins.
#[derive(Debug, Clone, PartialEq)]
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
    ((theta as f64 * n_bins as f64 / TAU).floor() as usize) % n_bins
}

/// Builds the R-table of `seg` (`theta`: normal directions of the image, `w`: its width).
pub fn build_rtable(seg: &Segment, theta: &[f32], w: usize, n_bins: usize) -> RTable {
    let mut counts = vec![0u32; n_bins + 1];
    let bins: Vec<usize> = seg
        .pixels
        .iter()
        .map(|&i| theta_bin(theta[i as usize], n_bins))
        .collect();
    for &b in &bins {
        counts[b + 1] += 1;
    }
    for b in 1..=n_bins {
        counts[b] += counts[b - 1];
    }
    let mut fill = counts.clone();
    let n = seg.pixels.len();
    let mut vecs = vec![(0.0f32, 0.0f32); n];
    let mut px = vec![(0i32, 0i32); n];
    for (k, &i) in seg.pixels.iter().enumerate() {
        let (x, y) = ((i as usize % w) as i32, (i as usize / w) as i32);
        let slot = fill[bins[k]] as usize;
        fill[bins[k]] += 1;
        vecs[slot] = (seg.centroid.0 - x as f32, seg.centroid.1 - y as f32);
        px[slot] = (x, y);
    }
    RTable {
        offsets: counts,
        vecs,
        px,
    }
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
/// directions, `w` its width.
pub fn voters(pixels: &[u32], theta: &[f32], w: usize, n_bins: usize) -> Vec<(i32, i32, u32)> {
    pixels
        .iter()
        .map(|&q| {
            let (x, y) = ((q as usize % w) as i32, (q as usize / w) as i32);
            (x, y, theta_bin(theta[q as usize], n_bins) as u32)
        })
        .collect()
}

/// Votes `A'` (its [`voters`]: pixel positions and orientation bins) against the R-table of `A`
/// over translations `tx in [lo, hi]`, `ty in [-dy, dy]`; `acc` is scratch space. `None` when the
/// window is empty or nothing voted. The caller guarantees `2 tol + 1 <= n_bins`.
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
    if hi < lo || right.is_empty() || len_a == 0 {
        return None;
    }
    let nx = (hi - lo + 1) as usize;
    let ny = (2 * dy + 1) as usize;
    acc.clear();
    acc.resize(nx * ny, 0);
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
    // First maximum in scan order (ty, then tx ascending).
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
        score: best as f32 / len_a.max(right.len()) as f32,
        tx: (sx / sw) as f32,
        ty: (sy / sw) as f32,
        peak: best,
    })
}
