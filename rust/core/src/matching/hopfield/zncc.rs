//! Window ZNCC along an image row, for one left point against every disparity at once.
//!
//! The similarity of C.10 (7x7 zero-mean normalised cross-correlation, never raw intensity) and
//! the four half-windows of the depth-edge test (left, right, top, bottom: 3 columns or 3 rows
//! of the 7x7 window, without the centre column or row) come out of ONE pass over the 49 taps.
//! The 7x7 window splits into nine cells (3 row bands top / centre / bottom times 3 column groups
//! left / centre / right); every region is a union of cells. For eight disparities at a time the
//! products `(L - c) * R` are accumulated per cell in registers, the five regions are cell sums,
//! and each is centred with the region's right-window sum:
//! `sum (L - mu) R = sum (L - c) R - (mu - c) sum R`. Right-window sums and inverse norms come
//! from `f64` cell sums computed once per image row ([`RightStats`], one band of rows per task).

use rayon::prelude::*;

use crate::alloc::try_reserve_len;
use crate::error::Result;
use crate::image::ImageView;
use crate::simd::{has_avx2, simd_fn};

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

/// Disparities evaluated together: one AVX2 register of `f32`.
const LANES: usize = 8;

fn region_n(k: usize) -> usize {
    let (x0, x1, y0, y1) = REGIONS[k];
    ((x1 - x0 + 1) * (y1 - y0 + 1)) as usize
}

// `blocks_avx2` starts each band's cells at rows 0, SIM_RADIUS and SIM_RADIUS + 1 and reads
// them uninitialised otherwise: those must be the first rows of bands 0, 1 and 2.
const _: () = assert!(
    part_of(0) == 0
        && part_of(SIM_RADIUS - 1) == 0
        && part_of(SIM_RADIUS) == 1
        && part_of(SIM_RADIUS + 1) == 2
        && part_of(SIDE - 1) == 2
);

/// Band (rows) or group (columns) of a window offset `0..SIDE`: 0 = before the centre, 1 = the
/// centre, 2 = after.
#[inline(always)]
const fn part_of(i: usize) -> usize {
    if i < SIM_RADIUS {
        0
    } else if i == SIM_RADIUS {
        1
    } else {
        2
    }
}

/// The five region values from the nine cell values `cell[band][group]`.
#[inline(always)]
fn regions_of<T: Copy + std::ops::Add<Output = T>>(c: &[[T; 3]; 3]) -> [T; N_REGIONS] {
    let left = c[0][0] + c[1][0] + c[2][0];
    let right = c[0][2] + c[1][2] + c[2][2];
    let top = c[0][0] + c[0][1] + c[0][2];
    let bottom = c[2][0] + c[2][1] + c[2][2];
    let full = left + right + c[0][1] + c[1][1] + c[2][1];
    [full, left, right, top, bottom]
}

/// Right-image window sums and inverse zero-mean norms for every region and pixel of a band of
/// rows `y0..y0 + rows` (0 where the window does not fit or is textureless). Layout
/// `(rows, 2 * N_REGIONS, W + LANES)`: per image row, the five sum rows then the five
/// inverse-norm rows, so one region's values along a row are contiguous; each row is padded by
/// one block of zeros so that a block of lanes never reads past it. Built from `f64` band sums
/// (vertical 3-row sums, then horizontal 3-column sums; no running sums, so no drift along a
/// row). The matcher fills one small band per task ([`RightStats::fill_band`]) instead of the
/// whole image: far less memory to touch.
#[derive(Debug, Clone, Default)]
pub struct RightStats {
    stride: usize,
    y0: usize,
    rows: usize,
    buf: Vec<f32>,
    scratch: StatsScratch,
}

/// Vertical 3-row sums `S(z)` (rows `z, z+1, z+2`, in that order) of values and squares, and
/// their horizontal 3-sums `h[x] = v[x] + v[x+1] + v[x+2]`: `f64`, one image row each.
#[derive(Debug, Clone, Default)]
struct BandSums {
    v: [Vec<f64>; 2],
    h: [Vec<f64>; 2],
}

/// Rows of [`BandSums`] kept while a band is filled: row `y` reads the top band `S(y - 3)` and
/// the bottom band `S(y + 1)`, so `S(z)` serves as the bottom band of row `z - 1` and, four
/// rows later, as the top band of row `z + 3` (slot `z % RING`).
const RING: usize = 5;

/// Scratch of [`RightStats::fill_band`]: the ring of band sums, the all-rows sums of the current
/// row (same layout) and the `f32` squared norms of one region.
#[derive(Debug, Clone, Default)]
struct StatsScratch {
    ring: [BandSums; RING],
    all: BandSums,
    n2: Vec<f32>,
}

impl StatsScratch {
    /// Room (checked) for rows `w` wide: [`BandSums::resize`] and `stats_row`'s `n2` then
    /// do not reallocate.
    fn reserve(&mut self, w: usize, what: &'static str) -> Result<()> {
        for b in self.ring.iter_mut().chain(std::iter::once(&mut self.all)) {
            for a in b.v.iter_mut().chain(b.h.iter_mut()) {
                try_reserve_len(a, w, what)?;
            }
        }
        try_reserve_len(&mut self.n2, w, what)
    }
}

impl BandSums {
    fn resize(&mut self, w: usize) {
        for a in self.v.iter_mut().chain(self.h.iter_mut()) {
            a.resize(w, 0.0); // only grows: every value read is overwritten first
        }
    }
}

/// `h[x] = v[x] + v[x + 1] + v[x + 2]` (left to right) for `x < w - 2`.
#[inline(always)]
fn hsum3(v: &[f64], h: &mut [f64]) {
    for (((o, &a), &b), &c) in h.iter_mut().zip(v).zip(&v[1..]).zip(&v[2..]) {
        *o = a + b + c;
    }
}

simd_fn! {
/// `S(z)` of the three image rows `rows` into `out` (values, squares, their horizontal sums).
fn band_sums(rows: [&[f32]; 3], out: &mut BandSums) {
    let [v, q] = &mut out.v;
    for ((((ov, oq), &a), &b), &c) in v.iter_mut().zip(q.iter_mut()).zip(rows[0]).zip(rows[1]).zip(rows[2]) {
        let (a, b, c) = (a as f64, b as f64, c as f64);
        *ov = a + b + c;
        *oq = a * a + b * b + c * c;
    }
    hsum3(&out.v[0], &mut out.h[0]);
    hsum3(&out.v[1], &mut out.h[1]);
}
}

