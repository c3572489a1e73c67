//! Moravec interest operator with the squares put back (algorithms.md C.1, densities of C.10).
//!
//! `M(x, y) = min(S_h, S_v, S_d, S_a)` where each `S` is the 5x5 window sum of squared differences
//! of adjacent pixels in one direction. Everything is `f32` in a fixed order (squared difference,
//! horizontal 5-sum left to right, then vertical 5-sum top to bottom: no running sums), so the
//! NumPy reference reproduces every value bit for bit.

use rayon::prelude::*;

use crate::image::Image;
use crate::simd::simd_fn;

/// Half-size of the Moravec window (5x5, the paper's size).
pub const MORAVEC_HALF: usize = 2;
/// Pixels at the border where `M` is not defined (set to 0): the 5x5 window plus the one-pixel
/// step of the differences, and the 7x7 similarity window (radius 3) must fit in the image.
pub const BORDER: usize = 3;

/// Parameters of [`interest_points`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterestParams {
    /// Threshold relative to the image's largest `M` (C.10: 0.1 % keeps the dense set that gives
    /// thousands of correct matches; the paper's 1 % filters little more).
    pub rel_threshold: f32,
    /// Half-size of the non-maximum suppression neighbourhood (C.10: 1 = 3x3; 5x5 sets the
    /// count far too low).
    pub nms_half: usize,
    /// The threshold is `rel_threshold` times the largest `M` of the `tile x tile` block holding
    /// the pixel (0 = of the whole image, C.10). 64 px (a few 40x40 compatibility windows)
    /// keeps weakly textured areas represented (C.3 "per grid cell for spread"): wood2's plank
    /// and laundry's basket get points, so the 4x4 coverage reaches 16/16.
    pub tile: usize,
    /// ... but never below `floor_rel` times the image's largest `M` (1e-4: truly flat areas,
    /// sensor noise only, stay empty).
    pub floor_rel: f32,
}

impl Default for InterestParams {
    fn default() -> Self {
        InterestParams {
            rel_threshold: 1e-3,
            nms_half: 1,
            tile: 64,
            floor_rel: 1e-4,
        }
    }
}

/// One interest point: integer pixel position and its Moravec value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterestPoint {
    pub x: u32,
    pub y: u32,
    pub value: f32,
}

/// Output rows per parallel task of [`moravec`]: each task recomputes the `2 * MORAVEC_HALF`
/// rows of horizontal sums it shares with its neighbours (12 % extra at 32 rows).
const ROWS_PER_TASK: usize = 32;

