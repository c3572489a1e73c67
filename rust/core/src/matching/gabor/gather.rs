//! Indexed row loads (`out[x] = src[idx[x]]`) for the shifted right responses.
//!
//! The position-shift kernels read the right image at a per-pixel position; as plain indexed
//! loads these loops stayed scalar and dominated the search and the Newton step. With AVX2 they
//! run 8 lanes at a time: a chunk whose indices lie within 16 of their minimum (nearly all of
//! them: the disparity changes slowly along a row) is one or two plain loads and in-register
//! permutations, the rest use the hardware gather. Loads are exact, so both paths give identical
//! results. Indices are clamped to the row (`min(idx, len - 1)`): callers pass in-range indices,
//! the clamp only makes an out-of-range one impossible to turn into an out-of-bounds read.

/// `out[x] = src[min(idx[x], src.len() - 1)]` for `x < min(out.len(), idx.len())`.
#[inline]
pub fn gather(src: &[f32], idx: &[u32], out: &mut [f32]) {
    if src.is_empty() {
        return;
    }
    #[cfg(target_arch = "x86_64")]
    {
        if src.len() <= i32::MAX as usize && std::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 is available (checked above) and `src.len() - 1` fits in an i32.
            unsafe { gather_avx2(src, idx, out) };
            return;
        }
    }
    gather_scalar(src, idx, out, 0);
}

#[inline(always)]
fn gather_scalar(src: &[f32], idx: &[u32], out: &mut [f32], from: usize) {
    let last = src.len() - 1;
    for (o, &i) in out.iter_mut().zip(idx).skip(from) {
        *o = src[(i as usize).min(last)];
    }
}

/// AVX2 building blocks shared with the fused search kernel.
#[cfg(target_arch = "x86_64")]
pub(crate) mod win {
    use std::arch::x86_64::*;

    /// Spread of 8 indices above their minimum that one window load covers.
    pub const NARROW: i32 = 7;
    /// ... and two loads.
    pub const WIDE: i32 = 15;

    /// `(min, idx - min, max - min)` of 8 indices; the spread `max - min` saturates at
    /// `i32::MAX` (it overflowed i32 for indices of both signs: a wrapped, negative spread
    /// would pass as a window). `idx - min` wraps, but only its low 3 bits are used.
    ///
    /// # Safety
    /// AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn window(iv: __m256i) -> (i32, __m256i, i32) {
        let lo = _mm256_min_epi32(iv, _mm256_permute2x128_si256::<1>(iv, iv));
        let lo = _mm256_min_epi32(lo, _mm256_shuffle_epi32::<0b01_00_11_10>(lo));
        let lo = _mm256_min_epi32(lo, _mm256_shuffle_epi32::<0b10_11_00_01>(lo));
        let hi = _mm256_max_epi32(iv, _mm256_permute2x128_si256::<1>(iv, iv));
        let hi = _mm256_max_epi32(hi, _mm256_shuffle_epi32::<0b01_00_11_10>(hi));
        let hi = _mm256_max_epi32(hi, _mm256_shuffle_epi32::<0b10_11_00_01>(hi));
        let (m, x) = (_mm256_cvtsi256_si32(lo), _mm256_cvtsi256_si32(hi));
        (
            m,
            _mm256_sub_epi32(iv, _mm256_set1_epi32(m)),
            x.saturating_sub(m),
        )
    }

    /// `p[rel]` for 8 offsets `rel` in `0..=spread` (`spread <= WIDE`): one load and a
    /// permutation, or two and a blend.
    ///
    /// # Safety
    /// AVX2; `p[0..8]` readable, and `p[0..16]` when `spread > NARROW`.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn load(p: *const f32, rel: __m256i, spread: i32) -> __m256 {
        // SAFETY: the caller guarantees the reads (see above).
        unsafe {
            let lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(p), rel);
            if spread <= NARROW {
                return lo;
            }
            // permutevar uses the low 3 bits of each lane, so `rel` indexes the second load too.
            let hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(p.add(8)), rel);
            let upper = _mm256_cmpgt_epi32(rel, _mm256_set1_epi32(NARROW));
            _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(upper))
        }
    }

    /// Floats a window load of `spread` reads past its start.
    #[inline]
    pub fn reach(spread: i32) -> usize {
        if spread <= NARROW {
            8
        } else {
            16
        }
    }
}

