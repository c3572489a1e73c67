//! Moravec interest operator with the squares put back (algorithms.md C.1, densities of C.10).
//!
//! `M(x, y) = min(S_h, S_v, S_d, S_a)` where each `S` is the 5x5 window sum of squared differences
//! of adjacent pixels in one direction. Everything is `f32` in a fixed order (squared difference,
//! horizontal 5-sum left to right, then vertical 5-sum top to bottom: no running sums), so the
//! NumPy reference reproduces every value bit for bit.

use rayon::prelude::*;

use crate::image::Image;

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

/// Sum of the 5x5 window of squared differences for the step `(sx, sy)` (`sy` in -1..=1), at
/// every pixel at least [`BORDER`] from the edge (0 elsewhere). Per row: squared differences,
/// horizontal 5-sums (left to right), then vertical 5-sums (top to bottom), all `f32`.
fn direction_sum(img: &Image, sx: usize, sy: isize) -> Vec<f32> {
    let (w, h) = img.size();
    let r = MORAVEC_HALF;
    let n = w - 2 * r; // horizontal sums exist for x in r..w-r
                       // hs[y * w + x]: horizontal 5-sum of the squared differences of row y (rows whose partner
                       // row exists; x in r..w-r-sx so the partner column exists for every term).
    let mut hs = vec![0.0f32; w * h];
    hs.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let yy = y as isize + sy;
        if yy < 0 || yy >= h as isize {
            return;
        }
        let a = &img.data[y * w..(y + 1) * w];
        let b = &img.data[yy as usize * w..(yy as usize + 1) * w];
        let sq: Vec<f32> = (0..w - sx)
            .map(|x| {
                let d = a[x] - b[x + sx];
                d * d
            })
            .collect();
        let m = n.saturating_sub(sx).min(sq.len().saturating_sub(2 * r));
        let dst = &mut out[r..r + m];
        dst.copy_from_slice(&sq[0..m]);
        for k in 1..=2 * r {
            for (o, &v) in dst.iter_mut().zip(&sq[k..k + m]) {
                *o += v;
            }
        }
    });
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w)
        .enumerate()
        .skip(BORDER)
        .take(h - 2 * BORDER)
        .for_each(|(y, row)| {
            row.copy_from_slice(&hs[(y - r) * w..(y - r + 1) * w]);
            for k in 1..=2 * r {
                let src = &hs[(y - r + k) * w..(y - r + k + 1) * w];
                for (o, &v) in row.iter_mut().zip(src) {
                    *o += v;
                }
            }
        });
    out
}

/// The Moravec interest map `M` (f32, row-major `(H, W)`); 0 within [`BORDER`] px of the edge.
pub fn moravec(img: &Image) -> Vec<f32> {
    let (w, h) = img.size();
    let mut out = vec![0.0f32; w * h];
    if w < 2 * BORDER + 1 || h < 2 * BORDER + 1 {
        return out;
    }
    // Horizontal, vertical, 45 degrees (down-right) and 135 degrees (up-right).
    let dirs: [(usize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];
    let sums: Vec<Vec<f32>> = dirs
        .iter()
        .map(|&(sx, sy)| direction_sum(img, sx, sy))
        .collect();
    out.par_chunks_mut(w)
        .enumerate()
        .skip(BORDER)
        .take(h - 2 * BORDER)
        .for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate().take(w - BORDER).skip(BORDER) {
                let i = y * w + x;
                *v = sums[0][i].min(sums[1][i]).min(sums[2][i]).min(sums[3][i]);
            }
        });
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

/// Selection step of [`interest_points`] on a precomputed map.
pub fn select_points(m: &[f32], w: usize, h: usize, p: &InterestParams) -> Vec<InterestPoint> {
    let max = m.iter().copied().fold(0.0f32, f32::max);
    let r = p.nms_half as isize;
    let mut out = Vec::new();
    if max <= 0.0 {
        return out;
    }
    // Largest M per tile (a single tile covering the image when `tile == 0`).
    let tile = if p.tile == 0 { w.max(h) } else { p.tile };
    let tiles_x = w.div_ceil(tile);
    let mut tile_max = vec![0.0f32; tiles_x * h.div_ceil(tile)];
    for (y, row) in m.chunks(w).enumerate() {
        for (x, &v) in row.iter().enumerate() {
            let t = (y / tile) * tiles_x + x / tile;
            tile_max[t] = tile_max[t].max(v);
        }
    }
    let floor = max * p.floor_rel;
    let thr_at = |x: usize, y: usize| {
        (tile_max[(y / tile) * tiles_x + x / tile] * p.rel_threshold).max(floor)
    };
    for y in BORDER..h.saturating_sub(BORDER) {
        'px: for x in BORDER..w.saturating_sub(BORDER) {
            let v = m[y * w + x];
            if v <= 0.0 || v < thr_at(x, y) {
                continue;
            }
            for dy in -r..=r {
                for dx in -r..=r {
                    if dx == 0 && dy == 0 {
                        continue;
                    }
                    let (xx, yy) = (x as isize + dx, y as isize + dy);
                    if xx < 0 || yy < 0 || xx >= w as isize || yy >= h as isize {
                        continue;
                    }
                    let n = m[yy as usize * w + xx as usize];
                    let earlier = dy < 0 || (dy == 0 && dx < 0);
                    if n > v || (earlier && n == v) {
                        continue 'px;
                    }
                }
            }
            out.push(InterestPoint {
                x: x as u32,
                y: y as u32,
                value: v,
            });
        }
    }
    out
}