simd_fn! {
/// Sums and inverse norms of the five regions along one row, written to `sums` / `invs`
/// (`N_REGIONS` rows of `stride` values each; the columns where the window does not fit are
/// left alone, but for the left region's, which runs 4 further into the padding). `top` =
/// `S(y - 3)`, `bot` = `S(y + 1)`, `mid` = image row `y`; `all` and `n2` are scratch. The top
/// region is skipped unless `with_top` (the caller copies it: see [`fill_rows`]).
fn stats_row(top: &BandSums, mid: &[f32], bot: &BandSums, all: &mut BandSums, n2: &mut Vec<f32>, with_top: bool, stride: usize, sums: &mut [f32], invs: &mut [f32]) {
    let w = mid.len();
    for i in 0..2 {
        let square = i == 1;
        for (((o, &t), &b), &m) in all.v[i].iter_mut().zip(&top.v[i]).zip(&bot.v[i]).zip(mid) {
            let m = m as f64;
            *o = t + if square { m * m } else { m } + b;
        }
    }
    hsum3(&all.v[0], &mut all.h[0]);
    hsum3(&all.v[1], &mut all.h[1]);
    // Region k: (vertical sums: 0 top, 1 bottom, 2 all; horizontal parts): full / top / bottom
    // = left 3 + centre + right 3 columns of the all / top / bottom band sums; left = the 3
    // columns before the centre of all. The right region at x is the left one at x + 4 (the
    // same 3-column sum): the left one is computed 4 columns further and copied.
    const PARTS: [(usize, bool, bool, bool); N_REGIONS] = [
        (2, true, true, true),
        (2, true, false, false),
        (2, false, false, true),
        (0, true, true, true),
        (1, true, true, true),
    ];
    let xs = SIM_RADIUS..w - SIM_RADIUS;
    let n_x = xs.len();
    let shift = SIM_RADIUS + 1;
    n2.resize(n_x + shift, 0.0);
    for (k, &(i, l, c, r)) in PARTS.iter().enumerate() {
        if k == HALF_RIGHT || (k == HALF_TOP && !with_top) {
            continue;
        }
        let m = if k == HALF_LEFT { n_x + shift } else { n_x };
        let n = region_n(k) as f64;
        let min_n2 = n * MIN_WINDOW_STD * MIN_WINDOW_STD;
        let src = [top, bot, &*all][i];
        let part = |a: usize| -> (&[f64], &[f64], &[f64]) {
            let h = &src.h[a];
            (&h[..m], &src.v[a][SIM_RADIUS..SIM_RADIUS + m.min(n_x)], &h[shift..shift + m.min(n_x)])
        };
        let (sl, sc, sr) = part(0);
        let (ql, qc, qr) = part(1);
        let srow = &mut sums[k * stride + SIM_RADIUS..k * stride + SIM_RADIUS + m];
        let irow = &mut invs[k * stride + SIM_RADIUS..k * stride + SIM_RADIUS + m];
        // The parts as compile-time flags: with run-time ones the vectoriser turned the skipped
        // loads into masked loads (microcoded on AMD). Same sums in the same order.
        let f = (n, min_n2, (sl, sc, sr), (ql, qc, qr), srow, &mut n2[..m]);
        match (l, c, r) {
            (true, true, true) => region_row::<true, true, true>(f),
            (true, false, false) => region_row::<true, false, false>(f),
            _ => unreachable!("PARTS computes two patterns"),
        }
        // A loop of its own: the f32 square root and division then run 8 lanes wide (4 in
        // the f64 loop above), the costliest operations of the statistics.
        for (o, &q) in irow.iter_mut().zip(n2.iter()) {
            *o = if q > 0.0 { 1.0 / q.sqrt() } else { 0.0 };
        }
    }
    for buf in [sums, invs] {
        let (lo, hi) = buf.split_at_mut(HALF_RIGHT * stride);
        let from = HALF_LEFT * stride + SIM_RADIUS + shift;
        hi[SIM_RADIUS..SIM_RADIUS + n_x].copy_from_slice(&lo[from..from + n_x]);
    }
}
}

