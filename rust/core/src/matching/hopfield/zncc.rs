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
//! from `f64` cell sums computed once per image ([`RightStats`]).

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

/// Disparities evaluated together: one AVX2 register of `f32`.
const LANES: usize = 8;

fn region_n(k: usize) -> usize {
    let (x0, x1, y0, y1) = REGIONS[k];
    ((x1 - x0 + 1) * (y1 - y0 + 1)) as usize
}

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

/// Scratch of [`stats_row`] (`f64`, one image row each): vertical sums of the top band (rows
/// -3..=-1), the bottom band (1..=3) and all seven rows, for values (`v[0..3]`) and squares
/// (`v[3..6]`); `h[i][x] = v[i][x] + v[i][x + 1] + v[i][x + 2]`.
#[derive(Debug, Clone, Default)]
struct StatsScratch {
    v: [Vec<f64>; 6],
    h: [Vec<f64>; 6],
}

/// `out[x] = a[x] + b[x] + c[x]` in `f64` (values, or squares when `square`).
#[inline(always)]
fn sum3(out: &mut [f64], a: &[f32], b: &[f32], c: &[f32], square: bool) {
    let f = |v: f32| {
        let v = v as f64;
        if square {
            v * v
        } else {
            v
        }
    };
    for (((o, &a), &b), &c) in out.iter_mut().zip(a).zip(b).zip(c) {
        *o = f(a) + f(b) + f(c);
    }
}

/// Statistics of image row `y` (`SIM_RADIUS <= y < H - SIM_RADIUS`) into `chunk`
/// (`2 * N_REGIONS * stride` values).
fn fill_row(img: &Image, y: usize, stride: usize, s: &mut StatsScratch, chunk: &mut [f32]) {
    let w = img.width;
    let rows: [&[f32]; SIDE] = std::array::from_fn(|r| &img.data[(y + r - SIM_RADIUS) * w..][..w]);
    let (sums, invs) = chunk.split_at_mut(N_REGIONS * stride);
    stats_row(&rows, s, stride, sums, invs);
}

