//! Position-shift search (A.5 step 2 at the top level, the A.9 re-search below it).
//!
//! For each pixel, the candidate `base + o` (`o` in `offs`) maximising the box-pooled normalised
//! binocular energy `sum 2 Re(y_l conj y_r) / sum (|y_l|^2 + |y_r|^2)` over a `(2p+1)^2` box
//! (A.9: the raw energy favours high-contrast positions). Ties keep the first offset.
//!
//! Fused per band of rows: every offset's energy row is computed while the band's filter data is
//! in cache, pooled along x at once and along y from a ring of `2p+1` rows. (Full-image planes per
//! offset streamed the level data from memory once per offset: the search was memory-bound and
//! cost more than the filtering.) The pooled sums are formed in a fixed order per output pixel,
//! so the result does not depend on the band split or the thread count.

// Row kernels index several equally long rows in lockstep; index loops are the clearest form
// and the one LLVM vectorises once the slices are re-bounded to the row length.
#![allow(clippy::needless_range_loop)]

use super::fastmath::floor_fast;
use super::gather::gather;
use super::level::{LevelData, SUBROWS};
use super::pool::Buf;
use crate::error::Result;
use crate::simd::simd_fn;
use rayon::prelude::*;

/// Output rows per task: the `2p` halo rows are recomputed by each band, so bands are longer
/// than the other kernels' (`p = 2`: 12 % extra energy rows at 32 rows, 25 % at 16).
const SEARCH_BAND: usize = 32;

/// Per-pixel argmax of the pooled normalised energy over `base + offs` (see the module docs).
pub fn search(
    l: &LevelData,
    r: &LevelData,
    base: &[f32],
    offs: &[f32],
    pool: usize,
) -> Result<Buf> {
    search_impl(l, r, base, offs, pool, true)
}

/// [`search`], with the fused AVX2 row kernel allowed or not (tests compare the two).
pub(crate) fn search_impl(
    l: &LevelData,
    r: &LevelData,
    base: &[f32],
    offs: &[f32],
    pool: usize,
    allow_fused: bool,
) -> Result<Buf> {
    let (w, h) = (l.w, l.h);
    let mut out = Buf::from_slice(base)?;
    if w == 0 || h == 0 || offs.is_empty() {
        return Ok(out);
    }
    if pool == 0 {
        out.par_chunks_mut(w * SEARCH_BAND)
            .enumerate()
            .for_each(|(band, chunk)| {
                let mut sc = Scratch::new(w, 0);
                let mut best = vec![0f32; w];
                let fused = allow_fused && consecutive(offs) && avx2::available();
                for (i, orow) in chunk.chunks_mut(w).enumerate() {
                    let y = band * SEARCH_BAND + i;
                    if fused {
                        // SAFETY: AVX2 is available and `offs` are consecutive integers.
                        unsafe {
                            avx2::direct_row(
                                l,
                                r,
                                y,
                                &base[y * w..(y + 1) * w],
                                offs,
                                &mut sc.j0,
                                orow,
                            )
                        };
                        continue;
                    }
                    direct_row(
                        l,
                        r,
                        y,
                        &base[y * w..(y + 1) * w],
                        offs,
                        &mut sc,
                        &mut best,
                        orow,
                    );
                }
            });
        return Ok(out);
    }
    let ring = 2 * pool + 1;
    let k = offs.len();
    out.par_chunks_mut(w * SEARCH_BAND)
        .enumerate()
        .for_each(|(band, chunk)| {
            let y0 = band * SEARCH_BAND;
            let y1 = y0 + chunk.len() / w;
            // Ring of x-pooled rows: offset `oi`, row `yy` at ((oi * ring + yy % ring) * w).
            let mut rn = vec![0f32; k * ring * w];
            let mut rd = vec![0f32; k * ring * w];
            let mut best = vec![f32::NEG_INFINITY; w];
            let mut sc = Scratch::new(w, pool);
            for yy in y0.saturating_sub(pool)..(y1 + pool).min(h) {
                let drow = &base[yy * w..(yy + 1) * w];
                for (oi, &o) in offs.iter().enumerate() {
                    let at = (oi * ring + yy % ring) * w;
                    energy_row(
                        l,
                        r,
                        yy,
                        drow,
                        o,
                        &mut sc,
                        &mut rn[at..at + w],
                        &mut rd[at..at + w],
                    );
                }
                // Output rows whose last needed (clamped) row is `yy`.
                let ys = if yy == h - 1 {
                    yy.saturating_sub(pool)..h
                } else if yy >= pool {
                    yy - pool..yy - pool + 1
                } else {
                    continue;
                };
                for y in ys.filter(|y| (y0..y1).contains(y)) {
                    let rows: Vec<usize> = (-(pool as isize)..=pool as isize)
                        .map(|dy| (y as isize + dy).clamp(0, h as isize - 1) as usize % ring)
                        .collect();
                    best.iter_mut().for_each(|b| *b = f32::NEG_INFINITY);
                    let orow = &mut chunk[(y - y0) * w..(y - y0 + 1) * w];
                    let brow = &base[y * w..(y + 1) * w];
                    for (oi, &o) in offs.iter().enumerate() {
                        let at = oi * ring * w;
                        pick_row(
                            &rn[at..at + ring * w],
                            &rd[at..at + ring * w],
                            &rows,
                            w,
                            brow,
                            o,
                            &mut sc.num,
                            &mut sc.den,
                            &mut best,
                            orow,
                        );
                    }
                }
            }
        });
    Ok(out)
}