/// # Safety
/// The CPU must support AVX2, `src` must be non-empty with `src.len() - 1 <= i32::MAX`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gather_avx2(src: &[f32], idx: &[u32], out: &mut [f32]) {
    use std::arch::x86_64::{
        __m256i, _mm256_i32gather_ps, _mm256_loadu_si256, _mm256_min_epu32, _mm256_set1_epi32,
        _mm256_storeu_ps,
    };
    const LANES: usize = 8;
    let n = out.len().min(idx.len());
    let len = src.len();
    let maxi = _mm256_set1_epi32((len - 1) as i32);
    let mut x = 0;
    while x + LANES <= n {
        // SAFETY: x + 8 <= n bounds both the 8-lane load of `idx` and the store to `out`; the
        // clamped indices are <= src.len() - 1 (non-negative as i32), so every lane reads `src`.
        // When the 8 clamped indices lie within 16 of their minimum `m` (smooth disparities:
        // nearly every chunk) and the window m..m + reach fits in `src`, the chunk is one or two
        // plain loads and in-register permutations: the hardware gather is several times slower
        // (microcoded on AMD).
        unsafe {
            let iv = _mm256_min_epu32(
                _mm256_loadu_si256(idx.as_ptr().add(x) as *const __m256i),
                maxi,
            );
            let (m, rel, spread) = win::window(iv);
            let v = if spread <= win::WIDE && m as usize + win::reach(spread) <= len {
                win::load(src.as_ptr().add(m as usize), rel, spread)
            } else {
                _mm256_i32gather_ps::<4>(src.as_ptr(), iv)
            };
            _mm256_storeu_ps(out.as_mut_ptr().add(x), v);
        }
        x += LANES;
    }
    gather_scalar(src, idx, out, x);
}

/// `out[x] = a + t[x] (b - a)` with `a = src[i]`, `b = src[i + 1]`, `i = min(idx[x], len - 2)`
/// (`b = a` for a one-sample row): the gather and linear interpolation of a row at sub-pixel
/// positions in one pass, the index work shared by both samples. Same float operations as
/// two [`gather`]s and the interpolation loop, so the same results.
#[inline]
pub fn gather_lerp(src: &[f32], idx: &[u32], t: &[f32], out: &mut [f32]) {
    if src.is_empty() {
        return;
    }
    #[cfg(target_arch = "x86_64")]
    {
        if src.len() >= 2 && src.len() <= i32::MAX as usize && std::is_x86_feature_detected!("avx2")
        {
            // SAFETY: AVX2 is available (checked above), 2 <= src.len() and src.len() - 1 fits in
            // an i32.
            unsafe { gather_lerp_avx2(src, idx, t, out) };
            return;
        }
    }
    gather_lerp_scalar(src, idx, t, out, 0);
}

#[inline(always)]
fn gather_lerp_scalar(src: &[f32], idx: &[u32], t: &[f32], out: &mut [f32], from: usize) {
    let last = src.len() - 1;
    let top = src.len().saturating_sub(2);
    for ((o, &i), &t) in out.iter_mut().zip(idx).zip(t).skip(from) {
        let i = (i as usize).min(top);
        let (a, b) = (src[i], src[(i + 1).min(last)]);
        *o = a + t * (b - a);
    }
}