/// Arguments of [`region_row`]: `n`, `min_n2`, the value parts, the square parts, outputs.
type RegionArgs<'a> = (
    f64,
    f64,
    (&'a [f64], &'a [f64], &'a [f64]),
    (&'a [f64], &'a [f64], &'a [f64]),
    &'a mut [f32],
    &'a mut [f32],
);

/// Sum of one region along a row, from its left / centre / right parts, and its zero-mean
/// squared norm as `f32` where it reaches `min_n2` (else 0: textureless).
#[inline(always)]
fn region_row<const L: bool, const C: bool, const R: bool>(args: RegionArgs<'_>) {
    let (n, min_n2, (sl, sc, sr), (ql, qc, qr), srow, n2row) = args;
    let pick = |a: &[f64], b: &[f64], d: &[f64], x: usize| {
        let mut v = 0.0;
        if L {
            v += a[x];
        }
        if C {
            v += b[x];
        }
        if R {
            v += d[x];
        }
        v
    };
    for x in 0..srow.len().min(n2row.len()) {
        let sm = pick(sl, sc, sr, x);
        let sq = pick(ql, qc, qr, x);
        let n2 = sq - sm * sm / n;
        srow[x] = sm as f32;
        // min_n2 > 0, so a kept value stays > 0 as f32 (>= 2e-5): the flag survives.
        n2row[x] = if n2 >= min_n2 { n2 as f32 } else { 0.0 };
    }
}

impl RightStats {
    /// Statistics of every row of `img` (bands of rows in parallel).
    pub fn new(img: &ImageView<'_>) -> Self {
        let (w, h) = img.size();
        let stride = w + LANES;
        let row_len = 2 * N_REGIONS * stride;
        let mut buf = vec![0.0f32; row_len * h];
        const BAND: usize = 16;
        buf.par_chunks_mut(row_len * BAND)
            .enumerate()
            .for_each_init(StatsScratch::default, |s, (b, chunk)| {
                let y_lo = b * BAND;
                fill_rows(img, y_lo, y_lo + chunk.len() / row_len, s, chunk);
            });
        RightStats {
            stride,
            y0: 0,
            rows: h,
            buf,
            scratch: StatsScratch::default(),
        }
    }

    /// Recomputes `self` for the rows `y_lo..y_hi` of `img` only (reusing its buffers). A
    /// failed allocation of the band or its scratch (about 40 bytes a pixel of the band, 196 a
    /// pixel of one row) is [`crate::CoreError::OutOfMemory`] and leaves `self` as it was
    /// (nothing is written before every buffer is in place).
    pub fn fill_band(&mut self, img: &ImageView<'_>, y_lo: usize, y_hi: usize) -> Result<()> {
        const WHAT: &str = "the Hopfield matcher's right-image statistics";
        let (w, h) = img.size();
        let y_hi = y_hi.min(h);
        let y_lo = y_lo.min(y_hi);
        let stride = w + LANES;
        let rows = y_hi - y_lo;
        let row_len = 2 * N_REGIONS * stride;
        let n = row_len.saturating_mul(rows); // a saturated size fails to reserve
                                              // Every buffer grown (checked) before the band is recorded: a failure leaves the
                                              // previous band's description, never one the buffer is too short for.
                                              // Only grows, not cleared: fill_rows writes every value of the band.
        if self.buf.len() < n {
            try_reserve_len(&mut self.buf, n, WHAT)?;
            self.buf.resize(n, 0.0);
        }
        self.scratch.reserve(w, WHAT)?;
        self.stride = stride;
        self.y0 = y_lo;
        self.rows = rows;
        fill_rows(img, y_lo, y_hi, &mut self.scratch, &mut self.buf[..n]);
        Ok(())
    }
    /// Window sums of region `k` along row `y` (`W + LANES` values, zero past the image).
    #[inline]
    fn sums(&self, k: usize, y: usize) -> &[f32] {
        debug_assert!((self.y0..self.y0 + self.rows).contains(&y));
        let o = ((y - self.y0) * 2 * N_REGIONS + k) * self.stride;
        &self.buf[o..o + self.stride]
    }

    /// Inverse zero-mean norms of region `k` along row `y` (0 = undefined).
    #[inline]
    fn inv_norms(&self, k: usize, y: usize) -> &[f32] {
        let o = ((y - self.y0) * 2 * N_REGIONS + N_REGIONS + k) * self.stride;
        &self.buf[o..o + self.stride]
    }

    /// The right 7x7 window centred at `(x, y)` is textured: ZNCC with it is defined.
    pub fn defined(&self, x: usize, y: usize) -> bool {
        self.inv_norms(FULL, y)[x] > 0.0
    }

    /// Mean of the right 7x7 window centred at `(x, y)` (0 where it does not fit).
    pub fn mean(&self, x: usize, y: usize) -> f32 {
        self.sums(FULL, y)[x] / region_n(FULL) as f32
    }
}

/// Statistics of image rows `y_lo..y_hi` into `chunk` (`2 * N_REGIONS * (W + LANES)` values
/// per row), every value written: zeros where the window does not fit and in the padding.
fn fill_rows(
    img: &ImageView<'_>,
    y_lo: usize,
    y_hi: usize,
    s: &mut StatsScratch,
    chunk: &mut [f32],
) {
    let (w, h) = img.size();
    let stride = w + LANES;
    let row_len = 2 * N_REGIONS * stride;
    let (lo, hi) = if w >= SIDE && h >= SIDE {
        (y_lo.max(SIM_RADIUS), y_hi.min(h - SIM_RADIUS))
    } else {
        (y_hi, y_hi) // nothing fits
    };
    let row = |y: usize| &img.data[y * w..(y + 1) * w];
    if lo < hi {
        for b in s.ring.iter_mut().chain(std::iter::once(&mut s.all)) {
            b.resize(w);
        }
        // S(lo - 3) ..= S(lo): the top bands of the first four rows.
        for z in lo - SIM_RADIUS..=lo {
            band_sums([row(z), row(z + 1), row(z + 2)], &mut s.ring[z % RING]);
        }
    }
    for i in 0..chunk.len() / row_len {
        let y = y_lo + i;
        if !(lo..hi).contains(&y) {
            chunk[i * row_len..(i + 1) * row_len].fill(0.0);
            continue;
        }
        // S(y + 1) replaces S(y - 4), read for the last time by row y - 1.
        let z = y + 1;
        band_sums([row(z), row(z + 1), row(z + 2)], &mut s.ring[z % RING]);
        let (top, bot) = (&s.ring[(y - SIM_RADIUS) % RING], &s.ring[z % RING]);
        let (done, out) = chunk.split_at_mut(i * row_len);
        let out = &mut out[..row_len];
        // The top region of row y is the bottom one of row y - 4 (both read S(y - 3)).
        let copy_top = y >= lo + 4;
        let (sums, invs) = out.split_at_mut(N_REGIONS * stride);
        stats_row(
            top,
            row(y),
            bot,
            &mut s.all,
            &mut s.n2,
            !copy_top,
            stride,
            sums,
            invs,
        );
        if copy_top {
            let prev = &done[(i - 4) * row_len..(i - 3) * row_len];
            for (dst, src) in [
                (sums, &prev[..N_REGIONS * stride]),
                (invs, &prev[N_REGIONS * stride..]),
            ] {
                let (t, b) = (HALF_TOP * stride, HALF_BOTTOM * stride);
                dst[t..t + stride].copy_from_slice(&src[b..b + stride]);
            }
        }
        for line in out.chunks_mut(stride) {
            line[..SIM_RADIUS].fill(0.0);
            line[w - SIM_RADIUS..].fill(0.0);
        }
    }
}

/// Reusable buffers of [`zncc_curves`].
#[derive(Debug, Clone, Default)]
pub struct Curves {
    /// The 7 right rows of the search span, zero-padded to whole blocks of [`LANES`], for the
    /// rare span whose last block would read past the end of the image.
    rbuf: Vec<f32>,
    /// `curve[k][d]`: ZNCC of region `k` at disparity `d = 0..=d_hi` (0 = undefined; entries
    /// past `d_hi` are stale).
    pub curve: [Vec<f32>; N_REGIONS],
    /// Mean of the left 7x7 window.
    pub left_mean: f32,
    /// The left 7x7 window is textured (its full-window ZNCC is defined).
    pub left_defined: bool,
}

/// ZNCC curves of the five regions around left `(x, y)` against right `(x - d, yr)`,
/// `d = 0..=d_hi`. The caller guarantees `SIM_RADIUS <= x - d_hi`, `x + SIM_RADIUS < W` and
/// that rows `y` and `yr` are at least `SIM_RADIUS` from the top and bottom.
#[allow(clippy::too_many_arguments)]
pub fn zncc_curves(
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    stats: &RightStats,
    x: usize,
    y: usize,
    yr: usize,
    d_hi: usize,
    out: &mut Curves,
) {
    curves_with(has_avx2(), left, right, stats, x, y, yr, d_hi, out);
}

/// [`zncc_curves`] on the AVX2 path when `avx2` (and the CPU has it), else the portable one.
#[allow(clippy::too_many_arguments)]
fn curves_with(
    avx2: bool,
    left: &ImageView<'_>,
    right: &ImageView<'_>,
    stats: &RightStats,
    x: usize,
    y: usize,
    yr: usize,
    d_hi: usize,
    out: &mut Curves,
) {
    let len = d_hi + 1;
    let blocks = len.div_ceil(LANES);
    let lw = left.width;
    // Row references, not a copy: the copy's overlapping 16-byte stores stalled the f64 loads
    // that followed (store forwarding).
    let win: [&[f32; SIDE]; SIDE] = std::array::from_fn(|r| {
        let o = (y + r - SIM_RADIUS) * lw + x - SIM_RADIUS;
        left.data[o..o + SIDE].try_into().expect("SIDE values")
    });
    let (t, norm, mean) = template(&win);
    out.left_mean = mean;
    out.left_defined = norm.inv_l[FULL] > 0.0;
    // Right rows yr-3..=yr+3 from column x0 = x - d_hi - 3: block b reads columns
    // x0 + 8 b ..= x0 + 8 b + 14 of each. Read in place (the lanes past `len` read the next
    // pixels of the row, or of the next one, and are never stored) unless the last block would
    // run past the image: then from a copy padded with zeros.
    let w = right.width;
    let x0 = x - d_hi - SIM_RADIUS;
    let first = (yr - SIM_RADIUS) * w + x0;
    let reach = (SIDE - 1) * w + blocks * LANES + SIDE - 1;
    let (src, stride) = if first + reach <= right.data.len() {
        (&right.data[first..first + reach], w)
    } else {
        let span = blocks * LANES + SIDE - 1;
        let avail = (len + SIDE - 1).min(w - x0);
        out.rbuf.clear();
        out.rbuf.resize(SIDE * span, 0.0);
        for r in 0..SIDE {
            let row = &right.data[first + r * w..][..avail];
            out.rbuf[r * span..r * span + avail].copy_from_slice(row);
        }
        (&out.rbuf[..], span)
    };
    // Lanes past `len` read the padding of the statistics rows and are never stored.
    let xr_lo = x - d_hi;
    let st: [[&[f32]; N_REGIONS]; 2] = [
        std::array::from_fn(|k| &stats.sums(k, yr)[xr_lo..xr_lo + blocks * LANES]),
        std::array::from_fn(|k| &stats.inv_norms(k, yr)[xr_lo..xr_lo + blocks * LANES]),
    ];
    for cv in out.curve.iter_mut() {
        if cv.len() < len {
            cv.resize(len, 0.0);
        }
    }
    let curves: [&mut [f32]; N_REGIONS] = {
        let [a, b, c, d, e] = &mut out.curve;
        [
            &mut a[..len],
            &mut b[..len],
            &mut c[..len],
            &mut d[..len],
            &mut e[..len],
        ]
    };
    #[cfg(target_arch = "x86_64")]
    if avx2 && has_avx2() {
        // SAFETY: AVX2 is present; `src` holds `reach` values from the first read, every
        // statistics row `blocks * LANES` values and every curve `len`.
        unsafe { blocks_avx2(&t, src, stride, &st, &norm, curves) };
        return;
    }
    let _ = avx2;
    blocks_portable(&t, src, stride, &st, &norm, curves);
}

simd_fn! {
/// The left window `win` (7 rows of 7 values) centred on its mean `c` (`f32`), the regions'
/// centring shifts and inverse zero-mean norms, and `c`. Cell sums (values, squares) in `f64`,
/// each cell accumulated row by row, left to right.
fn template(win: &[&[f32; SIDE]; SIDE]) -> ([[f32; SIDE]; SIDE], Norm, f32) {
    let mut cs = [[0.0f64; 3]; 3];
    let mut cq = [[0.0f64; 3]; 3];
    for (r, row) in win.iter().enumerate() {
        let f: [f64; SIDE] = std::array::from_fn(|c| row[c] as f64);
        // The three cells of this row's band, unrolled: constant column groups.
        let (s, q) = (&mut cs[part_of(r)], &mut cq[part_of(r)]);
        let (mut s0, mut s1, mut s2) = (s[0], s[1], s[2]);
        let (mut q0, mut q1, mut q2) = (q[0], q[1], q[2]);
        for &v in &f[..SIM_RADIUS] {
            s0 += v;
            q0 += v * v;
        }
        s1 += f[SIM_RADIUS];
        q1 += f[SIM_RADIUS] * f[SIM_RADIUS];
        for &v in &f[SIM_RADIUS + 1..] {
            s2 += v;
            q2 += v * v;
        }
        *s = [s0, s1, s2];
        *q = [q0, q1, q2];
    }
    let (rs, rq) = (regions_of(&cs), regions_of(&cq));
    let c = rs[FULL] / region_n(FULL) as f64;
    // Element-wise over the five regions (vectorised: the divisions and square roots are the
    // slow part of a point's setup).
    let n: [f64; N_REGIONS] = std::array::from_fn(|k| region_n(k) as f64);
    let q: [f64; N_REGIONS] = std::array::from_fn(|k| rq[k] - rs[k] * rs[k] / n[k]);
    let shift: [f32; N_REGIONS] = std::array::from_fn(|k| (rs[k] / n[k] - c) as f32);
    // 0 for a textureless left region: its whole curve is then 0 (undefined).
    let inv_l: [f32; N_REGIONS] = std::array::from_fn(|k| {
        let ok = q[k] >= n[k] * MIN_WINDOW_STD * MIN_WINDOW_STD;
        if ok {
            (1.0 / q[k].sqrt()) as f32
        } else {
            0.0
        }
    });
    // Plain loops: the nested array::from_fn stayed an out-of-line call.
    let mut t = [[0.0f32; SIDE]; SIDE];
    for (tr, wr) in t.iter_mut().zip(win) {
        for (tv, &v) in tr.iter_mut().zip(wr.iter()) {
            *tv = (v as f64 - c) as f32;
        }
    }
    (t, Norm { shift, inv_l }, c as f32)
}
}

/// Largest value of `c` (`f32::MIN` when empty), eight lanes at a time.
#[inline]
pub fn max_of(c: &[f32]) -> f32 {
    let mut m = [f32::MIN; LANES];
    let mut chunks = c.chunks_exact(LANES);
    for ch in &mut chunks {
        for l in 0..LANES {
            m[l] = if ch[l] > m[l] { ch[l] } else { m[l] };
        }
    }
    let tail = chunks.remainder().iter().copied();
    m.into_iter()
        .chain(tail)
        .fold(f32::MIN, |a, v| if v > a { v } else { a })
}

/// The disparities `d_min..=d_hi` where `full` is a peak at least `s_min`: `full[d] >= s_min`,
/// `>=` its left neighbour and `>` its right one (the range's ends compare with one side only),
/// ascending, into `out`. On AVX2 the interior tests run eight at a time into a bit mask: as
/// branches they were unpredictable, and their mispredictions cost more than the tests.
pub fn row_peaks(full: &[f32], d_min: usize, d_hi: usize, s_min: f32, out: &mut Vec<usize>) {
    out.clear();
    if d_hi < d_min {
        return;
    }
    let c = &full[d_min..=d_hi];
    let n = c.len();
    let peak =
        |i: usize| c[i] >= s_min && (i == 0 || c[i] >= c[i - 1]) && (i + 1 == n || c[i] > c[i + 1]);
    // Interior positions 1..=done are tested eight at a time (AVX2), the rest one by one; only
    // the x86 branch sets it.
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_mut))]
    let mut done = 0;
    #[cfg(target_arch = "x86_64")]
    if has_avx2() && n >= LANES + 2 {
        out.extend((peak(0)).then_some(d_min));
        // SAFETY: AVX2 is present and n >= 10.
        done = unsafe { interior_peaks_avx2(c, s_min, d_min, out) };
    }
    for i in if done == 0 { 0 } else { done + 1 }..n {
        if peak(i) {
            out.push(d_min + i);
        }
    }
}