/// Row buffers of one band.
struct Scratch {
    si: Vec<u32>,
    /// 1 where the shifted position is inside the image, else 0 (a float mask, see `direct_row`).
    valid: Vec<f32>,
    /// `floor(x - d + 0.5)`: the shifted position at offset 0 (unpooled search).
    j0: Vec<i32>,
    /// Gathered right samples (re, im).
    gr: Vec<f32>,
    gi: Vec<f32>,
    num: Vec<f32>,
    den: Vec<f32>,
    /// A row padded by `p` clamped samples on each side (the x pooling).
    pad: Vec<f32>,
    p: usize,
}

impl Scratch {
    fn new(w: usize, p: usize) -> Self {
        Scratch {
            si: vec![0; w],
            valid: vec![0.0; w],
            j0: vec![0; w],
            gr: vec![0.0; w],
            gi: vec![0.0; w],
            num: vec![0.0; w],
            den: vec![0.0; w],
            pad: vec![0.0; w + 2 * p],
            p,
        }
    }
}

/// `out(x) = sum_{k=-p..p} v(clamp(x + k))`, summed in `k` order.
#[inline(always)]
fn pool_x(v: &[f32], pad: &mut [f32], p: usize, out: &mut [f32]) {
    let w = v.len();
    pad[p..p + w].copy_from_slice(v);
    for i in 0..p {
        pad[i] = v[0];
        pad[p + w + i] = v[w - 1];
    }
    out[..w].copy_from_slice(&pad[..w]);
    for k in 1..=2 * p {
        for (o, s) in out[..w].iter_mut().zip(&pad[k..k + w]) {
            *o += s;
        }
    }
}

