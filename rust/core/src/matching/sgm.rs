//! Semi-global matching on a census cost: the dense map's completion where the Gabor channel has
//! no value, and its second opinion where it has one (issue 5; algorithms.md A.9 found that a
//! filled SGBM is only beaten with global aggregation).
//!
//! Steps (NumPy reference: `tests/reference/sgm_ref.py`; integer arithmetic, so the two agree
//! exactly):
//! 1. 9x7 census of each image (bit set where the neighbour is darker than the centre; borders
//!    replicated); the cost `C(x, d)` is the Hamming distance of the codes at `x` and `x - d`;
//!    where `x - d` leaves the image, the best cost of the levels inside plus
//!    [`OUTSIDE_MARGIN`] (nearly neutral).
//! 2. Aggregation along 8 paths (Hirschmueller 2008) with P1 for a 1-level change and an
//!    intensity-adaptive P2 = `p2 / (1 + floor(|dI| / gamma))` (at least `p1 + 1`; `dI` in 0-255
//!    grey levels) for a jump: an edge in the image is where a depth jump may be.
//!    The four paths that come from above or the left run in one raster pass, the other four in a
//!    reverse raster pass; the two passes run on two threads, so the output does not depend on the
//!    thread count. They meet row by row: the first to reach a row leaves its sum there, the
//!    second adds its own and runs step 3 on the row (one volume of sums held, not two).
//! 3. Winner-take-all, a uniqueness test (no level beyond +-1 within `uniqueness` % of the
//!    winner), a left-right check against the right view's winners read off the same volume
//!    (within `lr_tol` levels), and the parabola vertex as the sub-pixel part.
//! 4. The left band, where the range reaches outside the right image (`x < d_max`): only the
//!    levels that land inside compete, and the pixel is reported only if its winner's right pixel
//!    lies at least `edge_margin` columns inside (`x - d >= edge_margin`). A pixel whose true match
//!    lies outside has its winner pushed against the edge (`x - d` near 0). With the margin 4
//!    (and [`OUTSIDE_MARGIN`]), 35-74 % of the band's GT pixels are reported on 16 GT scenes
//!    (tsukuba's band is too narrow), 87-99 % of them within 2 px (KITTI 78 %, about its rate
//!    inside); without the margin, wood2's band errors moved its bad-2.0 after the row fill
//!    from 1.9 to 3.7 %.

use std::sync::Mutex;

use rayon::prelude::*;

use crate::alloc::{try_collect, try_filled, try_reserve_len, try_zeroed};
use crate::error::{CoreError, Result};
use crate::image::ImageView;
use crate::simd::simd_fn;

/// Census half-window along x.
pub const RX: usize = 4;
/// Census half-window along y.
pub const RY: usize = 3;
/// Cost of every level of a pixel whose whole range falls outside the right image: one more
/// than the 62 census bits (levels outside beside levels inside cost the best inside level plus
/// [`OUTSIDE_MARGIN`]).
pub const OUTSIDE: u8 = ((2 * RX + 1) * (2 * RY + 1)) as u8;
/// What a level whose right pixel lies outside the image costs above the pixel's best inside
/// level. Over the 17 GT scenes (fused map's mean ratio to SGBM-3WAY + fill): 0 -> 0.658, 2 ->
/// 0.638, 4 -> 0.632, 5 -> 0.633, 6 -> 0.631, 8 -> 0.640, mean inside cost 0.663; the census map
/// alone was best at 5 (0.712; 0 -> 0.750).
pub const OUTSIDE_MARGIN: u8 = 5;
/// Pad value around each path-cost vector: larger than any path cost plus P1, far from overflow.
const BIG: u16 = 16_000;
/// Largest P2: eight path costs of at most `OUTSIDE + p2` each must fit a `u16` sum.
pub const MAX_P2: u16 = 4000;

/// Parameters of [`sgm_disparity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SgmParams {
    /// Penalty of a 1-level disparity change between path neighbours.
    pub p1: u16,
    /// Penalty of a larger jump, before the intensity adaptation.
    pub p2: u16,
    /// Grey levels (0-255) of intensity step that halve P2 once (`p2 / (1 + floor(step / gamma))`).
    pub gamma: f32,
    /// A level beyond +-1 of the winner within this percentage of its cost rejects the pixel.
    pub uniqueness: u32,
    /// Largest difference, in levels, between the left winner and the right view's winner.
    pub lr_tol: u32,
    /// In the left band (`x < d_max`), the fewest columns between the winner's right pixel and
    /// the right image's left edge (`x - d`) for the pixel to be reported.
    pub edge_margin: u32,
    /// Aggregation paths: 8 (Hirschmueller's, two passes over a cost volume) or 3 (left to
    /// right, right to left and top to bottom, OpenCV SGBM-3WAY's set, in one pass with no
    /// volume: [`sgm_three_paths`]).
    pub paths: u8,
}

impl Default for SgmParams {
    fn default() -> Self {
        SgmParams {
            p1: 8,
            p2: 96,
            gamma: 16.0,
            uniqueness: 5,
            lr_tol: 1,
            edge_margin: 4,
            paths: 8,
        }
    }
}

impl SgmParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        if self.p1 == 0 || self.p1 >= self.p2 {
            return Err(CoreError::param(
                "p1",
                format!(
                    "expected 0 < p1 < p2, got p1 = {}, p2 = {}",
                    self.p1, self.p2
                ),
            ));
        }
        if self.p2 > MAX_P2 {
            return Err(CoreError::param(
                "p2",
                format!("expected at most {MAX_P2}, got {}", self.p2),
            ));
        }
        if !(self.gamma.is_finite() && self.gamma > 0.0) {
            return Err(CoreError::param(
                "gamma",
                format!("expected a positive number, got {}", self.gamma),
            ));
        }
        if self.paths != 8 && self.paths != 3 {
            return Err(CoreError::param(
                "paths",
                format!("expected 8 or 3, got {}", self.paths),
            ));
        }
        if self.uniqueness > 100 {
            return Err(CoreError::param(
                "uniqueness",
                format!("expected a percentage in [0, 100], got {}", self.uniqueness),
            ));
        }
        Ok(())
    }
}

/// Interior columns of a census row coded at once: their two halves of the code fit in two
/// stack blocks of u32 (L1-resident; no allocation per row).
const CENSUS_BLOCK: usize = 64;

simd_fn! {
    /// One census row: `rows` are the 7 image rows around it (clamped at the image's edges).
    /// The interior columns are coded a block at a time in two u32 halves (bits 0-31, 32-61):
    /// a u64 lane per pixel and bit took twice the vector work for the same bits.
    fn census_row(rows: &[&[f32]], code: &mut [u64]) {
        let w = code.len();
        let centre = rows[RY];
        let (lo, hi) = if w > 2 * RX { (RX, w - RX) } else { (0, 0) };
        let mut x0 = lo;
        while x0 < hi {
            let n = CENSUS_BLOCK.min(hi - x0);
            let (mut low, mut high) = ([0u32; CENSUS_BLOCK], [0u32; CENSUS_BLOCK]);
            let ctr = &centre[x0..x0 + n];
            let mut bit = 0u32;
            for (dy, r) in rows.iter().enumerate() {
                for dx in -(RX as isize)..=RX as isize {
                    if dy == RY && dx == 0 {
                        continue;
                    }
                    let src = &r[(x0 as isize + dx) as usize..][..n];
                    let (half, b) = if bit < 32 {
                        (&mut low[..n], bit)
                    } else {
                        (&mut high[..n], bit - 32)
                    };
                    for ((c, &v), &cv) in half.iter_mut().zip(src).zip(ctr) {
                        *c |= u32::from(v < cv) << b;
                    }
                    bit += 1;
                }
            }
            for ((c, &a), &b) in code[x0..x0 + n].iter_mut().zip(&low).zip(&high) {
                *c = u64::from(a) | u64::from(b) << 32;
            }
            x0 += n;
        }
        // The edge columns, with clamped columns.
        for x in (0..lo).chain(hi..w) {
            let mut c = 0u64;
            let mut bit = 0u32;
            for (dy, r) in rows.iter().enumerate() {
                for dx in -(RX as isize)..=RX as isize {
                    if dy == RY && dx == 0 {
                        continue;
                    }
                    let xx = (x as isize + dx).clamp(0, w as isize - 1) as usize;
                    c |= u64::from(r[xx] < centre[x]) << bit;
                    bit += 1;
                }
            }
            code[x] = c;
        }
    }
}

/// 9x7 census codes, row-major: bit `k` (window row-major, centre skipped) set where that
/// neighbour is darker than the centre. [`CoreError::OutOfMemory`] when the codes (8 bytes a
/// pixel) cannot be allocated (a `vec!` aborted the process).
pub fn census(img: ImageView<'_>) -> Result<Vec<u64>> {
    let (w, h) = (img.width, img.height);
    let mut out = try_zeroed::<u64>(w * h, "the census matcher's census codes")?;
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let rows: Vec<&[f32]> = (-(RY as isize)..=RY as isize)
            .map(|dy| {
                let yy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                &img.data[yy * w..(yy + 1) * w]
            })
            .collect();
        census_row(&rows, row);
    });
    Ok(out)
}

simd_fn! {
    /// [`cost_row_impl`] for the baseline and AVX2.
    fn cost_row_simd(
        cl: &[u64],
        cr_rev: &[u64],
        d_min: i64,
        n: usize,
        out: &mut [u8],
        simd: Option<Avx2>,
    ) {
        cost_row_impl(cl, cr_rev, d_min, n, out, simd, None)
    }
}

