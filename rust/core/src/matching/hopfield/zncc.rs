//! Window ZNCC along an image row, for one left point against every disparity at once.
//!
//! The similarity of C.10 (7x7 zero-mean normalised cross-correlation, never raw intensity) and
//! the four half-windows of the depth-edge test (left, right, top, bottom: 3 columns or 3 rows
//! of the 7x7 window, without the centre column or row) come out of ONE pass over the 49 taps:
//! the products `(L - c) * R` are accumulated per (window row, column group) over contiguous
//! right-row slices (the inner loop vectorises), then summed per region and centred with the
//! region's right-window sum: `sum (L - mu) R = sum (L - c) R - (mu - c) sum R`. Right-window sums
//! and inverse norms come from `f64` integral images, computed once per image ([`RightStats`]).

use rayon::prelude::*;

use crate::image::Image;
use crate::simd::simd_fn;

/// Similarity window half-size (7x7, C.10).
pub const SIM_RADIUS: usize = 3;
const R: isize = SIM_RADIUS as isize;
const SIDE: usize = 2 * SIM_RADIUS + 1;
/// A window whose grey-level standard deviation is below this (1/4 of an 8-bit level) is
/// textureless: its ZNCC is undefined and reported as 0 (never a match).
pub const MIN_WINDOW_STD: f64 = 1e-3;

/// Number of regions: the full window and the four half-windows.
pub const N_REGIONS: usize = 5;
/// Region indices.
pub const FULL: usize = 0;
pub const HALF_LEFT: usize = 1;
pub const HALF_RIGHT: usize = 2;
pub const HALF_TOP: usize = 3;
pub const HALF_BOTTOM: usize = 4;

/// `(x0, x1, y0, y1)` offsets of each region relative to the centre (inclusive).
pub const REGIONS: [(isize, isize, isize, isize); N_REGIONS] = [
    (-R, R, -R, R),
    (-R, -1, -R, R),
    (1, R, -R, R),
    (-R, R, -R, -1),
    (-R, R, 1, R),
];

fn region_n(k: usize) -> usize {
    let (x0, x1, y0, y1) = REGIONS[k];
    ((x1 - x0 + 1) * (y1 - y0 + 1)) as usize
}

/// Column group of a window column offset: 0 = left of centre, 1 = centre, 2 = right.
#[inline]
fn group(dx: isize) -> usize {
    (dx.signum() + 1) as usize
}

/// Right-image window sums and inverse zero-mean norms for every region and pixel (0 where the
/// window does not fit or is textureless). Layout `(H, 2 * N_REGIONS, W)`: per image row, the
/// five sum rows then the five inverse-norm rows, so one region's values along a row are
/// contiguous. Built row-parallel with direct (not running) `f64` sums: vertical 7/3-row sums,
/// then horizontal 7/3-column sums.
#[derive(Debug, Clone)]
pub struct RightStats {
    width: usize,
    buf: Vec<f32>,
}

impl RightStats {
    pub fn new(img: &Image) -> Self {
        let (w, h) = img.size();
        let stride = 2 * N_REGIONS * w;
        let mut buf = vec![0.0f32; stride * h];
        if w < SIDE || h < SIDE {
            return RightStats { width: w, buf };
        }
        buf.par_chunks_mut(stride)
            .enumerate()
            .skip(SIM_RADIUS)
            .take(h - 2 * SIM_RADIUS)
            .for_each(|(y, chunk)| {
                // Vertical sums (value, square) over rows -3..=3, -3..=-1 and 1..=3.
                let mut vs = [vec![0.0f64; w], vec![0.0f64; w], vec![0.0f64; w]];
                let mut vq = [vec![0.0f64; w], vec![0.0f64; w], vec![0.0f64; w]];
                for dy in -R..=R {
                    let row = &img.data[(y as isize + dy) as usize * w..][..w];
                    let slots: &[usize] = match dy {
                        d if d < 0 => &[0, 1],
                        0 => &[0],
                        _ => &[0, 2],
                    };
                    for &k in slots {
                        for ((s, q), &v) in vs[k].iter_mut().zip(vq[k].iter_mut()).zip(row) {
                            let v = v as f64;
                            *s += v;
                            *q += v * v;
                        }
                    }
                }
                let (sums, invs) = chunk.split_at_mut(N_REGIONS * w);
                for k in 0..N_REGIONS {
                    let (x0, x1, _, _) = REGIONS[k];
                    let slot = match k {
                        HALF_TOP => 1,
                        HALF_BOTTOM => 2,
                        _ => 0,
                    };
                    let n = region_n(k) as f64;
                    let min_n2 = n * MIN_WINDOW_STD * MIN_WINDOW_STD;
                    let srow = &mut sums[k * w..(k + 1) * w];
                    let irow = &mut invs[k * w..(k + 1) * w];
                    for x in SIM_RADIUS..w - SIM_RADIUS {
                        let xa = (x as isize + x0) as usize;
                        let xb = (x as isize + x1) as usize;
                        let sm: f64 = vs[slot][xa..=xb].iter().sum();
                        let sq: f64 = vq[slot][xa..=xb].iter().sum();
                        let n2 = sq - sm * sm / n;
                        srow[x] = sm as f32;
                        if n2 >= min_n2 {
                            irow[x] = (1.0 / n2.sqrt()) as f32;
                        }
                    }
                }
            });
        RightStats { width: w, buf }
    }