/// `num = sum_c Re(y_l conj y_r)` over the channels at the right positions `si` of row `y`
/// (`gr`, `gi`: scratch rows). Inlined into the AVX2 row kernels that call it.
#[inline(always)]
fn channel_dot(
    l: &LevelData,
    r: &LevelData,
    y: usize,
    si: &[u32],
    num: &mut [f32],
    gr: &mut [f32],
    gi: &mut [f32],
) {
    let w = l.w;
    let ro = SUBROWS * y * w;
    let (num, gr, gi) = (&mut num[..w], &mut gr[..w], &mut gi[..w]);
    num.iter_mut().for_each(|v| *v = 0.0);
    for (lc, rc) in l.chan.iter().zip(&r.chan) {
        let (lre, lim) = (&lc[ro + 4 * w..ro + 5 * w], &lc[ro + 5 * w..ro + 6 * w]);
        gather(&rc[ro + 4 * w..ro + 5 * w], si, gr);
        gather(&rc[ro + 5 * w..ro + 6 * w], si, gi);
        for x in 0..w {
            num[x] += lre[x] * gr[x] + lim[x] * gi[x];
        }
    }
}

simd_fn! {
    /// Energy terms of row `y` at the integer shifts `floor(x - d + 0.5) - off`, pooled along x into
    /// `(hn, hd)`: `num = sum_c 2 Re(y_l conj y_r)`, `den = sum_c |y_l|^2 + |y_r|^2`, both zero
    /// where the shifted position leaves the image. Integer shifts: the candidates are 1 px apart
    /// and pooled over a box, so interpolation buys nothing; the Newton steps refine to sub-pixel.
    fn energy_row(
        l: &LevelData,
        r: &LevelData,
        y: usize,
        drow: &[f32],
        off: f32,
        sc: &mut Scratch,
        hn: &mut [f32],
        hd: &mut [f32],
    ) {
        let w = l.w;
        let o = y * w;
        let last = (w - 1) as f32;
        let (si, valid) = (&mut sc.si[..w], &mut sc.valid[..w]);
        for x in 0..w {
            let s = floor_fast(x as f32 - drow[x] + 0.5) - off;
            let v = s >= 0.0 && s <= last;
            valid[x] = if v { 1.0 } else { 0.0 };
            si[x] = if v { s as u32 } else { 0 };
        }
        let (num, den) = (&mut sc.num[..w], &mut sc.den[..w]);
        let (gr, gi) = (&mut sc.gr[..w], &mut sc.gi[..w]);
        channel_dot(l, r, y, si, num, gr, gi);
        gather(&r.energy[o..o + w], si, gr);
        let le = &l.energy[o..o + w];
        for x in 0..w {
            // Products with the 0/1 mask, not selects (see `direct_row`).
            let v = valid[x];
            num[x] = 2.0 * num[x] * v;
            den[x] = (le[x] + gr[x]) * v;
        }
        pool_x(num, &mut sc.pad, sc.p, hn);
        pool_x(den, &mut sc.pad, sc.p, hd);
    }
}

simd_fn! {
    /// One candidate for one output row: y-pools the ring rows `rows` (in order), and keeps
    /// `base + off` where its normalised energy beats `best`.
    fn pick_row(
        rn: &[f32],
        rd: &[f32],
        rows: &[usize],
        w: usize,
        base: &[f32],
        off: f32,
        num: &mut [f32],
        den: &mut [f32],
        best: &mut [f32],
        out: &mut [f32],
    ) {
        let (num, den) = (&mut num[..w], &mut den[..w]);
        let Some((&first, rest)) = rows.split_first() else {
            return;
        };
        num.copy_from_slice(&rn[first * w..(first + 1) * w]);
        den.copy_from_slice(&rd[first * w..(first + 1) * w]);
        for &s in rest {
            for (a, b) in num.iter_mut().zip(&rn[s * w..(s + 1) * w]) {
                *a += b;
            }
            for (a, b) in den.iter_mut().zip(&rd[s * w..(s + 1) * w]) {
                *a += b;
            }
        }
        let (base, best, out) = (&base[..w], &mut best[..w], &mut out[..w]);
        for x in 0..w {
            // Unconditional loads and stores (no VMASKMOVPS, see `direct_row`).
            let e = if den[x] > 0.0 { num[x] / den[x] } else { 0.0 };
            let (b, cand, cur) = (best[x], base[x] + off, out[x]);
            best[x] = b.max(e);
            out[x] = if e > b { cand } else { cur };
        }
    }
}