/// One row of the cost volume, `n` levels per pixel. `wide`: take [`hamming_avx512`] (compiled
/// for AVX-512 as a whole, so that it inlines); else `simd`: [`hamming_avx2`] where a pixel has
/// at least 32 levels inside the image; the compiler's loop otherwise, which the AVX2 build
/// vectorises by a nibble table as well, 16 levels a step. The same integers every way.
fn cost_row_as(
    cl: &[u64],
    cr_rev: &[u64],
    d_min: i64,
    n: usize,
    out: &mut [u8],
    simd: Option<Avx2>,
    wide: Option<Avx512>,
) {
    #[cfg(target_arch = "x86_64")]
    if let Some(t) = wide {
        #[target_feature(enable = "avx2,fma,popcnt,avx512f,avx512bw,avx512vl,avx512vpopcntdq")]
        unsafe fn avx512(
            cl: &[u64],
            cr_rev: &[u64],
            d_min: i64,
            n: usize,
            out: &mut [u8],
            t: Avx512,
        ) {
            cost_row_impl(cl, cr_rev, d_min, n, out, None, Some(t))
        }
        // SAFETY: `t` proves the running CPU has every feature enabled on `avx512`.
        return unsafe { avx512(cl, cr_rev, d_min, n, out, t) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = wide; // no AVX-512 off x86
    cost_row_simd(cl, cr_rev, d_min, n, out, simd)
}

/// [`cost_row_as`]'s body.
#[inline(always)]
fn cost_row_impl(
    cl: &[u64],
    cr_rev: &[u64],
    d_min: i64,
    n: usize,
    out: &mut [u8],
    simd: Option<Avx2>,
    wide: Option<Avx512>,
) {
    let w = cl.len() as i64;
    for (x, cell) in out.chunks_exact_mut(n).enumerate() {
        let a = cl[x];
        // Levels whose right pixel x - d_min - k lies in [0, w).
        let hi = (x as i64 - d_min).min(n as i64 - 1);
        let lo = (x as i64 - d_min - w + 1).max(0);
        if lo > hi {
            cell.fill(OUTSIDE);
            continue;
        }
        let (lo, hi) = (lo as usize, hi as usize);
        // Level k pairs with right pixel x - d_min - k, i.e. entry w - 1 - x + d_min + k of the
        // reversed right row: consecutive levels read consecutive codes (a vectorised popcount).
        let start = (w - 1 - x as i64 + d_min + lo as i64) as usize; // >= 0 by lo's bound
        let right = &cr_rev[start..start + hi + 1 - lo];
        let inside = &mut cell[lo..=hi];
        let fast = match wide {
            Some(t) => hamming_avx512(t, a, right, inside),
            None => simd.and_then(|t| hamming_avx2(t, a, right, inside)),
        };
        let (best, worst) = match fast {
            Some(bw) => bw,
            None => {
                for (v, &b) in inside.iter_mut().zip(right) {
                    *v = (a ^ b).count_ones() as u8;
                }
                let best = inside.iter().fold(OUTSIDE, |m, &v| m.min(v));
                (best, inside.iter().fold(0, |m, &v| m.max(v)))
            }
        };
        // Levels whose right pixel is outside the image cost a little more than the best
        // inside level: nearly neutral, so the paths from the left edge carry only a slight
        // preference for the levels that stay inside (with a high cost a flat region took
        // d_min from the edge, far along the rows; with none, the band's pixels followed the
        // levels outside).
        // Where every inside level costs the same (a flat patch) they stay neutral: nothing
        // to prefer, and a margin there would carry d_min from the edge across a flat image.
        let out = if worst == best {
            best
        } else {
            best.saturating_add(OUTSIDE_MARGIN).min(OUTSIDE)
        };
        cell[..lo].fill(out);
        cell[hi + 1..].fill(out);
    }
}

/// The Hamming costs `out[k] = popcount(a ^ right[k])` of one pixel in AVX-512 (`vpopcntq`,
/// 16 levels a step, the last step masked), and their minimum and maximum; `None` for no
/// levels. [`hamming_avx2`] counts by a nibble table, eleven instructions for four levels.
#[inline(always)]
fn hamming_avx512(_avx512: Avx512, a: u64, right: &[u64], out: &mut [u8]) -> Option<(u8, u8)> {
    let n = out.len();
    if n == 0 || right.len() < n {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: `_avx512` proves the CPU has AVX-512 F, BW, VL and VPOPCNTDQ;
        // `hamming_kernel512` reads `right[..n]` and writes `out[..n]` (the last step through
        // masks), within the lengths checked above.
        Some(unsafe { hamming_kernel512(a, right.as_ptr(), out.as_mut_ptr(), n) })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // Only the AVX-512 kernel reads the code.
        let _ = a;
        None
    }
}

/// [`hamming_avx512`]'s loop.
///
/// # Safety
/// The CPU has AVX-512 F, BW, VL and VPOPCNTDQ; `right` holds `n` codes and `out` `n` bytes,
/// `n >= 1`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512vpopcntdq")]
#[inline]
unsafe fn hamming_kernel512(a: u64, right: *const u64, out: *mut u8, n: usize) -> (u8, u8) {
    use std::arch::x86_64::*;
    let av = _mm512_set1_epi64(a as i64);
    let mut best = _mm_set1_epi8(-1);
    let mut worst = _mm_setzero_si128();
    let whole = n / 16 * 16;
    let mut k = 0;
    while k < whole {
        let x0 = _mm512_xor_si512(_mm512_loadu_si512(right.add(k).cast()), av);
        let x1 = _mm512_xor_si512(_mm512_loadu_si512(right.add(k + 8).cast()), av);
        // Counts of at most 64: each u64 truncated to its low byte, levels in order.
        let b = _mm_unpacklo_epi64(
            _mm512_cvtepi64_epi8(_mm512_popcnt_epi64(x0)),
            _mm512_cvtepi64_epi8(_mm512_popcnt_epi64(x1)),
        );
        _mm_storeu_si128(out.add(k).cast(), b);
        best = _mm_min_epu8(best, b);
        worst = _mm_max_epu8(worst, b);
        k += 16;
    }
    let rest = n - whole;
    if rest > 0 {
        // Masked-off codes are not read (no fault past the row) and their bytes not stored nor
        // counted in the minimum and maximum.
        let km = ((1u32 << rest) - 1) as __mmask16; // rest < 16
        let x0 = _mm512_maskz_loadu_epi64(km as __mmask8, right.add(whole).cast());
        let x1 =
            _mm512_maskz_loadu_epi64((km >> 8) as __mmask8, right.wrapping_add(whole + 8).cast());
        let b = _mm_unpacklo_epi64(
            _mm512_cvtepi64_epi8(_mm512_popcnt_epi64(_mm512_xor_si512(x0, av))),
            _mm512_cvtepi64_epi8(_mm512_popcnt_epi64(_mm512_xor_si512(x1, av))),
        );
        _mm_mask_storeu_epi8(out.add(whole).cast(), km, b);
        best = _mm_mask_min_epu8(best, km, best, b);
        worst = _mm_mask_max_epu8(worst, km, worst, b);
    }
    fold_min_max(best, worst)
}

/// The least of `best`'s 16 bytes and the greatest of `worst`'s: both Hamming kernels' last
/// step, halving the vectors four times.
///
/// # Safety
/// SSE2 only, which every x86_64 CPU has.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn fold_min_max(
    best: std::arch::x86_64::__m128i,
    worst: std::arch::x86_64::__m128i,
) -> (u8, u8) {
    use std::arch::x86_64::*;
    let lo = _mm_min_epu8(best, _mm_srli_si128::<8>(best));
    let hi = _mm_max_epu8(worst, _mm_srli_si128::<8>(worst));
    let lo = _mm_min_epu8(lo, _mm_srli_si128::<4>(lo));
    let hi = _mm_max_epu8(hi, _mm_srli_si128::<4>(hi));
    let lo = _mm_min_epu8(lo, _mm_srli_si128::<2>(lo));
    let hi = _mm_max_epu8(hi, _mm_srli_si128::<2>(hi));
    let lo = _mm_min_epu8(lo, _mm_srli_si128::<1>(lo));
    let hi = _mm_max_epu8(hi, _mm_srli_si128::<1>(hi));
    (_mm_cvtsi128_si32(lo) as u8, _mm_cvtsi128_si32(hi) as u8)
}

/// The Hamming costs `out[k] = popcount(a ^ right[k])` of one pixel in AVX2, 32 levels a
/// vector, and their minimum and maximum; `None` below 32 levels. The compiler's loop counted
/// 16 levels a step and packed each four u64 counts to bytes on their own, then took the
/// minimum and maximum in two more passes.
#[inline(always)]
fn hamming_avx2(_avx2: Avx2, a: u64, right: &[u64], out: &mut [u8]) -> Option<(u8, u8)> {
    let n = out.len();
    if n < 32 || right.len() < n {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    {
        // A tail of under 16 levels is counted one by one: a last vector overlapping the one
        // before would count 32 (teddyH's 129 levels: 160 counted for 129).
        let tail = n % 32;
        let nv = if tail >= 16 { n } else { n - tail };
        // SAFETY: `_avx2` proves the CPU has AVX2; `hamming_kernel` reads `right[..nv]` and
        // writes `out[..nv]`, within the lengths checked above (`32 <= nv <= n`).
        let (mut best, mut worst) =
            unsafe { hamming_kernel(a, right.as_ptr(), out.as_mut_ptr(), nv) };
        for (v, &b) in out[nv..].iter_mut().zip(&right[nv..n]) {
            *v = (a ^ b).count_ones() as u8;
            best = best.min(*v);
            worst = worst.max(*v);
        }
        Some((best, worst))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // Only the AVX2 kernel reads the code.
        let _ = a;
        None
    }
}

/// [`hamming_avx2`]'s loop.
///
/// # Safety
/// The CPU has AVX2; `right` holds `n` codes and `out` `n` bytes, `n >= 32`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn hamming_kernel(a: u64, right: *const u64, out: *mut u8, n: usize) -> (u8, u8) {
    use std::arch::x86_64::*;
    let av = _mm256_set1_epi64x(a as i64);
    let nibble = _mm256_set1_epi8(0x0f);
    #[rustfmt::skip]
    let bits = _mm256_setr_epi8(
        0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,
        0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,
    );
    // After the packs and the quadword permute a lane holds byte pairs 0 2 4 6 1 3 5 7 (of 16
    // levels): back in order.
    #[rustfmt::skip]
    let order = _mm256_setr_epi8(
        0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15,
        0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15,
    );
    let zero = _mm256_setzero_si256();
    let mut best = _mm256_set1_epi8(-1);
    let mut worst = zero;
    let mut k = 0;
    while k < n {
        // The last block ends at level n, overlapping the one before: the levels computed
        // twice get the same values.
        let k0 = k.min(n - 32);
        // Eight vectors of four u64 counts (at most 64 each): levels k0 + 4 i + q.
        let mut s = [zero; 8];
        for (i, si) in s.iter_mut().enumerate() {
            let x = _mm256_xor_si256(_mm256_loadu_si256(right.add(k0 + 4 * i).cast()), av);
            let lo = _mm256_shuffle_epi8(bits, _mm256_and_si256(x, nibble));
            let hi = _mm256_shuffle_epi8(bits, _mm256_and_si256(_mm256_srli_epi16::<4>(x), nibble));
            *si = _mm256_sad_epu8(_mm256_add_epi8(lo, hi), zero);
        }
        // To bytes (no saturation below 65): per 128-bit half, levels 0 1 4 5 8 9 ... of the
        // 32 in the low half and 2 3 6 7 ... in the high one.
        let q0 = _mm256_packus_epi32(
            _mm256_packus_epi32(s[0], s[1]),
            _mm256_packus_epi32(s[2], s[3]),
        );
        let q1 = _mm256_packus_epi32(
            _mm256_packus_epi32(s[4], s[5]),
            _mm256_packus_epi32(s[6], s[7]),
        );
        let b = _mm256_packus_epi16(q0, q1);
        let b = _mm256_shuffle_epi8(_mm256_permute4x64_epi64::<0xd8>(b), order);
        _mm256_storeu_si256(out.add(k0).cast(), b);
        best = _mm256_min_epu8(best, b);
        worst = _mm256_max_epu8(worst, b);
        k += 32;
    }
    let lo = _mm_min_epu8(
        _mm256_castsi256_si128(best),
        _mm256_extracti128_si256::<1>(best),
    );
    let hi = _mm_max_epu8(
        _mm256_castsi256_si128(worst),
        _mm256_extracti128_si256::<1>(worst),
    );
    fold_min_max(lo, hi)
}

/// The cost volume `C[(y * w + x) * n + k]` for disparity `d_min + k`.
pub fn cost_volume(cl: &[u64], cr: &[u64], w: usize, d_min: i64, n: usize) -> Vec<u8> {
    let mut c = Vec::new();
    cost_volume_into(cl, cr, w, d_min, n, &mut c);
    c
}

/// [`cost_volume`] into `c`, resized to fit; every entry is written, so `c` may hold anything
/// before (a kept buffer is reused without a fill).
pub fn cost_volume_into(cl: &[u64], cr: &[u64], w: usize, d_min: i64, n: usize, c: &mut Vec<u8>) {
    c.resize(cl.len() * n, 0);
    c.par_chunks_mut(w * n)
        .enumerate()
        .for_each_init(Vec::new, |rev, (y, row)| {
            rev.clear();
            rev.extend(cr[y * w..(y + 1) * w].iter().rev());
            cost_row_as(
                &cl[y * w..(y + 1) * w],
                rev,
                d_min,
                n,
                row,
                Avx2::detect(),
                Avx512::detect(),
            )
        });
}

/// P2 by intensity step: `lut[q] = max(p2 / (1 + q), p1 + 1)` for `q = floor(step / gamma)`,
/// the last entry standing for every larger `q` (a table instead of a division per path step).
fn p2_table(p: &SgmParams) -> Vec<u16> {
    let len = usize::from(p.p2 / (p.p1 + 1)) + 2;
    (0..len)
        .map(|q| ((u32::from(p.p2) / (1 + q as u32)) as u16).max(p.p1 + 1))
        .collect()
}

/// P2 for a step between grey values `a` and `b` (in [0, 1]).
#[inline(always)]
fn p2_at(a: f32, b: f32, gamma: f32, lut: &[u16]) -> u16 {
    let q = ((a * 255.0 - b * 255.0).abs() / gamma).floor() as usize; // saturates
    lut[q.min(lut.len() - 1)]
}

/// A path cost: `u16` always fits; `u8` fits when [`u8_fits`] (the default parameters), and then
/// halves the path buffers' memory traffic and doubles the lanes per vector. Both give the same
/// integers (see [`PathCost::step`]).
trait PathCost: Copy + Ord {
    /// Pad around each path-cost vector: at least any path cost plus P1.
    const PAD: Self;
    const MAX: Self;
    fn of(v: u16) -> Self;
    fn wide(self) -> u16;
    /// `c + min(b, min(a, n) + p1, lim) - m`, with `m <= min(b, ...)` and `lim = m + p2`.
    fn step(c: Self, a: Self, b: Self, n: Self, p1: Self, lim: Self, m: Self) -> Self;
    /// [`step4`]'s loop by hand-written AVX2 (`n >= 32` levels; `lim_r = m_r + p2_r`); `None`
    /// for the types that have none.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn step4_avx2(
        _avx2: Avx2,
        _lp: &[&[Self]; 4],
        _m: [Self; 4],
        _lim: [Self; 4],
        _p1: Self,
        _c: &[u8],
        _out: &mut [&mut [Self]; 4],
        _acc: &mut [u16],
    ) -> Option<[Self; 4]> {
        None
    }
}

impl PathCost for u16 {
    const PAD: Self = BIG;
    const MAX: Self = u16::MAX;
    #[inline(always)]
    fn of(v: u16) -> Self {
        v
    }
    #[inline(always)]
    fn wide(self) -> u16 {
        self
    }
    #[inline(always)]
    fn step(c: Self, a: Self, b: Self, n: Self, p1: Self, lim: Self, m: Self) -> Self {
        c + b.min(a.min(n) + p1).min(lim) - m
    }
}

impl PathCost for u8 {
    const PAD: Self = u8::MAX;
    const MAX: Self = u8::MAX;
    #[inline(always)]
    fn of(v: u16) -> Self {
        v as u8 // callers pass values below 256 (`u8_fits`)
    }
    #[inline(always)]
    fn wide(self) -> u16 {
        u16::from(self)
    }
    #[inline(always)]
    fn step(c: Self, a: Self, b: Self, n: Self, p1: Self, lim: Self, m: Self) -> Self {
        // `min(a, n) + p1` saturates only above `lim` (<= 255), where the minimum is `lim`
        // either way; the result is at most `c + p2`, below 256 when `u8_fits`.
        (b.min(a.min(n).saturating_add(p1)).min(lim) - m) + c
    }
    #[inline(always)]
    fn step4_avx2(
        avx2: Avx2,
        lp: &[&[Self]; 4],
        m: [Self; 4],
        lim: [Self; 4],
        p1: Self,
        c: &[u8],
        out: &mut [&mut [Self]; 4],
        acc: &mut [u16],
    ) -> Option<[Self; 4]> {
        step4_u8_avx2(avx2, lp, m, lim, p1, c, out, acc)
    }
}

/// Proof that the running CPU has AVX2 (made only by [`Avx2::detect`]): the hand-written
/// path step needs it.
#[derive(Clone, Copy)]
struct Avx2(());

impl Avx2 {
    fn detect() -> Option<Self> {
        crate::simd::has_avx2().then_some(Avx2(()))
    }
}

/// Proof that the running CPU has AVX-512 F, BW, VL and VPOPCNTDQ (made only by
/// [`Avx512::detect`]): the `vpopcntq` Hamming costs need them.
#[derive(Clone, Copy)]
struct Avx512(());

impl Avx512 {
    fn detect() -> Option<Self> {
        crate::simd::has_avx512().then_some(Avx512(()))
    }
}