simd_fn! {
/// Sums and inverse norms of the five regions along one row (`rows`: the 7 image rows around
/// it), written to `sums` / `invs` (`N_REGIONS` rows of `stride` values each).
fn stats_row(rows: &[&[f32]; SIDE], s: &mut StatsScratch, stride: usize, sums: &mut [f32], invs: &mut [f32]) {
    let w = rows[0].len();
    for a in s.v.iter_mut().chain(s.h.iter_mut()) {
        a.resize(w, 0.0); // only grows: every value read below is overwritten first
    }
    for (i, square) in [(0, false), (3, true)] {
        let [top, bot, all] = &mut s.v[i..i + 3] else {
            return; // unreachable: v has six rows
        };
        sum3(top, rows[0], rows[1], rows[2], square);
        sum3(bot, rows[4], rows[5], rows[6], square);
        for (((o, &t), &b), &m) in all.iter_mut().zip(top.iter()).zip(bot.iter()).zip(rows[3]) {
            let m = m as f64;
            *o = t + if square { m * m } else { m } + b;
        }
    }
    for (v, h) in s.v.iter().zip(s.h.iter_mut()) {
        for (((o, &a), &b), &c) in h.iter_mut().zip(v).zip(&v[1..]).zip(&v[2..]) {
            *o = a + b + c;
        }
    }
    // Region k: (vertical sums i, horizontal parts): full / top / bottom = left 3 + centre +
    // right 3 columns of the all / top / bottom band sums; left / right = 3 columns of all.
    const PARTS: [(usize, bool, bool, bool); N_REGIONS] = [
        (2, true, true, true),
        (2, true, false, false),
        (2, false, false, true),
        (0, true, true, true),
        (1, true, true, true),
    ];
    let xs = SIM_RADIUS..w - SIM_RADIUS;
    let n_x = xs.len();
    for (k, &(i, l, c, r)) in PARTS.iter().enumerate() {
        let n = region_n(k) as f64;
        let min_n2 = n * MIN_WINDOW_STD * MIN_WINDOW_STD;
        let part = |a: usize| -> (&[f64], &[f64], &[f64]) {
            (&s.h[a][..n_x], &s.v[a][SIM_RADIUS..SIM_RADIUS + n_x], &s.h[a][SIM_RADIUS + 1..SIM_RADIUS + 1 + n_x])
        };
        let (sl, sc, sr) = part(i);
        let (ql, qc, qr) = part(3 + i);
        let srow = &mut sums[k * stride + SIM_RADIUS..k * stride + SIM_RADIUS + n_x];
        let irow = &mut invs[k * stride + SIM_RADIUS..k * stride + SIM_RADIUS + n_x];
        // The parts as compile-time flags: with run-time ones the vectoriser turned the skipped
        // loads into masked loads (microcoded on AMD). Same sums in the same order.
        let f = (n, min_n2, (sl, sc, sr), (ql, qc, qr), srow, irow);
        match (l, c, r) {
            (true, true, true) => region_row::<true, true, true>(f),
            (true, false, false) => region_row::<true, false, false>(f),
            (false, false, true) => region_row::<false, false, true>(f),
            _ => unreachable!("PARTS has three patterns"),
        }
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

/// Sum and inverse norm of one region along a row, from its left / centre / right parts.
#[inline(always)]
fn region_row<const L: bool, const C: bool, const R: bool>(args: RegionArgs<'_>) {
    let (n, min_n2, (sl, sc, sr), (ql, qc, qr), srow, irow) = args;
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
    for x in 0..srow.len().min(irow.len()) {
        let sm = pick(sl, sc, sr, x);
        let sq = pick(ql, qc, qr, x);
        let n2 = sq - sm * sm / n;
        srow[x] = sm as f32;
        irow[x] = if n2 >= min_n2 {
            1.0 / (n2 as f32).sqrt()
        } else {
            0.0
        };
    }
}

impl RightStats {
    /// Statistics of every row of `img` (row-parallel).
    pub fn new(img: &Image) -> Self {
        let (w, h) = img.size();
        let stride = w + LANES;
        let row_len = 2 * N_REGIONS * stride;
        let mut buf = vec![0.0f32; row_len * h];
        if w >= SIDE && h >= SIDE {
            buf.par_chunks_mut(row_len)
                .enumerate()
                .skip(SIM_RADIUS)
                .take(h - 2 * SIM_RADIUS)
                .for_each_init(StatsScratch::default, |s, (y, chunk)| {
                    fill_row(img, y, stride, s, chunk);
                });
        }
        RightStats {
            stride,
            y0: 0,
            rows: h,
            buf,
            scratch: StatsScratch::default(),
        }
    }

    /// Recomputes `self` for the rows `y_lo..y_hi` of `img` only (reusing its buffers).
    pub fn fill_band(&mut self, img: &Image, y_lo: usize, y_hi: usize) {
        let (w, h) = img.size();
        let y_hi = y_hi.min(h);
        let y_lo = y_lo.min(y_hi);
        self.stride = w + LANES;
        self.y0 = y_lo;
        self.rows = y_hi - y_lo;
        let row_len = 2 * N_REGIONS * self.stride;
        self.buf.clear();
        self.buf.resize(row_len * self.rows, 0.0);
        if w < SIDE || h < SIDE {
            return;
        }
        let lo = y_lo.max(SIM_RADIUS);
        let hi = y_hi.min(h - SIM_RADIUS);
        for y in lo..hi {
            let o = (y - y_lo) * row_len;
            fill_row(
                img,
                y,
                self.stride,
                &mut self.scratch,
                &mut self.buf[o..o + row_len],
            );
        }
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

    /// Mean of the right 7x7 window centred at `(x, y)` (0 where it does not fit).
    pub fn mean(&self, x: usize, y: usize) -> f32 {
        self.sums(FULL, y)[x] / region_n(FULL) as f32
    }
}

/// Reusable buffers of [`zncc_curves`].
#[derive(Debug, Clone, Default)]
pub struct Curves {
    /// The 7 right rows of the search span, zero-padded to whole blocks of [`LANES`].
    rbuf: Vec<f32>,
    /// `curve[k][d]`: ZNCC of region `k` at disparity `d = 0..=d_hi` (0 = undefined; entries
    /// past `d_hi` are stale).
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
    let blocks = len.div_ceil(LANES);
    let span = blocks * LANES + SIDE - 1;
    // Template cell sums (values, squares) in f64: region means and zero-mean norms.
    let mut tmpl = [[0.0f32; SIDE]; SIDE];
    let mut cs = [[0.0f64; 3]; 3];
    let mut cq = [[0.0f64; 3]; 3];
    for (r, row) in tmpl.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = left.at(x + c - SIM_RADIUS, y + r - SIM_RADIUS);
            let f = *v as f64;
            cs[part_of(r)][part_of(c)] += f;
            cq[part_of(r)][part_of(c)] += f * f;
        }
    }
    let (rs, rq) = (regions_of(&cs), regions_of(&cq));
    let c = rs[FULL] / region_n(FULL) as f64;
    let mut shift = [0.0f32; N_REGIONS];
    let mut inv_l = [0.0f32; N_REGIONS];
    for k in 0..N_REGIONS {
        let n = region_n(k) as f64;
        let q = rq[k] - rs[k] * rs[k] / n;
        shift[k] = (rs[k] / n - c) as f32;
        // 0 for a textureless left region: its whole curve is then 0 (undefined).
        if q >= n * MIN_WINDOW_STD * MIN_WINDOW_STD {
            inv_l[k] = (1.0 / q.sqrt()) as f32;
        }
    }
    out.left_mean = c as f32;
    let mut t = [[0.0f32; SIDE]; SIDE];
    for (tr, lr) in t.iter_mut().zip(&tmpl) {
        for (tv, &lv) in tr.iter_mut().zip(lr) {
            *tv = (lv as f64 - c) as f32;
        }
    }
    // Right rows yr-3..=yr+3, columns x - d_hi - 3 .. x + 3 (+ zero padding of the last block).
    let w = right.width;
    let x0 = x - d_hi - SIM_RADIUS;
    let avail = (len + SIDE - 1).min(w - x0);
    // Only grows; lanes past `len` read stale (finite) values and are never stored.
    if out.rbuf.len() < SIDE * span {
        out.rbuf.resize(SIDE * span, 0.0);
    }
    for r in 0..SIDE {
        let src = &right.data[(yr + r - SIM_RADIUS) * w + x0..][..avail];
        out.rbuf[r * span..r * span + avail].copy_from_slice(src);
    }
    let xr_lo = x - d_hi;
    // Lanes past `len` read the padding of the statistics rows and are never stored.
    let sums: [&[f32]; N_REGIONS] = std::array::from_fn(|k| &stats.sums(k, yr)[xr_lo..]);
    let invs: [&[f32]; N_REGIONS] = std::array::from_fn(|k| &stats.inv_norms(k, yr)[xr_lo..]);
    for cv in out.curve.iter_mut() {
        if cv.len() < blocks * LANES {
            cv.resize(blocks * LANES, 0.0);
        }
    }
    let rbuf = &out.rbuf;
    let norm = Norm { shift, inv_l };
    let avx2 = has_avx2();
    for bl in 0..blocks {
        let j0 = bl * LANES;
        let rows: [&[f32]; SIDE] = std::array::from_fn(|r| &rbuf[r * span + j0..r * span + j0 + WIN]);
        let st: [[&[f32]; N_REGIONS]; 2] = [
            std::array::from_fn(|k| &sums[k][j0..j0 + LANES]),
            std::array::from_fn(|k| &invs[k][j0..j0 + LANES]),
        ];
        let vals = block_zncc(avx2, &t, &rows, &st, &norm);
        for (cv, v) in out.curve.iter_mut().zip(&vals) {
            if let Some(dst) = cv[j0..].first_chunk_mut::<LANES>() {
                *dst = *v;
            }
        }
    }
    // Index j = xr - xr_lo = d_hi - d: reverse into disparity order.
    for cv in out.curve.iter_mut() {
        cv[..len].reverse();
    }
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

/// Right-row values one block of disparities reads: [`LANES`] positions plus the window.
const WIN: usize = LANES + SIDE - 1;

/// Per-region centring and left normalisation of one point: `(A - shift S) * inv_R * inv_l`.
struct Norm {
    shift: [f32; N_REGIONS],
    inv_l: [f32; N_REGIONS],
}

/// Does the running CPU have AVX2 (checked once per point; the answer is cached by std)?
#[inline]
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// ZNCC of the five regions for one block of [`LANES`] disparities. `rows[r]`: right row `r`
/// of the window from the block's first lane ([`WIN`] values); `st[0][k]` / `st[1][k]`: region
/// `k`'s right sums / inverse norms per lane ([`LANES`] values). The AVX2 and the portable versions perform the
/// same `f32` operations in the same order (mul then add, no FMA): identical results.
#[inline]
fn block_zncc(
    avx2: bool,
    t: &[[f32; SIDE]; SIDE],
    rows: &[&[f32]; SIDE],
    st: &[[&[f32]; N_REGIONS]; 2],
    norm: &Norm,
) -> [[f32; LANES]; N_REGIONS] {
    let fits = rows.iter().all(|r| r.len() >= WIN) && st.iter().flatten().all(|v| v.len() >= LANES);
    debug_assert!(fits);
    #[cfg(target_arch = "x86_64")]
    if avx2 && fits {
        // SAFETY: AVX2 is present (checked by the caller) and every row holds WIN values.
        return unsafe { block_zncc_avx2(t, rows, st, norm) };
    }
    let _ = avx2;
    let mut cells = [[[0.0f32; LANES]; 3]; 3];
    for (r, (tr, row)) in t.iter().zip(rows).enumerate() {
        for (c, &tv) in tr.iter().enumerate() {
            let acc = &mut cells[part_of(r)][part_of(c)];
            for l in 0..LANES {
                acc[l] += tv * row[c + l];
            }
        }
    }
    let regs = regions_of(&cells.map(|band| band.map(Lanes)));
    std::array::from_fn(|k| {
        std::array::from_fn(|l| {
            (regs[k].0[l] - norm.shift[k] * st[0][k][l]) * st[1][k][l] * norm.inv_l[k]
        })
    })
}

/// AVX2 body of [`block_zncc`]: the nine cell accumulators live in registers.
///
/// # Safety
/// The CPU must support AVX2, every `rows[r]` must hold at least [`WIN`] values and every
/// `st[i][k]` at least [`LANES`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn block_zncc_avx2(
    t: &[[f32; SIDE]; SIDE],
    rows: &[&[f32]; SIDE],
    st: &[[&[f32]; N_REGIONS]; 2],
    norm: &Norm,
) -> [[f32; LANES]; N_REGIONS] {
    use std::arch::x86_64::*;
    // The seven taps of template row `r` on right row `r`, into the band's three cells
    // (a macro, not a function: every intrinsic must sit inside this AVX2 function).
    macro_rules! band {
        ($cells:ident, $r:expr) => {{
            let (tr, row) = (&t[$r], rows[$r].as_ptr());
            for c in 0..SIDE {
                let g = part_of(c);
                let v = _mm256_loadu_ps(row.add(c));
                $cells[g] = _mm256_add_ps($cells[g], _mm256_mul_ps(_mm256_set1_ps(tr[c]), v));
            }
        }};
    }
    let z = _mm256_setzero_ps();
    let (mut top, mut mid, mut bot) = ([z; 3], [z; 3], [z; 3]);
    for r in 0..SIM_RADIUS {
        band!(top, r);
    }
    band!(mid, SIM_RADIUS);
    for r in SIM_RADIUS + 1..SIDE {
        band!(bot, r);
    }
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
    let mut out = [[0.0f32; LANES]; N_REGIONS];
    for k in 0..N_REGIONS {
        let s = _mm256_loadu_ps(st[0][k].as_ptr());
        let iv = _mm256_loadu_ps(st[1][k].as_ptr());
        let centred = _mm256_sub_ps(regs[k], _mm256_mul_ps(_mm256_set1_ps(norm.shift[k]), s));
        let v = _mm256_mul_ps(_mm256_mul_ps(centred, iv), _mm256_set1_ps(norm.inv_l[k]));
        _mm256_storeu_ps(out[k].as_mut_ptr(), v);
    }
    out
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

    #[test]
    fn avx2_and_portable_blocks_are_bit_identical() {
        if !has_avx2() {
            return; // nothing to compare on this CPU
        }
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..50 {
            let t: [[f32; SIDE]; SIDE] =
                std::array::from_fn(|_| std::array::from_fn(|_| next() - 0.5));
            let data: Vec<Vec<f32>> = (0..SIDE)
                .map(|_| (0..WIN).map(|_| next()).collect())
                .collect();
            let rows: [&[f32]; SIDE] = std::array::from_fn(|r| data[r].as_slice());
            let st_data: Vec<Vec<f32>> = (0..2 * N_REGIONS)
                .map(|_| (0..LANES).map(|_| next()).collect())
                .collect();
            let st: [[&[f32]; N_REGIONS]; 2] = std::array::from_fn(|i| {
                std::array::from_fn(|k| st_data[i * N_REGIONS + k].as_slice())
            });
            let norm = Norm {
                shift: std::array::from_fn(|_| next() - 0.5),
                inv_l: std::array::from_fn(|_| next() + 0.5),
            };
            let a = block_zncc(true, &t, &rows, &st, &norm);
            let b = block_zncc(false, &t, &rows, &st, &norm);
            for k in 0..N_REGIONS {
                for l in 0..LANES {
                    assert_eq!(a[k][l].to_bits(), b[k][l].to_bits(), "region {k} lane {l}");
                }
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
        let full = RightStats::new(&img);
        let mut band = RightStats::default();
        band.fill_band(&img, 9, 17);
        for y in 9..17 {
            for k in 0..N_REGIONS {
                assert_eq!(full.sums(k, y), band.sums(k, y));
                assert_eq!(full.inv_norms(k, y), band.inv_norms(k, y));
            }
        }
    }
}