simd_fn! {
    /// One output row of the unpooled search (`p = 0`): every offset evaluated per pixel, no
    /// ring and no pooling pass. Same terms and tie rule as the pooled path.
    fn direct_row(
        l: &LevelData,
        r: &LevelData,
        y: usize,
        drow: &[f32],
        offs: &[f32],
        sc: &mut Scratch,
        best: &mut [f32],
        out: &mut [f32],
    ) {
        let w = l.w;
        let o = y * w;
        let (drow, best, out) = (&drow[..w], &mut best[..w], &mut out[..w]);
        let (si, valid, j0) = (&mut sc.si[..w], &mut sc.valid[..w], &mut sc.j0[..w]);
        let (num, gr, gi) = (&mut sc.num[..w], &mut sc.gr[..w], &mut sc.gi[..w]);
        for x in 0..w {
            j0[x] = floor_fast(x as f32 - drow[x] + 0.5) as i32;
        }
        best.iter_mut().for_each(|b| *b = f32::NEG_INFINITY);
        let le = &l.energy[o..o + w];
        for &off in offs {
            let oi = off as i32;
            for x in 0..w {
                // Saturating: `j0` saturates to i32::MIN / i32::MAX for shifts off the i32
                // range, where `j0 - oi` overflowed (0..w is left out either way).
                let j = j0[x].saturating_sub(oi);
                let v = j >= 0 && j < w as i32;
                valid[x] = if v { 1.0 } else { 0.0 };
                si[x] = if v { j as u32 } else { 0 };
            }
            channel_dot(l, r, y, si, num, gr, gi);
            gather(&r.energy[o..o + w], si, gr);
            for x in 0..w {
                // No load or store under a condition: LLVM turns those into VMASKMOVPS, which is
                // microcoded on AMD (the masked loads and the masked store of `best` were a large
                // share of the search on Zen 3). The gathered terms are finite, so a product with
                // the 0/1 mask is exact, and it cannot be folded back into a masked load.
                let v = valid[x];
                let n = 2.0 * num[x] * v;
                let d = (le[x] + gr[x]) * v;
                let e = if d > 0.0 { n / d } else { 0.0 };
                let (b, cand, cur) = (best[x], drow[x] + off, out[x]);
                let better = e > b;
                best[x] = b.max(e);
                out[x] = if better { cand } else { cur };
            }
        }
    }
}

/// True when `offs` are consecutive integers in increasing order (the re-search and the top-level
/// search both are): the fused AVX2 row kernel relies on it.
fn consecutive(offs: &[f32]) -> bool {
    offs.iter().all(|o| o.fract() == 0.0 && o.abs() < 65536.0)
        && offs.windows(2).all(|p| p[1] - p[0] == 1.0)
}

/// The unpooled search row fused over offsets in registers (AVX2).
///
/// [`direct_row`] makes, per offset, a pass of index work, one gather per channel plane and a
/// pass of energy arithmetic, through row buffers. Here each 8-pixel chunk is done for every
/// offset at once: the candidates of offset `o` sit at `j0 - o`, so when the chunk's `j0` lie
/// within 16 of their minimum (smooth disparities: nearly all chunks) every offset is one or two
/// loads per plane and the same in-register permutation, and the running best stays in
/// registers. The float
/// operations are those of [`direct_row`] in the same order, so the output is the same bit for
/// bit (tested).
mod avx2 {
    use super::LevelData;
    #[cfg(target_arch = "x86_64")]
    use super::SUBROWS;
    #[cfg(target_arch = "x86_64")]
    use crate::matching::gabor::gather::win;
    #[cfg(target_arch = "x86_64")]
    use std::arch::x86_64::*;