/// [`step4`] for `u8` path costs in AVX2, 32 levels a vector: the compiler's loop runs 16 (the
/// `u16` sums set its width). The same operations per level as [`PathCost::step`] for `u8`,
/// so the same integers; the four sums are widened in registers (even and odd levels as `u16`
/// lanes, interleaved back at the end). `None` below 32 levels.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn step4_u8_avx2(
    _avx2: Avx2,
    lp: &[&[u8]; 4],
    m: [u8; 4],
    lim: [u8; 4],
    p1: u8,
    c: &[u8],
    out: &mut [&mut [u8]; 4],
    acc: &mut [u16],
) -> Option<[u8; 4]> {
    let n = c.len();
    if n < 32
        || acc.len() < n
        || lp.iter().any(|v| v.len() < n + 2)
        || out.iter().any(|v| v.len() < n + 2)
    {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    {
        let lp = lp.map(|v| v.as_ptr());
        let out = [0, 1, 2, 3].map(|r| out[r].as_mut_ptr());
        // SAFETY: `_avx2` proves the CPU has AVX2; `kernel` reads `lp_r[..n + 2]` and `c[..n]`,
        // writes `out_r[1..n + 1]` and `acc[..n]`, all within the lengths checked above.
        Some(unsafe { kernel(lp, m, lim, p1, c.as_ptr(), n, out, acc.as_mut_ptr()) })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // Only the AVX2 kernel reads the penalties.
        let _ = (m, lim, p1);
        None
    }
}

/// [`step4_u8_avx2`]'s loop.
///
/// # Safety
/// The CPU has AVX2; `lp_r` and `out_r` hold `n + 2` values, `c` and `acc` `n`, `n >= 32`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
#[inline]
unsafe fn kernel(
    lp: [*const u8; 4],
    m: [u8; 4],
    lim: [u8; 4],
    p1: u8,
    c: *const u8,
    n: usize,
    out: [*mut u8; 4],
    acc: *mut u16,
) -> [u8; 4] {
    use std::arch::x86_64::*;
    let pv = _mm256_set1_epi8(p1 as i8);
    let mv = m.map(|v| _mm256_set1_epi8(v as i8));
    let lv = lim.map(|v| _mm256_set1_epi8(v as i8));
    let low = _mm256_set1_epi16(0xff);
    let mut mn = [_mm256_set1_epi8(-1); 4];
    let mut k = 0;
    while k < n {
        // The last block ends at level n, overlapping the one before: the levels computed
        // twice get the same values (inputs and outputs are distinct buffers).
        let k0 = k.min(n - 32);
        let cv = _mm256_loadu_si256(c.add(k0).cast());
        let (mut even, mut odd) = (_mm256_setzero_si256(), _mm256_setzero_si256());
        for r in 0..4 {
            let a = _mm256_loadu_si256(lp[r].add(k0).cast());
            let b = _mm256_loadu_si256(lp[r].add(k0 + 1).cast());
            let nx = _mm256_loadu_si256(lp[r].add(k0 + 2).cast());
            let t = _mm256_adds_epu8(_mm256_min_epu8(a, nx), pv);
            let t = _mm256_min_epu8(_mm256_min_epu8(b, t), lv[r]);
            let v = _mm256_add_epi8(_mm256_sub_epi8(t, mv[r]), cv);
            _mm256_storeu_si256(out[r].add(k0 + 1).cast(), v);
            mn[r] = _mm256_min_epu8(mn[r], v);
            even = _mm256_add_epi16(even, _mm256_and_si256(v, low));
            odd = _mm256_add_epi16(odd, _mm256_srli_epi16::<8>(v));
        }
        // Per 128-bit half: levels 0-7 | 16-23 and 8-15 | 24-31, then in order.
        let lo = _mm256_unpacklo_epi16(even, odd);
        let hi = _mm256_unpackhi_epi16(even, odd);
        _mm256_storeu_si256(
            acc.add(k0).cast(),
            _mm256_permute2x128_si256::<0x20>(lo, hi),
        );
        _mm256_storeu_si256(
            acc.add(k0 + 16).cast(),
            _mm256_permute2x128_si256::<0x31>(lo, hi),
        );
        k += 32;
    }
    mn.map(|v| {
        let x = _mm_min_epu8(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
        let x = _mm_min_epu8(x, _mm_srli_epi16::<8>(x));
        let x = _mm_minpos_epu16(_mm_and_si128(x, _mm_set1_epi16(0xff)));
        _mm_cvtsi128_si32(x) as u8
    })
}

/// Whether path costs fit `u8`: a path cost is at most `OUTSIDE + P2`, and `m + P2` (the jump
/// limit) at most `OUTSIDE + 2 P2`, which must stay below 256 (the default P2 96 gives 255).
fn u8_fits(lut: &[u16]) -> bool {
    let p2_max = lut.iter().copied().max().unwrap_or(0);
    u32::from(OUTSIDE) + 2 * u32::from(p2_max) <= 255
}

/// The four paths' step at one pixel: for each path `r`,
/// `out_r[k] = c[k] + min(lp_r[k], lp_r[k +- 1] + p1, m_r + p2_r) - m_r` (`lp_r`, `out_r`: `n + 2`
/// values with a pad at each end; `m_r` = min of `lp_r`; a path's first pixel has a zero
/// `lp_r`, which gives `out_r = c`). Writes their sum to `acc` and returns their minima.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn step4<T: PathCost>(
    lp: [&[T]; 4],
    m: [T; 4],
    p2: [u16; 4],
    p1: u16,
    c: &[u8],
    mut out: [&mut [T]; 4],
    acc: &mut [u16],
    avx2: Option<Avx2>,
) -> [T; 4] {
    let n = c.len();
    if let Some(avx2) = avx2 {
        let lim: [T; 4] = std::array::from_fn(|r| T::of(m[r].wide() + p2[r]));
        if let Some(mn) = T::step4_avx2(avx2, &lp, m, lim, T::of(p1), c, &mut out, acc) {
            return mn;
        }
    }
    let acc = &mut acc[..n];
    let [o0, o1, o2, o3] = out;
    let (o0, o1, o2, o3) = (
        &mut o0[1..n + 1],
        &mut o1[1..n + 1],
        &mut o2[1..n + 1],
        &mut o3[1..n + 1],
    );
    let lo = |r: usize| (&lp[r][..n], &lp[r][1..n + 1], &lp[r][2..n + 2]);
    let ((a0, b0, c0), (a1, b1, c1), (a2, b2, c2), (a3, b3, c3)) = (lo(0), lo(1), lo(2), lo(3));
    let lim: [T; 4] = std::array::from_fn(|r| T::of(m[r].wide() + p2[r]));
    let p1 = T::of(p1);
    let mut mn = [T::MAX; 4];
    for k in 0..n {
        let ck = T::of(u16::from(c[k]));
        let v0 = T::step(ck, a0[k], b0[k], c0[k], p1, lim[0], m[0]);
        let v1 = T::step(ck, a1[k], b1[k], c1[k], p1, lim[1], m[1]);
        let v2 = T::step(ck, a2[k], b2[k], c2[k], p1, lim[2], m[2]);
        let v3 = T::step(ck, a3[k], b3[k], c3[k], p1, lim[3], m[3]);
        o0[k] = v0;
        o1[k] = v1;
        o2[k] = v2;
        o3[k] = v3;
        acc[k] = v0.wide() + v1.wide() + v2.wide() + v3.wide();
        mn[0] = mn[0].min(v0);
        mn[1] = mn[1].min(v1);
        mn[2] = mn[2].min(v2);
        mn[3] = mn[3].min(v3);
    }
    mn
}

/// The path buffers of one [`pass_impl`] (see there).
struct PassPaths<T> {
    prev: [Vec<T>; 3],
    cur: [Vec<T>; 3],
    prev_min: [Vec<T>; 3],
    cur_min: [Vec<T>; 3],
    hl: Vec<T>,
    hl_next: Vec<T>,
    /// A path's first pixel steps from zeros (its output is then its cost).
    zero: Vec<T>,
}

impl<T: PathCost> PassPaths<T> {
    /// [`CoreError::OutOfMemory`] when they cannot be allocated. Not inlined: with its error
    /// paths inside [`pass_impl`], the AVX2 pass no longer inlined [`step4`]'s closures and ran
    /// 15 times slower.
    #[inline(never)]
    fn new(w: usize, n: usize) -> Result<Self> {
        const WHAT: &str = "the census matcher's path costs";
        let stride = n + 2;
        let path = || try_filled(w * stride, T::PAD, WHAT);
        let minima = || try_filled(w, T::of(0), WHAT);
        Ok(PassPaths {
            prev: [path()?, path()?, path()?],
            cur: [path()?, path()?, path()?],
            prev_min: [minima()?, minima()?, minima()?],
            cur_min: [minima()?, minima()?, minima()?],
            hl: try_filled(stride, T::PAD, WHAT)?,
            hl_next: try_filled(stride, T::PAD, WHAT)?,
            zero: zero_path(n)?,
        })
    }
}

/// Four paths in one raster (`forward`) or reverse raster pass; hands each row's summed costs
/// to `emit`. Path costs are kept as `T` ([`PathCost`]). [`CoreError::OutOfMemory`] when the
/// path buffers (six rows of `w (n + 2)` path costs) cannot be allocated (a `vec!` aborted the
/// process).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn pass_impl<T: PathCost>(
    c: &[u8],
    img: &[f32],
    w: usize,
    h: usize,
    n: usize,
    p: &SgmParams,
    forward: bool,
    row: &mut Vec<u16>,
    emit: &mut dyn FnMut(usize, &mut Vec<u16>),
    avx2: Option<Avx2>,
) -> Result<()> {
    let stride = n + 2;
    let lut = p2_table(p);
    // `row`: the four paths' sum for one row (`w * n` values); `emit` may swap in another
    // buffer. Every entry is written before it is read, so its contents do not matter.
    // Path costs of the previous row for the vertical path and the diagonals whose
    // predecessor is at x - sgn and x + sgn; index x * stride.
    let PassPaths {
        mut prev,
        mut cur,
        mut prev_min,
        mut cur_min,
        mut hl,
        mut hl_next,
        zero,
    } = PassPaths::new(w, n)?;
    let sgn: isize = if forward { 1 } else { -1 };
    for i in 0..h {
        let y = if forward { i } else { h - 1 - i };
        let yp = y as isize - sgn; // predecessor row
        let irow = &img[y * w..(y + 1) * w];
        let prow =
            (yp >= 0 && yp < h as isize).then(|| &img[yp as usize * w..(yp as usize + 1) * w]);
        let mut hmin = T::of(0);
        for j in 0..w {
            let x = if forward { j } else { w - 1 - j };
            let ci = &c[(y * w + x) * n..(y * w + x + 1) * n];
            let acc = &mut row[x * n..(x + 1) * n];
            let v = irow[x];
            let mut lps: [&[T]; 4] = [&zero; 4];
            let mut ms = [T::of(0); 4];
            let mut p2s = [0u16; 4];
            if j > 0 {
                // Horizontal path, predecessor x - sgn on this row.
                lps[0] = &hl;
                ms[0] = hmin;
                p2s[0] = p2_at(v, irow[(x as isize - sgn) as usize], p.gamma, &lut);
            }
            if let Some(pr) = prow {
                // Vertical and diagonal paths from the previous row.
                for (r, dx) in [(0usize, 0isize), (1, -sgn), (2, sgn)] {
                    let xp = x as isize + dx;
                    if xp >= 0 && xp < w as isize {
                        let xp = xp as usize;
                        lps[r + 1] = &prev[r][xp * stride..(xp + 1) * stride];
                        ms[r + 1] = prev_min[r][xp];
                        p2s[r + 1] = p2_at(v, pr[xp], p.gamma, &lut);
                    }
                }
            }
            let [c0, c1, c2] = &mut cur;
            let outs = [
                &mut hl_next[..],
                &mut c0[x * stride..(x + 1) * stride],
                &mut c1[x * stride..(x + 1) * stride],
                &mut c2[x * stride..(x + 1) * stride],
            ];
            let mn = step4(lps, ms, p2s, p.p1, ci, outs, acc, avx2);
            hmin = mn[0];
            for r in 0..3 {
                cur_min[r][x] = mn[r + 1];
            }
            std::mem::swap(&mut hl, &mut hl_next);
        }
        // Every x of `cur` and `cur_min` is written in the next row before it is read.
        std::mem::swap(&mut prev, &mut cur);
        std::mem::swap(&mut prev_min, &mut cur_min);
        emit(y, row);
    }
    Ok(())
}

/// `fn $name`: [`pass_impl`] with `$t` path costs, compiled for the baseline and AVX2 (the
/// per-level loop of the four paths vectorises); `$avx2`: whether its hand-written AVX2 step
/// is taken where the CPU has it.
macro_rules! pass_with {
    ($name:ident, $t:ty, $avx2:expr) => {
        simd_fn! {
            fn $name(
                c: &[u8],
                img: &[f32],
                w: usize,
                h: usize,
                n: usize,
                p: &SgmParams,
                forward: bool,
                row: &mut Vec<u16>,
                emit: &mut dyn FnMut(usize, &mut Vec<u16>),
            ) -> Result<()> {
                pass_impl::<$t>(c, img, w, h, n, p, forward, row, emit, $avx2)
            }
        }
    };
}
pass_with!(pass_u8, u8, Avx2::detect());
pass_with!(pass_u16, u16, None);

simd_fn! {
    /// `a += b`, element-wise (one row of the two passes' sums).
    fn add_into(a: &mut [u16], b: &[u16]) {
        for (x, y) in a.iter_mut().zip(b) {
            *x += *y;
        }
    }
}

/// Minimum of a slice (`u16::MAX` when empty). Inlined into [`select_row`], which is compiled
/// for AVX2 as a whole: as a dispatched function of its own it was called three times a pixel.
#[inline(always)]
fn min_u16(v: &[u16]) -> u16 {
    v.iter().fold(u16::MAX, |m, &x| m.min(x))
}

/// First index of the minimum of a non-empty slice (at most 2048 values), and the minimum.
#[inline(always)]
fn argmin(cell: &[u16]) -> (usize, u16) {
    let m = min_u16(cell);
    // The least index holding it, as a minimum over u16 indices: one vectorised pass where a
    // scan for the first match took a branch per level.
    let mut j = 0u16;
    let mut k = u16::MAX;
    for &v in cell {
        k = k.min(if v == m { j } else { u16::MAX });
        j = j.wrapping_add(1);
    }
    (usize::from(k), m)
}

/// Minimum of a slice (at most 2048 values) outside indices `k - 1 ..= k + 1` (`u16::MAX` when
/// nothing is left): one vectorised pass with those lanes masked, where the two ranges either
/// side each ended in a scalar tail.
#[inline(always)]
fn min_apart(cell: &[u16], k: usize) -> u16 {
    let first = (k as u16).wrapping_sub(1); // k = 0: 0xffff, and j - first < 3 for j in 0..2
    let mut j = 0u16;
    let mut m = u16::MAX;
    for &v in cell {
        m = m.min(if j.wrapping_sub(first) < 3 {
            u16::MAX
        } else {
            v
        });
        j = j.wrapping_add(1);
    }
    m
}

simd_fn! {
    /// The right view's winner at every right pixel `xr` of a row: the first level `j`
    /// minimising `S[xr + d_min + j, j]` (Hirschmueller's left-right check reads it off the same
    /// volume). Kept in reversed order, `rk[w - 1 - xr]`: for one left pixel the levels then map
    /// to consecutive entries, and the update is a vectorised compare-and-select. Levels are
    /// visited in increasing `j` for every `xr`, so a strict `<` keeps the first minimum.
    fn right_winners(s: &[u16], w: usize, n: usize, d_min: i64, rbest: &mut [u16], rk: &mut [u16]) {
        rbest.fill(u16::MAX);
        rk.fill(0);
        for xl in 0..w {
            let cell = &s[xl * n..(xl + 1) * n];
            // Levels j with 0 <= xl - d_min - j < w.
            let j_hi = (xl as i64 - d_min).min(n as i64 - 1);
            let j_lo = (xl as i64 - d_min - w as i64 + 1).max(0);
            if j_lo > j_hi {
                continue;
            }
            let (j_lo, j_hi) = (j_lo as usize, j_hi as usize);
            let base = (w as i64 - 1 - xl as i64 + d_min + j_lo as i64) as usize;
            let len = j_hi + 1 - j_lo;
            let rb = &mut rbest[base..base + len];
            let rj = &mut rk[base..base + len];
            // The level as a u16 counter (n <= 2048): a usize one made the compiler carry four
            // vectors of u64 indices and pack them to u16 lanes every 16 levels.
            let mut j = j_lo as u16;
            for ((&v, b), kk) in cell[j_lo..=j_hi].iter().zip(rb).zip(rj) {
                // Arithmetic select: stores every lane, so the loop vectorises without masks.
                let mask = u16::from(v < *b).wrapping_neg();
                *kk = (j & mask) | (*kk & !mask);
                *b = (*b).min(v);
                j = j.wrapping_add(1);
            }
        }
    }
}

/// [`select_row`]'s buffers: the right view's winners of a row (see [`right_winners`]), one
/// per worker, allocated once per call instead of once a row.
struct Winners {
    rbest: Vec<u16>,
    rk: Vec<u16>,
}

impl Winners {
    /// Checked, outside the row loop (kept out of line: see [`pass_impl`]'s buffers).
    #[inline(never)]
    fn new(w: usize) -> Result<Self> {
        const WHAT: &str = "the census matcher's right winners";
        Ok(Winners {
            rbest: try_zeroed(w, WHAT)?,
            rk: try_zeroed(w, WHAT)?,
        })
    }
}