    /// Window sums of region `k` along row `y`.
    #[inline]
    fn sums(&self, k: usize, y: usize) -> &[f32] {
        let o = (y * 2 * N_REGIONS + k) * self.width;
        &self.buf[o..o + self.width]
    }

    /// Inverse zero-mean norms of region `k` along row `y` (0 = undefined).
    #[inline]
    fn inv_norms(&self, k: usize, y: usize) -> &[f32] {
        let o = (y * 2 * N_REGIONS + N_REGIONS + k) * self.width;
        &self.buf[o..o + self.width]
    }

    /// Mean of the right 7x7 window centred at `(x, y)` (0 where it does not fit).
    pub fn mean(&self, x: usize, y: usize) -> f32 {
        self.sums(FULL, y)[x] / region_n(FULL) as f32
    }
}

/// Reusable buffers of [`zncc_curves`].
#[derive(Debug, Clone, Default)]
pub struct Curves {
    part: Vec<f32>,
    acc: Vec<f32>,
    /// `curve[k][d]`: ZNCC of region `k` at disparity `d = 0..=d_hi` (0 = undefined).
    pub curve: [Vec<f32>; N_REGIONS],
    /// Mean of the left 7x7 window.
    pub left_mean: f32,
}

simd_fn! {
/// ZNCC curves of the five regions around left `(x, y)` against right `(x - d, yr)`,
/// `d = 0..=d_hi`. The caller guarantees `SIM_RADIUS <= x - d_hi`, `x + SIM_RADIUS < W` and
/// that rows `y` and `yr` are at least `SIM_RADIUS` from the top and bottom.
pub fn zncc_curves(
    left: &Image,
    right: &Image,
    stats: &RightStats,
    x: usize,
    y: usize,
    yr: usize,
    d_hi: usize,
    out: &mut Curves,
) {
    let len = d_hi + 1;
    // Template statistics in f64.
    let mut tmpl = [[0.0f64; SIDE]; SIDE];
    for (r, row) in tmpl.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = left.at(x + c - SIM_RADIUS, y + r - SIM_RADIUS) as f64;
        }
    }
    let mut mu = [0.0f64; N_REGIONS];
    let mut lnorm = [0.0f64; N_REGIONS];
    for k in 0..N_REGIONS {
        let (x0, x1, y0, y1) = REGIONS[k];
        let n = region_n(k) as f64;
        let mut m = 0.0;
        for dy in y0..=y1 {
            for dx in x0..=x1 {
                m += tmpl[(dy + R) as usize][(dx + R) as usize];
            }
        }
        m /= n;
        let mut q = 0.0;
        for dy in y0..=y1 {
            for dx in x0..=x1 {
                let v = tmpl[(dy + R) as usize][(dx + R) as usize] - m;
                q += v * v;
            }
        }
        mu[k] = m;
        lnorm[k] = if q >= n * MIN_WINDOW_STD * MIN_WINDOW_STD {
            q.sqrt()
        } else {
            0.0
        };
    }
    let c = mu[FULL];
    out.left_mean = c as f32;
    // Partial sums part[(row * 3 + group) * len + j], j = x_r - (x - d_hi).
    out.part.clear();
    out.part.resize(SIDE * 3 * len, 0.0);
    let xr_lo = x - d_hi;
    let w = right.width;
    for (r, trow) in tmpl.iter().enumerate() {
        let row_r = yr + r - SIM_RADIUS;
        let rrow = &right.data[row_r * w..(row_r + 1) * w];
        for (cc, &tv) in trow.iter().enumerate() {
            let t = (tv - c) as f32;
            let start = xr_lo + cc - SIM_RADIUS;
            let src = &rrow[start..start + len];
            let g = group(cc as isize - R);
            let dst = &mut out.part[(r * 3 + g) * len..(r * 3 + g + 1) * len];
            for (a, &rv) in dst.iter_mut().zip(src) {
                *a += t * rv;
            }
        }
    }
    for k in 0..N_REGIONS {
        let curve = &mut out.curve[k];
        curve.clear();
        curve.resize(len, 0.0);
        if lnorm[k] == 0.0 {
            continue;
        }
        let (x0, x1, y0, y1) = REGIONS[k];
        let (g0, g1) = (group(x0), group(x1));
        let acc = &mut out.acc;
        acc.clear();
        acc.resize(len, 0.0);
        for r in (y0 + R) as usize..=(y1 + R) as usize {
            for g in g0..=g1 {
                let src = &out.part[(r * 3 + g) * len..(r * 3 + g + 1) * len];
                for (a, &v) in acc.iter_mut().zip(src) {
                    *a += v;
                }
            }
        }
        let shift = (mu[k] - c) as f32;
        let inv_l = (1.0 / lnorm[k]) as f32;
        let sums = &stats.sums(k, yr)[xr_lo..xr_lo + len];
        let invs = &stats.inv_norms(k, yr)[xr_lo..xr_lo + len];
        for (j, ((&a, &s), &iv)) in acc.iter().zip(sums).zip(invs).enumerate() {
            curve[d_hi - j] = (a - shift * s) * iv * inv_l;
        }
    }
}
}