/// # Safety
/// The CPU must support AVX2, `src.len()` must be in `2..=i32::MAX`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gather_lerp_avx2(src: &[f32], idx: &[u32], t: &[f32], out: &mut [f32]) {
    use std::arch::x86_64::{
        __m256i, _mm256_add_epi32, _mm256_add_ps, _mm256_i32gather_ps, _mm256_loadu_ps,
        _mm256_loadu_si256, _mm256_min_epu32, _mm256_mul_ps, _mm256_set1_epi32, _mm256_storeu_ps,
        _mm256_sub_ps,
    };
    const LANES: usize = 8;
    let n = out.len().min(idx.len()).min(t.len());
    let len = src.len();
    let top = len - 2;
    let maxi = _mm256_set1_epi32(top as i32);
    let one = _mm256_set1_epi32(1);
    let mut x = 0;
    while x + LANES <= n {
        // SAFETY: x + 8 <= n bounds the 8-lane loads of `idx` and `t` and the store to `out`;
        // clamped indices are <= len - 2, so i and i + 1 are in `src`. The window loads read
        // src[m..m + reach + 1], in bounds by the test (see `gather_avx2`).
        unsafe {
            let iv = _mm256_min_epu32(
                _mm256_loadu_si256(idx.as_ptr().add(x) as *const __m256i),
                maxi,
            );
            let (m, rel, spread) = win::window(iv);
            let (a, b) = if spread <= win::WIDE && m as usize + win::reach(spread) < len {
                let p = src.as_ptr().add(m as usize);
                (win::load(p, rel, spread), win::load(p.add(1), rel, spread))
            } else {
                (
                    _mm256_i32gather_ps::<4>(src.as_ptr(), iv),
                    _mm256_i32gather_ps::<4>(src.as_ptr(), _mm256_add_epi32(iv, one)),
                )
            };
            let tv = _mm256_loadu_ps(t.as_ptr().add(x));
            let v = _mm256_add_ps(a, _mm256_mul_ps(tv, _mm256_sub_ps(b, a)));
            _mm256_storeu_ps(out.as_mut_ptr().add(x), v);
        }
        x += LANES;
    }
    gather_lerp_scalar(src, idx, t, out, x);
}

#[cfg(test)]
mod tests {
    #[test]
    fn gathers_and_clamps() {
        let src: Vec<f32> = (0..37).map(|i| i as f32 * 0.5).collect();
        // Scattered, consecutive (the plain-load path) and clamped runs.
        let scattered = (0..29).map(|i| (i * 7 % 41) as u32);
        let runs = (0..24)
            .map(|i| 3 + i as u32)
            .chain((0..16).map(|i| 30 + i as u32));
        // Chunks within an 8-wide window (permuted loads), one running past the end of `src`.
        let windows = [3u32, 3, 5, 4, 9, 10, 6, 8, 31, 33, 36, 36, 35, 30, 29, 36];
        // Two-load windows (spread 8..=15, also descending and ending at the last sample) and
        // one that would read past the end (the gather fallback).
        let wide = [
            10u32, 20, 12, 25, 11, 13, 24, 10, 30, 28, 27, 25, 24, 22, 21, 19, 25, 36, 30, 22, 26,
            33, 29, 21, 27, 36, 30, 29, 28, 33, 35, 36,
        ];
        let all: Vec<u32> = scattered.chain(runs).chain(windows).chain(wide).collect();
        // Every alignment of the patterns to the 8-lane chunks.
        for skip in 0..8 {
            let idx = &all[skip..];
            let mut out = vec![0f32; idx.len()];
            super::gather(&src, idx, &mut out);
            for (o, &i) in out.iter().zip(idx) {
                assert_eq!(*o, src[(i as usize).min(36)]);
            }
        }
    }