simd_fn! {
    /// Winner, uniqueness, left-right check and sub-pixel vertex for one row of the summed volume.
    fn select_row(
        s: &[u16],
        w: usize,
        n_all: usize,
        d_min: i64,
        p: &SgmParams,
        win: &mut Winners,
        out: &mut [f32],
    ) {
        let d_max = d_min + n_all as i64 - 1;
        let Winners { rbest, rk } = win;
        right_winners(s, w, n_all, d_min, rbest, rk);
        for (x, o) in out.iter_mut().enumerate() {
            // Levels 0..inside land in the right image. The right band (d_min < 0) is not reported.
            let inside = (x as i64 - d_min + 1).min(n_all as i64);
            if inside <= 0 || x as i64 - d_min >= w as i64 {
                *o = f32::NAN;
                continue;
            }
            let band = x as i64 - d_max < 0;
            let n = inside as usize;
            let cell = &s[x * n_all..x * n_all + n];
            let (k, m) = argmin(cell);
            // In the band a true match outside the image pushes the winner against its edge
            // (n - 1 - k = x - d: the winner's right column).
            if band && ((n - 1 - k) as u32) < p.edge_margin {
                *o = f32::NAN;
                continue;
            }
            let best = u64::from(m);
            let other = u64::from(min_apart(cell, k));
            let unique = 100 * other > (100 + u64::from(p.uniqueness)) * best;
            let xr = (x as i64 - (d_min + k as i64)) as usize; // k < inside: in the image
            let consistent = usize::from(rk[w - 1 - xr]).abs_diff(k) <= p.lr_tol as usize;
            *o = if unique && consistent {
                let mut frac = 0.0f64;
                if k > 0 && k < n - 1 {
                    let (sm, sp) = (f64::from(cell[k - 1]), f64::from(cell[k + 1]));
                    let den = sm + sp - 2.0 * best as f64;
                    if den > 0.0 {
                        frac = (sm - sp) / (2.0 * den);
                    }
                }
                ((d_min + k as i64) as f64 + frac) as f32
            } else {
                f32::NAN
            };
        }
    }
}

/// The cost volume and the row buffers kept between calls (video frames), so that the next
/// call of the same size reuses them instead of faulting fresh pages in: on teddyH (900x750,
/// 129 levels) they are an 87 MB volume and about 375 rows of 232 KB (the rows one pass
/// reaches before the other), and a fused `depth_map` call faulted in about 200 MB of fresh
/// pages without them. At most [`KEEP_MAX_BYTES`] are kept; [`release_kept`] frees them.
mod kept {
    use std::sync::Mutex;

    /// Bytes kept at most between calls.
    pub const KEEP_MAX_BYTES: usize = 256 << 20;

    struct Kept {
        volume: Vec<u8>,
        rows: Vec<Vec<u16>>,
        /// The three-path matcher's rows in flight: costs and sums.
        pairs: Vec<(Vec<u8>, Vec<u16>)>,
    }

    static KEPT: Mutex<Kept> = Mutex::new(Kept {
        volume: Vec::new(),
        rows: Vec::new(),
        pairs: Vec::new(),
    });

    /// What is kept, or None in a forked process whose copy of it is held by a thread it does
    /// not have ([`crate::alloc::cache_lock`]): the call then allocates its own buffers.
    fn lock() -> Option<std::sync::MutexGuard<'static, Kept>> {
        crate::alloc::cache_lock(&KEPT)
    }

    /// The kept volume (any length) and the kept rows of exactly `row_len` values.
    pub fn take(row_len: usize) -> (Vec<u8>, Vec<Vec<u16>>) {
        let Some(mut k) = lock() else {
            return (Vec::new(), Vec::new());
        };
        let volume = std::mem::take(&mut k.volume);
        let rows = std::mem::take(&mut k.rows);
        drop(k);
        let rows = rows.into_iter().filter(|r| r.len() == row_len).collect();
        (volume, rows)
    }

    /// Keeps the volume, then as many rows as fit under [`KEEP_MAX_BYTES`].
    /// The three-path rows kept stay, and count against the limit.
    pub fn put(volume: Vec<u8>, mut rows: Vec<Vec<u16>>) {
        let Some(kept_pairs) = lock().map(|k| pairs_bytes(&k.pairs)) else {
            return; // freed, not kept
        };
        let mut room = KEEP_MAX_BYTES.saturating_sub(kept_pairs);
        let volume = if volume.capacity() <= room {
            room -= volume.capacity();
            volume
        } else {
            Vec::new()
        };
        let per_row = rows.first().map_or(1, |r| (r.capacity() * 2).max(1));
        rows.truncate(room / per_row);
        let Some(mut k) = lock() else {
            return;
        };
        k.volume = volume;
        k.rows = rows;
    }

    fn pairs_bytes(pairs: &[(Vec<u8>, Vec<u16>)]) -> usize {
        pairs
            .iter()
            .map(|(c, a)| c.capacity() + 2 * a.capacity())
            .sum()
    }

    /// The kept three-path rows of exactly `row_len` levels.
    pub fn take_pairs(row_len: usize) -> Vec<(Vec<u8>, Vec<u16>)> {
        let pairs = lock()
            .map(|mut k| std::mem::take(&mut k.pairs))
            .unwrap_or_default();
        pairs
            .into_iter()
            .filter(|(c, _)| c.len() == row_len)
            .collect()
    }

    /// Keeps as many three-path rows as fit under [`KEEP_MAX_BYTES`] (the volume and 8-path
    /// rows, which a three-path call does not use, are left as they are).
    pub fn put_pairs(mut pairs: Vec<(Vec<u8>, Vec<u16>)>) {
        let per = pairs
            .first()
            .map_or(1, |(c, a)| (c.capacity() + 2 * a.capacity()).max(1));
        let Some(mut k) = lock() else {
            return; // freed, not kept
        };
        let room = KEEP_MAX_BYTES.saturating_sub(
            k.volume.capacity() + k.rows.iter().map(|r| r.capacity() * 2).sum::<usize>(),
        );
        pairs.truncate(room / per);
        k.pairs = pairs;
    }

    /// Bytes kept.
    pub fn held_bytes() -> usize {
        let Some(k) = lock() else {
            return 0;
        };
        k.volume.capacity()
            + k.rows.iter().map(|r| r.capacity() * 2).sum::<usize>()
            + pairs_bytes(&k.pairs)
    }

    /// Frees what is kept; returns the bytes.
    pub fn release() -> usize {
        let held = held_bytes();
        let Some(mut k) = lock() else {
            return 0;
        };
        k.volume = Vec::new();
        k.rows = Vec::new();
        k.pairs = Vec::new();
        held
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_child_forked_while_the_kept_buffers_are_held_goes_without_them() {
        // The lock, held by a thread of the parent at fork (a census match running in another
        // Python thread), stayed held in the child: its first match waited forever.
        assert!(crate::alloc::tests::ends_in_a_child_forked_while_held(
            &KEPT,
            || {
                let (volume, rows) = take(8);
                assert!(volume.is_empty() && rows.is_empty());
                put(vec![1; 64], vec![vec![2; 8]]); // freed, not kept
                assert!(take_pairs(8).is_empty());
                put_pairs(vec![(vec![1; 8], vec![2; 8])]);
                assert_eq!((held_bytes(), release()), (0, 0));
            }
        ));
    }
}

pub use kept::KEEP_MAX_BYTES;

/// Bytes of cost volume and row buffers kept for the next call.
pub fn kept_bytes() -> usize {
    kept::held_bytes()
}

/// Frees the buffers kept for the next call; returns the bytes released.
pub fn release_kept() -> usize {
    kept::release()
}

/// Dense disparity of the pair over `[d_min, d_max]` (integers), `NaN` where the uniqueness test
/// or the left-right check fails. Row-major `(H, W)`.
pub fn sgm_disparity(
    left: ImageView<'_>,
    right: ImageView<'_>,
    d_min: i32,
    d_max: i32,
    p: &SgmParams,
) -> Result<Vec<f32>> {
    p.validate()?;
    if (left.width, left.height) != (right.width, right.height) {
        return Err(CoreError::SizeMismatch {
            left: (left.width, left.height),
            right: (right.width, right.height),
        });
    }
    if d_max < d_min {
        return Err(CoreError::param(
            "d_max",
            format!("expected d_max >= d_min, got d_min = {d_min}, d_max = {d_max}"),
        ));
    }
    let n = (i64::from(d_max) - i64::from(d_min) + 1) as usize;
    if n > 2048 {
        return Err(CoreError::param(
            "d_max",
            format!("the range holds {n} levels; at most 2048 are supported"),
        ));
    }
    let (w, h) = (left.width, left.height);
    if p.paths == 3 {
        return sgm_three_paths(left, right, i64::from(d_min), n, p);
    }
    let mut out = try_filled(w * h, f32::NAN, "the census matcher's disparity map")?;
    let (cl, cr) = rayon::join(|| census(left), || census(right));
    let (cl, cr) = (cl?, cr?);
    let (mut c, rows) = kept::take(w * n);
    // The cost volume (w h n bytes) is the largest buffer: a failed allocation is an error,
    // not an abort of the process.
    try_reserve_len(&mut c, cl.len() * n, "the census matcher's cost volume")?;
    cost_volume_into(&cl, &cr, w, i64::from(d_min), n, &mut c);
    drop((cl, cr));
    // Row buffers of `w * n` sums: the kept ones first, then fresh ones; a row's buffer goes
    // back to this list once both passes have added into it.
    let free = Mutex::new(rows);
    // Set when a row buffer could not be allocated: the passes then run on (their sums are
    // dropped, not parked) and the call returns the error.
    let starved = std::sync::atomic::AtomicBool::new(false);
    let fresh = || -> Option<Vec<u16>> {
        let kept = free.lock().unwrap_or_else(|e| e.into_inner()).pop();
        match kept {
            Some(r) => Some(r),
            None => {
                let r = try_zeroed(w * n, "the census matcher's row sums").ok();
                if r.is_none() {
                    starved.store(true, std::sync::atomic::Ordering::Relaxed);
                }
                r
            }
        }
    };
    // The two passes meet row by row: whichever reaches a row first leaves its sum there; the
    // second adds its own and selects the row. One volume of sums is held at most (the rows
    // each pass reached first), not one per pass; the addition commutes, so the output does
    // not depend on which came first.
    // Each slot also holds its row of the output, which the second pass to reach the row
    // selects into (no row-sized buffer a row, and no list of them).
    let slots: Vec<RowSlot<'_>> = try_collect(
        h,
        out.chunks_mut(w).map(|o| Mutex::new((None, o))),
        "the census matcher's row slots",
    )?;
    // Path costs as u8 where they fit, else u16: the same integers.
    let pass = if u8_fits(&p2_table(p)) {
        pass_u8
    } else {
        pass_u16
    };
    // Set when a pass could not allocate its path buffers: the other then parks no more sums
    // for it (they would never be met).
    let alone = std::sync::atomic::AtomicBool::new(false);
    let (mut win_a, mut win_b) = (Winners::new(w)?, Winners::new(w)?);
    let meet = |forward: bool, win: &mut Winners| -> Result<()> {
        let mut emit = |y: usize, row: &mut Vec<u16>| {
            let mut slot = slots[y].lock().unwrap_or_else(|e| e.into_inner());
            let (parked, o) = &mut *slot;
            let Some(other) = parked.take() else {
                if alone.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                if let Some(next) = fresh() {
                    *parked = Some(std::mem::replace(row, next));
                }
                return;
            };
            add_into(row, &other);
            free.lock().unwrap_or_else(|e| e.into_inner()).push(other);
            select_row(row, w, n, i64::from(d_min), p, win, o);
        };
        let Some(mut row) = fresh() else {
            return Ok(());
        };
        let ran = pass(&c, left.data, w, h, n, p, forward, &mut row, &mut emit);
        if ran.is_err() {
            alone.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        free.lock().unwrap_or_else(|e| e.into_inner()).push(row);
        ran
    };
    let (a, b) = rayon::join(|| meet(true, &mut win_a), || meet(false, &mut win_b));
    drop(slots);
    kept::put(c, free.into_inner().unwrap_or_else(|e| e.into_inner()));
    // A pass without path buffers first: the row sums it starved the other of follow from it.
    a?;
    b?;
    if starved.into_inner() {
        return Err(CoreError::oom(
            h.saturating_mul(w * n * 2),
            "the census matcher's row sums",
        ));
    }
    Ok(out)
}

/// A row of the 8-path matcher: the sums of the pass that reached it first, parked until the
/// other pass arrives, and the row of the output it is then selected into.
type RowSlot<'a> = Mutex<(Option<Vec<u16>>, &'a mut [f32])>;

/// One path's step at one pixel (see [`step4`]): `out[1..n + 1]` gets the new path costs, which
/// are stored into `acc` (`ADD` false) or added to it; returns their minimum.
#[inline(always)]
fn step1<T: PathCost, const ADD: bool>(
    lp: &[T],
    m: T,
    p2: u16,
    p1: u16,
    c: &[u8],
    out: &mut [T],
    acc: &mut [u16],
) -> T {
    let n = c.len();
    let (a, b, nx) = (&lp[..n], &lp[1..n + 1], &lp[2..n + 2]);
    let (out, acc) = (&mut out[1..n + 1], &mut acc[..n]);
    let lim = T::of(m.wide() + p2);
    let p1 = T::of(p1);
    let mut mn = T::MAX;
    for k in 0..n {
        let v = T::step(T::of(u16::from(c[k])), a[k], b[k], nx[k], p1, lim, m);
        out[k] = v;
        acc[k] = if ADD { acc[k] + v.wide() } else { v.wide() };
        mn = mn.min(v);
    }
    mn
}

/// The horizontal paths' state: a path's first pixel steps from `zero` (zeros inside the two
/// pads), then from the previous pixel's costs (`last`; `next` receives the new ones).
struct Horizontal<T> {
    zero: Vec<T>,
    last: Vec<T>,
    next: Vec<T>,
}

impl<T: PathCost> Horizontal<T> {
    fn new(n: usize) -> Result<Self> {
        const WHAT: &str = "the census matcher's horizontal path costs";
        Ok(Horizontal {
            zero: zero_path(n)?,
            last: try_filled(n + 2, T::PAD, WHAT)?,
            next: try_filled(n + 2, T::PAD, WHAT)?,
        })
    }
}

/// The vertical path's state: the previous row's path costs (`n + 2` per pixel) and their
/// minima; `cur` / `cur_min` receive this row's.
struct VerticalPath<T> {
    zero: Vec<T>,
    prev: Vec<T>,
    prev_min: Vec<T>,
    cur: Vec<T>,
    cur_min: Vec<T>,
}

impl<T: PathCost> VerticalPath<T> {
    /// [`CoreError::OutOfMemory`] when the two rows of path costs (`2 w (n + 2)` values)
    /// cannot be allocated.
    fn new(w: usize, n: usize) -> Result<Self> {
        const WHAT: &str = "the census matcher's vertical path costs";
        Ok(VerticalPath {
            zero: zero_path(n)?,
            prev: try_filled(w * (n + 2), T::PAD, WHAT)?,
            prev_min: try_filled(w, T::of(0), WHAT)?,
            cur: try_filled(w * (n + 2), T::PAD, WHAT)?,
            cur_min: try_filled(w, T::of(0), WHAT)?,
        })
    }
}