/// The peaks of [`row_peaks`] at `1..=8 m` (`8 m <= c.len() - 2`, largest such `m`) appended
/// to `out` as `d0 + i`; returns `8 m`. `>=` / `>` as ordered quiet compares: false on NaN,
/// like the scalar tests.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn interior_peaks_avx2(c: &[f32], s_min: f32, d0: usize, out: &mut Vec<usize>) -> usize {
    use std::arch::x86_64::*;
    let end = (c.len() - 2) / LANES * LANES;
    let s = _mm256_set1_ps(s_min);
    let p = c.as_ptr();
    let mut i = 1;
    while i <= end {
        // Reads c[i - 1 ..= i + 8], inside c as i + 8 <= end + 1 <= len - 1.
        let v = _mm256_loadu_ps(p.add(i));
        let l = _mm256_loadu_ps(p.add(i - 1));
        let r = _mm256_loadu_ps(p.add(i + 1));
        let ok = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(v, s),
                _mm256_cmp_ps::<_CMP_GE_OQ>(v, l),
            ),
            _mm256_cmp_ps::<_CMP_GT_OQ>(v, r),
        );
        let mut bits = _mm256_movemask_ps(ok) as u32;
        while bits != 0 {
            out.push(d0 + i + bits.trailing_zeros() as usize);
            bits &= bits - 1;
        }
        i += LANES;
    }
    end
}