    #[test]
    fn gather_lerp_equals_two_gathers_and_the_interpolation() {
        let src: Vec<f32> = (0..41)
            .map(|i| ((i * 37) % 23) as f32 * 0.25 - 1.0)
            .collect();
        let scattered = (0..29).map(|i| (i * 7 % 45) as u32);
        let runs = (0..24)
            .map(|i| 3 + i as u32)
            .chain((0..16).map(|i| 30 + i as u32));
        let windows = [3u32, 3, 5, 4, 9, 10, 6, 8, 31, 33, 39, 39, 38, 30, 29, 40];
        let wide = [
            10u32, 20, 12, 25, 11, 13, 24, 10, 30, 28, 27, 25, 24, 22, 21, 19, 25, 39, 30, 24, 26,
            33, 29, 24, 27, 39, 30, 29, 28, 33, 35, 39,
        ];
        let all: Vec<u32> = scattered.chain(runs).chain(windows).chain(wide).collect();
        let t: Vec<f32> = (0..all.len()).map(|i| (i % 9) as f32 / 8.0).collect();
        for skip in 0..8 {
            let (idx, tt) = (&all[skip..], &t[skip..]);
            let mut out = vec![0f32; idx.len()];
            super::gather_lerp(&src, idx, tt, &mut out);
            for ((o, &i), &t) in out.iter().zip(idx).zip(tt) {
                let i = (i as usize).min(39);
                let (a, b) = (src[i], src[i + 1]);
                assert_eq!(o.to_bits(), (a + t * (b - a)).to_bits(), "index {i}");
            }
        }
        // A one-sample row interpolates between the sample and itself.
        let mut out = [0f32; 9];
        super::gather_lerp(&[2.5], &[0; 9], &[0.5; 9], &mut out);
        assert!(out.iter().all(|&v| v == 2.5));
    }

    #[test]
    fn every_size_equals_the_scalar_loops() {
        // Rows of 1..=70 samples and around 128; index rows of 0..=70 (and 127..=129) entries,
        // `out` shorter, equal and longer; patterns: runs at the left and right ends, spreads
        // 0..=21 (one-load, two-load and gather chunks), indices past the end (clamped). Bit
        // equality with the scalar loops, and `out` untouched past the indices.
        let pats: [fn(usize, usize) -> u32; 7] = [
            |x, _| x as u32,
            |x, len| (len - 1 - x % len) as u32,
            |x, len| (len + 3).saturating_sub(x % 11) as u32,
            |x, _| (x % 8) as u32,
            |x, _| (2 * x) as u32,
            |x, _| (3 * x + x % 5) as u32,
            |x, len| ((x * 7919) % (len + 9)) as u32,
        ];
        for len in (1..=70usize).chain([127, 128, 129]) {
            let src: Vec<f32> = (0..len).map(|i| (i as f32 * 0.37).sin() + 0.01).collect();
            let t: Vec<f32> = (0..140).map(|i| (i % 13) as f32 / 12.0).collect();
            for n in (0..=70usize).chain([127, 128, 129]) {
                for (p, pat) in pats.iter().enumerate() {
                    let idx: Vec<u32> = (0..n).map(|x| pat(x, len)).collect();
                    for n_out in [n.saturating_sub(3), n, n + 5] {
                        let (mut a, mut b) = (vec![-7.0f32; n_out], vec![-7.0f32; n_out]);
                        super::gather(&src, &idx, &mut a);
                        super::gather_scalar(&src, &idx, &mut b, 0);
                        assert_eq!(a, b, "gather len {len} n {n} out {n_out} pattern {p}");
                        let tt = &t[..n.min(t.len())];
                        let (mut a, mut b) = (vec![-7.0f32; n_out], vec![-7.0f32; n_out]);
                        super::gather_lerp(&src, &idx, tt, &mut a);
                        super::gather_lerp_scalar(&src, &idx, tt, &mut b, 0);
                        let same = a.iter().zip(&b).all(|(u, v)| u.to_bits() == v.to_bits());
                        assert!(same, "gather_lerp len {len} n {n} out {n_out} pattern {p}");
                    }
                }
            }
        }
    }
}
