//! Separable, scale-normalised, zero-mean Laplacian of Gaussian (algorithms.md B.3).
//!
//! `K = sigma^2 lap(G) = a(x) g(y) + g(x) a(y)` with `g(t) = exp(-t^2 / 2 sigma^2)` and
//! `a(t) = (t^2 / sigma^2 - 1) g(t) / (2 pi sigma^2)`. The 1-D `a` is made exactly zero-mean on the
//! truncated support (`a <- a - g sum(a) / sum(g)`), so `sum K = sum(a) sum(g) * 2 = 0`: a flat
//! bright area gives no response and no spurious zero crossing. Borders reflect without repeating
//! the edge pixel (OpenCV's BORDER_REFLECT_101). Two row passes (`g`, `a`) and one column pass
//! that sums both products: four 1-D convolutions instead of a `(2r+1)^2` kernel.

// Row kernels index equally long rows in lockstep; index loops are the form LLVM vectorises.
#![allow(clippy::needless_range_loop)]

use crate::alloc::{try_reserve_len, try_zeroed};
use crate::error::Result;
use crate::image::Image;
use crate::parallel::for_each_row;
use crate::simd::simd_fn;

/// Kernel truncation in standard deviations (B.2: radius `ceil(4 sigma)`).
pub const TRUNCATE_SIGMAS: f64 = 4.0;

/// Truncation radius of the LoG of std `sigma`.
pub fn radius_for(sigma: f32) -> usize {
    (TRUNCATE_SIGMAS * sigma as f64).ceil().max(1.0) as usize
}

/// The two 1-D kernels `(g, a)` (taps `-r..=r`), `a` zero-mean on its support.
///
/// A `sigma` that is not in `(0, MAX_SIGMA]` is [`crate::CoreError::InvalidParameter`].
pub fn log_kernels(sigma: f32) -> Result<(Vec<f32>, Vec<f32>)> {
    // Public: a Rust caller reaches it alone. 0 or NaN made the kernels NaN, inf made them
    // empty (callers indexing the centre tap panicked), a huge sigma sized them past memory
    // (an abort): refused here, and so for log_filter too.
    if !(sigma > 0.0 && sigma <= MAX_SIGMA) {
        return Err(crate::CoreError::param(
            "sigma",
            format!("must lie in (0, {MAX_SIGMA}] px, got {sigma}"),
        ));
    }
    let r = radius_for(sigma) as isize;
    let s2 = (sigma as f64) * (sigma as f64);
    let g: Vec<f64> = (-r..=r)
        .map(|t| (-((t * t) as f64) / (2.0 * s2)).exp())
        .collect();
    let norm = 1.0 / (2.0 * std::f64::consts::PI * s2);
    let mut a: Vec<f64> = (-r..=r)
        .zip(&g)
        .map(|(t, gv)| norm * ((t * t) as f64 / s2 - 1.0) * gv)
        .collect();
    let (sa, sg): (f64, f64) = (a.iter().sum(), g.iter().sum());
    for (av, gv) in a.iter_mut().zip(&g) {
        *av -= gv * sa / sg;
    }
    Ok((
        g.iter().map(|&v| v as f32).collect(),
        a.iter().map(|&v| v as f32).collect(),
    ))
}

/// Reflect-101 index of `i` in `0..n` (folds repeatedly for kernels wider than the image).
#[inline]
pub fn reflect(mut i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let n = n as isize;
    loop {
        if i < 0 {
            i = -i;
        } else if i >= n {
            i = 2 * (n - 1) - i;
        } else {
            return i as usize;
        }
    }
}

simd_fn! {
    /// `og[x] = sum_j g[j] p[x + j]`, `oa[x] = sum_j a[j] p[x + j]` over a padded row (symmetric
    /// kernels: centre tap, then pairs), for `x` in `0..og.len()`.
    fn row_pass(p: &[f32], g: &[f32], a: &[f32], og: &mut [f32], oa: &mut [f32]) {
        let w = og.len();
        let r = g.len() / 2;
        let oa = &mut oa[..w];
        let c = &p[r..r + w];
        for x in 0..w {
            og[x] = g[r] * c[x];
            oa[x] = a[r] * c[x];
        }
        for j in 1..=r {
            let lo = &p[r - j..r - j + w];
            let hi = &p[r + j..r + j + w];
            let (gj, aj) = (g[r + j], a[r + j]);
            for x in 0..w {
                let s = lo[x] + hi[x];
                og[x] += gj * s;
                oa[x] += aj * s;
            }
        }
    }
}