/// The two horizontal paths of one row (left to right stored into `acc`, right to left added):
/// `c` and `acc` hold `n` levels per pixel.
#[inline(always)]
fn horizontal_impl<T: PathCost>(
    c: &[u8],
    irow: &[f32],
    n: usize,
    p: &SgmParams,
    lut: &[u16],
    acc: &mut [u16],
    hp: &mut Horizontal<T>,
) {
    let w = irow.len();
    for forward in [true, false] {
        let mut hmin = T::of(0);
        for j in 0..w {
            let (x, xp) = if forward {
                (j, j.wrapping_sub(1))
            } else {
                (w - 1 - j, w - j)
            };
            let (ci, a) = (&c[x * n..(x + 1) * n], &mut acc[x * n..(x + 1) * n]);
            let (lp, m, p2) = if j == 0 {
                (&hp.zero[..], T::of(0), 0)
            } else {
                (&hp.last[..], hmin, p2_at(irow[x], irow[xp], p.gamma, lut))
            };
            hmin = if forward {
                step1::<T, false>(lp, m, p2, p.p1, ci, &mut hp.next, a)
            } else {
                step1::<T, true>(lp, m, p2, p.p1, ci, &mut hp.next, a)
            };
            std::mem::swap(&mut hp.last, &mut hp.next);
        }
    }
}

/// The top-to-bottom path of one row, added to `acc` (`prow`: the previous row's image, `None`
/// on the first row); `vp` moves on to this row.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn vertical_impl<T: PathCost>(
    c: &[u8],
    irow: &[f32],
    prow: Option<&[f32]>,
    n: usize,
    p: &SgmParams,
    lut: &[u16],
    acc: &mut [u16],
    vp: &mut VerticalPath<T>,
) {
    let stride = n + 2;
    for x in 0..irow.len() {
        let (lp, m, p2) = match prow {
            Some(pr) => (
                &vp.prev[x * stride..(x + 1) * stride],
                vp.prev_min[x],
                p2_at(irow[x], pr[x], p.gamma, lut),
            ),
            None => (&vp.zero[..], T::of(0), 0),
        };
        vp.cur_min[x] = step1::<T, true>(
            lp,
            m,
            p2,
            p.p1,
            &c[x * n..(x + 1) * n],
            &mut vp.cur[x * stride..(x + 1) * stride],
            &mut acc[x * n..(x + 1) * n],
        );
    }
    std::mem::swap(&mut vp.prev, &mut vp.cur);
    std::mem::swap(&mut vp.prev_min, &mut vp.cur_min);
}

/// [`horizontal_impl`] for one path-cost type (`simd_fn!` takes no generics).
type HorizontalFn<T> = fn(&[u8], &[f32], usize, &SgmParams, &[u16], &mut [u16], &mut Horizontal<T>);
/// [`vertical_impl`] for one path-cost type.
type VerticalFn<T> =
    fn(&[u8], &[f32], Option<&[f32]>, usize, &SgmParams, &[u16], &mut [u16], &mut VerticalPath<T>);

/// `fn $h` / `fn $v`: [`horizontal_impl`] / [`vertical_impl`] with `$t` path costs, compiled
/// for the baseline and AVX2.
macro_rules! three_paths_for {
    ($t:ty, $h:ident, $v:ident) => {
        simd_fn! {
            fn $h(
                c: &[u8],
                irow: &[f32],
                n: usize,
                p: &SgmParams,
                lut: &[u16],
                acc: &mut [u16],
                hp: &mut Horizontal<$t>,
            ) {
                horizontal_impl(c, irow, n, p, lut, acc, hp)
            }
        }
        simd_fn! {
            fn $v(
                c: &[u8],
                irow: &[f32],
                prow: Option<&[f32]>,
                n: usize,
                p: &SgmParams,
                lut: &[u16],
                acc: &mut [u16],
                vp: &mut VerticalPath<$t>,
            ) {
                vertical_impl(c, irow, prow, n, p, lut, acc, vp)
            }
        }
    };
}
three_paths_for!(u8, horizontal_u8, vertical_u8);
three_paths_for!(u16, horizontal_u16, vertical_u16);

/// A path-cost vector of `n + 2` entries: zeros inside the two pads.
fn zero_path<T: PathCost>(n: usize) -> Result<Vec<T>> {
    let mut z = try_filled(n + 2, T::of(0), "the census matcher's path costs")?;
    z[0] = T::PAD;
    z[n + 1] = T::PAD;
    Ok(z)
}

/// The matcher with `paths` 3: left to right, right to left and top to bottom (OpenCV
/// SGBM-3WAY's set), one row at a time with no cost volume. Two workers meet row by row: the
/// first computes each row's costs and its two horizontal paths, the second adds the vertical
/// path, which needs the rows in order, and selects the row; the first takes those steps itself
/// when it is [`THREE_PATHS_LEAD`] rows ahead (on one thread, every row from then on). Every
/// row is the same arithmetic whichever worker runs it, so the output does not depend on the
/// thread count.
fn sgm_three_paths(
    left: ImageView<'_>,
    right: ImageView<'_>,
    d_min: i64,
    n: usize,
    p: &SgmParams,
) -> Result<Vec<f32>> {
    let lut = p2_table(p);
    if u8_fits(&lut) {
        three_paths_as::<u8>(left, right, d_min, n, p, &lut, horizontal_u8, vertical_u8)
    } else {
        three_paths_as::<u16>(left, right, d_min, n, p, &lut, horizontal_u16, vertical_u16)
    }
}

/// Rows the first worker of [`sgm_three_paths`] may run ahead of the vertical path before it
/// takes the vertical path's next row itself: the rows in flight, and so the memory, stay
/// bounded (a few rows of `3 w n` bytes) even when the second worker never starts.
pub const THREE_PATHS_LEAD: usize = 8;

/// One row in flight: its costs and its path sums.
type Row = (Vec<u8>, Vec<u16>);

/// The rows between the two workers of [`sgm_three_paths`].
struct Flight {
    /// Rows with their horizontal paths, in order, waiting for the vertical path.
    ready: std::collections::VecDeque<(usize, Row)>,
    /// Rows done with, to be reused.
    free: Vec<Row>,
    /// Every row has been queued.
    all_queued: bool,
}

/// The vertical path's state and the output, which the two workers of [`sgm_three_paths`]
/// take turns at.
struct Vertical<'a, T> {
    path: VerticalPath<T>,
    win: Winners,
    out: &'a mut [f32],
}

/// Marks every row queued (and wakes the second worker) when dropped.
struct AllQueued<'a>(&'a std::sync::Mutex<Flight>, &'a std::sync::Condvar);

impl Drop for AllQueued<'_> {
    fn drop(&mut self) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).all_queued = true;
        self.1.notify_all();
    }
}