    pub fn available() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            std::is_x86_feature_detected!("avx2")
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    /// # Safety
    /// The CPU must support AVX2 ([`available`]); `offs` must be consecutive integers.
    #[cfg(not(target_arch = "x86_64"))]
    pub unsafe fn direct_row(
        _l: &LevelData,
        _r: &LevelData,
        _y: usize,
        _drow: &[f32],
        _offs: &[f32],
        _j0: &mut [i32],
        _out: &mut [f32],
    ) {
        unreachable!("AVX2 kernel called without AVX2")
    }

    /// 8 samples of `src`: `src[base + rel]` from a window load (`window`: the caller checked
    /// `0 <= base`, `base + reach(spread) <= src.len()`, `rel` in `0..=spread`), else a gather
    /// at `idx` (in `0..src.len()`).
    ///
    /// # Safety
    /// AVX2, and the bounds above.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn load(
        src: &[f32],
        base: i32,
        rel: __m256i,
        spread: i32,
        idx: __m256i,
        window: bool,
    ) -> __m256 {
        // SAFETY: see the function's contract.
        unsafe {
            if window {
                win::load(src.as_ptr().add(base as usize), rel, spread)
            } else {
                _mm256_i32gather_ps::<4>(src.as_ptr(), idx)
            }
        }
    }

    /// # Safety
    /// The CPU must support AVX2 ([`available`]); `offs` must be consecutive integers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub unsafe fn direct_row(
        l: &LevelData,
        r: &LevelData,
        y: usize,
        drow: &[f32],
        offs: &[f32],
        j0: &mut [i32],
        out: &mut [f32],
    ) {
        const LANES: usize = 8;
        let w = l.w;
        let (o, ro) = (y * w, SUBROWS * y * w);
        let (drow, out, j0) = (&drow[..w], &mut out[..w], &mut j0[..w]);
        for x in 0..w {
            j0[x] = super::floor_fast(x as f32 - drow[x] + 0.5) as i32;
        }
        // Channels present in both levels (as `channel_dot` zips them): `rrows[c]` below is
        // read for every c < nch.
        let nch = l.chan.len().min(r.chan.len());
        // Per channel: the left (re, im) rows and the right (re, im) rows of row y.
        let lrows: Vec<(&[f32], &[f32])> = l
            .chan
            .iter()
            .map(|c| (&c[ro + 4 * w..ro + 5 * w], &c[ro + 5 * w..ro + 6 * w]))
            .collect();
        let rrows: Vec<(&[f32], &[f32])> = r
            .chan
            .iter()
            .map(|c| (&c[ro + 4 * w..ro + 5 * w], &c[ro + 5 * w..ro + 6 * w]))
            .collect();
        let (le, re) = (&l.energy[o..o + w], &r.energy[o..o + w]);
        let o0 = offs[0] as i32;
        let wi = w as i32;
        let zero = _mm256_setzero_ps();
        let two = _mm256_set1_ps(2.0);
        let one = _mm256_set1_ps(1.0);
        let lastv = _mm256_set1_epi32(wi - 1);
        debug_assert!(lrows.len() >= nch && rrows.len() >= nch);
        debug_assert!(lrows
            .iter()
            .chain(&rrows)
            .all(|(a, b)| a.len() == w && b.len() == w));
        let mut x = 0;
        while x + LANES <= w {
            // SAFETY (whole block): x + 8 <= w bounds every 8-lane load and store at x of the
            // row slices (all of length w); `lrows` and `rrows` hold `nch` channels. Window
            // loads at `base` are made only when 0 <= base and base + reach <= w (tested in i64:
            // `j0` saturates to i32::MIN / i32::MAX for shifts off the i32 range, where the i32
            // `first - oi` and `base + reach` overflowed and could pass the test); gathers use
            // indices clamped to 0..=w-1.
            unsafe {
                let jv = _mm256_loadu_si256(j0.as_ptr().add(x) as *const __m256i);
                let (first, rel, spread) = win::window(jv);
                let (window, reach) = (spread <= win::WIDE, win::reach(spread) as i32);
                let dv = _mm256_loadu_ps(drow.as_ptr().add(x));
                let mut cur = _mm256_loadu_ps(out.as_ptr().add(x));
                let mut best = _mm256_set1_ps(f32::NEG_INFINITY);
                let lev = _mm256_loadu_ps(le.as_ptr().add(x));
                for (k, &off) in offs.iter().enumerate() {
                    let oi = o0 + k as i32;
                    let base = i64::from(first) - i64::from(oi);
                    let in_window = window && base >= 0 && base + i64::from(reach) <= i64::from(wi);
                    // Only used (as a pointer offset) when in_window: then 0 <= base < w.
                    let base = base as i32;
                    // Shifted positions, their validity (0 <= j < w) and clamped indices.
                    let j = _mm256_sub_epi32(jv, _mm256_set1_epi32(oi));
                    let (v, idx) = if in_window {
                        (one, j)
                    } else {
                        let inside = _mm256_andnot_si256(
                            _mm256_cmpgt_epi32(_mm256_setzero_si256(), j),
                            _mm256_cmpgt_epi32(_mm256_set1_epi32(wi), j),
                        );
                        let idx = _mm256_and_si256(_mm256_min_epi32(j, lastv), inside);
                        (_mm256_and_ps(_mm256_castsi256_ps(inside), one), idx)
                    };
                    let mut num = zero;
                    for c in 0..nch {
                        let (lre, lim) = *lrows.get_unchecked(c);
                        let (rre, rim) = *rrows.get_unchecked(c);
                        let gr = load(rre, base, rel, spread, idx, in_window);
                        let gi = load(rim, base, rel, spread, idx, in_window);
                        let p = _mm256_add_ps(
                            _mm256_mul_ps(_mm256_loadu_ps(lre.as_ptr().add(x)), gr),
                            _mm256_mul_ps(_mm256_loadu_ps(lim.as_ptr().add(x)), gi),
                        );
                        num = _mm256_add_ps(num, p);
                    }
                    let ge = load(re, base, rel, spread, idx, in_window);
                    let n = _mm256_mul_ps(_mm256_mul_ps(two, num), v);
                    let d = _mm256_mul_ps(_mm256_add_ps(lev, ge), v);
                    let e =
                        _mm256_and_ps(_mm256_div_ps(n, d), _mm256_cmp_ps::<_CMP_GT_OQ>(d, zero));
                    let better = _mm256_cmp_ps::<_CMP_GT_OQ>(e, best);
                    best = _mm256_max_ps(best, e);
                    let cand = _mm256_add_ps(dv, _mm256_set1_ps(off));
                    cur = _mm256_blendv_ps(cur, cand, better);
                }
                _mm256_storeu_ps(out.as_mut_ptr().add(x), cur);
            }
            x += LANES;
        }
        // The tail (< 8 pixels), with the scalar operations of `direct_row`.
        for x in x..w {
            let mut best = f32::NEG_INFINITY;
            let mut cur = out[x];
            for (k, &off) in offs.iter().enumerate() {
                // Saturating: `j0` may be i32::MIN / i32::MAX (see above); out of 0..w either way.
                let j = j0[x].saturating_sub(o0 + k as i32);
                let valid = j >= 0 && j < wi;
                let v = if valid { 1.0 } else { 0.0 };
                let jj = if valid { j as usize } else { 0 };
                let mut num = 0.0;
                for c in 0..nch {
                    let (lre, lim) = lrows[c];
                    let (rre, rim) = rrows[c];
                    num += lre[x] * rre[jj] + lim[x] * rim[jj];
                }
                let n = 2.0 * num * v;
                let d = (le[x] + re[jj]) * v;
                let e = if d > 0.0 { n / d } else { 0.0 };
                let better = e > best;
                best = best.max(e);
                if better {
                    cur = drow[x] + off;
                }
            }
            out[x] = cur;
        }
    }
}