/// Per-region centring and left normalisation of one point: `(A - shift S) * inv_R * inv_l`.
struct Norm {
    shift: [f32; N_REGIONS],
    inv_l: [f32; N_REGIONS],
}

/// Block `b` (lanes `j = 8 b + l`, right column `x - d_hi + j`, disparity `d_hi - j`) of the
/// five regions into the curves, which are in disparity order: lane `l` goes to
/// `d = len - 1 - 8 b - l`, and only the lanes with `j < len`.
#[inline(always)]
fn store_block(curves: &mut [&mut [f32]; N_REGIONS], j0: usize, vals: &[[f32; LANES]; N_REGIONS]) {
    for (cv, v) in curves.iter_mut().zip(vals) {
        let len = cv.len();
        for (l, &x) in v.iter().enumerate().take(len - j0) {
            cv[len - 1 - j0 - l] = x;
        }
    }
}

/// The curves of one point, [`LANES`] disparities per block: `src` holds right row `r` of the
/// window at `r * stride`, block `b` reading `src[r * stride + 8 b + c + l]` for tap column `c`
/// and lane `l`; `st[0][k]` / `st[1][k]`: region `k`'s right sums / inverse norms per lane.
/// The AVX2 version ([`blocks_avx2`]) performs the same `f32` operations in the same order
/// (mul then add, no FMA): identical results.
fn blocks_portable(
    t: &[[f32; SIDE]; SIDE],
    src: &[f32],
    stride: usize,
    st: &[[&[f32]; N_REGIONS]; 2],
    norm: &Norm,
    mut curves: [&mut [f32]; N_REGIONS],
) {
    let len = curves[0].len();
    for j0 in (0..len).step_by(LANES) {
        let mut cells = [[[0.0f32; LANES]; 3]; 3];
        for (r, tr) in t.iter().enumerate() {
            let row = &src[r * stride + j0..r * stride + j0 + WIN];
            for (c, &tv) in tr.iter().enumerate() {
                let acc = &mut cells[part_of(r)][part_of(c)];
                for l in 0..LANES {
                    acc[l] += tv * row[c + l];
                }
            }
        }
        let regs = regions_of(&cells.map(|band| band.map(Lanes)));
        let vals: [[f32; LANES]; N_REGIONS] = std::array::from_fn(|k| {
            let (s, iv) = (&st[0][k][j0..j0 + LANES], &st[1][k][j0..j0 + LANES]);
            std::array::from_fn(|l| (regs[k].0[l] - norm.shift[k] * s[l]) * iv[l] * norm.inv_l[k])
        });
        store_block(&mut curves, j0, &vals);
    }
}

/// Right-row values one block of disparities reads: [`LANES`] positions plus the window.
const WIN: usize = LANES + SIDE - 1;

/// Blocks per pass of [`blocks_avx2`]: their nine cells each stay in L1 between template rows.
#[cfg(target_arch = "x86_64")]
const CHUNK: usize = 16;