/// The four steps `(sx, sy)`: horizontal, vertical, 45 degrees (down-right), 135 (up-right).
const DIRS: [(usize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];

simd_fn! {
/// Horizontal 5-sums of the squared differences between row `a` and row `b` shifted by `sx`:
/// `out[x] = sq[x-2] + sq[x-1] + sq[x] + sq[x+1] + sq[x+2]` (left to right, `f32`) for
/// `x in 2..w-2-sx`, 0 elsewhere; `sq` is scratch.
fn hsum_row(a: &[f32], b: &[f32], sx: usize, sq: &mut Vec<f32>, out: &mut [f32]) {
    let w = a.len();
    let r = MORAVEC_HALF;
    out.fill(0.0);
    if w < 2 * r + 1 + sx {
        return;
    }
    sq.resize(w - sx, 0.0);
    for ((o, &p), &q) in sq.iter_mut().zip(a).zip(&b[sx..]) {
        let d = p - q;
        *o = d * d;
    }
    let m = w - 2 * r - sx;
    let dst = &mut out[r..r + m];
    dst.copy_from_slice(&sq[..m]);
    for k in 1..=2 * r {
        for (o, &v) in dst.iter_mut().zip(&sq[k..k + m]) {
            *o += v;
        }
    }
}
}

simd_fn! {
/// One row of `M`: per direction the vertical 5-sum of its horizontal sums (top to bottom),
/// then the minimum over the four directions. `hs[dir]` holds the five rows `y-2..=y+2`.
fn min_row(hs: &[[&[f32]; 2 * MORAVEC_HALF + 1]; 4], acc: &mut [f32], out: &mut [f32]) {
    for (d, rows) in hs.iter().enumerate() {
        acc.copy_from_slice(rows[0]);
        for row in &rows[1..] {
            for (o, &v) in acc.iter_mut().zip(row.iter()) {
                *o += v;
            }
        }
        if d == 0 {
            out.copy_from_slice(acc);
        } else {
            for (o, &v) in out.iter_mut().zip(acc.iter()) {
                *o = o.min(v);
            }
        }
    }
}
}

/// The Moravec interest map `M` (f32, row-major `(H, W)`); 0 within [`BORDER`] px of the edge.
/// Row bands in parallel; every value is computed in the fixed order of the module docs, so the
/// map does not depend on the thread count.
pub fn moravec(img: &Image) -> Vec<f32> {
    let (w, h) = img.size();
    let mut out = vec![0.0f32; w * h];
    if w < 2 * BORDER + 1 || h < 2 * BORDER + 1 {
        return out;
    }
    let r = MORAVEC_HALF;
    let row = |y: usize| &img.data[y * w..(y + 1) * w];
    let inner = &mut out[BORDER * w..(h - BORDER) * w];
    inner
        .par_chunks_mut(ROWS_PER_TASK * w)
        .enumerate()
        .for_each_init(
            || (Vec::new(), Vec::new(), vec![0.0f32; w]),
            |(hs, sq, acc), (t, band)| {
                let y0 = BORDER + t * ROWS_PER_TASK;
                let n = band.len() / w;
                // Horizontal sums of rows y0-2 .. y0+n+1 for each direction.
                let n_hs = n + 2 * r;
                hs.resize(4 * n_hs * w, 0.0); // every value is overwritten by hsum_row
                for (d, &(sx, sy)) in DIRS.iter().enumerate() {
                    for i in 0..n_hs {
                        let y = y0 + i - r;
                        let yy = (y as isize + sy) as usize; // in 0..h: y in 1..h-1, |sy| <= 1
                        let dst = &mut hs[(d * n_hs + i) * w..(d * n_hs + i + 1) * w];
                        hsum_row(row(y), row(yy), sx, sq, dst);
                    }
                }
                for (i, orow) in band.chunks_mut(w).enumerate() {
                    let rows: [[&[f32]; 2 * MORAVEC_HALF + 1]; 4] = std::array::from_fn(|d| {
                        std::array::from_fn(|k| {
                            &hs[(d * n_hs + i + k) * w..(d * n_hs + i + k + 1) * w]
                        })
                    });
                    min_row(&rows, acc, orow);
                    orow[..BORDER].fill(0.0);
                    orow[w - BORDER..].fill(0.0);
                }
            },
        );
    out
}

/// Interest points of `img`: local maxima of [`moravec`] over a `(2 nms_half + 1)^2`
/// neighbourhood (strictly greater than neighbours earlier in raster order, at least as large as
/// later ones), with `M > 0` and `M >= max(rel_threshold * max_tile(M), floor_rel * max(M))`;
/// raster order.
pub fn interest_points(img: &Image, p: &InterestParams) -> Vec<InterestPoint> {
    let m = moravec(img);
    let (w, h) = img.size();
    select_points(&m, w, h, p)
}

/// Selection step of [`interest_points`] on a precomputed map (rows in parallel, raster order).
pub fn select_points(m: &[f32], w: usize, h: usize, p: &InterestParams) -> Vec<InterestPoint> {
    let max = m.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 || w == 0 {
        return Vec::new();
    }
    // Largest M per tile (a single tile covering the image when `tile == 0`).
    let tile = if p.tile == 0 { w.max(h) } else { p.tile };
    let tiles_x = w.div_ceil(tile);
    let tile_max: Vec<f32> = m
        .par_chunks(tile * w)
        .flat_map_iter(|band| {
            let mut tm = vec![0.0f32; tiles_x];
            for row in band.chunks(w) {
                for (t, seg) in row.chunks(tile).enumerate() {
                    tm[t] = seg.iter().copied().fold(tm[t], f32::max);
                }
            }
            tm
        })
        .collect();
    let floor = max * p.floor_rel;
    let r = p.nms_half;
    // Is `v` (at x, y) above its later and strictly above its earlier neighbours?
    let is_peak = |x: usize, y: usize, v: f32| -> bool {
        let (x0, x1) = (x.saturating_sub(r), (x + r).min(w - 1));
        for yy in y.saturating_sub(r)..=(y + r).min(h - 1) {
            let nrow = &m[yy * w..(yy + 1) * w];
            for (xx, &n) in nrow.iter().enumerate().take(x1 + 1).skip(x0) {
                let earlier = yy < y || (yy == y && xx < x);
                if n > v || (earlier && n == v) {
                    return false;
                }
            }
        }
        true
    };
    // The 3x3 case (C.10's default) without loops or branches: BORDER >= 1 keeps every
    // neighbour inside the image.
    let peak = |x: usize, y: usize, v: f32| -> bool {
        if r != 1 {
            return is_peak(x, y, v);
        }
        let (up, mid, dn) = (
            &m[(y - 1) * w..y * w],
            &m[y * w..(y + 1) * w],
            &m[(y + 1) * w..(y + 2) * w],
        );
        (v > up[x - 1])
            & (v > up[x])
            & (v > up[x + 1])
            & (v > mid[x - 1])
            & (v >= mid[x + 1])
            & (v >= dn[x - 1])
            & (v >= dn[x])
            & (v >= dn[x + 1])
    };
    (BORDER..h.saturating_sub(BORDER))
        .into_par_iter()
        .flat_map_iter(|y| {
            let row = &m[y * w..(y + 1) * w];
            let tiles = &tile_max[(y / tile) * tiles_x..(y / tile + 1) * tiles_x];
            let mut out = Vec::new();
            for (t, &tm) in tiles.iter().enumerate() {
                let thr = (tm * p.rel_threshold).max(floor);
                let xs = (t * tile).max(BORDER)..((t + 1) * tile).min(w.saturating_sub(BORDER));
                for x in xs {
                    let v = row[x];
                    // Strictly greater than the neighbours earlier in raster order, at least
                    // as large as the later ones (deterministic ties); the centre compares
                    // equal to itself and is neither.
                    if v > 0.0 && v >= thr && peak(x, y, v) {
                        out.push(InterestPoint {
                            x: x as u32,
                            y: y as u32,
                            value: v,
                        });
                    }
                }
            }
            out
        })
        .collect()
}