simd_fn! {
    /// `out += k * (lo + hi)` (one symmetric tap pair of the column pass).
    fn col_tap(out: &mut [f32], k: f32, lo: &[f32], hi: &[f32]) {
        let w = out.len();
        let (lo, hi) = (&lo[..w], &hi[..w]);
        for x in 0..w {
            out[x] += k * (lo[x] + hi[x]);
        }
    }
}

/// Largest `sigma` of [`log_filter`] (px): the largest nominal channel the matcher takes.
pub const MAX_SIGMA: f32 = 64.0;

/// `L = I (*) K_sigma` (float32, same size as the image).
///
/// A failed allocation of its planes is [`crate::CoreError::OutOfMemory`]; a `sigma` that is
/// not in `(0, MAX_SIGMA]` is [`crate::CoreError::InvalidParameter`].
pub fn log_filter(img: &Image, sigma: f32) -> Result<Vec<f32>> {
    // The binding and the matcher bound sigma before calling; a Rust caller reaches this
    // alone: log_kernels refuses a sigma outside (0, MAX_SIGMA] before anything is sized.
    let (g, a) = log_kernels(sigma)?;
    let (w, h) = img.size();
    let r = g.len() / 2;
    // Row passes: hg = I *_x g, ha = I *_x a.
    let mut hg = try_zeroed::<f32>(w * h, "a LoG plane of the MCGM matcher")?;
    let mut ha = try_zeroed::<f32>(w * h, "a LoG plane of the MCGM matcher")?;
    // A row's padded copy is allocated checked (`with_capacity` aborted the process); the
    // first failure is recorded and returned before the column pass.
    let failed = std::sync::Mutex::new(None);
    crate::parallel::for_each_row2(&mut hg, &mut ha, w, |y, og, oa| {
        let src = &img.data[y * w..(y + 1) * w];
        // The padded row: reflected borders around a copy of the row (no reflect per pixel).
        let mut p: Vec<f32> = Vec::new();
        if let Err(e) = try_reserve_len(&mut p, w + 2 * r, "a LoG row of the MCGM matcher") {
            let mut f = failed.lock().unwrap_or_else(|p| p.into_inner());
            f.get_or_insert(e);
            return;
        }
        p.extend((-(r as isize)..0).map(|i| src[reflect(i, w)]));
        p.extend_from_slice(src);
        p.extend((w as isize..(w + r) as isize).map(|i| src[reflect(i, w)]));
        row_pass(&p, &g, &a, og, oa);
    });
    if let Some(e) = failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    // Column pass: L = ha *_y g + hg *_y a.
    let mut out = try_zeroed::<f32>(w * h, "a LoG plane of the MCGM matcher")?;
    for_each_row(&mut out, w, |y, o| {
        let rows = |i: isize| {
            let yy = reflect(i, h);
            yy * w..(yy + 1) * w
        };
        // Row slices: a loop without index checks, which the compiler vectorises.
        let (har, hgr) = (&ha[y * w..(y + 1) * w], &hg[y * w..(y + 1) * w]);
        for x in 0..w {
            o[x] = g[r] * har[x] + a[r] * hgr[x];
        }
        for j in 1..=r {
            let (ylo, yhi) = (y as isize - j as isize, y as isize + j as isize);
            col_tap(o, g[r + j], &ha[rows(ylo)], &ha[rows(yhi)]);
            col_tap(o, a[r + j], &hg[rows(ylo)], &hg[rows(yhi)]);
        }
    });
    Ok(out)
}

/// 2x2 mean decimation (floor of odd sizes; at least 1x1): pixel `(i, j)` of the result is the
/// mean of full-resolution pixels `(2i..2i+1, 2j..2j+1)`, centred at `(2i + 0.5, 2j + 0.5)`.
pub fn decimate2(img: &Image) -> Result<Image> {
    let (w, h) = img.size();
    let (w2, h2) = ((w / 2).max(1), (h / 2).max(1));
    let mut data = try_zeroed::<f32>(w2 * h2, "the MCGM matcher's half-resolution image")?;
    for_each_row(&mut data, w2, |y, o| {
        let y0 = (2 * y).min(h - 1);
        let y1 = (2 * y + 1).min(h - 1);
        for (x, v) in o.iter_mut().enumerate() {
            let x0 = (2 * x).min(w - 1);
            let x1 = (2 * x + 1).min(w - 1);
            *v = 0.25 * (img.at(x0, y0) + img.at(x1, y0) + img.at(x0, y1) + img.at(x1, y1));
        }
    });
    Ok(Image {
        width: w2,
        height: h2,
        data,
    })
}