/// AVX2 body of [`blocks_portable`], template row by template row: the row's seven taps stay
/// in registers while it runs over up to [`CHUNK`] blocks, each block's nine cell accumulators
/// kept in a small array between rows. Every cell still receives its taps in row-major order
/// from zero (same sums); a block then costs its 49 right-row loads and 12 accumulator reloads
/// instead of 49 + 49 template broadcasts (the loads bounded the block-by-block version).
/// Full blocks are stored with their lanes reversed straight into disparity order.
///
/// # Safety
/// The CPU must support AVX2, `src` must hold `6 * stride + 8 * blocks + 6` values, every
/// `st[i][k]` `8 * blocks` (blocks = `ceil(len / 8)`, `len` the curves' common length).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn blocks_avx2(
    t: &[[f32; SIDE]; SIDE],
    src: &[f32],
    stride: usize,
    st: &[[&[f32]; N_REGIONS]; 2],
    norm: &Norm,
    mut curves: [&mut [f32]; N_REGIONS],
) {
    use std::arch::x86_64::*;
    let len = curves[0].len();
    let blocks = len.div_ceil(LANES);
    debug_assert!(src.len() >= (SIDE - 1) * stride + blocks * LANES + SIDE - 1);
    debug_assert!(st.iter().flatten().all(|v| v.len() >= blocks * LANES));
    debug_assert!(curves.iter().all(|c| c.len() == len));
    let z = _mm256_setzero_ps();
    let shift: [__m256; N_REGIONS] = [
        _mm256_set1_ps(norm.shift[0]),
        _mm256_set1_ps(norm.shift[1]),
        _mm256_set1_ps(norm.shift[2]),
        _mm256_set1_ps(norm.shift[3]),
        _mm256_set1_ps(norm.shift[4]),
    ];
    let inv_l: [__m256; N_REGIONS] = [
        _mm256_set1_ps(norm.inv_l[0]),
        _mm256_set1_ps(norm.inv_l[1]),
        _mm256_set1_ps(norm.inv_l[2]),
        _mm256_set1_ps(norm.inv_l[3]),
        _mm256_set1_ps(norm.inv_l[4]),
    ];
    let rev = _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0);
    // cells[b][3 * band + group]; every entry is written (first row of its band) before read.
    // SAFETY: `acc.read()` below happens only for rows after their band's first one, which
    // wrote the block's three cells of that band (`first`; checked against `part_of` at compile
    // time above); the array of __m256 is 32-byte aligned, so the reads and writes are too.
    let mut cells = std::mem::MaybeUninit::<[[__m256; 9]; CHUNK]>::uninit();
    let cp = cells.as_mut_ptr().cast::<__m256>();
    let base = src.as_ptr();
    for b0 in (0..blocks).step_by(CHUNK) {
        let nb = CHUNK.min(blocks - b0);
        for (r, trow) in t.iter().enumerate() {
            let band = part_of(r);
            // The first row of a band starts its cells from zero (as the sums always did).
            let first = r == 0 || r == SIM_RADIUS || r == SIM_RADIUS + 1;
            let tr: [__m256; SIDE] = std::array::from_fn(|c| _mm256_set1_ps(trow[c]));
            let row = base.add(r * stride + b0 * LANES);
            for b in 0..nb {
                let p = row.add(b * LANES);
                let acc = cp.add(b * 9 + 3 * band);
                let (mut a0, mut a1, mut a2) = if first {
                    (z, z, z)
                } else {
                    (acc.read(), acc.add(1).read(), acc.add(2).read())
                };
                // Left and right groups alternate (each keeps its column order).
                a0 = _mm256_add_ps(a0, _mm256_mul_ps(tr[0], _mm256_loadu_ps(p)));
                a2 = _mm256_add_ps(a2, _mm256_mul_ps(tr[4], _mm256_loadu_ps(p.add(4))));
                a0 = _mm256_add_ps(a0, _mm256_mul_ps(tr[1], _mm256_loadu_ps(p.add(1))));
                a2 = _mm256_add_ps(a2, _mm256_mul_ps(tr[5], _mm256_loadu_ps(p.add(5))));
                a0 = _mm256_add_ps(a0, _mm256_mul_ps(tr[2], _mm256_loadu_ps(p.add(2))));
                a2 = _mm256_add_ps(a2, _mm256_mul_ps(tr[6], _mm256_loadu_ps(p.add(6))));
                a1 = _mm256_add_ps(a1, _mm256_mul_ps(tr[3], _mm256_loadu_ps(p.add(3))));
                acc.write(a0);
                acc.add(1).write(a1);
                acc.add(2).write(a2);
            }
        }
        for b in 0..nb {
            // SAFETY: rows 0, 3 and 4 wrote all nine cells of this block.
            let c: [__m256; 9] = cp.add(b * 9).cast::<[__m256; 9]>().read();
            let (top, mid, bot) = ([c[0], c[1], c[2]], [c[3], c[4], c[5]], [c[6], c[7], c[8]]);
            // regions_of, spelled out with the same association order.
            macro_rules! add {
                ($a:expr, $b:expr) => {
                    _mm256_add_ps($a, $b)
                };
            }
            let left = add!(add!(top[0], mid[0]), bot[0]);
            let right = add!(add!(top[2], mid[2]), bot[2]);
            let upper = add!(add!(top[0], top[1]), top[2]);
            let lower = add!(add!(bot[0], bot[1]), bot[2]);
            let full = add!(add!(add!(add!(left, right), top[1]), mid[1]), bot[1]);
            let regs = [full, left, right, upper, lower];
            let j0 = (b0 + b) * LANES;
            let full_block = j0 + LANES <= len;
            let mut part = [[0.0f32; LANES]; N_REGIONS];
            for k in 0..N_REGIONS {
                let s = _mm256_loadu_ps(st[0][k].as_ptr().add(j0));
                let iv = _mm256_loadu_ps(st[1][k].as_ptr().add(j0));
                let centred = _mm256_sub_ps(regs[k], _mm256_mul_ps(shift[k], s));
                let v = _mm256_mul_ps(_mm256_mul_ps(centred, iv), inv_l[k]);
                if full_block {
                    // Lanes j0..j0+8 are disparities len-1-j0 down to len-8-j0.
                    let dst = curves[k].as_mut_ptr().add(len - LANES - j0);
                    _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(v, rev));
                } else {
                    _mm256_storeu_ps(part[k].as_mut_ptr(), v);
                }
            }
            if !full_block {
                store_block(&mut curves, j0, &part);
            }
        }
    }
}

/// Eight lanes added element-wise (the region sums of [`regions_of`] on whole registers).
#[derive(Clone, Copy)]
struct Lanes([f32; LANES]);