#[allow(clippy::too_many_arguments)]
fn three_paths_as<T: PathCost + Send>(
    left: ImageView<'_>,
    right: ImageView<'_>,
    d_min: i64,
    n: usize,
    p: &SgmParams,
    lut: &[u16],
    horizontal: HorizontalFn<T>,
    vertical: VerticalFn<T>,
) -> Result<Vec<f32>> {
    use std::sync::{Condvar, Mutex, MutexGuard};
    fn lock(m: &Mutex<Flight>) -> MutexGuard<'_, Flight> {
        // Moves of whole rows only: a panic cannot leave it inconsistent.
        m.lock().unwrap_or_else(|e| e.into_inner())
    }
    let (w, h) = (left.width, left.height);
    let (cl, cr) = rayon::join(|| census(left), || census(right));
    let (cl, cr) = (cl?, cr?);
    let img = left.data;
    let mut out = try_filled(w * h, f32::NAN, "the census matcher's disparity map")?;
    // The rows kept from the last call of this size first (a video's next frame).
    let flight = Mutex::new(Flight {
        ready: Default::default(),
        free: kept::take_pairs(w * n),
        all_queued: false,
    });
    let queued = Condvar::new();
    let state = Mutex::new(Vertical {
        path: VerticalPath::<T>::new(w, n)?,
        win: Winners::new(w)?,
        out: &mut out,
    });
    // The vertical path and the selection of the next queued row, by whichever worker calls it;
    // false when no row is queued. The rows are taken and run in order under `state`'s lock
    // (always taken before `flight`'s), so the output does not depend on who runs them.
    let vertical_step = || -> bool {
        let mut v = state.lock().unwrap_or_else(|e| e.into_inner());
        let Some((y, (c, mut acc))) = lock(&flight).ready.pop_front() else {
            return false;
        };
        let v = &mut *v;
        let prow = (y > 0).then(|| &img[(y - 1) * w..y * w]);
        let irow = &img[y * w..(y + 1) * w];
        vertical(&c, irow, prow, n, p, lut, &mut acc, &mut v.path);
        select_row(
            &acc,
            w,
            n,
            d_min,
            p,
            &mut v.win,
            &mut v.out[y * w..(y + 1) * w],
        );
        lock(&flight).free.push((c, acc));
        true
    };
    // The first worker's buffers, allocated here where a failure is simply returned.
    let mut rev = Vec::new();
    try_reserve_len(&mut rev, w, "the census matcher's reversed census row")?;
    let mut hp = Horizontal::<T>::new(n)?;
    // A row in flight: its costs (`w n` bytes) and path sums (`2 w n`); zeroed, as `vec!`.
    let new_row = || -> Result<Row> {
        Ok((
            try_zeroed(w * n, "the census matcher's row costs")?,
            try_zeroed(w * n, "the census matcher's row path sums")?,
        ))
    };
    // Ends with an error when a row cannot be allocated: the rows queued are still taken by
    // the vertical path, and the call returns the error.
    let first = || -> Result<()> {
        // Set when this worker ends, by a panic or an error too: the second would otherwise
        // wait forever and `join` could not hand the panic on.
        let _end = AllQueued(&flight, &queued);
        for y in 0..h {
            #[cfg(test)]
            assert!((w, h, y) != tests::PANIC_AT, "a fault injected by a test");
            let reused = lock(&flight).free.pop();
            let (mut c, mut acc) = match reused {
                Some(r) => r,
                None => new_row()?,
            };
            rev.clear();
            rev.extend(cr[y * w..(y + 1) * w].iter().rev());
            cost_row_as(
                &cl[y * w..(y + 1) * w],
                &rev,
                d_min,
                n,
                &mut c,
                Avx2::detect(),
                Avx512::detect(),
            );
            horizontal(&c, &img[y * w..(y + 1) * w], n, p, lut, &mut acc, &mut hp);
            let waiting = {
                let mut f = lock(&flight);
                f.ready.push_back((y, (c, acc)));
                f.ready.len()
            };
            queued.notify_one();
            if waiting > THREE_PATHS_LEAD {
                vertical_step(); // too far ahead (or alone): take the vertical path's next row
            }
        }
        drop(_end);
        while vertical_step() {}
        Ok(())
    };
    let second = || loop {
        {
            let mut f = lock(&flight);
            while f.ready.is_empty() && !f.all_queued {
                f = queued.wait(f).unwrap_or_else(|e| e.into_inner());
            }
            if f.ready.is_empty() {
                return; // all queued and all taken
            }
        }
        vertical_step();
    };
    // The first worker on this thread: on one thread `join` runs it to the end (it takes every
    // row's vertical path itself once it is `THREE_PATHS_LEAD` ahead), then the second, which
    // finds nothing left.
    let (ran, ()) = rayon::join(first, second);
    drop(state);
    kept::put_pairs(flight.into_inner().unwrap_or_else(|e| e.into_inner()).free);
    ran?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize, shift: f32) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 + shift, (i / w) as f32);
                0.5 + 0.25 * (0.37 * x).sin() * (0.23 * y + 0.11 * x * x / 40.0).cos()
            })
            .collect()
    }

    /// The default parameters with three paths.
    fn three() -> SgmParams {
        SgmParams {
            paths: 3,
            ..SgmParams::default()
        }
    }

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Asserts that at least 95 % of the 80x40 ramp pair's inner pixels (rows 5-34, columns
    /// 20-74) are within 0.5 px of disparity 6.
    fn assert_shift_6(d: &[f32], w: usize, h: usize) {
        let inner: Vec<f32> = (5..h - 5)
            .flat_map(|y| (20..w - 5).map(move |x| (x, y)))
            .map(|(x, y)| d[y * w + x])
            .collect();
        let good = inner.iter().filter(|v| (**v - 6.0).abs() < 0.5).count();
        assert!(good * 100 >= inner.len() * 95, "{good} of {}", inner.len());
    }

    #[test]
    fn recovers_a_constant_shift() {
        let (w, h) = (80, 40);
        let l = ramp(w, h, 0.0);
        let r = ramp(w, h, 6.0); // r(x) = l(x + 6): disparity 6
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let d = sgm_disparity(lv, rv, 0, 15, &SgmParams::default()).unwrap();
        assert_shift_6(&d, w, h);
        // The left band (x < 15): the match lands at x - 6 >= edge_margin from x = 10 on.
        let band: Vec<f32> = (5..h - 5)
            .flat_map(|y| (10..15).map(move |x| (x, y)))
            .map(|(x, y)| d[y * w + x])
            .collect();
        let good = band.iter().filter(|v| (**v - 6.0).abs() < 0.5).count();
        assert!(good * 100 >= band.len() * 90, "{good} of {}", band.len());
        // Right pixel within edge_margin (4) columns of the edge, or outside: not reported.
        assert!((0..h)
            .all(|y| (0..10).all(|x| d[y * w + x].is_nan() || (x as f32 - d[y * w + x]) >= 3.5)));
    }

    #[test]
    fn rejects_bad_parameters_and_shapes() {
        let img = vec![0.5f32; 64];
        let v = ImageView::new(8, 8, &img).unwrap();
        let small = ImageView::new(4, 4, &img[..16]).unwrap();
        let bad = |p: SgmParams| sgm_disparity(v, v, 0, 4, &p).unwrap_err();
        let d = SgmParams::default();
        assert!(matches!(
            bad(SgmParams { p1: 0, ..d }),
            CoreError::InvalidParameter { name: "p1", .. }
        ));
        assert!(matches!(
            bad(SgmParams { p2: 5000, ..d }),
            CoreError::InvalidParameter { name: "p2", .. }
        ));
        assert!(matches!(
            bad(SgmParams {
                gamma: f32::NAN,
                ..d
            }),
            CoreError::InvalidParameter { name: "gamma", .. }
        ));
        assert!(matches!(
            sgm_disparity(v, v, 4, 2, &d).unwrap_err(),
            CoreError::InvalidParameter { name: "d_max", .. }
        ));
        assert!(matches!(
            sgm_disparity(v, small, 0, 4, &d).unwrap_err(),
            CoreError::SizeMismatch { .. }
        ));
    }

    #[test]
    fn census_and_costs_on_a_step() {
        // A vertical step: left half dark. Census bits count darker neighbours.
        let (w, h) = (12, 9);
        let img: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 6 { 0.2 } else { 0.8 })
            .collect();
        let v = ImageView::new(w, h, &img).unwrap();
        let c = census(v).unwrap();
        assert_eq!(
            c[4 * w + 2],
            0,
            "a flat neighbourhood has no darker neighbour"
        );
        // x = 6, the first bright column: its window holds dark columns 2-5, 4 x 7 darker pixels.
        assert_eq!(c[4 * w + 6].count_ones(), 28);
        let vol = cost_volume(&c, &c, w, 0, 3);
        let cell = |x: usize, k: usize| vol[(4 * w + x) * 3 + k];
        assert_eq!(cell(6, 0), 0);
        assert_eq!(cell(6, 1), (c[4 * w + 6] ^ c[4 * w + 5]).count_ones() as u8);
        // Right pixel outside: the best inside level's cost (here level 0, a perfect match).
        assert_eq!((cell(0, 1), cell(1, 2), cell(0, 0)), (0, 0, 0));
        let far = cost_volume(&c, &c, w, 20, 2);
        assert!(far.iter().all(|&v| v == OUTSIDE), "no level inside");
    }

    #[test]
    fn kept_buffers_do_not_change_the_output() {
        // Calls of other sizes in between leave a larger volume and rows of another length in
        // the keep; the output must not depend on what they hold.
        let (w, h) = (80, 40);
        let (l, r) = (ramp(w, h, 0.0), ramp(w, h, 6.0));
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let p = SgmParams::default();
        release_kept();
        let first = sgm_disparity(lv, rv, 0, 15, &p).unwrap();
        let (l2, r2) = (ramp(120, 50, 0.0), ramp(120, 50, 3.0));
        let big = (
            ImageView::new(120, 50, &l2).unwrap(),
            ImageView::new(120, 50, &r2).unwrap(),
        );
        sgm_disparity(big.0, big.1, 0, 31, &p).unwrap();
        let again = sgm_disparity(lv, rv, 0, 15, &p).unwrap();
        let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&first, &again));
        sgm_disparity(lv, rv, 0, 15, &p).unwrap();
        assert!(same(&first, &sgm_disparity(lv, rv, 0, 15, &p).unwrap()));
        // The three-path matcher's kept rows, between calls of either kind and size.
        let p3 = SgmParams { paths: 3, ..p };
        let first3 = sgm_disparity(lv, rv, 0, 15, &p3).unwrap();
        for (a, b, d, q) in [
            (big.0, big.1, 31, p3),
            (lv, rv, 15, p3),
            (big.0, big.1, 31, p),
        ] {
            sgm_disparity(a, b, 0, d, &q).unwrap();
            assert!(same(&first3, &sgm_disparity(lv, rv, 0, 15, &p3).unwrap()));
            assert!(same(&first, &sgm_disparity(lv, rv, 0, 15, &p).unwrap()));
        }
        assert!(kept_bytes() <= KEEP_MAX_BYTES);
    }

    /// Every row's summed path costs of one pass, with `u8` or `u16` path costs.
    fn pass_rows(u8_costs: bool, forward: bool, p: &SgmParams) -> Vec<(usize, Vec<u16>)> {
        let (w, h, n) = (90, 40, 24);
        let (l, r) = (ramp(w, h, 0.0), ramp(w, h, 7.0));
        // Strong steps too: the intensity-adaptive P2 takes all its levels.
        let l: Vec<f32> = l
            .iter()
            .enumerate()
            .map(|(i, v)| if i % 13 < 2 { 1.0 } else { *v })
            .collect();
        let cl = census(ImageView::new(w, h, &l).unwrap()).unwrap();
        let cr = census(ImageView::new(w, h, &r).unwrap()).unwrap();
        let c = cost_volume(&cl, &cr, w, -3, n);
        let mut rows = Vec::new();
        let mut emit = |y: usize, row: &mut Vec<u16>| rows.push((y, row.clone()));
        let mut row = vec![0u16; w * n];
        let run = if u8_costs { pass_u8 } else { pass_u16 };
        run(&c, &l, w, h, n, p, forward, &mut row, &mut emit).unwrap();
        rows
    }

    #[test]
    fn u8_and_u16_path_costs_give_the_same_sums() {
        let p = SgmParams::default();
        assert!(u8_fits(&p2_table(&p)));
        for forward in [true, false] {
            assert_eq!(pass_rows(true, forward, &p), pass_rows(false, forward, &p));
        }
        // The largest P2 that fits, with the smallest gamma (every step a full P2 or P1 + 1).
        let edge = SgmParams {
            p2: 96,
            gamma: 0.5,
            ..p
        };
        assert_eq!(pass_rows(true, true, &edge), pass_rows(false, true, &edge));
        let over = SgmParams { p2: 97, ..p };
        assert!(!u8_fits(&p2_table(&over)));
    }

    #[test]
    fn the_avx2_path_step_gives_the_compilers_integers() {
        // The hand-written AVX2 step against the portable loop, through whole passes in both
        // directions (all eight paths), for every level count 1..=66 (below 32 the loop runs;
        // above, the last block of 32 overlaps the one before by every amount 0..=31) and for
        // three to seven blocks, aligned or not, up to 200, on census and random cost volumes,
        // with P1 and P2 at their u8 extremes and gammas that take every P2 level or none.
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: nothing to compare");
            return;
        };
        let (w, h) = (13, 7);
        let d = SgmParams::default();
        let params = [
            d,
            SgmParams { p1: 1, p2: 2, ..d },
            SgmParams {
                p1: 1,
                p2: 96,
                gamma: 0.5,
                ..d
            },
            SgmParams {
                p1: 95,
                p2: 96,
                ..d
            },
            SgmParams {
                p2: 96,
                gamma: 1e6,
                ..d
            },
        ];
        let img: Vec<f32> = noise(w, h, 5)
            .iter()
            .zip(ramp(w, h, 0.0))
            .map(|(a, b)| 0.5 * a + b * 0.5)
            .collect();
        let (cl, cr) = (
            census(ImageView::new(w, h, &ramp(w, h, 0.0)).unwrap()).unwrap(),
            census(ImageView::new(w, h, &ramp(w, h, 5.0)).unwrap()).unwrap(),
        );
        let mut s = 12345u32;
        let mut rand = move || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            s >> 8
        };
        let run = |c: &[u8], n: usize, p: &SgmParams, forward: bool, a: Option<Avx2>| {
            let mut rows = Vec::new();
            let mut emit = |y: usize, row: &mut Vec<u16>| rows.push((y, row.clone()));
            let mut row = vec![0u16; w * n];
            pass_impl::<u8>(c, &img, w, h, n, p, forward, &mut row, &mut emit, a).unwrap();
            rows
        };
        for n in (1..=66).chain([95, 96, 97, 127, 128, 129, 160, 199, 200]) {
            // Random costs, a tenth of them OUTSIDE (the largest a cost can be).
            let random: Vec<u8> = (0..w * h * n)
                .map(|_| match rand() % 10 {
                    0 => OUTSIDE,
                    _ => (rand() % (u32::from(OUTSIDE) + 1)) as u8,
                })
                .collect();
            let censused = cost_volume(&cl, &cr, w, -3, n);
            for c in [&random, &censused] {
                for p in &params {
                    assert!(u8_fits(&p2_table(p)));
                    for forward in [true, false] {
                        let want = run(c, n, p, forward, None);
                        assert_eq!(want.len(), h);
                        assert_eq!(run(c, n, p, forward, Some(avx2)), want, "{n} levels {p:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_avx2_path_step_keeps_the_saturating_add_of_step4s_contract() {
        // `step4` on its own, with path costs anywhere in u8 (up to the 255 pads) and any P1,
        // P2 within its contract (`m_r` the minimum of `lp_r`, `m_r + p2_r` and every result
        // below 256): `min(a, n) + p1` then passes 255, which a pass under `u8_fits` never
        // reaches, and the hand-written step must saturate there like `PathCost::step`.
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: nothing to compare");
            return;
        };
        let mut s = 987_654_321u32;
        let mut rand = move |below: u32| {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) % below
        };
        for n in (1..=130).chain([191, 200, 255, 256, 257]) {
            for trial in 0..20 {
                // Each path's costs between a floor and 255; some levels at 255.
                let mut lp = [(); 4].map(|_| vec![u8::MAX; n + 2]);
                for v in &mut lp {
                    let floor = rand(256);
                    for x in &mut v[1..n + 1] {
                        *x = match rand(8) {
                            0 => u8::MAX,
                            _ => (floor + rand(256 - floor)) as u8,
                        };
                    }
                }
                let m: [u8; 4] = std::array::from_fn(|r| *lp[r].iter().min().unwrap());
                let p2: [u16; 4] = std::array::from_fn(|r| rand(256 - u32::from(m[r])) as u16);
                let p1 = if trial % 4 == 0 {
                    255
                } else {
                    rand(256) as u16
                };
                let c_max = 255 - u32::from(*p2.iter().max().unwrap());
                let c: Vec<u8> = (0..n).map(|_| rand(c_max + 1) as u8).collect();
                let run = |a: Option<Avx2>| {
                    let mut out = [(); 4].map(|_| vec![0u8; n + 2]);
                    let mut acc = vec![0u16; n];
                    let [o0, o1, o2, o3] = &mut out;
                    let lps = [&lp[0][..], &lp[1][..], &lp[2][..], &lp[3][..]];
                    let mn = step4(lps, m, p2, p1, &c, [o0, o1, o2, o3], &mut acc, a);
                    (mn, out, acc)
                };
                assert_eq!(run(Some(avx2)), run(None), "{n} levels, trial {trial}");
            }
        }
    }

    #[test]
    fn three_paths_recover_a_shift_alike_on_any_thread_count_and_cost_width() {
        let (w, h) = (80, 40);
        let (l, r) = (ramp(w, h, 0.0), ramp(w, h, 6.0));
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let p = three();
        let d = sgm_disparity(lv, rv, 0, 15, &p).unwrap();
        assert_shift_6(&d, w, h);
        // Not the eight paths' map: another aggregation (so the option is not ignored).
        let eight = sgm_disparity(lv, rv, 0, 15, &SgmParams::default()).unwrap();
        let bits = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_ne!(bits(&d), bits(&eight));
        // One worker (it takes the vertical path's rows too) and three give the same bits.
        for threads in [1, 3] {
            let again = pool(threads).install(|| sgm_disparity(lv, rv, 0, 15, &p).unwrap());
            assert_eq!(bits(&again), bits(&d), "{threads} threads");
        }
        // u8 and u16 path costs: the same integers, with steps that take every P2 level.
        let lut = p2_table(&p);
        assert!(u8_fits(&lut));
        let spiky: Vec<f32> = l
            .iter()
            .enumerate()
            .map(|(i, v)| if i % 13 < 2 { 1.0 } else { *v })
            .collect();
        let sv = ImageView::new(w, h, &spiky).unwrap();
        let a = three_paths_as::<u8>(sv, rv, -3, 19, &p, &lut, horizontal_u8, vertical_u8).unwrap();
        let b =
            three_paths_as::<u16>(sv, rv, -3, 19, &p, &lut, horizontal_u16, vertical_u16).unwrap();
        assert_eq!(bits(&a), bits(&b));
        assert!(a.iter().filter(|v| v.is_finite()).count() > w * h / 3);
    }

    #[test]
    fn three_paths_hold_a_few_rows_even_on_one_thread() {
        // On one thread the second worker starts only after the first is done: the first takes
        // the vertical path's rows itself once it is THREE_PATHS_LEAD ahead. A size no other
        // test uses, so the rows kept afterwards are this call's.
        let (w, h) = (70, 300);
        let (l, r) = (ramp(w, h, 0.0), ramp(w, h, 4.0));
        let lv = ImageView::new(w, h, &l).unwrap();
        let rv = ImageView::new(w, h, &r).unwrap();
        let d = pool(1).install(|| sgm_disparity(lv, rv, 0, 9, &three()).unwrap());
        let rows = kept::take_pairs(w * 10).len();
        assert!(rows <= THREE_PATHS_LEAD + 3, "{rows} rows allocated");
        let good = d.iter().filter(|v| (**v - 4.0).abs() < 0.5).count();
        assert!(good * 10 >= d.len() * 8, "{good} of {}", d.len());
    }

    /// `(w, h, y)`: the three-path matcher's first worker panics on row `y` of a pair of this
    /// size (a size no other test uses).
    pub(super) const PANIC_AT: (usize, usize, usize) = (37, 23, 5);

    #[test]
    fn a_panicking_worker_ends_the_call_instead_of_hanging_it() {
        // Without the end marker the second worker would wait for rows forever and `join`
        // could not return; the call must end (with the panic) within seconds.
        let (w, h, _) = PANIC_AT;
        let img = ramp(w, h, 0.0);
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let v = ImageView::new(w, h, &img).unwrap();
            let got = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool(2).install(|| sgm_disparity(v, v, 0, 7, &three()))
            }));
            let _ = tx.send(got.is_err());
        });
        let panicked = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("the call hung");
        assert!(panicked);
    }

    /// Run by [`path_buffers_too_large_to_allocate_are_an_error`] in a child process: under an
    /// address-space limit of 90 MiB more than is mapped, pairs of 2 rows and 2048 levels whose
    /// first buffer that does not fit is a path buffer. Three paths, 32768 px wide: the vertical
    /// path's two rows of path costs (134 MB); 16384 px wide: they fit (67 MB), a row in flight
    /// (34 MB of costs, then 67 MB of sums) does not. Eight paths (one pass after the other on
    /// one thread), 8192 px wide: the cost volume and the first pass's row sums fit (67 MB), its
    /// six rows of path costs (101 MB) do not.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of path_buffers_too_large_to_allocate_are_an_error"]
    fn path_buffers_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let cases = [(32768usize, 3u8), (16384, 3), (8192, 8)];
        let imgs: Vec<Vec<f32>> = cases.iter().map(|&(w, _)| ramp(w, 2, 0.0)).collect();
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (90 << 20));
        for (&(w, paths), img) in cases.iter().zip(&imgs) {
            let v = ImageView::new(w, 2, img).unwrap();
            let p = SgmParams {
                paths,
                ..SgmParams::default()
            };
            match sgm_disparity(v, v, 0, 2047, &p) {
                Ok(d) => println!("child: {w} {paths}: matched {}", d.len()),
                Err(e) => println!("child: {w} {paths}: error: {e}"),
            }
            release_kept();
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn path_buffers_too_large_to_allocate_are_an_error() {
        // The path buffers (the 8-path passes' six rows of w (n + 2) path costs, the 3-path
        // vertical path's two and its rows in flight) were allocated with vec!: a failed
        // allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
        let stdout = crate::segment::tests::run_oom_child(
            "matching::sgm::tests::path_buffers_under_a_memory_limit",
        );
        for want in [
            "child: 32768 3: error: out of memory: the census matcher's vertical path costs \
             needs 64.06 MiB (67174400 bytes)",
            "child: 16384 3: error: out of memory: the census matcher's row costs needs 32.00 \
             MiB (33554432 bytes)",
            "child: 8192 8: error: out of memory: the census matcher's path costs needs 16.02 \
             MiB (16793600 bytes)",
        ] {
            assert!(stdout.contains(want), "{want} not in {stdout}");
        }
    }

    /// Run by [`row_slots_too_large_to_allocate_are_an_error`] in a child process: a 1 px
    /// wide, 512 Ki-row pair with one level under an address-space limit of 15 MiB more than is
    /// mapped. The map (4 bytes a row), census codes (16) and cost volume (1) fit; the 8-path
    /// passes' row slots (48 bytes a row) do not.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of row_slots_too_large_to_allocate_are_an_error"]
    fn row_slots_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let h = 1usize << 19;
        let img = ramp(1, h, 0.0);
        rayon::join(|| (), || ()); // the pool's thread started before the limit
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (15 << 20));
        let v = ImageView::new(1, h, &img).unwrap();
        match sgm_disparity(v, v, 0, 0, &SgmParams::default()) {
            Ok(d) => println!("child: matched {}", d.len()),
            Err(e) => println!("child: error: {e}"),
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn row_slots_too_large_to_allocate_are_an_error() {
        // The 8-path passes' per-row slots were collected, and each selected row allocated and
        // listed (vec!, push) before being copied into the map: h-sized, unchecked, a failed
        // allocation aborted the process (SIGABRT) instead of returning OutOfMemory.
        let stdout = crate::segment::tests::run_oom_child(
            "matching::sgm::tests::row_slots_under_a_memory_limit",
        );
        let want = "child: error: out of memory: the census matcher's row slots needs 24.00 MiB \
                    (25165824 bytes)";
        assert!(stdout.contains(want), "{want} not in {stdout}");
    }

    #[test]
    fn paths_other_than_8_or_3_are_refused() {
        let img = vec![0.5f32; 64];
        let v = ImageView::new(8, 8, &img).unwrap();
        let p = SgmParams {
            paths: 4,
            ..SgmParams::default()
        };
        assert!(matches!(
            sgm_disparity(v, v, 0, 4, &p).unwrap_err(),
            CoreError::InvalidParameter { name: "paths", .. }
        ));
    }

    #[test]
    fn tiny_images_and_single_levels_work() {
        let img: Vec<f32> = (0..6).map(|i| i as f32 / 6.0).collect();
        let v = ImageView::new(3, 2, &img).unwrap();
        for paths in [8, 3] {
            let p = SgmParams {
                paths,
                ..SgmParams::default()
            };
            for (a, b) in [(0, 0), (0, 5), (-2, 2)] {
                let d = sgm_disparity(v, v, a, b, &p).unwrap();
                assert_eq!(d.len(), 6);
            }
            // One row, one column.
            let row = ImageView::new(6, 1, &img).unwrap();
            let col = ImageView::new(1, 6, &img).unwrap();
            assert_eq!(sgm_disparity(row, row, 0, 3, &p).unwrap().len(), 6);
            assert_eq!(sgm_disparity(col, col, 0, 0, &p).unwrap().len(), 6);
        }
    }

    /// A deterministic pseudo-random image in [0, 1] on a coarse grey scale (ties too).
    fn noise(w: usize, h: usize, seed: u32) -> Vec<f32> {
        let mut s = seed;
        (0..w * h)
            .map(|_| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                ((s >> 24) % 6) as f32 / 5.0
            })
            .collect()
    }

    #[test]
    fn census_equals_its_definition() {
        // Bit k (the 9 x 7 window row-major, centre skipped) where the neighbour, at clamped
        // coordinates, is darker than the centre; widths below, at and above the window, and
        // one of three interior blocks (CENSUS_BLOCK), the last one short.
        for (w, h) in [(23usize, 9usize), (6, 4), (9, 3), (150, 8)] {
            let img = noise(w, h, 5);
            let c = census(ImageView::new(w, h, &img).unwrap()).unwrap();
            for y in 0..h as isize {
                for x in 0..w as isize {
                    let at = |xx: isize, yy: isize| {
                        let (xx, yy) = (xx.clamp(0, w as isize - 1), yy.clamp(0, h as isize - 1));
                        img[yy as usize * w + xx as usize]
                    };
                    let mut want = 0u64;
                    let mut bit = 0;
                    for dy in -(RY as isize)..=RY as isize {
                        for dx in -(RX as isize)..=RX as isize {
                            if (dx, dy) == (0, 0) {
                                continue;
                            }
                            want |= u64::from(at(x + dx, y + dy) < at(x, y)) << bit;
                            bit += 1;
                        }
                    }
                    assert_eq!(c[y as usize * w + x as usize], want, "{w}x{h} ({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn costs_outside_the_right_image_follow_the_best_inside_level() {
        // Levels whose right pixel x - d_min - k leaves the image cost the best inside level
        // plus OUTSIDE_MARGIN (at most OUTSIDE), or the best itself where all inside levels cost
        // the same; with no level inside, OUTSIDE.
        let w = 6;
        // Left codes of 62 bits; the right ones 61, 62, 57, 62, 62, 62 bits away from them.
        let cl = vec![(1u64 << 62) - 1; w];
        let cr: Vec<u64> = [1u64, 0, 0b11111, 0, 0, 0].to_vec();
        let n = 4;
        let vol = cost_volume(&cl, &cr, w, -1, n);
        let cell = |x: usize| &vol[x * n..(x + 1) * n];
        // x 0: levels 0..=1 read right pixels 1 and 0 (62, 61): the others 61 + 5 = 66 -> 63.
        assert_eq!(cell(0), &[62, 61, OUTSIDE, OUTSIDE]);
        // x 2: levels read right 3, 2, 1, 0: 62, 57, 62, 61; all inside.
        assert_eq!(cell(2), &[62, 57, 62, 61]);
        // x 5: level 0 reads right 6 (outside), then 5, 4, 3: all 62, so the outside one too.
        assert_eq!(cell(5), &[62, 62, 62, 62]);
        // x 4: right 5, 4, 3, 2 -> 62, 62, 62, 57.
        assert_eq!(cell(4), &[62, 62, 62, 57]);
        // The right band: x 5, d_min -1, level 0 reads right 6 (outside), the others right 5,
        // 4, 3 (52, 62, 62): 52 + 5.
        let cr2: Vec<u64> = [0u64, 0, 0, 0, 0, (1 << 10) - 1].to_vec();
        let vol = cost_volume(&cl, &cr2, w, -1, n);
        assert_eq!(&vol[5 * n..6 * n], &[57, 52, 62, 62]);
        // d_min 0, the right codes against themselves: x 0 has one inside level (0, so the
        // outside ones tie with it); x 1 has 0 and 1 inside, the outside one 0 + 5.
        let vol = cost_volume(&cr, &cr, w, 0, 3);
        assert_eq!(
            (&vol[..3], &vol[3..6]),
            (&[0u8, 0, 0][..], &[0u8, 1, 5][..])
        );
    }

    #[test]
    fn p2_shrinks_with_the_intensity_step() {
        // p2 / (1 + floor(|dI| / gamma)), at least p1 + 1, |dI| in grey levels.
        let lut = p2_table(&SgmParams::default());
        assert_eq!(lut, vec![96, 48, 32, 24, 19, 16, 13, 12, 10, 9, 9, 9]);
        let g = |a: f32, b: f32| p2_at(a / 255.0, b / 255.0, 16.0, &lut);
        assert_eq!(
            (g(0.0, 15.9), g(0.0, 16.1), g(100.0, 60.0), g(0.0, 255.0)),
            (96, 48, 32, 9)
        );
    }

    /// One path's costs by the recurrence, in i64: `L(p, k) = C(p, k) + min(L(q, k),
    /// L(q, k +- 1) + p1, min L(q) + P2(p, q)) - min L(q)` with `q = p + r` its predecessor
    /// (`L = C` where `q` leaves the image), P2 from the grey step between `p` and `q`.
    fn direct_path(
        c: &[u8],
        img: &[f32],
        w: usize,
        h: usize,
        n: usize,
        p: &SgmParams,
        r: (isize, isize),
    ) -> Vec<i64> {
        let lut = p2_table(p);
        let mut l = vec![0i64; w * h * n];
        // Visit predecessors first: rows in the direction of r's y, columns of r's x.
        let ys: Vec<usize> = if r.1 < 0 {
            (0..h).collect()
        } else {
            (0..h).rev().collect()
        };
        let xs: Vec<usize> = if r.0 < 0 {
            (0..w).collect()
        } else {
            (0..w).rev().collect()
        };
        for &y in &ys {
            for &x in &xs {
                let (qx, qy) = (x as isize + r.0, y as isize + r.1);
                let i = y * w + x;
                if qx < 0 || qy < 0 || qx >= w as isize || qy >= h as isize {
                    for k in 0..n {
                        l[i * n + k] = i64::from(c[i * n + k]);
                    }
                    continue;
                }
                let q = qy as usize * w + qx as usize;
                let lq = &l[q * n..(q + 1) * n].to_vec();
                let m = *lq.iter().min().unwrap();
                let p2 = i64::from(p2_at(img[i], img[q], p.gamma, &lut));
                for k in 0..n {
                    let mut best = lq[k].min(m + p2);
                    if k > 0 {
                        best = best.min(lq[k - 1] + i64::from(p.p1));
                    }
                    if k + 1 < n {
                        best = best.min(lq[k + 1] + i64::from(p.p1));
                    }
                    l[i * n + k] = i64::from(c[i * n + k]) + best - m;
                }
            }
        }
        l
    }

    /// The matcher by its definition (module docs) on the summed path costs `s`.
    fn direct_select(
        s: &[i64],
        w: usize,
        h: usize,
        n: usize,
        d_min: i64,
        p: &SgmParams,
    ) -> Vec<f32> {
        let d_max = d_min + n as i64 - 1;
        let mut out = vec![f32::NAN; w * h];
        for y in 0..h {
            let at = |x: usize, k: usize| s[(y * w + x) * n + k];
            // The right view's winner at xr: the first level j minimising S(xr + d_min + j, j)
            // over the left pixels in the image.
            let rk: Vec<usize> = (0..w as i64)
                .map(|xr| {
                    let cands: Vec<(i64, usize)> = (0..n)
                        .filter_map(|j| {
                            let xl = xr + d_min + j as i64;
                            (xl >= 0 && xl < w as i64).then(|| (at(xl as usize, j), j))
                        })
                        .collect();
                    cands.iter().min().map_or(0, |c| c.1)
                })
                .collect();
            for x in 0..w {
                // Levels landing in the right image (x - d in 0..w); the right band is dropped.
                if x as i64 - d_min >= w as i64 || x as i64 - d_min < 0 {
                    continue;
                }
                let inside = ((x as i64 - d_min + 1) as usize).min(n);
                let cell: Vec<i64> = (0..inside).map(|k| at(x, k)).collect();
                let best = *cell.iter().min().unwrap();
                let k = cell.iter().position(|&v| v == best).unwrap();
                let xr = x as i64 - d_min - k as i64;
                if (x as i64) < d_max && xr < i64::from(p.edge_margin) {
                    continue;
                }
                let other = (0..inside)
                    .filter(|&j| j.abs_diff(k) > 1)
                    .map(|j| cell[j])
                    .min()
                    .unwrap_or(i64::from(u16::MAX));
                let unique = 100 * other > (100 + i64::from(p.uniqueness)) * best;
                let consistent = rk[xr as usize].abs_diff(k) <= p.lr_tol as usize;
                if !(unique && consistent) {
                    continue;
                }
                let mut frac = 0.0f64;
                if k > 0 && k + 1 < inside {
                    let (sm, sp) = (cell[k - 1] as f64, cell[k + 1] as f64);
                    let den = sm + sp - 2.0 * best as f64;
                    if den > 0.0 {
                        frac = (sm - sp) / (2.0 * den);
                    }
                }
                out[y * w + x] = ((d_min + k as i64) as f64 + frac) as f32;
            }
        }
        out
    }

    #[test]
    fn both_matchers_equal_their_definition() {
        // 8 paths (horizontal, vertical and both diagonals, each way) and 3 (left to right,
        // right to left, top to bottom) on a shifted pair with sharp steps (every P2 level),
        // ranges with d_min 0 and negative, more than 16 levels (argmin's blocks), and
        // parameters off their defaults.
        let (w, h) = (46usize, 13usize);
        let l: Vec<f32> = ramp(w, h, 0.0)
            .iter()
            .zip(noise(w, h, 9))
            .enumerate()
            .map(|(i, (v, z))| match (i % w, i / w) {
                // A flat patch: cost ties between levels.
                (20..=31, 0..=4) => 0.5,
                _ if i % 11 < 2 => z,
                _ => *v,
            })
            .collect();
        let r = ramp(w, h, 5.0);
        let (lv, rv) = (
            ImageView::new(w, h, &l).unwrap(),
            ImageView::new(w, h, &r).unwrap(),
        );
        let loose = SgmParams {
            p1: 5,
            p2: 150,
            gamma: 9.0,
            uniqueness: 0,
            lr_tol: 2,
            edge_margin: 0,
            paths: 8,
        };
        for (d_min, d_max) in [(0i32, 8i32), (-3, 17)] {
            let n = (d_max - d_min + 1) as usize;
            let c = cost_volume(
                &census(lv).unwrap(),
                &census(rv).unwrap(),
                w,
                i64::from(d_min),
                n,
            );
            for base in [SgmParams::default(), loose] {
                for paths in [8u8, 3] {
                    let p = SgmParams { paths, ..base };
                    let dirs: &[(isize, isize)] = if paths == 8 {
                        &[
                            (-1, 0),
                            (1, 0),
                            (0, -1),
                            (0, 1),
                            (-1, -1),
                            (1, -1),
                            (-1, 1),
                            (1, 1),
                        ]
                    } else {
                        &[(-1, 0), (1, 0), (0, -1)]
                    };
                    let mut s = vec![0i64; w * h * n];
                    for &dir in dirs {
                        for (a, b) in s.iter_mut().zip(direct_path(&c, &l, w, h, n, &p, dir)) {
                            *a += b;
                        }
                    }
                    let want = direct_select(&s, w, h, n, i64::from(d_min), &p);
                    let got = sgm_disparity(lv, rv, d_min, d_max, &p).unwrap();
                    for i in 0..w * h {
                        assert_eq!(
                            got[i].to_bits(),
                            want[i].to_bits(),
                            "{paths} paths, {d_min}..={d_max}, {p:?}: ({}, {}) {} vs {}",
                            i % w,
                            i / w,
                            got[i],
                            want[i]
                        );
                    }
                    let found = want.iter().filter(|v| v.is_finite()).count();
                    assert!(found > w * h / 3, "{found} found");
                }
            }
        }
    }

    #[test]
    fn each_pass_sums_its_four_paths_by_their_definition() {
        // The raster pass sums the paths from the left, above and both upper diagonals, the
        // reverse pass their opposites, each from its first pixel on (the diagonals entering
        // from the first and last columns too). The levels at both ends of the range cost the
        // most, so their path costs climb far above the minimum (each level P1 plus its cost
        // above the next): with P2 = MAX_P2 the pads must exceed every path cost.
        let (w, h, n) = (15usize, 9usize, 10usize);
        let img = noise(w, h, 3);
        let c: Vec<u8> = noise(w * h * n, 1, 11)
            .iter()
            .enumerate()
            .map(|(i, v)| match i % n {
                0..=3 => OUTSIDE,
                k if k >= n - 3 => OUTSIDE - 1,
                _ => (v * 20.0).round() as u8,
            })
            .collect();
        let d = SgmParams::default();
        let big = SgmParams { p2: MAX_P2, ..d };
        for (p, u8_costs) in [(d, true), (d, false), (big, false)] {
            for (forward, dirs) in [
                (true, [(-1, 0), (0, -1), (-1, -1), (1, -1)]),
                (false, [(1, 0), (0, 1), (1, 1), (-1, 1)]),
            ] {
                let mut want = vec![0i64; w * h * n];
                for dir in dirs {
                    for (a, b) in want.iter_mut().zip(direct_path(&c, &img, w, h, n, &p, dir)) {
                        *a += b;
                    }
                }
                let mut rows = Vec::new();
                let mut emit = |y: usize, row: &mut Vec<u16>| rows.push((y, row.clone()));
                let mut row = vec![0u16; w * n];
                let run = if u8_costs { pass_u8 } else { pass_u16 };
                run(&c, &img, w, h, n, &p, forward, &mut row, &mut emit).unwrap();
                assert_eq!(rows.len(), h);
                for (y, r) in rows {
                    let got: Vec<i64> = r.iter().map(|&v| i64::from(v)).collect();
                    let tag = format!("{p:?} u8 {u8_costs} forward {forward} row {y}");
                    assert_eq!(got, want[y * w * n..(y + 1) * w * n], "{tag}");
                }
            }
        }
    }

    #[test]
    fn right_winners_equal_their_definition() {
        // At each right pixel xr: the first level j minimising S(xr + d_min + j, j) over the left
        // pixels in the image (u16::MAX and level 0 where none is), for ranges reaching past
        // either edge of the row; the outputs are overwritten whatever they held.
        // Level counts past 16 and 32 run the vectorised loop (its u16 level counter) with and
        // without a tail.
        for (w, n, d_min) in [6usize, 17, 40, 129]
            .into_iter()
            .flat_map(|n| [-9i64, -4, 0, 3, 20].map(|d| (13 + n, n, d)))
        {
            let s: Vec<u16> = noise(w * n, 1, 7)
                .iter()
                .map(|v| (v * 5.0).round() as u16)
                .collect();
            let (mut rbest, mut rk) = (vec![7u16; w], vec![7u16; w]);
            right_winners(&s, w, n, d_min, &mut rbest, &mut rk);
            for xr in 0..w as i64 {
                let want = (0..n)
                    .filter_map(|j| {
                        let xl = xr + d_min + j as i64;
                        (0..w as i64)
                            .contains(&xl)
                            .then(|| (s[xl as usize * n + j], j as u16))
                    })
                    .min()
                    .unwrap_or((u16::MAX, 0));
                let i = w - 1 - xr as usize;
                assert_eq!(
                    (rbest[i], rk[i]),
                    want,
                    "{n} levels, d_min {d_min}, xr {xr}"
                );
            }
        }
    }

    #[test]
    fn argmin_and_min_apart_equal_their_definition() {
        // The first index of the minimum, and the minimum away from it by more than one index
        // (at either end too), on cells of 1..=200 values drawn from a few so that they tie.
        let mut s = 99u32;
        let mut rand = move || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            s >> 8
        };
        for n in 1..=200usize {
            for spread in [3u32, 40] {
                let cell: Vec<u16> = (0..n).map(|_| (rand() % spread + 7) as u16).collect();
                let m = *cell.iter().min().unwrap();
                let first = cell.iter().position(|&v| v == m).unwrap();
                assert_eq!(argmin(&cell), (first, m), "{cell:?}");
                for k in 0..n {
                    let want = (0..n)
                        .filter(|&i| i.abs_diff(k) > 1)
                        .map(|i| cell[i])
                        .min()
                        .unwrap_or(u16::MAX);
                    assert_eq!(min_apart(&cell, k), want, "k {k} of {cell:?}");
                }
            }
        }
    }

    #[test]
    fn argmin_min_apart_and_right_winners_hold_at_every_level_count_and_the_limit() {
        // The u16 level counters of argmin, min_apart and right_winners against plain
        // definitions at every level count 1..=300 and at the 2048-level limit: ties everywhere,
        // the minimum only at the last level, tied at both ends, or at the last two levels
        // (where a counter that wrapped, or a last match kept for the first, gives another
        // winner).
        let mut s = 5u32;
        let mut rand = move || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            s >> 8
        };
        for n in (1..=300usize).chain([2047, 2048]) {
            let mut cells: Vec<Vec<u16>> = vec![
                (0..n).map(|_| (rand() % 3 + 7) as u16).collect(),
                vec![9; n],
            ];
            for at in [
                vec![n - 1],
                vec![0, n - 1],
                vec![n.saturating_sub(2), n - 1],
            ] {
                let mut c: Vec<u16> = (0..n).map(|_| (rand() % 40 + 9) as u16).collect();
                at.iter().for_each(|&i| c[i] = 3);
                cells.push(c);
            }
            for cell in &cells {
                let m = *cell.iter().min().unwrap();
                let first = cell.iter().position(|&v| v == m).unwrap();
                assert_eq!(argmin(cell), (first, m), "{n} levels");
                let ks: Vec<usize> = if n <= 300 {
                    (0..n).collect()
                } else {
                    vec![0, 1, 2, first, n / 2, n - 3, n - 2, n - 1]
                };
                // The minimum outside k - 1 ..= k + 1 from the minima of the levels below
                // (before[i]: levels 0..i) and above (after[i]: levels i..n): O(n) a cell where
                // a filter over every level for every k took O(n^2).
                let mut before = vec![u16::MAX; n + 1];
                let mut after = vec![u16::MAX; n + 1];
                for i in 0..n {
                    before[i + 1] = before[i].min(cell[i]);
                    after[n - 1 - i] = after[n - i].min(cell[n - 1 - i]);
                }
                for k in ks {
                    let want = before[k.saturating_sub(1)].min(after[(k + 2).min(n)]);
                    assert_eq!(min_apart(cell, k), want, "{n} levels, k {k}");
                }
            }
        }
        // right_winners over 2048 levels, the least cost at the last level of each left pixel.
        let (n, w) = (2048usize, 2060usize);
        for d_min in [-2047i64, 0, 5] {
            let s: Vec<u16> = (0..w * n)
                .map(|i| {
                    if i % n == n - 1 {
                        1
                    } else {
                        (rand() % 50 + 2) as u16
                    }
                })
                .collect();
            let (mut rbest, mut rk) = (vec![7u16; w], vec![7u16; w]);
            right_winners(&s, w, n, d_min, &mut rbest, &mut rk);
            for xr in 0..w as i64 {
                let want = (0..n)
                    .filter_map(|j| {
                        let xl = xr + d_min + j as i64;
                        (0..w as i64)
                            .contains(&xl)
                            .then(|| (s[xl as usize * n + j], j as u16))
                    })
                    .min()
                    .unwrap_or((u16::MAX, 0));
                let i = w - 1 - xr as usize;
                assert_eq!((rbest[i], rk[i]), want, "d_min {d_min}, xr {xr}");
            }
        }
    }

    /// Whole cost rows by the kernel a token picks against the compiler's loop, for each level
    /// count: odd and even widths, ranges past either edge, on random 64-bit codes, census-like
    /// 62-bit ones and equal codes (a flat patch: every inside level ties).
    fn same_cost_rows_as_the_compilers(
        seed: u64,
        levels: impl IntoIterator<Item = usize>,
        avx2: Option<Avx2>,
        avx512: Option<Avx512>,
    ) {
        let mut s = seed;
        let mut rand = move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            s
        };
        for n in levels {
            for w in [1usize, 2, 31, 64, 97, 230] {
                for d_min in [-40i64, 0, 5] {
                    let codes: [Vec<u64>; 3] = [
                        (0..2 * w).map(|_| rand()).collect(),
                        (0..2 * w).map(|_| rand() >> 2).collect(),
                        vec![0x0123_4567_89ab_cdef; 2 * w],
                    ];
                    for c in &codes {
                        let (cl, rev): (&[u64], Vec<u64>) =
                            (&c[..w], c[w..].iter().rev().copied().collect());
                        let mut want = vec![0u8; w * n];
                        let mut got = vec![1u8; w * n];
                        cost_row_as(cl, &rev, d_min, n, &mut want, None, None);
                        cost_row_as(cl, &rev, d_min, n, &mut got, avx2, avx512);
                        assert_eq!(got, want, "{n} levels, width {w}, d_min {d_min}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_avx2_hamming_costs_are_the_compilers() {
        // The AVX2 kernel's rows. A row's pixels hand the kernel every
        // length 1..=min(n, w) (their inside levels; d_min 0: pixel x has x + 1), so width 230
        // with n >= 230 already gives every length 32..=230 the kernel takes (every tail
        // 0..=31: below 16 one by one, above it a last vector overlapping the one before):
        // level counts 1..=48 and a few long ones (other cell strides, 2047 and 2048) kill the
        // same mutants as every count 1..=200, in a fraction of the time.
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: nothing to compare");
            return;
        };
        same_cost_rows_as_the_compilers(
            7,
            (1..=48).chain([63, 64, 65, 129, 200, 230, 300, 2047, 2048]),
            Some(avx2),
            None,
        );
    }

    #[test]
    fn the_avx512_hamming_costs_are_the_compilers() {
        // The AVX-512 kernel's rows. A row's pixels hand the kernel
        // every length 1..=min(n, w) (their inside levels; d_min 0: pixel x has x + 1), so
        // width 230 with n >= 230 already gives every tail 0..=15 of the masked last step
        // after 0..=13 whole steps: level counts 1..=48 and a few long ones (other cell
        // strides, 2047 and 2048) kill the same mutants as every count 1..=300, in an eighth of
        // the time.
        let Some(avx512) = Avx512::detect() else {
            eprintln!("no AVX-512 (F, BW, VL, VPOPCNTDQ) on this CPU: nothing to compare");
            return;
        };
        same_cost_rows_as_the_compilers(
            11,
            (1..=48).chain([63, 64, 65, 129, 230, 300, 2047, 2048]),
            None,
            Some(avx512),
        );
    }

    #[test]
    fn the_avx512_hamming_costs_count_every_bit() {
        // As the AVX2 test below: every count 0..=64 (64 kills a count capped or wrapped at 63)
        // in every lane of a step and of the masked tail, at every length, from either end of
        // the codes, and the minimum and maximum it returns (a reduction that drops a lane, or
        // counts a masked-off one, fails).
        let Some(avx512) = Avx512::detect() else {
            eprintln!("no AVX-512 (F, BW, VL, VPOPCNTDQ) on this CPU: nothing to compare");
            return;
        };
        let a = 0xf0f0_0000_ffff_1234u64;
        let mut b: Vec<u64> = (0..=64u32)
            .map(|p| a ^ 1u64.checked_shl(p).map_or(u64::MAX, |v| v - 1))
            .collect();
        b.extend((0..16u64).map(|v| a ^ (v * 0x1111_1111_1111_1111)));
        for n in 1..=b.len() {
            for right in [&b[..n], &b[b.len() - n..]] {
                let rev: Vec<u64> = right.iter().rev().copied().collect();
                for r in [right, &rev[..]] {
                    let want: Vec<u8> = r.iter().map(|&x| (a ^ x).count_ones() as u8).collect();
                    // Bytes past `n` must stay as they were (the tail's store is masked).
                    let mut got = vec![0xaa; n + 16];
                    let bw = hamming_avx512(avx512, a, r, &mut got[..n]);
                    assert_eq!(got[..n], want, "{n} levels");
                    assert!(got[n..].iter().all(|&v| v == 0xaa), "{n} levels");
                    let (lo, hi) = (*want.iter().min().unwrap(), *want.iter().max().unwrap());
                    assert_eq!(bw, Some((lo, hi)), "{n} levels");
                }
            }
        }
        assert_eq!(hamming_avx512(avx512, a, &b[..0], &mut []), None);
    }

    #[test]
    fn the_avx2_hamming_costs_count_every_bit() {
        // The kernel against the definition, popcount(a ^ b), where every count 0..=64 occurs
        // (64 kills a count capped or wrapped at 63, which census codes of 62 bits never reach)
        // and every nibble value in every nibble (kills a wrong table entry, a high nibble
        // shifted in without its mask and counts packed out of level order); the minimum and
        // maximum it returns too (from either end, so a reduction that drops a lane fails).
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: nothing to compare");
            return;
        };
        let a = 0xf0f0_0000_ffff_1234u64;
        let mut b: Vec<u64> = (0..=64u32)
            .map(|p| a ^ 1u64.checked_shl(p).map_or(u64::MAX, |v| v - 1))
            .collect();
        for v in 0..16u64 {
            for at in 0..16 {
                b.push(a ^ (v << (4 * at)));
            }
        }
        b.extend((0..16u64).map(|v| a ^ (v * 0x1111_1111_1111_1111)));
        for n in 32..=b.len() {
            for right in [&b[..n], &b[b.len() - n..]] {
                let rev: Vec<u64> = right.iter().rev().copied().collect();
                for r in [right, &rev[..]] {
                    let want: Vec<u8> = r.iter().map(|&x| (a ^ x).count_ones() as u8).collect();
                    let mut got = vec![0u8; n];
                    let bw = hamming_avx2(avx2, a, r, &mut got);
                    assert_eq!(got, want, "{n} levels");
                    let (lo, hi) = (*want.iter().min().unwrap(), *want.iter().max().unwrap());
                    assert_eq!(bw, Some((lo, hi)), "{n} levels");
                }
            }
        }
        assert_eq!(hamming_avx2(avx2, a, &b[..31], &mut [0; 31]), None);
    }

    #[test]
    fn parameter_limits_are_exact() {
        // 0 < p1 < p2 <= MAX_P2, uniqueness <= 100, at most 2048 levels.
        let img = vec![0.5f32; 64];
        let v = ImageView::new(8, 8, &img).unwrap();
        let d = SgmParams::default();
        let run = |p: SgmParams, d_max: i32| sgm_disparity(v, v, 0, d_max, &p);
        assert!(run(SgmParams { p1: 96, ..d }, 4).is_err());
        assert!(run(SgmParams { p1: 95, ..d }, 4).is_ok());
        assert!(run(SgmParams { p2: MAX_P2, ..d }, 4).is_ok());
        // gamma > 0: a zero or negative step scale is refused, the smallest positive one taken.
        for gamma in [0.0, -1.0] {
            assert!(matches!(
                run(SgmParams { gamma, ..d }, 4).unwrap_err(),
                CoreError::InvalidParameter { name: "gamma", .. }
            ));
        }
        assert!(run(
            SgmParams {
                gamma: f32::MIN_POSITIVE,
                ..d
            },
            4
        )
        .is_ok());
        assert!(run(
            SgmParams {
                uniqueness: 101,
                ..d
            },
            4
        )
        .is_err());
        assert!(run(
            SgmParams {
                uniqueness: 100,
                ..d
            },
            4
        )
        .is_ok());
        assert!(run(d, 2047).is_ok());
        assert!(matches!(
            run(d, 2048).unwrap_err(),
            CoreError::InvalidParameter { name: "d_max", .. }
        ));
    }
}
