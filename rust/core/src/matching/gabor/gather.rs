//! Indexed row loads (`out[x] = src[idx[x]]`) for the shifted right responses.
//!
//! The position-shift kernels read the right image at a per-pixel position; as plain indexed
//! loads these loops stayed scalar and dominated the search and the Newton step. With AVX2 they
//! use the hardware gather, 8 lanes at a time. Loads are exact, so both paths give identical
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

/// # Safety
/// The CPU must support AVX2, `src` must be non-empty with `src.len() - 1 <= i32::MAX`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gather_avx2(src: &[f32], idx: &[u32], out: &mut [f32]) {
    use std::arch::x86_64::{
        __m256i, _mm256_add_epi32, _mm256_castsi256_ps, _mm256_cmpeq_epi32, _mm256_i32gather_ps,
        _mm256_loadu_ps, _mm256_loadu_si256, _mm256_min_epu32, _mm256_movemask_ps,
        _mm256_set1_epi32, _mm256_setr_epi32, _mm256_storeu_ps,
    };
    const LANES: usize = 8;
    let n = out.len().min(idx.len());
    let maxi = _mm256_set1_epi32((src.len() - 1) as i32);
    let ramp = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let mut x = 0;
    while x + LANES <= n {
        // SAFETY: x + 8 <= n bounds both the 8-lane load of `idx` and the store to `out`; the
        // clamped indices are <= src.len() - 1 (non-negative as i32), so every lane reads `src`.
        // A run of 8 consecutive clamped indices i..i+7 (smooth disparities: most chunks) is read
        // with one plain load, in bounds because i + 7 is itself a clamped index.
        unsafe {
            let iv = _mm256_loadu_si256(idx.as_ptr().add(x) as *const __m256i);
            let iv = _mm256_min_epu32(iv, maxi);
            let first = (*idx.get_unchecked(x) as usize).min(src.len() - 1);
            let run = _mm256_add_epi32(_mm256_set1_epi32(first as i32), ramp);
            let same = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(iv, run)));
            let v = if same == 0xff {
                _mm256_loadu_ps(src.as_ptr().add(first))
            } else {
                _mm256_i32gather_ps::<4>(src.as_ptr(), iv)
            };
            _mm256_storeu_ps(out.as_mut_ptr().add(x), v);
        }
        x += LANES;
    }
    gather_scalar(src, idx, out, x);
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
        let idx: Vec<u32> = scattered.chain(runs).collect();
        let mut out = vec![0f32; idx.len()];
        super::gather(&src, &idx, &mut out);
        for (o, &i) in out.iter().zip(&idx) {
            assert_eq!(*o, src[(i as usize).min(36)]);
        }
    }
}