impl std::ops::Add for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn add(self, o: Lanes) -> Lanes {
        Lanes(std::array::from_fn(|l| self.0[l] + o.0[l]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Image;

    /// Xorshift noise in [0, 1), one stream per seed.
    fn unit_noise(s: u64) -> impl FnMut() -> f32 {
        let mut rng = crate::testing::xorshift(s);
        move || (rng() >> 40) as f32 / (1u64 << 24) as f32
    }

    #[test]
    fn avx2_and_portable_curves_are_bit_identical() {
        if !has_avx2() {
            return; // nothing to compare on this CPU
        }
        let mut next = unit_noise(0x2545_f491_4f6c_dd1d);
        let (w, h) = (90, 20);
        let left = Image::new(w, h, (0..w * h).map(|_| next()).collect()).expect("valid");
        let left = left.view();
        let right = Image::new(w, h, (0..w * h).map(|_| next()).collect()).expect("valid");
        let right = right.view();
        let stats = RightStats::new(&right);
        let (mut a, mut b) = (Curves::default(), Curves::default());
        // Full and partial last blocks, spans ending at the image's last pixel (the copy).
        for (x, y, d_hi) in [
            (40, 8, 37),
            (86, 16, 63),
            (86, 10, 8),
            (20, 3, 0),
            (60, 12, 15),
        ] {
            curves_with(true, &left, &right, &stats, x, y, y, d_hi, &mut a);
            curves_with(false, &left, &right, &stats, x, y, y, d_hi, &mut b);
            for k in 0..N_REGIONS {
                for d in 0..=d_hi {
                    let (u, v) = (a.curve[k][d], b.curve[k][d]);
                    assert_eq!(u.to_bits(), v.to_bits(), "x {x} region {k} d {d}");
                }
            }
        }
    }

    #[test]
    fn avx2_and_portable_curves_agree_on_every_size() {
        // Images 7..=70 (and 127..=129) wide, 7 and 9 high; points at both window borders
        // (x = 3, x = W - 4) and inside; every d_hi from 0 to x - 3 (1..=8 blocks: full and
        // partial last blocks, CHUNK boundaries at 128+; spans read in place and from the
        // zero-padded copy at the image's end). Bit equality of all five curves.
        if !has_avx2() {
            return; // nothing to compare on this CPU
        }
        let mut next = unit_noise(0x5851_f42d_4c95_7f2d);
        let (mut a, mut b) = (Curves::default(), Curves::default());
        for w in (7..=70usize).chain([127, 128, 129, 140]) {
            for h in [7usize, 9] {
                let left = Image::new(w, h, (0..w * h).map(|_| next()).collect()).expect("valid");
                let right = Image::new(w, h, (0..w * h).map(|_| next()).collect()).expect("valid");
                let (left, right) = (left.view(), right.view());
                let stats = RightStats::new(&right);
                let mut xs = vec![SIM_RADIUS, w - 1 - SIM_RADIUS, w / 2];
                xs.dedup();
                for &x in &xs {
                    for y in SIM_RADIUS..h - SIM_RADIUS {
                        for d_hi in 0..=x - SIM_RADIUS {
                            curves_with(true, &left, &right, &stats, x, y, y, d_hi, &mut a);
                            curves_with(false, &left, &right, &stats, x, y, y, d_hi, &mut b);
                            for k in 0..N_REGIONS {
                                let same = a.curve[k][..=d_hi]
                                    .iter()
                                    .zip(&b.curve[k][..=d_hi])
                                    .all(|(u, v)| u.to_bits() == v.to_bits());
                                assert!(same, "w {w} h {h} x {x} y {y} d_hi {d_hi} region {k}");
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn row_peaks_match_the_scalar_definition() {
        let mut next = unit_noise(0x9e37_79b9_7f4a_7c15);
        let mut got = Vec::new();
        // Every length 1..=70 (the 8-wide interior tests: 10 = LANES + 2 and up) and a few
        // longer ones.
        for len in (1..=70).chain([97, 130]) {
            // Coarse values: plateaus and exact ties with s_min occur.
            let full: Vec<f32> = (0..len + 3).map(|_| (next() * 8.0).floor() / 8.0).collect();
            for (d_min, s_min) in [(0, 0.5), (1, 0.0), (2, 0.875), (0, 2.0)] {
                let d_hi = len - 1;
                let want: Vec<usize> = (d_min..=d_hi)
                    .filter(|&d| {
                        let c = full[d];
                        c >= s_min
                            && (d == d_min || c >= full[d - 1])
                            && (d == d_hi || c > full[d + 1])
                    })
                    .collect();
                row_peaks(&full, d_min, d_hi, s_min, &mut got);
                assert_eq!(got, want, "len {len} d_min {d_min} s_min {s_min}");
            }
        }
    }

    #[test]
    fn band_statistics_equal_the_whole_image_ones() {
        let (w, h) = (40, 30);
        let data: Vec<f32> = (0..w * h)
            .map(|i| ((i * 7919) % 251) as f32 / 250.0)
            .collect();
        let img = Image::new(w, h, data).expect("valid");
        let img = img.view();
        let full = RightStats::new(&img);
        let mut band = RightStats::default();
        band.fill_band(&img, 9, 17).unwrap();
        for y in 9..17 {
            for k in 0..N_REGIONS {
                assert_eq!(full.sums(k, y), band.sums(k, y));
                assert_eq!(full.inv_norms(k, y), band.inv_norms(k, y));
            }
        }
    }

    /// Run by [`a_band_too_large_to_allocate_is_an_error_and_the_next_band_is_right`] in a
    /// child process: a 4096x512 image whose whole-image band (80 MiB) does not fit under an
    /// address-space limit of 32 MiB more than is mapped, then a 16-row band that does.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of a_band_too_large_to_allocate_is_an_error_and_the_next_band_is_right"]
    fn band_statistics_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let (w, h) = (4096, 512);
        let data: Vec<f32> = (0..w * h)
            .map(|i| ((i * 7919) % 251) as f32 / 250.0)
            .collect();
        let img = Image::new(w, h, data).expect("valid");
        let img = img.view();
        let full = RightStats::new(&img);
        let mut band = RightStats::default();
        band.fill_band(&img, 0, 8).unwrap();
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (32 << 20));
        match band.fill_band(&img, 0, h) {
            Ok(()) => println!("child: filled {} rows", band.rows),
            Err(e) => println!("child: error: {e}"),
        }
        // The failed call left the previous band as it was; the next one is right.
        let same = |b: &RightStats, ys: std::ops::Range<usize>| {
            ys.clone().all(|y| {
                (0..N_REGIONS).all(|k| {
                    full.sums(k, y) == b.sums(k, y) && full.inv_norms(k, y) == b.inv_norms(k, y)
                })
            }) && (b.y0, b.rows) == (ys.start, ys.len())
        };
        println!("child: kept {}", same(&band, 0..8));
        band.fill_band(&img, 200, 216).unwrap();
        println!("child: next {}", same(&band, 200..216));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_band_too_large_to_allocate_is_an_error_and_the_next_band_is_right() {
        // fill_band grew its band and scratch with resize: a failed allocation aborted the
        // process (SIGABRT) instead of returning OutOfMemory.
        let stdout = crate::segment::tests::run_oom_child(
            "matching::hopfield::zncc::tests::band_statistics_under_a_memory_limit",
        );
        for want in [
            "child: error: out of memory: the Hopfield matcher's right-image statistics needs \
             80.16 MiB (84049920 bytes)",
            "child: kept true",
            "child: next true",
        ] {
            assert!(stdout.contains(want), "{want} not in {stdout}");
        }
    }

    /// Right image for the scalar checks: hashed noise in [0, 1) with a patch of near-constant
    /// values (standard deviation 5e-4, below [`MIN_WINDOW_STD`]) at x 10..22, y 4..13; the
    /// left image is the right one shifted by 3 px, scaled, with noise added (and the same
    /// patch, so textureless left windows occur too).
    fn scalar_pair(w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
        let mut next = unit_noise(0x2545_f491_4f6c_dd1d);
        let patch = |x: usize, y: usize| (10..22).contains(&x) && (4..13).contains(&y);
        let flat = |x: usize, y: usize| 0.5 + ((x + 2 * y) % 3) as f32 * 6e-4;
        let right: Vec<f32> = (0..w * h)
            .map(|i| {
                let v = next();
                if patch(i % w, i / w) {
                    flat(i % w, i / w)
                } else {
                    v
                }
            })
            .collect();
        let left: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let v = 0.7 * right[y * w + (x + w - 3) % w] + 0.3 * next();
                if patch(x, y) {
                    flat(x, y)
                } else {
                    v
                }
            })
            .collect();
        (left, right)
    }

    /// Sum, mean-free sum of squares and values of region `k` around `(x, y)` (f64).
    fn region_stats(img: &[f32], w: usize, k: usize, x: usize, y: usize) -> (f64, f64, Vec<f64>) {
        let (x0, x1, y0, y1) = REGIONS[k];
        let mut vals = Vec::new();
        for dy in y0..=y1 {
            for dx in x0..=x1 {
                let (u, v) = ((x as isize + dx) as usize, (y as isize + dy) as usize);
                vals.push(img[v * w + u] as f64);
            }
        }
        let n = vals.len() as f64;
        let sum: f64 = vals.iter().sum();
        let q: f64 = vals.iter().map(|v| (v - sum / n) * (v - sum / n)).sum();
        (sum, q, vals)
    }

    /// The right statistics against their definition: every region's window sum and inverse
    /// zero-mean norm where the window fits (0 for a textureless window), 0 elsewhere and in
    /// the padding, and the window mean.
    #[test]
    fn right_statistics_equal_the_definition() {
        let (w, h) = (40, 16);
        let (_, right) = scalar_pair(w, h);
        let img = ImageView::new(w, h, &right).expect("valid");
        let stats = RightStats::new(&img);
        let mut flat_windows = 0;
        for y in 0..h {
            for k in 0..N_REGIONS {
                let (sums, invs) = (stats.sums(k, y), stats.inv_norms(k, y));
                assert_eq!(sums.len(), w + LANES);
                for x in 0..w + LANES {
                    let fits = (SIM_RADIUS..w - SIM_RADIUS).contains(&x)
                        && (SIM_RADIUS..h - SIM_RADIUS).contains(&y);
                    if !fits {
                        assert_eq!((sums[x], invs[x]), (0.0, 0.0), "region {k} at ({x}, {y})");
                        continue;
                    }
                    let (sum, q, vals) = region_stats(&right, w, k, x, y);
                    let n = vals.len() as f64;
                    assert!(
                        (sums[x] as f64 - sum).abs() < 1e-4,
                        "region {k} at ({x}, {y})"
                    );
                    let want = if q >= n * MIN_WINDOW_STD * MIN_WINDOW_STD {
                        1.0 / q.sqrt()
                    } else {
                        flat_windows += 1;
                        0.0
                    };
                    let tol = 1e-5 * want.max(1.0);
                    assert!(
                        (invs[x] as f64 - want).abs() < tol,
                        "region {k} at ({x}, {y})"
                    );
                    if k == FULL {
                        assert!((stats.mean(x, y) as f64 - sum / n).abs() < 1e-6);
                    }
                }
            }
        }
        assert!(flat_windows > 0);
    }

    /// The five curves of both paths against ZNCC computed from its definition in `f64`
    /// (0 where either window is textureless), and the left window's mean, at every point,
    /// row offset -1..=1 and disparity of a small image.
    #[test]
    fn curves_equal_the_definition() {
        let (w, h) = (40, 16);
        let (left, right) = scalar_pair(w, h);
        let (lv, rv) = (
            ImageView::new(w, h, &left).expect("valid"),
            ImageView::new(w, h, &right).expect("valid"),
        );
        let stats = RightStats::new(&rv);
        let mut c = Curves::default();
        let (mut textureless, mut strong) = (0, 0);
        for y in SIM_RADIUS..h - SIM_RADIUS {
            for yr in y.saturating_sub(1).max(SIM_RADIUS)..=(y + 1).min(h - 1 - SIM_RADIUS) {
                for x in SIM_RADIUS..w - SIM_RADIUS {
                    let d_hi = x - SIM_RADIUS;
                    for avx2 in [false, true] {
                        curves_with(avx2, &lv, &rv, &stats, x, y, yr, d_hi, &mut c);
                        let (lsum, _, _) = region_stats(&left, w, FULL, x, y);
                        assert!((c.left_mean as f64 - lsum / 49.0).abs() < 1e-6);
                        for k in 0..N_REGIONS {
                            let (ls, lq, lvals) = region_stats(&left, w, k, x, y);
                            let n = lvals.len() as f64;
                            for d in 0..=d_hi {
                                let (rs, rq, rvals) = region_stats(&right, w, k, x - d, yr);
                                let min = n * MIN_WINDOW_STD * MIN_WINDOW_STD;
                                let want = if lq < min || rq < min {
                                    textureless += 1;
                                    0.0
                                } else {
                                    let cross: f64 = lvals
                                        .iter()
                                        .zip(&rvals)
                                        .map(|(a, b)| (a - ls / n) * (b - rs / n))
                                        .sum();
                                    cross / (lq * rq).sqrt()
                                };
                                strong += usize::from(want > 0.9);
                                let got = c.curve[k][d] as f64;
                                assert!(
                                    (got - want).abs() < 1e-4,
                                    "avx2 {avx2} ({x}, {y}) yr {yr} region {k} d {d}: {got} vs {want}"
                                );
                            }
                        }
                    }
                }
            }
        }
        assert!(textureless > 0 && strong > 0);
    }

    /// The largest value for every length around the lane width, negative values included;
    /// `f32::MIN` for none.
    /// The textureless limit [`MIN_WINDOW_STD`] on both sides: a checkerboard `0.5 +- a` (every
    /// region's standard deviation within 0.2 % of `a`) is defined at `a = 1.2e-3` (ZNCC 1
    /// against itself), undefined (0) at `a = 0.8e-3`, on the left or on the right.
    #[test]
    fn textureless_limit_is_the_window_standard_deviation() {
        let (w, h) = (20, 16);
        let board = |a: f32| -> Vec<f32> {
            (0..w * h)
                .map(|i| {
                    if (i % w + i / w) % 2 == 0 {
                        0.5 + a
                    } else {
                        0.5 - a
                    }
                })
                .collect()
        };
        let (hi, lo) = (board(1.2e-3), board(0.8e-3));
        let mut c = Curves::default();
        for (left, right, defined) in [(&hi, &hi, true), (&lo, &hi, false), (&hi, &lo, false)] {
            let (lv, rv) = (
                ImageView::new(w, h, left).expect("valid"),
                ImageView::new(w, h, right).expect("valid"),
            );
            let stats = RightStats::new(&rv);
            for k in 0..N_REGIONS {
                let inv = stats.inv_norms(k, 8)[10];
                assert_eq!(inv > 0.0, std::ptr::eq(right, &hi), "region {k}");
            }
            zncc_curves(&lv, &rv, &stats, 10, 8, 8, 2, &mut c);
            for k in 0..N_REGIONS {
                let v = c.curve[k][0];
                if defined {
                    assert!((v - 1.0).abs() < 1e-3, "region {k}: {v}");
                } else {
                    assert_eq!(v, 0.0, "region {k}");
                }
            }
        }
    }

    #[test]
    fn max_of_is_the_largest_value() {
        assert_eq!(max_of(&[]), f32::MIN);
        for n in 1..=20 {
            let v: Vec<f32> = (0..n).map(|i| -1.0 - ((i * 7) % 5) as f32).collect();
            for peak in 0..n {
                let mut v = v.clone();
                v[peak] = -0.5;
                assert_eq!(max_of(&v), -0.5, "n {n} peak {peak}");
            }
        }
    }
}
