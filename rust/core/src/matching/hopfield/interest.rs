//! Moravec interest operator with the squares put back (algorithms.md C.1, densities of C.10).
//!
//! `M(x, y) = min(S_h, S_v, S_d, S_a)` where each `S` is the 5x5 window sum of squared differences
//! of adjacent pixels in one direction. Sums are taken in `f64` in a fixed order (horizontal pass
//! left to right, then vertical pass top to bottom) so the NumPy reference reproduces every value
//! bit for bit; `M` is returned as `f32`.

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
}

impl Default for InterestParams {
    fn default() -> Self {
        InterestParams {
            rel_threshold: 1e-3,
            nms_half: 1,
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

/// Squared difference image for the step `(sx, sy)` (with `sy` in -1..=1), `f64`, same size as
/// the image; entries whose partner pixel falls outside are 0 (never read inside the valid area).
fn sq_diff(img: &Image, sx: usize, sy: isize) -> Vec<f64> {
    let (w, h) = img.size();
    let mut out = vec![0.0f64; w * h];
    for y in 0..h {
        let yy = y as isize + sy;
        if yy < 0 || yy >= h as isize {
            continue;
        }
        let yy = yy as usize;
        for x in 0..w.saturating_sub(sx) {
            let d = img.at(x, y) as f64 - img.at(x + sx, yy) as f64;
            out[y * w + x] = d * d;
        }
    }
    out
}

/// 5x5 window sum at every valid pixel (horizontal pass then vertical, both in increasing order).
fn box5(sq: &[f64], w: usize, h: usize) -> Vec<f64> {
    let r = MORAVEC_HALF;
    let mut hs = vec![0.0f64; w * h];
    for y in 0..h {
        for x in r..w.saturating_sub(r) {
            let row = &sq[y * w..(y + 1) * w];
            let mut acc = row[x - r];
            for &v in &row[x - r + 1..=x + r] {
                acc += v;
            }
            hs[y * w + x] = acc;
        }
    }
    let mut out = vec![0.0f64; w * h];
    for y in r..h.saturating_sub(r) {
        for x in 0..w {
            let mut acc = hs[(y - r) * w + x];
            for v in (y - r + 1)..=(y + r) {
                acc += hs[v * w + x];
            }
            out[y * w + x] = acc;
        }
    }
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
    let sums: Vec<Vec<f64>> = dirs
        .iter()
        .map(|&(sx, sy)| box5(&sq_diff(img, sx, sy), w, h))
        .collect();
    for y in BORDER..h - BORDER {
        for x in BORDER..w - BORDER {
            let i = y * w + x;
            let m = sums[0][i].min(sums[1][i]).min(sums[2][i]).min(sums[3][i]);
            out[i] = m as f32;
        }
    }
    out
}

/// Interest points of `img`: local maxima of [`moravec`] over a `(2 nms_half + 1)^2`
/// neighbourhood (strictly greater than neighbours earlier in raster order, at least as large as
/// later ones), with `M > 0` and `M >= rel_threshold * max(M)`; raster order.
pub fn interest_points(img: &Image, p: &InterestParams) -> Vec<InterestPoint> {
    let m = moravec(img);
    let (w, h) = img.size();
    select_points(&m, w, h, p)
}

/// Selection step of [`interest_points`] on a precomputed map.
pub fn select_points(m: &[f32], w: usize, h: usize, p: &InterestParams) -> Vec<InterestPoint> {
    let max = m.iter().copied().fold(0.0f32, f32::max);
    let thr = max * p.rel_threshold;
    let r = p.nms_half as isize;
    let mut out = Vec::new();
    if max <= 0.0 {
        return out;
    }
    for y in BORDER..h.saturating_sub(BORDER) {
        'px: for x in BORDER..w.saturating_sub(BORDER) {
            let v = m[y * w + x];
            if v <= 0.0 || v < thr {
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
